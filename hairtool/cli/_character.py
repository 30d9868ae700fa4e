"""The character paths of ``hairtool anime`` and ``hairtool simulate``: a ``.vrm``, ``.glb`` or
``.gltf`` IN poses its hair chains and OUT receives the character with the animation."""

from __future__ import annotations

import argparse
import json

from hairtool.errors import ParameterError

DEFAULT_FRAMES = 120  # hairtool simulate's --frames and --fps when neither IN's animation nor the user says
DEFAULT_FPS = 24.0
CHAIN_PATTERN_HELP = "a regular expression on node names picking the hair chains (default: the VRM springs)"
BVH_HELP = "IN a character: also write its hair chains' motion as BVH here"


def _refuse(args: argparse.Namespace, command: str, used: set[str]) -> None:
    """Options of ``command`` a character does not use, given other than their defaults, are
    refused rather than ignored."""
    from hairtool.cli import command_parser

    parser = command_parser(command)
    for action in parser._actions:
        dest = action.dest
        if dest in used or dest in ("help", "input", "output") or not hasattr(args, dest):
            continue
        if getattr(args, dest) != action.default:
            flag = action.option_strings[-1] if action.option_strings else dest
            raise ParameterError(
                flag.lstrip("-"),
                getattr(args, dest),
                f"no value: hairtool {command} does not use it for a character",
            )


ANIME_OPTIONS = {
    "period",
    "fps",
    "hold",
    "cycles",
    "frames",
    "amplitude",
    "wavelength",
    "gravity",
    "profile",
    "phase_spread",
    "amplitude_spread",
    "seed",
    "compare",
    "json",
    "chains",
    "bvh",
    "export_sheet",
    "command",
    "_run",
}
SIMULATE_OPTIONS = {
    "motion",
    "frames",
    "fps",
    "substeps",
    "json",
    "springs",
    "chains",
    "bvh",
    "command",
    "_run",
}


def _print(args: argparse.Namespace, report: dict) -> None:
    if args.json:
        print(json.dumps(report, indent=2))
        return
    for key, value in report.items():
        if not isinstance(value, (list, dict)):
            print(f"{key}: {value}")


def _write_bvh(args: argparse.Namespace, character, rotations, report: dict) -> None:
    if getattr(args, "bvh", None) is None:
        return
    from hairtool.character.bvh import write_chains_bvh

    write_chains_bvh(args.bvh, character, rotations, args.fps)
    report["bvh"] = args.bvh


def run_anime(args: argparse.Namespace) -> int:
    """``hairtool anime CHARACTER OUT``: the cycle on the chains, STEP keys at the drawings."""
    from hairtool.anime.pose import bunch_variation
    from hairtool.anime.wave import WaveParams
    from hairtool.character.compare import compare_motions
    from hairtool.character.cycle import ChainWave, character_cycle
    from hairtool.character.export import write_animated
    from hairtool.character.read import load_character
    from hairtool.character.springs import head_shake, simulate

    _refuse(args, "anime", ANIME_OPTIONS)
    character = load_character(args.input, getattr(args, "chains", None))
    params = WaveParams(args.amplitude, args.wavelength, args.gravity, args.profile, args.period)
    scale, phase = bunch_variation(len(character.chains), args.amplitude_spread, args.phase_spread, args.seed)
    waves = {
        c: ChainWave(amplitude_scale=float(scale[c]), phase=float(phase[c]))
        for c in range(len(character.chains))
    }
    cyc = character_cycle(character, params, fps=args.fps, hold=args.hold, waves=waves)
    shot = args.frames if args.frames is not None else args.cycles * cyc.schedule.n_frames
    if args.frames is None and args.cycles < 1:
        raise ParameterError("cycles", args.cycles, "a whole number ≥ 1")
    frames = cyc.frames(shot)
    report = {"character": args.input, "chains": len(character.chains), **cyc.schedule.to_dict(shot)}
    report.pop("exposure")
    if args.export_sheet is not None:
        from hairtool.anime.schedule import write_sheet

        write_sheet(args.export_sheet, cyc.schedule, shot)
        report["sheet"] = args.export_sheet
    if args.compare is not None:
        if args.compare != "springs":
            raise ParameterError(
                "compare", args.compare, "'springs' for a character: its spring bones on a head shake"
            )
        driver = head_shake(character, shot, args.fps)
        report["compare_springs"] = compare_motions(character, frames, simulate(character, driver, args.fps))
    if args.output is not None:
        loop = shot if shot % cyc.schedule.n_frames == 0 else None
        rest = character.nodes.rotation
        report["written"] = write_animated(
            args.input, args.output, frames, rest, args.fps, name="anime cycle", step=True, loop_frames=loop
        )
    _write_bvh(args, character, frames, report)
    _print(args, report)
    return 0


def _animation_driver(args: argparse.Namespace, character, name: str):
    """The character's own animation (``name``, or its last) sampled at ``--fps`` (default its
    own rate) for ``--frames`` (default its length; later frames hold its last pose)."""
    import numpy as np

    clips = character.clips
    if not clips:
        raise ParameterError("motion", args.motion, f"an animation in {args.input} (it has none)")
    if name:
        found = [c for c in clips if c.name == name]
        if not found:
            names = ", ".join(repr(c.name) for c in clips)
            raise ParameterError(
                "motion", args.motion, f"animation:NAME with a NAME of {args.input}: {names}"
            )
        clip = found[-1]
    else:
        clip = clips[-1]
    args.fps = clip.frame_rate() if args.fps is None else args.fps
    if not np.isfinite(args.fps) or args.fps <= 0:
        raise ParameterError("fps", args.fps, "a positive frame rate")
    frames = round(clip.duration * args.fps) + 1 if args.frames is None else args.frames
    if frames < 1:
        raise ParameterError("frames", frames, "at least 1 frame")
    args.frames = frames
    return np.stack([clip.sample(character.nodes, f / args.fps) for f in range(frames)])


def run_springs(args: argparse.Namespace) -> int:
    """``hairtool simulate CHARACTER OUT --springs``: VRM spring bones on a head shake or turn, or
    driven by the character's own animation; LINEAR keys."""
    from hairtool.character.export import write_animated
    from hairtool.character.read import load_character
    from hairtool.character.springs import head_shake, simulate

    if not args.springs:
        raise ParameterError("springs", False, "--springs for a character (its VRM spring bones)")
    _refuse(args, "simulate", SIMULATE_OPTIONS)
    character = load_character(args.input, getattr(args, "chains", None))
    motion = args.motion
    if motion == "animation" or motion.startswith("animation:"):
        driver = _animation_driver(args, character, motion.partition(":")[2])
    elif motion in ("shake", "turn", "still"):
        args.frames = DEFAULT_FRAMES if args.frames is None else args.frames
        args.fps = DEFAULT_FPS if args.fps is None else args.fps
        turn = 0.0 if motion == "still" else 30.0
        period = 1.0 if motion == "shake" else args.frames / args.fps * 2
        driver = head_shake(character, args.frames, args.fps, turn_deg=turn, period=period)
    else:
        raise ParameterError("motion", motion, "shake, turn, still or animation[:NAME] for a character")
    rotations = simulate(character, driver, args.fps, 1 if args.substeps is None else args.substeps)
    report = {"character": args.input, "chains": len(character.chains), "motion": motion}
    report["written"] = write_animated(
        args.input,
        args.output,
        rotations,
        character.nodes.rotation,
        args.fps,
        name="spring bones",
        step=False,
    )
    _write_bvh(args, character, rotations, report)
    _print(args, report)
    return 0
