"""Frozen-hair pipeline timings per groom size: each stage, the whole pipeline, the numpy twins.

Sizes: the paper's Table 1 (100, 300, 500 strands × 20), 5,000 and 50,000 × 20 scalp samples,
and the real grooms. Clump radius h = 2× the median root spacing, k = 3. ``pipeline_ms``: rest
groom → result (freeze + one align sample + clump), run again on the same input, so
ClumpWithGaps keeps its neighbour list; ``cold_ms``: the same with the list built every time;
``clump_ms``: ClumpWithGaps alone with its list built, ``list_ms`` of it; ``update_ms``: one
studio mouse move with the cursor held still (align + clump, freeze cached); ``drag_ms``: one
mouse move of a drag with the studio's brush (the cursor circling a tip), where the strands
move and ClumpWithGaps is redone near them (:mod:`hairtool.frozen.clump_region`): on ``drag_redone``
of the vertices per move (1: a full run);
``reference_ms``: the pipeline with the numpy twins (null above ``--reference-limit`` vertices).
``mean_neighbours``: other-strand vertices within h per moving vertex; ``threads``: numba threads.
"""

from __future__ import annotations

import argparse
import itertools
import os
from pathlib import Path

HELP = "time FreezeDeform, UserAlign, ClumpWithGaps and the whole pipeline against numpy"

PAPER_SIZES = ["100x20", "300x20", "500x20"]
DEFAULT_SIZES = [*PAPER_SIZES, "5000x20", "50000x20", "real"]


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--sizes",
        nargs="+",
        default=None,
        metavar="SIZE",
        help="STRANDSxVERTICES (scalp samples), 'real' (every groom in tests/data/grooms) or a path",
    )
    parser.add_argument("--quick", action="store_true", help="100x20 and 500x20 only, fewer repeats")
    parser.add_argument("--repeat", type=int, default=15, help="timed runs per number (median)")
    parser.add_argument(
        "--reference-limit", type=int, default=120_000, help="skip numpy above this many vertices"
    )
    parser.add_argument("--threads", type=int, default=None, help="numba threads (default: all)")


def _grooms(sizes: list[str]):
    from hairtool.bench import GROOMS_DIR
    from hairtool.errors import ParameterError
    from hairtool.io import read_groom
    from hairtool.samples import scalp

    for size in sizes:
        if size == "real":
            for path in sorted(GROOMS_DIR.glob("*.tfx")):
                yield path.stem, read_groom(path)
        elif "x" in size and all(p.isdigit() for p in size.split("x")):
            s, v = (int(p) for p in size.split("x"))
            yield f"scalp {size}", scalp(s, v, seed=0)
        elif os.path.exists(size):
            yield Path(size).stem, read_groom(size)
        else:
            raise ParameterError("sizes", size, "STRANDSxVERTICES, 'real' or a groom file")


def _fresh(ws):
    """The workspace with its neighbour list forgotten, so the time includes building one."""
    ws.invalidate()
    return ws


def _drag_ms(pipe, moves: int = 40) -> tuple[float, float]:
    """Median ms per move of a drag like the studio's (its brush of 0.25× the groom's extent,
    the cursor circling a tip near the middle) and the mean share of the vertices that
    ClumpWithGaps redid per move."""
    import numpy as np

    from hairtool.bench import median_ms

    lo, hi = pipe.rest.bounds
    extent = float(np.max(hi - lo))
    tips = pipe.rest.tips.astype(np.float64)
    tip = tips[np.argmin(np.linalg.norm(tips - (lo + hi) / 2.0, axis=1))]
    a = np.linspace(0.0, 2.0 * np.pi, moves, endpoint=False)
    path = itertools.cycle(tip + 0.1 * extent * np.column_stack([np.cos(a), np.sin(a), np.zeros(moves)]))

    def move():
        pipe.align(next(path), 0.25 * extent, 0.8)

    redone = []

    def move_and_count():
        move()
        redone.append(pipe.clump_redone)

    move()
    return median_ms(move_and_count, moves, warmup=0), sum(redone) / len(redone)


def _cursor(groom):
    """A cursor beside the groom that catches about half of the tips, and its radius."""
    import numpy as np

    lo, hi = groom.bounds
    centre = (lo + hi) / 2.0
    size = float(np.linalg.norm(hi - lo))
    offset = np.array([0.6, 0.2, 0.0]) * size
    return centre + offset, 0.7 * size


def run(args: argparse.Namespace) -> list[dict]:
    import numba
    import numpy as np

    from hairtool.bench import median_ms
    from hairtool.errors import ParameterError
    from hairtool.frozen.align import align, align_reference
    from hairtool.frozen.clump import ClumpWorkspace, clump, clump_reference
    from hairtool.frozen.freeze import freeze, freeze_reference
    from hairtool.frozen.pipeline import FrozenPipeline
    from hairtool.frozen.strand_clumps import auto_clump_radius

    if args.repeat < 1:
        raise ParameterError("repeat", args.repeat, "a whole number ≥ 1")
    if args.threads is not None:
        numba.set_num_threads(max(1, min(args.threads, numba.config.NUMBA_NUM_THREADS)))
    sizes = args.sizes or (["100x20", "500x20"] if args.quick else DEFAULT_SIZES)
    repeat = 3 if args.quick else args.repeat
    rows = []
    theta = float(np.radians(30.0))
    for name, rest in _grooms(sizes):
        h = auto_clump_radius(rest)
        c, r = _cursor(rest)
        ws = ClumpWorkspace()

        def pipeline(rest=rest, c=c, r=r, h=h, ws=ws):
            return clump(align(freeze(rest, 7.0, 7.0, theta, 0), c, r, 0.8), h, 3, None, "printed", 0, ws)

        def reference(rest=rest, c=c, r=r, h=h):
            g = align_reference(freeze_reference(rest, 7.0, 7.0, theta, 0), c, r, 0.8)
            return clump_reference(g, h, 3, None, "printed", 0)

        frozen = freeze(rest, 7.0, 7.0, theta, 0)
        aligned = align(frozen, c, r, 0.8)
        pipe = FrozenPipeline(rest)
        row = {
            "groom": name,
            "strands": rest.strand_count,
            "vertices": rest.vertex_count,
            "freeze_ms": median_ms(lambda rest=rest: freeze(rest, 7.0, 7.0, theta, 0), repeat),
            "align_ms": median_ms(lambda f=frozen, c=c, r=r: align(f, c, r, 0.8), repeat),
            "clump_ms": median_ms(
                lambda a=aligned, h=h, ws=ws: clump(a, h, 3, None, "printed", 0, _fresh(ws)), repeat
            ),
            "list_ms": median_ms(lambda a=aligned, h=h, ws=ws: _fresh(ws).neighbour_list(a, h), repeat),
            "pipeline_ms": median_ms(pipeline, repeat),
            "cold_ms": median_ms(lambda ws=ws, run=pipeline: (_fresh(ws), run()), repeat),
            "update_ms": median_ms(lambda p=pipe, c=c, r=r: p.align(c, r, 0.8), repeat),
        }
        row["drag_ms"], row["drag_redone"] = _drag_ms(FrozenPipeline(rest))
        row["mean_neighbours"] = ws.mean_neighbours
        if rest.vertex_count <= args.reference_limit:
            row["reference_ms"] = median_ms(reference, max(1, min(repeat, 3)), warmup=0)
            row["speedup"] = row["reference_ms"] / row["pipeline_ms"]
        else:
            row["reference_ms"] = None
            row["speedup"] = None
        row["threads"] = numba.get_num_threads()
        rows.append(row)
    return rows
