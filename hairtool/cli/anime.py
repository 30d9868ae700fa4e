"""Periodic anime hair motion (Furukawa & Nakata 2018): the limited-animation schedule of a wave
cycle and, given a groom, the cycle itself.

Without IN, prints only the schedule: frames per cycle, pictures, their holds, Δt and the
exposure sheet (which picture shows on each frame; frames and pictures count from 0). With IN,
every strand (or every --guides chain with the strands nearest to it) is posed by the wave
f(x,t) = −(a/s)(x/π)^p (cos(x/k − 2πt/T) + 1/s) at each picture time and the pictures are held
as the sheet says; OUT receives the animation (formats without time samples keep frame 0).

IN is a groom or animation file (its first frame is the rest pose) or a built-in sample:
sample:NAME[:STRANDS[:VERTICES]] with NAME one of portrait (2-D), scalp (3-D), comb, e.g.
sample:portrait or sample:scalp:500:24.

Render hair: with --count N (children grown from IN as guides, on --scalp if given) or
--from-dense --guides G (G guides picked from a dense IN: --guides is then a number, and every
guide is a chain of its own), the guides wave and OUT receives the children following them
frame by frame; in USD with the guides as a second prim of purpose "guide", elsewhere with the
guides animation in --guides-out (default OUT.guides.EXT).
"""

from __future__ import annotations

import argparse
import json

from hairtool.cli import _guides
from hairtool.cli._character import BVH_HELP, CHAIN_PATTERN_HELP, run_anime
from hairtool.cli._inputs import GROOM_INPUT_HELP, parse_vector
from hairtool.errors import ParameterError
from hairtool.io.specs import load_groom

HELP = "anime hair cycles: limited-animation schedule, wave poses, errors against a reference"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.formatter_class = argparse.RawDescriptionHelpFormatter
    parser.add_argument("input", nargs="?", metavar="IN", help=GROOM_INPUT_HELP)
    parser.add_argument("output", nargs="?", metavar="OUT", help="write the animation here (.npz, .usda, …)")
    t = parser.add_argument_group("timing")
    t.add_argument("--period", type=float, default=0.45, help="cycle length T in seconds (default 0.45)")
    t.add_argument("--fps", type=float, default=24.0, help="frames per second, N_FPS (default 24)")
    t.add_argument(
        "--hold", type=int, default=2, help="frames each drawing is held, N_Dup: 2 = on twos (default 2)"
    )
    t.add_argument("--cycles", type=int, default=1, help="how many cycles the shot repeats (default 1)")
    t.add_argument("--frames", type=int, help="shot length in frames (overrides --cycles)")
    w = parser.add_argument_group("swing (the wave f(x, t), eq. (1))")
    w.add_argument("--amplitude", type=float, default=0.8, help="swing size a (default 0.8)")
    w.add_argument("--wavelength", type=float, default=1.0, help="wave length k > 0 (default 1)")
    w.add_argument("--gravity", type=float, default=1.2, help="weight s ≠ 0: sag a/s² (default 1.2)")
    w.add_argument("--profile", type=float, default=1.0, help="whip toward the tip p ≥ 0 (default 1)")
    b = parser.add_argument_group("bunches")
    b.add_argument(
        "--guides",
        help="chain strand ids, e.g. 0,5,10-13; other strands follow the nearest "
        "(with --from-dense: the number G of guides to pick)",
    )
    b.add_argument(
        "--sway", help="x,y,z direction positive wave y bends toward (default the scene's up: 0,1,0 or 0,0,1)"
    )
    b.add_argument("--phase-spread", type=float, default=0.25, help="random phase per bunch, in cycles [0,1]")
    b.add_argument("--amplitude-spread", type=float, default=0.1, help="random amplitude scale 1±this [0,1]")
    b.add_argument(
        "--seed", type=int, default=0, help="seed of the per-bunch draws and of the children (default 0)"
    )
    o = parser.add_argument_group("output")
    o.add_argument("--compare", metavar="REF", help="report angular and position errors against REF")
    o.add_argument("--export-sheet", metavar="CSV", help="write the exposure sheet: frame, picture, time")
    o.add_argument("--json", action="store_true", help="print a JSON object")
    o.add_argument(
        "--chains", metavar="PATTERN", help=f"IN a .vrm/.glb/.gltf character: {CHAIN_PATTERN_HELP}"
    )
    o.add_argument("--bvh", metavar="BVH", help=BVH_HELP)
    _guides.add_arguments(parser, seed=False, guides=False)


def parse_ids(text: str) -> list[int]:
    """``"0,5,10-13"`` → [0, 5, 10, 11, 12, 13]."""
    ids: list[int] = []
    try:
        for part in text.split(","):
            lo, sep, hi = part.strip().partition("-")
            ids.extend(range(int(lo), int(hi) + 1) if sep else [int(lo)])
    except ValueError:
        raise ParameterError("guides", text, "strand ids like 0,5,10-13") from None
    if not ids:
        raise ParameterError("guides", text, "strand ids like 0,5,10-13")
    return ids


def _dense_guides(text: str | None) -> int | None:
    """``--guides`` with ``--from-dense``: a whole number of guides to pick."""
    if text is None:
        return None
    try:
        return int(text)
    except ValueError:
        raise ParameterError("guides", text, "a whole number of guides to pick with --from-dense") from None


def run(args: argparse.Namespace) -> int:
    from hairtool.anime.schedule import schedule, write_sheet
    from hairtool.anime.wave import WaveParams, cycle_animation
    from hairtool.character.read import is_character_path

    if args.input is not None and is_character_path(args.input):
        return run_anime(args)
    for flag in ("chains", "bvh"):
        if getattr(args, flag) is not None:
            raise ParameterError(flag, getattr(args, flag), "a .vrm, .glb or .gltf character as IN")

    params = WaveParams(args.amplitude, args.wavelength, args.gravity, args.profile, args.period)
    sched = schedule(args.period, args.fps, args.hold)
    if args.frames is None:
        if args.cycles < 1:
            raise ParameterError("cycles", args.cycles, "a whole number ≥ 1")
        shot = args.cycles * sched.n_frames
    else:
        shot = args.frames
    report = sched.to_dict(shot)
    report["wave"] = {
        "amplitude": params.amplitude,
        "wavelength": params.wavelength,
        "gravity": params.gravity,
        "profile": params.profile,
        "period": params.period,
    }
    render = _guides.wanted(args)
    chains = args.guides
    if args.from_dense:
        args.guides, chains = _dense_guides(args.guides), None
    if args.input is None:
        for flag in ("output", "compare"):
            if getattr(args, flag) is not None:
                raise ParameterError(flag, getattr(args, flag), "an IN groom to make the cycle from")
        if render:
            raise ParameterError("count", args.count, "an IN groom and an OUT file for render hair")
        _guides.check(args, guides_option=False, input_hair=False)  # render-hair options alone: refused
    else:
        from hairtool.io import format_for

        if args.output is not None:
            out_fmt = format_for(args.output, writing=True)  # refuse a bad extension before posing
        if render and args.output is None:
            raise ParameterError("count", args.count, "an OUT file to write the render hair to")
        _guides.check(args, animated=True, guides_option=False)
        # With render hair (asked for, or the input's own), the guides wave; a preview of the
        # cycle without OUT writes none.
        writes = args.output is not None
        groom, binding, bind_ms = _guides.prepare(args, load_groom(args.input), keep_hair=writes)
        render = binding is not None
        variation = {
            "guides": None if chains is None else parse_ids(chains),
            "sway": None if args.sway is None else parse_vector("sway", args.sway),
            "amplitude_spread": args.amplitude_spread,
            "phase_spread": args.phase_spread,
            "seed": args.seed,
        }
        anim = cycle_animation(groom, params, fps=args.fps, hold=args.hold, frames=shot, **variation)
        report.update(input=args.input, strands=anim.strand_count, vertices=anim.vertex_count)
        if args.compare is not None:
            from hairtool.anime.metrics import compare_cycle
            from hairtool.io import read

            report["compare"] = {
                "reference": args.compare,
                **compare_cycle(anim, read(args.compare)).to_dict(),
            }
        if args.output is not None and render:
            report.update(_guides.write_animation(args, binding, anim), bind_ms=round(bind_ms, 2))
            report["output_frames"] = anim.n_frames if out_fmt.animated else 1
        elif args.output is not None:
            from hairtool.io import write

            write(args.output, anim)
            report["output"] = args.output
            report["output_frames"] = anim.n_frames if out_fmt.animated else 1
        if args.output is not None:  # USD to USD: the scene beside the hair, primvars on children
            _guides.carry(args, _guides.primvar_pairs(groom, binding) if render else [])
    if args.export_sheet is not None:
        write_sheet(args.export_sheet, sched, shot)
        report["sheet"] = args.export_sheet
    if args.json:
        print(json.dumps(report))
    else:
        print(_text(report))
    return 0


def _text(r: dict) -> str:
    lines = [
        f"cycle: T = {r['period']:g} s at {r['fps']:g} fps, hold {r['hold']} -> "
        f"{r['n_frames']} frames ({r['cycle_seconds']:.4g} s), {r['n_pictures']} pictures, "
        f"dt = {r['dt']:.6g} s, K = {r['k']}",
        "holds: " + " ".join(str(h) for h in r["holds"]),
        f"exposure ({r['shot_frames']} frames): " + " ".join(str(p) for p in r["exposure"]),
    ]
    if "strands" in r:
        lines.append(f"posed {r['strands']} strands, {r['vertices']} vertices from {r['input']}")
    if "compare" in r:
        c = r["compare"]
        lines.append(
            f"vs {c['reference']}: angular error {c['angular_error_deg']:.3f} deg, "
            f"position error {c['position_error_pct']:.3f} % over {c['frames_compared']} frame(s)"
        )
    if "children" in r:
        lines.append(f"render hair: {r['children']} children following {r['guides']} guides")
    if "output" in r:
        lines.append(f"wrote {r['output']} ({r['output_frames']} frame(s))")
    if "guides_output" in r:
        lines.append(f"wrote the guides to {r['guides_output']}")
    if "sheet" in r:
        lines.append(f"wrote exposure sheet {r['sheet']}")
    return "\n".join(lines)
