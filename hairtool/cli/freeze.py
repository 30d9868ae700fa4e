"""Give a groom the frozen-hair look (Kim 2026): FreezeDeform → UserAlign → ClumpWithGaps.

Align samples (--align, repeatable) are applied in order, like mouse moves in the studio.
With --count (children grown from the input as guides) or --from-dense --guides G (guides picked
from the input), the pipeline runs on the guides and OUT receives the render strands
interpolated from the frozen guides (see ``hairtool interpolate``).

Freeze styles one pose. An animation IN is refused unless --frame F names the pose to style
(0 = the first): freezing every frame would clump and align each pose on its own, so the locks
would jump from frame to frame; style the rest pose, then simulate or cycle it. OUT is a static
groom in IN's space, unit and prims (no frame range).
"""

from __future__ import annotations

import argparse
import json
import math

from hairtool.cli import _guides

HELP = "freeze a groom: stiff stretch/bend noise, cursor alignment, clumping with gaps"


def _point(text: str) -> tuple[float, float, float]:
    parts = text.split(",")
    try:
        values = [float(p) for p in parts]
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected X,Y,Z numbers, got {text!r}") from None
    if len(values) == 2:
        values.append(0.0)
    if len(values) != 3:
        raise argparse.ArgumentTypeError(f"expected X,Y,Z, got {text!r}")
    return values[0], values[1], values[2]


def _radius(text: str) -> float | None:
    if text == "auto":
        return None
    try:
        return float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a distance or 'auto', got {text!r}") from None


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("input", metavar="IN", help="groom to read (.tfx, .hair, .usd*, .npz, .obj)")
    parser.add_argument("output", metavar="OUT", help="groom to write (.hair, .usd*, .npz, .obj)")
    parser.add_argument(
        "--frame",
        type=int,
        default=None,
        metavar="F",
        help="the pose of an animation IN to freeze (0 = first)",
    )
    f = parser.add_argument_group("stylised noise (FreezeDeform, eqs. 2–7)")
    f.add_argument(
        "--stretch-stiffness",
        type=float,
        default=7.0,
        help="stiffness (stretch) k_s ≥ 1: lengths vary by ±1/k_s",
    )
    f.add_argument(
        "--bend-stiffness", type=float, default=7.0, help="stiffness (bend) k_b > 0: bends up to θ_max/k_b"
    )
    f.add_argument(
        "--max-bend-angle", type=float, default=30.0, help="max bend angle θ_max in degrees, [0, 180]"
    )
    f.add_argument("--seed", type=int, default=0, help="random seed of the noise (same seed, same bytes)")
    f.add_argument(
        "--strand-variation",
        type=float,
        default=0.0,
        help="stiffness variation between strands in [0, 4]: ×2^±spread",
    )
    f.add_argument("--no-freeze", action="store_true", help="no stylised noise")
    parser.add_argument(
        "--strokes",
        metavar="STROKES.json",
        help="replay a stroke log (align, comb, smooth, length, puff, clump, mask, delete, pinch, "
        "snake_hook, slide, add, density; the studio exports one) after the --align cursors",
    )
    a = parser.add_argument_group("align brush (UserAlign, eqs. 8–13)")
    a.add_argument(
        "--align",
        type=_point,
        action="append",
        default=[],
        metavar="X,Y,Z",
        help="brush position (repeatable: a drag)",
    )
    a.add_argument(
        "--radius", type=float, default=None, help="brush size r: tips this close turn (default: groom size)"
    )
    a.add_argument(
        "--intensity", type=float, default=0.8, help="strength x in [0, 1]: 1 turns strands like rods"
    )
    a.add_argument(
        "--align-mode",
        choices=["paper", "preserve-length"],
        default="paper",
        help="follow the cursor as printed (eq. 13; strands may stretch), or keep strand lengths",
    )
    c = parser.add_argument_group("clumps (ClumpWithGaps, eqs. 14–19)")
    c.add_argument(
        "--clump-radius", type=_radius, default=None, help="clump size h, or 'auto' (2× median root spacing)"
    )
    c.add_argument("--clump-iterations", type=int, default=3, help="clump passes k in [0, 100]")
    c.add_argument(
        "--clump-step",
        type=float,
        default=None,
        help="clump strength Δt²/m (default: 0.2·h over the mean kernel weight)",
    )
    c.add_argument(
        "--gap-mode",
        choices=["printed", "text", "off"],
        default="printed",
        help="keep gaps between clumps: sharp edges (eqs. 17–19 as printed), soft (as described), or none",
    )
    c.add_argument("--no-clump", action="store_true", help="no clumps")
    c.add_argument(
        "--keep-lengths",
        action="store_true",
        help="give every segment back its length after clumping (default: as printed, lengths stretch)",
    )
    _guides.add_arguments(parser, seed=False)
    parser.add_argument(
        "--prim",
        action="append",
        default=None,
        metavar="PATH",
        help="the curve prim to freeze (repeatable; a glob such as '/root/*/Brows*'); each prim is "
        "frozen as a groom of its own, and the prims not picked are written as they were (default: all)",
    )
    parser.add_argument("--json", action="store_true", help="print timings and sizes as JSON")


def _surface(args: argparse.Namespace, strokes):
    """The head (``--scalp`` and its ``--scalp-up-axis``, also without ``--count``) that strokes
    and align cursors collide with and slide strokes slide on, as ``(path, up axis)`` to read in
    the groom's frame (:func:`_head`), or None; a log with slide strokes and no ``--scalp`` is
    refused before any work."""
    from hairtool.errors import ParameterError
    from hairtool.frozen.brushes import NEED_SURFACE

    needs = sorted({s.brush for s in strokes or () if getattr(s, "brush", None) in NEED_SURFACE})
    if needs and args.scalp is None:
        raise ParameterError("scalp", None, f"a head mesh (--scalp MESH) for {', '.join(needs)} strokes")
    if args.scalp is None or not (strokes or args.align):
        return None
    from hairtool.guides.scalp_file import check_up_axis

    head = (args.scalp, args.scalp_up_axis)
    check_up_axis(*head)
    if not _guides.wanted(args):
        args.scalp = args.scalp_up_axis = None  # the surface's only: no children to grow on it
    return head


def _head(head, groom):
    """The :func:`_surface` head read in ``groom``'s frame and checked to lie at its roots."""
    if head is None:
        return None
    from hairtool.guides.planting import HeadSurface
    from hairtool.guides.scalp_file import load_scalp

    return HeadSurface(load_scalp(head[0], groom, head[1]))


def _pose(args: argparse.Namespace):
    """The groom to freeze: IN, or the ``--frame`` pose of an animation IN (which is refused
    without it), as a static groom without the animation's frame range."""
    from hairtool import io
    from hairtool.errors import ParameterError
    from hairtool.groom import Animation

    obj = io.read(args.input)
    frames = obj.n_frames if isinstance(obj, Animation) else 1
    if args.frame is None and frames > 1:
        raise ParameterError(
            "frame",
            None,
            f"the pose to freeze: {args.input} is an animation of {frames} frames (--frame 0…{frames - 1})",
        )
    f = 0 if args.frame is None else args.frame
    if not 0 <= f < frames:
        raise ParameterError("frame", f, f"a frame of {args.input} in [0, {frames - 1}]")
    if not isinstance(obj, Animation):
        return obj
    pose = obj.frame(f)
    return pose.with_metadata(pose.metadata.derived())


def _one_prim(args: argparse.Namespace, groom):
    """Render hair grows from one prim's guides at a time: with several hair prims, ``--prim``
    must pick one, and only its render hair is written (said before any work)."""
    from hairtool.errors import ParameterError
    from hairtool.prims import picked, split

    hair = [g for g in split(groom) if all(c.purpose != "guide" for c in g.metadata.curves)]
    if not _guides.wanted(args) or len(split(groom)) != len(hair):
        if args.prim and len(split(groom)) != len(hair):
            expected = "no --prim: the input holds render hair and its guides"
            raise ParameterError("prim", args.prim[0], expected)
        return groom
    chosen = [g for g, pick in zip(split(groom), picked(groom, args.prim), strict=True) if pick]
    if len(chosen) != 1:
        paths = ", ".join(c.path for g in chosen for c in g.metadata.curves)
        expected = f"--prim picking one prim to grow render hair from ({paths}); OUT holds its hair"
        raise ParameterError("prim", args.prim, expected)
    return chosen[0]


def run(args: argparse.Namespace) -> int:
    import numpy as np

    from hairtool import io
    from hairtool.errors import ParameterError
    from hairtool.frozen.compile_plan import pipeline_kernels
    from hairtool.frozen.pipeline import FrozenParams, FrozenPipeline

    params = FrozenParams(
        stretch_stiffness=args.stretch_stiffness,
        bend_stiffness=args.bend_stiffness,
        max_bend_angle=math.radians(args.max_bend_angle),
        seed=args.seed,
        strand_variation=args.strand_variation,
        freeze=not args.no_freeze,
        clump=not args.no_clump,
        clump_radius=args.clump_radius,
        clump_iterations=args.clump_iterations,
        clump_step=args.clump_step,
        gap_mode=args.gap_mode,
        keep_lengths=args.keep_lengths,
    )
    if not math.isfinite(args.max_bend_angle) or not 0 <= args.max_bend_angle <= 180:
        raise ParameterError("max-bend-angle", args.max_bend_angle, "degrees in [0, 180]")
    params.validate()
    from hairtool.frozen.align import check_align_params

    check_align_params(
        (0.0, 0.0, 0.0), 1.0 if args.radius is None else args.radius, args.intensity, args.align_mode
    )
    strokes = None
    if args.strokes is not None:
        from hairtool.frozen.strokes import read_strokes

        strokes = read_strokes(args.strokes)  # a bad log is refused before any work
    head = _surface(args, strokes)
    _guides.check(args)
    io.format_for(args.output, writing=True)  # refuse an unwritable extension before working
    pose = _pose(args)
    surface = _head(head, pose)
    # With render hair (asked for, or the input's own), the pipeline runs on the guides.
    groom, binding, bind_ms = _guides.prepare(args, _one_prim(args, pose))
    lo, hi = groom.bounds
    radius = float(np.linalg.norm(hi - lo)) if args.radius is None else args.radius
    timings: list[dict] = []
    pipes: list[FrozenPipeline] = []
    changed: list[tuple] = []  # (prim, its strands before, the pipeline) where strokes planted or removed

    def freeze(part):
        pipe = FrozenPipeline(part, params, surface)
        timings.append(pipe.timings)
        for cursor in args.align:
            pipe.align(cursor, radius, args.intensity, args.align_mode)
            timings.append(pipe.timings)
        for stroke in strokes or ():
            pipe.apply_samples(stroke.pipeline_samples(float(pipe.scalp_centre[0])))
            timings.append(pipe.timings)
        pipe.settle()  # the result of the whole groom's clumping, as the studio's after a release
        pipes.append(pipe)
        prims = part.metadata.for_strands(part.strand_count).curves
        if len(prims) == 1 and not np.array_equal(pipe.origin, np.arange(part.strand_count)):
            changed.append((prims[0], part, pipe))
        return pipe.result

    emptied = []
    # A small groom runs the serial kernels; on a cold cache a second process compiles some
    with pipeline_kernels(groom.vertex_count):
        if binding is None and groom is pose:  # each prim a groom of its own (hairtool.prims)
            from hairtool.prims import per_prim, split

            several = len(split(groom)) > 1

            def freeze_or_empty(part):
                """A prim whose strands a stroke deleted, every one, is kept empty (as Blender keeps
                an empty Curves object) where the scene holds other prims."""
                from hairtool.frozen.brushes.delete import EveryStrandGone

                try:
                    return freeze(part)
                except EveryStrandGone:
                    if not several:
                        raise
                    emptied.extend(part.metadata.curves)
                    return None

            result = per_prim(groom, freeze_or_empty, args.prim)
        else:
            result = freeze(groom)
    pipe = pipes[0] if pipes else None
    report = {}
    pairs = _guides.primvar_pairs(groom, binding)  # (the source's guides: before strokes change them)
    if binding is not None and not np.array_equal(pipe.origin, np.arange(groom.strand_count)):
        pairs = []  # guides planted or removed: the children follow other guides than the source's
        # add, delete or density strokes: the children follow the guides planted and removed
        from hairtool.guides.follow import follow_guides, guides_now

        origin = pipe.origin
        binding = follow_guides(binding, guides_now(groom, pipe.aligned, origin), origin, pipe.surface)
    if binding is not None:
        hair = _guides.render(args, binding).update(pipe.result)
        report = _guides.write(args, hair, pipe.result)
        report |= {"guides": groom.strand_count, "children": binding.child_count, "bind_ms": bind_ms}
    else:
        io.write(args.output, result)
    from hairtool.io.usd_carry import keep_emptied

    if emptied:
        import sys

        kept = keep_emptied(args.input, args.output, emptied)
        for prim in emptied:
            how = "kept empty" if prim.path in kept else "left out (the format holds no empty prim)"
            print(
                f"hairtool freeze: info: the strokes deleted every strand of {prim.path}; it is {how}",
                file=sys.stderr,
            )
    # USD to USD: the scene beside the hair, the guide prim's primvars on the children
    _guides.carry(args, pairs)
    if changed and binding is not None:  # the written guides' primvars (just below) on the children
        _guides.carry_planted(args, changed, _guides.primvar_pairs(pipe.result, binding, written=True))
    elif changed:
        _guides.carry_planted(args, changed)
    if args.json:
        one = len(pipes) == 1
        report |= {
            "strands": groom.strand_count,
            "result_strands": result.strand_count,  # after add, delete and density strokes
            "vertices": groom.vertex_count,
            # per prim where the input had several (hairtool.prims)
            "clump_radius": pipe.clump_radius if one else [q.clump_radius for q in pipes],
            "mean_neighbours": pipe.mean_neighbours if one else [q.mean_neighbours for q in pipes],
            "timings_ms": timings,
        }
        print(json.dumps(report, indent=1))
    return 0
