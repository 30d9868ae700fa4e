"""Keyframe selection speed: features, the Gram cost table and the all-K DP, against the direct
O(n³D) table (where it finishes in a minute) and one float64 X @ X.T of the same matrix.

Feature arrays are random walks, except D = 96,000 which is a swaying hair animation of 2,000
strands resampled to 16 points (the features step is timed there). After the rows of the chosen
interpolation come, for the sizes up to 3,000 dimensions, the other objectives and
interpolations: the worst-frame objective, fitted Hermite handles, and the total and worst-frame
objectives with ten pinned and ten excluded frames (``constrained``, with ``constraint_overhead``
against the same table without them), each a table plus the all-K DP; and seed
003's quaternion-distance table (objective ``quaternion``, interp ``slerp``, dims = joints) of a
real capture of that many frames, the 1,064-frame PyMO walk (23 joints) played forward and back.
Tables and DPs are the median of ``--repeat`` runs (features and the direct table: one).
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from hairtool.errors import ParameterError

HELP = "keyframes: cost table + DP for all K vs the direct O(n^3 D) table and one X @ X.T"

SIZES = ((300, 69), (1300, 69), (1000, 3000), (1000, 96000))
QUICK = ((40, 6), (120, 48))
DIRECT_LIMIT_S = 60.0
HAIR_SAMPLES = 16


def add_arguments(parser: argparse.ArgumentParser) -> None:
    from hairtool.bench import add_common_arguments

    parser.add_argument("--sizes", help="comma-separated FRAMESxDIMS, e.g. 300x69,1300x69")
    parser.add_argument("--max-keys", type=int, default=100, help="DP for every K up to this")
    parser.add_argument("--interp", choices=("linear", "hermite"), default="linear")
    parser.add_argument("--no-direct", action="store_true", help="skip the direct O(n^3 D) table")
    add_common_arguments(parser, quick="tiny sizes (for tests)", repeat=3)


def _parse_sizes(text: str) -> list[tuple[int, int]]:
    out = []
    for part in text.split(","):
        try:
            n, d = (int(v) for v in part.lower().split("x"))
        except ValueError:
            raise ParameterError("sizes", text, "comma-separated FRAMESxDIMS like 300x69") from None
        if n < 3 or d < 1:
            raise ParameterError("sizes", part, "at least 3 frames and 1 dimension")
        out.append((n, d))
    return out


def _features(n: int, d: int) -> tuple[np.ndarray, float | None]:
    """Frame features and the seconds spent computing them (None for a raw random walk)."""
    if d >= 48_000 and d % (3 * HAIR_SAMPLES) == 0:
        from hairtool import samples
        from hairtool.keys.features import FeatureOptions, hair_features
        from hairtool.simulate.sway import sway_animation

        anim = sway_animation(samples.scalp(d // (3 * HAIR_SAMPLES), 24, seed=0), n, flick_frame=n // 2)
        t0 = time.perf_counter()
        x = hair_features(anim, FeatureOptions(samples=HAIR_SAMPLES))
        return x, time.perf_counter() - t0
    rng = np.random.default_rng(n * 100_003 + d)
    return np.cumsum(rng.normal(size=(n, d)), axis=0), None


def _time(fn, repeat: int = 1):
    """``fn()`` and the median of ``repeat`` timings of it (the first run of a table also pays
    for faulting in its fresh memory, which a single timing charged to whichever row came first)."""
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return out, statistics.median(times)


def run(args: argparse.Namespace) -> list[dict]:
    from hairtool.bench import setup
    from hairtool.keys.costs import cost_table
    from hairtool.keys.dp import solve_layers
    from hairtool.keys.segment_direct import direct_cost_table

    repeat = setup(args)
    sizes = QUICK if args.quick else (_parse_sizes(args.sizes) if args.sizes else SIZES)
    # compile (or load) the kernels outside the timings
    warm = np.cumsum(np.random.default_rng(0).normal(size=(8, 2)), axis=0)
    solve_layers(cost_table(warm, args.interp), 4)
    from hairtool.keys.features import resample_frames

    frozen = np.zeros((1, 4, 3), dtype=np.float32)
    frozen.flags.writeable = False  # Animation frames are read-only: numba's signature differs
    resample_frames(frozen, [2, 2], 3)
    rows = []
    for n, d in sizes:
        x, features_s = _features(n, d)
        _, gram_s = _time(lambda x=x: x @ x.T, repeat)
        table, table_s = _time(lambda x=x: cost_table(x, args.interp), repeat)
        kmax = min(args.max_keys, n)
        _, dp_s = _time(lambda t=table, k=kmax: solve_layers(t, k), repeat)
        select_s = table_s + dp_s
        direct_s, agree = None, None
        if not args.no_direct:
            m = min(n, 40)
            _, probe = _time(lambda x=x, m=m: direct_cost_table(x[:m], args.interp))
            if probe * (n / m) ** 3 <= DIRECT_LIMIT_S:
                direct, direct_s = _time(lambda x=x: direct_cost_table(x, args.interp))
                agree = float(np.abs(table - direct).max() / max(np.abs(direct).max(), 1e-300))
        rows.append(
            {
                "frames": n,
                "dims": d,
                "objective": "total",
                "interp": args.interp,
                "constrained": False,
                "features_s": features_s,
                "table_s": table_s,
                "dp_s": dp_s,
                "select_s": select_s,
                "gram_s": gram_s,
                "select_over_gram": select_s / gram_s if gram_s > 0 else None,
                "direct_s": direct_s,
                "direct_over_select": None if direct_s is None else direct_s / select_s,
                "table_rel_diff": agree,
            }
        )
    for n, d in sizes:
        if d <= 3000:
            rows += _other_modes(n, d, min(args.max_keys, n), repeat)
    for n in sorted({n for n, d in sizes if d <= 3000}):
        rows.append(_quaternion_row(n, min(args.max_keys, n), repeat))
    return rows


QUATERNION_CAPTURE = "pymo_walk.bvh"


def _quaternion_row(n: int, kmax: int, repeat: int = 1) -> dict:
    """Seed 003's quaternion-distance table of an n-frame capture, plus the all-K DP on it."""
    from hairtool.bench import MOTION_DIR, threads
    from hairtool.keys.dp import solve_layers
    from hairtool.mocap.bvh import read_bvh
    from hairtool.mocap.costs import rotation_cost_table

    motion = read_bvh(MOTION_DIR / QUATERNION_CAPTURE)
    v = motion.values
    laps = [v if lap % 2 == 0 else v[::-1] for lap in range(n // len(v) + 1)]
    motion = motion.with_values(np.concatenate(laps)[:n])
    rotation_cost_table(motion.with_values(motion.values[: min(n, 12)]))  # compile outside the timing
    table, table_s = _time(lambda: rotation_cost_table(motion), repeat)
    _, dp_s = _time(lambda: solve_layers(table, kmax), repeat)
    return {
        "frames": n,
        "dims": motion.n_joints,
        "objective": "quaternion",
        "interp": "slerp",
        "constrained": False,
        "table_s": table_s,
        "dp_s": dp_s,
        "select_s": table_s + dp_s,
        "threads": threads(),
    }


def _other_modes(n: int, d: int, kmax: int, repeat: int = 1) -> list[dict]:
    """Table + all-K DP for the worst-frame objective, fitted handles, and pins/exclusions. A
    constrained row times its DP against the unconstrained one on the same table, taking turns,
    and reports what the constraints add to the selection (``constraint_overhead``): apart, the
    two would differ as much by the machine's drift between them as by the constraints."""
    from hairtool.keys.constraints import KeyConstraints
    from hairtool.keys.costs import cost_table
    from hairtool.keys.dp import solve_layers

    x, _ = _features(n, d)
    frames = np.unique(np.linspace(1, n - 2, min(22, (n - 2) // 3)).round().astype(int))  # distinct
    cons = KeyConstraints(pins=tuple(frames[::2][:10]), excludes=tuple(frames[1::2][:10]))
    out = []
    for objective, interp, constrained in (
        ("worst", "linear", False),
        ("worst", "hermite", False),
        ("total", "hermite-fit", False),
        ("total", "linear", True),
        ("worst", "linear", True),
    ):
        warm = x[: min(n, 12)]
        solve_layers(cost_table(warm, interp, 0.0, objective), 3, objective)
        table, table_s = _time(lambda i=interp, o=objective: cost_table(x, i, 0.0, o), repeat)
        row = {"frames": n, "dims": d, "objective": objective, "interp": interp, "constrained": constrained}
        if constrained:
            dp_s, free_s = _time_turns(
                [
                    lambda t=table, o=objective: solve_layers(t, kmax, o, constraints=cons),
                    lambda t=table, o=objective: solve_layers(t, kmax, o),
                ],
                max(repeat, 5),
            )
            row["dp_unconstrained_s"] = free_s
            row["constraint_overhead"] = (table_s + dp_s) / (table_s + free_s) - 1.0
        else:
            _, dp_s = _time(lambda t=table, o=objective: solve_layers(t, kmax, o), repeat)
        out.append({**row, "table_s": table_s, "dp_s": dp_s, "select_s": table_s + dp_s})
    return out


def _time_turns(fns, repeat: int) -> list[float]:
    """Median seconds of each of ``fns``, run in turn ``repeat`` times (the order alternating), so
    that a slow moment of the machine falls on all of them."""
    times: list[list[float]] = [[] for _ in fns]
    for r in range(repeat):
        order = range(len(fns)) if r % 2 == 0 else reversed(range(len(fns)))
        for i in order:
            t0 = time.perf_counter()
            fns[i]()
            times[i].append(time.perf_counter() - t0)
    return [statistics.median(t) for t in times]
