"""Strand dynamics speed: simulated frames per second of :func:`hairtool.simulate.dynamics.simulate`.

Each groom runs the CLI's default set-up (head turn, 8 substeps, 24 fps, head collisions) with
two gusts for ``--frames`` frames; frame 0 is the rest pose, so ``sim_fps`` counts frames − 1.
The numpy twin (:func:`~hairtool.simulate.dynamics.simulate_reference`) runs the same set-up for
``--reference-frames`` frames in the same run, up to ``--reference-limit`` vertices.
"""

from __future__ import annotations

import argparse

from hairtool.bench import add_common_arguments

HELP = "hair dynamics: simulated frames per second (numba) against the numpy twin"

DEFAULT_GROOMS = ["2000x24", "10000x24"]
QUICK_GROOMS = ["100x8"]


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--frames", type=int, help="frames per run, frame 0 the rest (default 49, quick 6)")
    parser.add_argument("--substeps", type=int, default=8, help="solver steps per frame (default 8)")
    parser.add_argument("--reference-frames", type=int, help="frames of the numpy twin (default 5, quick 3)")
    parser.add_argument(
        "--reference-limit", type=int, default=250_000, help="skip the numpy twin above this many vertices"
    )
    add_common_arguments(parser, quick="a 100x8 scalp, 6 frames, one run", repeat=3, grooms=DEFAULT_GROOMS)


def run(args: argparse.Namespace) -> list[dict]:
    from hairtool.bench import grooms, median_ms, ratio, setup, threads
    from hairtool.errors import ParameterError
    from hairtool.samples import scalp
    from hairtool.simulate.dynamics import simulate, simulate_reference

    repeat = setup(args)
    frames = (6 if args.quick else 49) if args.frames is None else args.frames
    ref_frames = (3 if args.quick else 5) if args.reference_frames is None else args.reference_frames
    if frames < 2 or ref_frames < 2:
        raise ParameterError("frames", min(frames, ref_frames), "at least 2 (frame 0 is the rest pose)")
    setup_kw = {"motion": "turn", "substeps": args.substeps, "fps": 24.0, "gusts": 2}
    simulate(scalp(20, 4), frames=3, **setup_kw)  # compile (or load) the kernel outside the timings
    rows = []
    for name, groom, _ in grooms(args.grooms or (QUICK_GROOMS if args.quick else DEFAULT_GROOMS)):
        ms = median_ms(lambda g=groom: simulate(g, frames=frames, **setup_kw), repeat, warmup=0)
        row = {
            "groom": name,
            "strands": groom.strand_count,
            "vertices": groom.vertex_count,
            "frames": frames,
            "substeps": args.substeps,
            "sim_ms": ms,
            "ms_per_frame": ms / (frames - 1),
            "sim_fps": (frames - 1) / (ms / 1e3),
            "reference_fps": None,
        }
        if groom.vertex_count <= args.reference_limit:
            ref_ms = median_ms(
                lambda g=groom: simulate_reference(g, frames=ref_frames, **setup_kw), 1, warmup=0
            )
            row["reference_fps"] = (ref_frames - 1) / (ref_ms / 1e3)
        row["speedup"] = ratio(row["sim_fps"], row["reference_fps"])
        row["threads"] = threads()
        rows.append(row)
    return rows
