"""Grow render strands from guide curves: children scattered on a scalp mesh (or around the guide
roots), each following its k nearest guides; or, with --from-dense, pick G guides from a dense
groom and bind every strand to them (the render strands then give back the dense groom).

The render strands go to OUT; with --from-dense the guides go to --guides-out (default:
OUT with ".guides" before the extension).

An animated IN (time-sampled points, or hair under a moving parent) gives animated render
hair: the children grow once from the guides of the first frame and follow their guides'
motion frame by frame with the same weights, at IN's time codes (its range kept); --frame F
writes the children of frame F alone (static). --from-dense on an animation needs --frame.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

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
    parser.add_argument(
        "--frame",
        type=int,
        default=None,
        metavar="F",
        help="of an animated IN, grow the children of this frame alone (0 = the first) and write "
        "them static (default: children following every frame)",
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
    out, used, report, pairs = [], [], {"guides": 0, "children": 0}, []
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
        pairs += _guides.primvar_pairs(guides, binding)
        report["guides"] += guides.strand_count
        report["children"] += binding.child_count
    io.write(args.output, concat(out))
    _guides.carry(args, pairs)
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


def _animated(args: argparse.Namespace, anim) -> dict:
    """Children of an animated groom: grown from each picked prim's first-frame guides, following
    them every frame (:mod:`hairtool.guides.animated_prims`); the prims not picked pass through
    with their motion. A dense groom's guides are picked from one pose: ``--frame`` is asked."""
    import copy

    from hairtool import io
    from hairtool.errors import ParameterError
    from hairtool.guides.animate import RenderHairAnimation
    from hairtool.guides.animated_prims import JoinedFrames, split_animation
    from hairtool.guides.files import AnimationWithGuides, split_guides
    from hairtool.guides.prim_bindings import OnRenderPrim
    from hairtool.prims import picked, shares

    if args.from_dense:
        raise ParameterError(
            "frame", None, f"the pose to pick guides from: {args.input} is an animation of "
            f"{anim.n_frames} frames (--frame 0…{anim.n_frames - 1})",
        )  # fmt: skip
    rest = anim.rest
    report = {"guides": 0, "children": 0, "frames": anim.n_frames}
    guide_prims = split_guides(anim)[1]
    if guide_prims is not None or len(split_animation(anim)) == 1:
        guides, binding, _ = _guides.prepare(args, rest)
        moving = anim if guide_prims is None else guide_prims
        report |= _guides.write_animation(args, binding, moving)
        _guides.carry(args, _guides.primvar_pairs(guides, binding))
        return report | {"guides": guides.strand_count, "children": binding.child_count}
    parts, chosen = split_animation(anim), picked(rest, args.prim)
    counts = iter(shares(args.count, [p.strand_count for p, c in zip(parts, chosen, strict=True) if c]))
    usd_out = _guides.is_usd(args.output)
    out, moved, pairs = [], [], []
    for part, pick in zip(parts, chosen, strict=True):
        if not pick:
            out.append(part)
            continue
        one = copy.copy(args)
        one.count = next(counts)
        guides, binding, _ = _guides.prepare(one, part.rest)
        hair = RenderHairAnimation(binding, part, _guides.render(one, binding).clump)
        out.append(AnimationWithGuides(hair) if usd_out else OnRenderPrim(hair))
        moved.append(part)
        pairs += _guides.primvar_pairs(guides, binding)
        report["guides"] += guides.strand_count
        report["children"] += binding.child_count
    joined = JoinedFrames(out)
    if usd_out:
        from hairtool.io import usd

        usd.write(Path(args.output), joined)
    else:
        io.write(args.output, joined.animation())
    if args.guides_out or not usd_out:
        io.write(_guides.guides_path(args), JoinedFrames(moved).animation())
    _guides.carry(args, pairs)
    return report


def run(args: argparse.Namespace) -> int:
    from hairtool.cli._inputs import read_frames
    from hairtool.groom import Animation
    from hairtool.prims import picked, split

    _guides.check(args, required=True, animated=True)
    source = read_frames(args.input, args.frame)
    if isinstance(source, Animation) and source.n_frames > 1:
        report = _animated(args, source)
        if args.json:
            print(json.dumps({"output": str(args.output), **report}, indent=1))
        return 0
    if isinstance(source, Animation):
        source = source.rest
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
    _guides.carry(args, _guides.primvar_pairs(guides, binding))
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
