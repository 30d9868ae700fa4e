"""Grow render strands from guide curves: children scattered on a scalp mesh (or around the guide
roots), each following its k nearest guides; or, with --from-dense, pick G guides from a dense
groom and bind every strand to them (the render strands then give back the dense groom).

The render strands go to OUT; with --from-dense the guides go to --guides-out (default:
OUT with ".guides" before the extension).
"""

from __future__ import annotations

import argparse
import json
import time

from hairtool.cli import _guides
from hairtool.cli._inputs import GROOM_INPUT_HELP

HELP = "grow render strands (children) from guide curves, or pick guides from a dense groom"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "input", metavar="GUIDES", help=f"guides ({GROOM_INPUT_HELP}); with --from-dense the dense groom"
    )
    parser.add_argument("output", metavar="OUT", help="render strands to write (.hair, .usd*, .npz, .obj)")
    _guides.add_arguments(parser)
    parser.add_argument("--json", action="store_true", help="print sizes and timings as JSON")


def run(args: argparse.Namespace) -> int:
    from hairtool.io.specs import load_groom

    _guides.check(args, required=True)
    guides, binding, bind_ms = _guides.prepare(args, load_groom(args.input))
    hair = _guides.render(args, binding)
    t0 = time.perf_counter()
    out = hair.update(guides)
    build_ms = (time.perf_counter() - t0) * 1e3
    report = _guides.write(args, out, guides)
    if args.json:
        report |= {
            "guides": guides.strand_count,
            "children": binding.child_count,
            "vertices": binding.vertex_count,
            "guides_per_child": binding.guides_per_child,
            "bind_ms": bind_ms,
            "interpolate_ms": build_ms,
        }
        print(json.dumps(report, indent=1))
    return 0
