"""Motion-capture key-frame speed on the captures in ``shared/data/motion`` (seed 003's data).

Per capture: reading the BVH; joint-position and quaternion features; seed 003's quaternion
cost table (:func:`~hairtool.mocap.costs.rotation_cost_table`, O(F³J)); the exact DP for K = a tenth
of the frames (with the error curve up to 100 keys) on that table, in numba and in its numpy
twin; and the default path of ``hairtool keys CAPTURE.bvh``: position features → Gram cost
table → DP. The quaternion table's numpy twin is a Python loop over the pairs, so both run
on the first ``--reference-frames`` frames for ``reference_over_table``.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from hairtool.bench import MOTION_DIR, add_common_arguments

HELP = "mocap keys: BVH read, features, quaternion cost table, DP, against the numpy twins"

QUICK_CAPTURE = "freebvh.bvh"
#: Slow numbers (the whole quaternion table of a long take) stop repeating after this many seconds.
BUDGET_S = 5.0


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "captures", nargs="*", type=Path, help=f"BVH files (default: every .bvh in {MOTION_DIR})"
    )
    parser.add_argument(
        "--reference-frames", type=int, help="frames both quaternion tables run on (default 60, quick 20)"
    )
    add_common_arguments(parser, quick=f"{QUICK_CAPTURE} only, 20 reference frames, one run", repeat=5)


def _captures(args: argparse.Namespace) -> list[Path]:
    from hairtool.errors import ParameterError

    if args.captures:
        return args.captures
    if args.quick:
        return [MOTION_DIR / QUICK_CAPTURE]
    paths = sorted(MOTION_DIR.glob("*.bvh"))
    if not paths:
        raise ParameterError("captures", str(MOTION_DIR), "a folder with .bvh files")
    return paths


def run(args: argparse.Namespace) -> list[dict]:
    from hairtool.bench import median_ms, ratio, setup, threads
    from hairtool.errors import ParameterError
    from hairtool.keys.costs import cost_table
    from hairtool.keys.dp import select_keys
    from hairtool.mocap.bvh import read_bvh
    from hairtool.mocap.costs import motion_features, rotation_cost_table, rotation_cost_table_reference

    repeat = setup(args)
    n_ref = (20 if args.quick else 60) if args.reference_frames is None else args.reference_frames
    if n_ref < 3:
        raise ParameterError("reference-frames", n_ref, "at least 3")
    rows = []
    for path in _captures(args):
        motion = read_bvh(path)
        n = motion.n_frames
        head = motion.with_values(motion.values[: min(n, n_ref)])
        rotation_cost_table(head)  # compile (or load) the kernels outside the timings
        kept: dict = {}  # the first timed run's table, so a long take's table is built once

        def full_table(m=motion, kept=kept):
            kept["table"] = rotation_cost_table(m)

        table_ms = median_ms(full_table, repeat, warmup=0, max_time=BUDGET_S)
        k = max(2, n // 10)

        def select(c=kept["table"], k=k, numba=True):
            return select_keys(c, keys=k, use_numba=numba)

        def positions_keys(m=motion, k=k):
            return select_keys(cost_table(motion_features(m, "positions")), keys=k)

        head_ms = median_ms(lambda h=head: rotation_cost_table(h), repeat)
        reference_ms = median_ms(lambda h=head: rotation_cost_table_reference(h), 1, warmup=0)
        rows.append(
            {
                "capture": path.stem,
                "frames": n,
                "joints": motion.n_joints,
                "read_ms": median_ms(lambda p=path: read_bvh(p), repeat),
                "features_ms": median_ms(lambda m=motion: motion_features(m, "positions"), repeat),
                "quat_features_ms": median_ms(lambda m=motion: motion_features(m, "rotations"), repeat),
                "table_ms": table_ms,
                "keys": k,
                "select_ms": median_ms(select, repeat),
                "select_numpy_ms": median_ms(lambda: select(numba=False), repeat, max_time=BUDGET_S),
                "positions_keys_ms": median_ms(positions_keys, repeat),
                "reference_frames": head.n_frames,
                "head_table_ms": head_ms,
                "head_reference_ms": reference_ms,
                "reference_over_table": ratio(reference_ms, head_ms),
                "threads": threads(),
            }
        )
    return rows
