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
    parser.add_argument(
        "--prim",
        action="append",
        default=None,
        metavar="PATH",
        help="the curve prim to grow children from (repeatable; a glob). Each prim's children follow "
        "its guides alone and go to a render prim of its own; the prims not picked are written as "
        "they were (default: all)",
    )
    parser.add_argument("--json", action="store_true", help="print sizes and timings as JSON")


def _several(args: argparse.Namespace, groom) -> dict:
    """Several hair prims (hair and eyebrows): the children of each picked prim grow from its
    guides alone and go to its own render prim (``--count`` shared in proportion to the
    guides); the prims not picked are written as they were."""
    import copy

    from hairtool import io
    from hairtool.guides.files import with_guides
    from hairtool.prims import concat, picked, shares, split

    parts, chosen = split(groom), picked(groom, args.prim)
    counts = iter(shares(args.count, [g.strand_count for g, c in zip(parts, chosen, strict=True) if c]))
    out, used, report = [], [], {"guides": 0, "children": 0}
    for part, pick in zip(parts, chosen, strict=True):
        if not pick:
            out.append(part)
            continue
        one = copy.copy(args)
        one.count = next(counts)
        guides, binding, _ = _guides.prepare(one, part)
        hair = _guides.render(one, binding).update(guides)
        out.append(with_guides(hair, guides) if _guides.is_usd(args.output) else hair)
        used.append(guides)
        report["guides"] += guides.strand_count
        report["children"] += binding.child_count
    io.write(args.output, concat(out))
    from hairtool.io.usd_carry import carry_between

    carry_between(args.input, args.output)  # USD to USD: the scene beside the hair
    if args.guides_out:
        io.write(_guides.guides_path(args), concat(used))
    return report


def _one_prim(args: argparse.Namespace, groom):
    """A scalp mesh or a dense groom belongs to one prim: with several, ``--prim`` picks it."""
    from hairtool.errors import ParameterError
    from hairtool.prims import picked, split

    chosen = [g for g, c in zip(split(groom), picked(groom, args.prim), strict=True) if c]
    if len(chosen) != 1:
        flag = "--scalp" if args.scalp is not None else "--from-dense"
        paths = ", ".join(c.path for g in chosen for c in g.metadata.curves)
        raise ParameterError(
            "prim", args.prim, f"--prim picking one prim for {flag} ({paths}); OUT holds its hair"
        )
    return chosen[0]


def run(args: argparse.Namespace) -> int:
    from hairtool.io.specs import load_groom
    from hairtool.prims import picked, split

    _guides.check(args, required=True)
    source = load_groom(args.input)
    several = len(split(source)) > 1 and all(c.purpose != "guide" for c in source.metadata.curves)
    if several and not (args.scalp or args.from_dense):
        report = _several(args, source)
        if args.json:
            print(json.dumps({"output": str(args.output), **report}, indent=1))
        return 0
    if several:
        source = _one_prim(args, source)
    elif args.prim:
        picked(source, args.prim)  # (a pattern that picks nothing is refused)
    guides, binding, bind_ms = _guides.prepare(args, source)
    hair = _guides.render(args, binding)
    t0 = time.perf_counter()
    out = hair.update(guides)
    build_ms = (time.perf_counter() - t0) * 1e3
    report = _guides.write(args, out, guides)
    from hairtool.io.usd_carry import carry_between

    carry_between(args.input, args.output)  # USD to USD: the scene beside the hair
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
