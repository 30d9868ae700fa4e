"""Frozen-hair pipeline timings per groom size: each stage, the whole pipeline, the numpy twins.

Sizes: the paper's Table 1 (100, 300, 500 strands × 20), 5,000 and 50,000 × 20 scalp samples,
the real grooms, and the generated shapes they lack (:mod:`hairtool.guides.shapes`: a ponytail
gathered into a tie, curls, a 10,000 × 16 straight cut, three hair systems). Clump radius
h = 2× the median root spacing, k = 3. ``pipeline_ms``: rest
groom → result (freeze + one align sample + clump), run again on the same input, so
ClumpWithGaps keeps its neighbour list; ``cold_ms``: the same with the list built every time;
``clump_ms``: ClumpWithGaps alone with its list built, ``list_ms`` of it; ``update_ms``: one
studio mouse move with the cursor held still (align + clump, freeze cached).

Brush-local moves (:mod:`hairtool.frozen.local`): ``drag_ms`` is one mouse move of a drag with a
brush of 0.05× the groom's extent, the cursor circling a tip near the middle, where the brush,
ClumpWithGaps and the length pass run on the strands under the brush and those their clumps
reach (``drag_redone`` of the vertices per move); ``crop_ms`` the same moves on a groom made only
of the strands within two brush radii of the path (``crop_strands`` of them; the same h and
step), and ``drag_per_crop`` their ratio: near 1 when a move costs the brush, not the groom
(target: drag_ms ≤ 1.5 × crop_ms + 1 ms). ``lists_ms``: of a drag move, the kept grid's update
and the region's neighbour lists, against ``list_ms``, the list built cold for the whole groom,
and ``grid_ms``, the kept grid's cold build (once per groom).
The release after a comb stroke (:func:`comb_stroke`: the strands within the brush of that tip,
moved as a comb moves them): ``release_ms``, ClumpWithGaps on the whole groom with the list of
the points before the stroke brought up to date (:mod:`hairtool.frozen.neighbour_update`, the
studio's release), against ``release_cold_ms`` with it built from scratch (what every run cost
before), ``stroke_moved`` the share of the vertices the stroke moved.
``reference_ms``: the pipeline with the numpy twins (null above ``--reference-limit`` vertices).
``mean_neighbours``: other-strand vertices within h per moving vertex; ``threads``: numba threads.
"""

from __future__ import annotations

import argparse
import itertools
import os
import time
from pathlib import Path

HELP = "time FreezeDeform, UserAlign, ClumpWithGaps and the whole pipeline against numpy"

PAPER_SIZES = ["100x20", "300x20", "500x20"]
DEFAULT_SIZES = [*PAPER_SIZES, "5000x20", "50000x20", "real", "shapes"]
#: The generated groom shapes (:mod:`hairtool.guides.shapes`), ``--sizes`` names.
SHAPES = ("ponytail", "curls", "straight", "systems")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--sizes",
        nargs="+",
        default=None,
        metavar="SIZE",
        help="STRANDSxVERTICES (scalp samples), 'real' (every groom in tests/data/grooms, "
        "or $HAIRTOOL_BENCH_DATA/grooms), 'shapes' (the generated ponytail, curls, straight "
        "cut and hair systems), one of those names, NAME:STRANDSxVERTICES, or a path",
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
            yield from _real_grooms(GROOMS_DIR)
        elif size == "shapes" or size.split(":")[0] in SHAPES:
            yield from _shapes(size)
        elif "x" in size and all(p.isdigit() for p in size.split("x")):
            s, v = (int(p) for p in size.split("x"))
            yield f"scalp {size}", scalp(s, v, seed=0)
        elif os.path.exists(size):
            yield Path(size).stem, read_groom(size)
        else:
            raise ParameterError("sizes", size, "STRANDSxVERTICES, 'real' or a groom file")


def _shapes(size: str):
    """``shapes`` (every generated shape at its bench size), ``NAME`` or ``NAME:SxV`` (a shape of
    :mod:`hairtool.guides.shapes` at S strands of V vertices)."""
    from hairtool.errors import ParameterError
    from hairtool.guides.shapes import SIZES, shape

    if size == "shapes":
        for name in SHAPES:
            yield f"{name} {SIZES[name][0]}x{SIZES[name][1]}", shape(name)
        return
    name, _, dims = size.partition(":")
    s, v = SIZES[name]
    if dims:
        parts = dims.split("x")
        if len(parts) != 2 or not all(p.isdigit() for p in parts):
            raise ParameterError("sizes", size, "NAME:STRANDSxVERTICES, e.g. ponytail:3066x16")
        s, v = int(parts[0]), int(parts[1])
    yield f"{name} {s}x{v}", shape(name, s, v)


REAL_SUFFIXES = (".tfx", ".hair", ".usd", ".usda", ".usdc", ".npz")  # (.obj there are head meshes)


def _real_grooms(folder: Path):
    """Every groom file in ``folder`` (the checkout's tests/data/grooms, or
    ``$HAIRTOOL_BENCH_DATA``/grooms), by name."""
    from hairtool.io import read_groom

    for path in sorted(folder.iterdir()) if folder.is_dir() else ():
        if path.suffix.lower() in REAL_SUFFIXES:
            yield path.stem, read_groom(path)


def _fresh(ws):
    """The workspace with its neighbour list forgotten, so the time includes building one."""
    ws.invalidate()
    return ws


BRUSH = 0.05  # of the groom's extent: the drag's brush radius


def _drag_path(rest, moves: int = 40):
    """The drag's cursor positions: a loop of radius 0.1× the extent around the tip nearest the
    middle, and the brush radius."""
    import numpy as np

    lo, hi = rest.bounds
    extent = float(np.max(hi - lo))
    tips = rest.tips.astype(np.float64)
    tip = tips[np.argmin(np.linalg.norm(tips - (lo + hi) / 2.0, axis=1))]
    a = np.linspace(0.0, 2.0 * np.pi, moves, endpoint=False)
    return tip + 0.1 * extent * np.column_stack([np.cos(a), np.sin(a), np.zeros(moves)]), BRUSH * extent


def _drag_ms(pipe, path, radius: float) -> tuple[float, float, float]:
    """Median ms per move of the drag (after one untimed move), the mean share of the vertices
    ClumpWithGaps redid per move, and the median ms of the grid update and region lists."""
    import statistics

    from hairtool.bench import median_ms

    moves = itertools.cycle(path)
    redone, lists = [], []

    def move():
        pipe.align(next(moves), radius, 0.8)
        redone.append(pipe.clump_redone)
        local = pipe.local_clump
        lists.append(0.0 if local is None or pipe.clump_redone >= 1.0 else local.lists_ms)

    move()
    redone.clear()
    lists.clear()
    ms = median_ms(move, len(path), warmup=0)
    return ms, sum(redone) / len(redone), statistics.median(lists)


def comb_stroke(rest, centre, radius: float, shift):
    """``rest``'s points after a comb stroke: the strands with a vertex within ``radius`` of
    ``centre`` moved by ``shift`` times their share of the way from root (0) to tip (1)."""
    import numpy as np

    p = rest.points.astype(np.float64)
    e = p - np.asarray(centre, np.float64)
    near = np.einsum("ij,ij->i", e, e) < radius * radius
    top = rest.topology
    hit = np.logical_or.reduceat(near, rest.offsets[:-1])[top.strand_index]
    along = (np.arange(rest.vertex_count) - rest.offsets[top.strand_index]) / np.maximum(
        np.diff(rest.offsets)[top.strand_index] - 1, 1
    )
    out = rest.points.copy()
    out[hit] += (along[hit, None] * np.asarray(shift, np.float64)[None]).astype(out.dtype)
    return out


def release_times(rest, repeat: int, h: float | None = None) -> dict:
    """The release after a comb stroke near the middle tip (see the module doc)."""
    import numpy as np

    from hairtool.bench import median_ms
    from hairtool.frozen.clump import ClumpWorkspace, clump_points
    from hairtool.frozen.strand_clumps import auto_clump_radius

    h = float(auto_clump_radius(rest)) if h is None else h
    path, radius = _drag_path(rest)
    centre = path.mean(axis=0)  # the tip the drag circles
    after = rest.with_points(comb_stroke(rest, centre, radius, (radius, 0.5 * radius, 0.0)))
    ws = ClumpWorkspace()

    def run(g):
        clump_points(g, h, 3, None, "printed", 0, ws)

    def stroked():  # back to the points before the stroke (untimed), then the release
        run(rest)
        t0 = time.perf_counter()
        run(after)
        return time.perf_counter() - t0

    run(rest)
    run(after)
    updates = ws.updates
    release = float(np.median([stroked() for _ in range(repeat)])) * 1e3
    return {
        "release_ms": release,
        "release_cold_ms": median_ms(lambda: (ws.invalidate(), run(after)), repeat),
        "release_updated": ws.updates > updates,
        "stroke_moved": float(np.mean(np.any(after.points != rest.points, axis=1))),
    }


def _crop(rest, path, radius: float):
    """The strands of ``rest`` with a vertex within two brush radii of the path."""
    import numpy as np

    p = rest.points.astype(np.float64)
    near = np.zeros(rest.vertex_count, bool)
    for c in path:
        e = p - c
        near |= np.einsum("ij,ij->i", e, e) < (2.0 * radius) ** 2
    ids = np.flatnonzero(np.logical_or.reduceat(near, rest.offsets[:-1]))
    return rest.subset(ids)


def _drag_and_crop(rest) -> dict:
    from hairtool.frozen.pipeline import FrozenParams, FrozenPipeline

    path, radius = _drag_path(rest)
    pipe = FrozenPipeline(rest)
    drag, redone, lists = _drag_ms(pipe, path, radius)
    crop = _crop(rest, path, radius)
    same = FrozenParams(clump_radius=pipe.clump_radius, clump_step=pipe.clump_step)
    crop_ms = _drag_ms(FrozenPipeline(crop, same), path, radius)[0]
    return {
        "drag_ms": drag,
        "crop_ms": crop_ms,
        "drag_per_crop": drag / crop_ms if crop_ms > 0 else None,
        "crop_strands": crop.strand_count,
        "drag_redone": redone,
        "lists_ms": lists,
    }


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
    from hairtool.frozen.vertex_grid import VertexGrid

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
        row.update(_drag_and_crop(rest))
        row.update(release_times(rest, max(1, min(repeat, 5)), h))
        row["grid_ms"] = median_ms(
            lambda r=rest, h=h: VertexGrid(r.points, r.topology.strand_index, 1.1 * h), max(1, min(repeat, 5))
        )
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
