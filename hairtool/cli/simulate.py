"""Simulate strand dynamics on a moving head and write the animation.

Inextensible strands by dynamic follow-the-leader (Müller et al. 2012): roots follow the head,
the hair swings, falls and catches wind; seeded gusts make short events for key-frame tests.
Motions (comma-separated, played in equal slots): still, turn, nod, shake, hop.

IN is a groom or animation file (its first frame is the rest pose) or a built-in sample:
sample:NAME[:STRANDS[:VERTICES]] with NAME portrait, scalp or comb, e.g. sample:scalp:500:24.
An animated IN (time-sampled points, or hair under a moving parent, such as a head nodded by an
armature) drives the simulation with its own motion, as Blender's hair dynamics follow their
emitter: the roots follow IN's roots every frame and the head moves with their rigid motion;
--motion is then refused, and --frames and --fps default to IN's (its time codes kept).
Space: the groom's own (a USD stage's up axis and metersPerUnit; Y-up centimetres for
formats that say nothing; the samples' head has radius 1 at the origin, 1 unit = 10 cm).
Gravity is in m/s² along the stage's −up; turn and shake are about the up axis, nod about
the lateral (x) axis; wind and gusts are in scene units/s². For a real groom, --fit-head fits
the head sphere to its roots and reads wind and gusts in head radii/s², so the defaults move
any groom as they move the samples. OUT keeps IN's up axis, unit, prim paths, basis, widths
and colours: a simulation of /root/Head/Hair/HairData writes /root/Head/Hair/HairData.

Render hair: with --count N (children grown from IN as guides, on --scalp if given) or
--from-dense --guides G (guides picked from a dense IN), the guides are simulated and OUT
receives the children following them frame by frame (see ``hairtool interpolate``); in USD
with the guides as a second prim of purpose "guide", elsewhere with the guides animation in
--guides-out (default OUT.guides.EXT).
"""

from __future__ import annotations

import argparse
import json
import time

from hairtool.cli import _guides
from hairtool.cli._character import BVH_HELP, CHAIN_PATTERN_HELP, DEFAULT_FPS, DEFAULT_FRAMES, run_springs
from hairtool.cli._inputs import GROOM_INPUT_HELP, parse_vector

HELP = "simulate hair dynamics on a moving head (turn, nod, shake, hop, wind gusts)"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    from hairtool.simulate.dynamics import GRAVITY

    parser.formatter_class = argparse.RawDescriptionHelpFormatter
    parser.add_argument("input", metavar="IN", help=GROOM_INPUT_HELP)
    parser.add_argument("output", metavar="OUT", help="animation file (.npz, .usda, …; others keep frame 0)")
    m = parser.add_argument_group("motion")
    m.add_argument(
        "--motion",
        default=None,
        help="still, turn, nod, shake, hop, comma-separated (default turn; an animated IN moves by itself); "
        "a character: shake, turn, still, or animation[:NAME] (its own animation, the last one unless NAME)",
    )
    m.add_argument(
        "--frames",
        type=int,
        default=None,
        help="frames to write (default 120, or an animated IN's; a character's animation: its length)",
    )
    m.add_argument(
        "--fps",
        type=float,
        default=None,
        help="frames per second (default 24, or an animated IN's; a character's animation: its own rate)",
    )
    m.add_argument(
        "--substeps",
        type=int,
        help="solver steps per frame (default 8; 1 for a character's spring bones, as viewers step them)",
    )
    f = parser.add_argument_group("forces")
    f.add_argument(
        "--gravity", type=float, default=GRAVITY, help=f"m/s² along the scene's −up (default {GRAVITY})"
    )
    f.add_argument("--damping", type=float, default=2.0, help="velocity decay per second (default 2)")
    f.add_argument("--stiffness", type=float, default=0.05, help="pull toward the styled shape, 0..1/frame")
    f.add_argument("--wind", metavar="X,Y,Z", help="constant wind acceleration, units/s²")
    f.add_argument("--gusts", type=int, default=0, help="number of seeded wind gusts (default 0)")
    f.add_argument("--gust-strength", type=float, default=300.0, help="gust peak, units/s² (default 300)")
    f.add_argument("--gust-duration", type=float, default=0.25, help="seconds per gust (default 0.25)")
    f.add_argument("--seed", type=int, default=0, help="seed of the gusts and of the children (default 0)")
    h = parser.add_argument_group("head")
    h.add_argument("--no-collide", action="store_true", help="let strands pass through the head sphere")
    h.add_argument("--head-center", metavar="X,Y,Z", help="head sphere centre (default 0,0,0)")
    h.add_argument("--head-radius", type=float, help="head sphere radius (default 1)")
    h.add_argument(
        "--fit-head",
        action="store_true",
        help="fit the head sphere to the roots, and read wind and gusts in head radii/s², "
        "so a groom of any scale moves as the samples do (instead of --head-center/--head-radius)",
    )
    _guides.add_arguments(parser, seed=False)
    parser.add_argument("--json", action="store_true", help="print a JSON object")
    c = parser.add_argument_group("character (IN a .vrm, .glb or .gltf: motion shake, turn or still)")
    c.add_argument("--springs", action="store_true", help="swing the hair chains by their VRM spring bones")
    c.add_argument("--chains", metavar="PATTERN", help=CHAIN_PATTERN_HELP)
    c.add_argument("--bvh", metavar="BVH", help=BVH_HELP)


def _driver(args: argparse.Namespace, source):
    """For an animated IN: its own motion drives the roots (said in one line on stderr), and
    --frames and --fps default to IN's; a named --motion beside it, or a dense groom to pick
    guides from, is refused. None for a static IN (--frames 120 and --fps 24 by default)."""
    import sys

    from hairtool.errors import ParameterError
    from hairtool.groom import Animation

    if not isinstance(source, Animation) or source.n_frames < 2:
        args.frames = DEFAULT_FRAMES if args.frames is None else args.frames
        args.fps = DEFAULT_FPS if args.fps is None else args.fps
        return None
    if args.motion is not None:
        raise ParameterError(
            "motion", args.motion, f"none: {args.input} is animated ({source.n_frames} frames) and its "
            "own root motion drives the hair (convert one frame to a static file to play a named motion)",
        )  # fmt: skip
    if args.from_dense:
        raise ParameterError(
            "from-dense", True, f"a static IN: {args.input} is animated (--count N grows children)"
        )
    args.frames = source.n_frames if args.frames is None else args.frames
    args.fps = source.fps if args.fps is None else args.fps
    codes = source.time_codes
    print(
        f"hairtool simulate: info: {args.input} is animated (time codes {codes[0]:g}…{codes[-1]:g}): "
        "the roots follow its roots every frame and the head moves with them, as hair dynamics "
        "follow their emitter",
        file=sys.stderr,
    )
    return True


def _driver_of(source, groom):
    """The root driver of the strands simulated (``groom``: IN's strands or its guides)."""
    from hairtool.guides.files import split_guides
    from hairtool.simulate.driver import RootDriver

    guides = split_guides(source)[1]
    moving = source if guides is None or groom.strand_count != guides.strand_count else guides
    return RootDriver(moving)


def run(args: argparse.Namespace) -> int:
    import numpy as np

    from hairtool.character.read import is_character_path

    if is_character_path(args.input):
        args.motion = "turn" if args.motion is None else args.motion
        return run_springs(args)  # --frames and --fps: its animation's, else the defaults

    from hairtool.cli._inputs import read_frames
    from hairtool.errors import ParameterError
    from hairtool.groom import Animation
    from hairtool.io import format_for, write
    from hairtool.simulate.dynamics import scaled_accelerations, simulate
    from hairtool.simulate.head_motion import fit_head, parse_motion

    for flag in ("springs", "chains", "bvh"):
        if getattr(args, flag):
            raise ParameterError(flag, getattr(args, flag), "a .vrm, .glb or .gltf character as IN")
    fmt = format_for(args.output, writing=True)  # refuse a bad extension before simulating
    _guides.check(args, animated=True)
    source = read_frames(args.input, None)
    driver = _driver(args, source)
    motion = parse_motion("turn" if args.motion is None else args.motion) if driver is None else "source"
    wind = parse_vector("wind", args.wind) if args.wind is not None else (0.0, 0.0, 0.0)
    # With render hair (asked for, or the input's own), the guides are simulated.
    rest = source.rest if isinstance(source, Animation) else source
    groom, binding, bind_ms = _guides.prepare(args, rest)
    if driver is not None:
        driver = _driver_of(source, groom)
    render = binding is not None
    if args.fit_head:
        if args.head_center is not None or args.head_radius is not None:
            raise ParameterError("fit-head", "with --head-center/--head-radius", "one or the other")
        centre, radius = fit_head(groom.roots)
        scale = radius  # accelerations were given for a head of radius 1
    else:
        centre = parse_vector("head-center", args.head_center or "0,0,0")
        radius = 1.0 if args.head_radius is None else args.head_radius
        scale = 1.0
    forces = scaled_accelerations(scale, args.gust_strength, wind)
    w = np.asarray(forces["wind"])
    strength = float(np.linalg.norm(w))
    wind_arg = None if args.wind is None else (w if strength > 0 else (0.0, 0.0, 1.0), strength)
    t0 = time.perf_counter()
    anim = simulate(
        groom,
        motion="still" if driver is not None else motion,
        driver=driver,
        frames=args.frames,
        fps=args.fps,
        substeps=8 if args.substeps is None else args.substeps,
        gravity=args.gravity,
        damping=args.damping,
        stiffness=args.stiffness,
        wind=wind_arg,
        gusts=args.gusts,
        gust_strength=forces["gust_strength"],
        gust_duration=args.gust_duration,
        collide=not args.no_collide,
        head_center=centre,
        head_radius=radius,
        seed=args.seed,
    )
    seconds = time.perf_counter() - t0
    extra = {}
    if render:
        extra = _guides.write_animation(args, binding, anim) | {"bind_ms": round(bind_ms, 2)}
    else:
        write(args.output, anim)
    _guides.carry(args, _guides.primvar_pairs(groom, binding))  # USD to USD: the scene beside the hair
    report = {
        **extra,
        "output": args.output,
        "animated": fmt.animated,
        "frames": anim.n_frames,
        "fps": anim.fps,
        "strands": anim.strand_count,
        "vertices": anim.vertex_count,
        "motion": motion,
        "gusts": args.gusts,
        "seed": args.seed,
        "head_center": [round(float(v), 6) for v in centre],
        "head_radius": round(float(radius), 6),
        "seconds": round(seconds, 4),
        "frames_per_second": round((anim.n_frames - 1) / seconds, 2) if anim.n_frames > 1 else None,
    }
    if args.json:
        print(json.dumps(report, indent=1))
    else:
        kept = "" if fmt.animated else " (this format keeps frame 0 only)"
        what = f"{anim.strand_count} strands"
        if render:
            what = f"{binding.child_count} render strands following {anim.strand_count} guides"
            if "guides_output" in extra:
                what += f" (guides in {extra['guides_output']})"
        print(
            f"wrote {args.output}{kept}: {anim.n_frames} frames at {anim.fps:g} fps, "
            f"{what}; simulated in {seconds:.2f} s"
        )
    return 0
