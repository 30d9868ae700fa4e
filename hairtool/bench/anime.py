"""Anime hair cycle speed: the whole cycle per frame, and the numba pose kernel against its numpy twin.

Each groom is posed with the paper's Fig. 2 wave (T 0.45 s at 24 fps on twos: 11 frames, 6
pictures), every strand its own bunch. ``cycle_ms``: :func:`hairtool.anime.wave.cycle_animation`
end to end (bunches, poses, holds, the Animation); ``pose_ms`` and ``pose_numpy_ms``: the
pictures alone through ``pose_numba`` and ``pose_reference`` in the same run.
"""

from __future__ import annotations

import argparse

from hairtool.bench import add_common_arguments

HELP = "anime cycles: generation time per frame and the numba pose against its numpy twin"

DEFAULT_GROOMS = ["2000x24", "20000x24", "sample:portrait"]
QUICK_GROOMS = ["100x8", "sample:portrait:20:10"]


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--fps", type=float, default=24.0, help="frames per second (default 24)")
    parser.add_argument("--hold", type=int, default=2, help="frames per picture (default 2, on twos)")
    add_common_arguments(
        parser, quick="a 100x8 scalp and a small portrait, one run", repeat=7, grooms=DEFAULT_GROOMS
    )


def run(args: argparse.Namespace) -> list[dict]:
    from hairtool.anime.schedule import schedule
    from hairtool.anime.wave import WaveParams, cycle_animation, make_bunches, pose_pictures
    from hairtool.bench import grooms, median_ms, ratio, setup, threads
    from hairtool.samples import scalp

    repeat = setup(args)
    params = WaveParams()
    sched = schedule(params.period, args.fps, args.hold)
    times = sched.picture_times
    cycle_animation(scalp(10, 4), params, fps=args.fps, hold=args.hold)  # compile or load the kernel
    rows = []
    for name, groom, _ in grooms(args.grooms or (QUICK_GROOMS if args.quick else DEFAULT_GROOMS)):
        bunches = make_bunches(groom)
        cycle_ms = median_ms(lambda g=groom: cycle_animation(g, params, fps=args.fps, hold=args.hold), repeat)
        pose_ms = median_ms(lambda g=groom, b=bunches: pose_pictures(g, params, times, b), repeat)
        numpy_ms = median_ms(
            lambda g=groom, b=bunches: pose_pictures(g, params, times, b, use_numba=False), repeat
        )
        rows.append(
            {
                "groom": name,
                "strands": groom.strand_count,
                "vertices": groom.vertex_count,
                "frames": sched.n_frames,
                "pictures": sched.n_pictures,
                "cycle_ms": cycle_ms,
                "ms_per_frame": cycle_ms / sched.n_frames,
                "pose_ms": pose_ms,
                "pose_numpy_ms": numpy_ms,
                "numpy_over_numba": ratio(numpy_ms, pose_ms),
                "threads": threads(),
            }
        )
    return rows
