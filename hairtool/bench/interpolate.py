"""Render hair from guides: children rebuilt from the guides' current shapes, per frame.

Rows: the target case (100,000 children × 16 vertices from 1,000 guides of a scalp sample,
roots around the guide roots), Sintel's 228 guides on her head with 20,000 and 50,000 children
(roots scattered on the scalp, guides by surface distance), and dense grooms bound to guides
picked among their strands (``from dense``: the exact path, x + (y − y⁰)). ``interpolate_ms``:
the children's points from guides one mouse move away from rest (the kernel, its guide tables
and frames; into a reused array), ``fastest_ms`` the fastest run (on a shared machine the
median carries the other processes' load); ``reference_ms``: the numpy twin on the same input;
``bind_ms``: making the binding, once (scatter, surface distances, weights, variation);
``clump_ms``: ClumpWithGaps on the children with their automatic radius and a built neighbour
list (``--clump``); ``threads``: numba threads.

``--release``: what a release costs with "Clump children" on and off, Sintel with 30,000 and
100,000 children (10,000 with ``--quick``). ``stroke``: the 10 % of the guides nearest one
guide root swung (one brush stroke), the release rebuilding what followed them, as the studio
does; ``all``: every guide moved (a parameter change). ``release_ms`` unclumped,
``clumped_ms`` with ClumpWithGaps among each guide's children (only the clumps the stroke
reached run again), ``ratio`` the two; ``whole_ms``: one run over all children at once (the
studio's clumping before), ``clumps_run``: clumps redone. Children only: the draw after a
release, the same either way, is ``python -m app.bench``'s, so this ratio is far above the
studio's (a stroke's unclumped children rebuild in a few ms, the full frame takes hundreds);
the issue's 1.5× budget reads the studio's release, frame included.
"""

from __future__ import annotations

import argparse

from hairtool.bench import GROOMS_DIR, add_common_arguments, median_ms, setup, threads

HELP = "time interpolating render strands (children) from guides against numpy"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_common_arguments(parser, quick="10,000 children and no dense grooms", repeat=15)
    parser.add_argument("--children", type=int, default=100_000, help="children in the target case")
    parser.add_argument("--guides", type=int, default=1_000, help="guides in the target case")
    parser.add_argument("--vertices", type=int, default=16, help="vertices per child in the target case")
    parser.add_argument("--clump", action="store_true", help="also time ClumpWithGaps on the children")
    parser.add_argument(
        "--release", action="store_true", help="only the release with and without Clump children (Sintel)"
    )


def _resources():
    """The bundled Sintel guides and head (``resources/`` of the checkout)."""
    from pathlib import Path

    import hairtool

    return Path(hairtool.__file__).resolve().parents[1] / "resources"


def _moved(guides):
    """The guides a small drag away from rest: tips swung sideways, roots kept."""
    import numpy as np

    lo, hi = guides.bounds
    push = np.float32(0.05 * float(np.max(hi - lo)))
    t = guides.topology.vertex_param[:, None]
    return guides.with_points(guides.points + push * t * np.array([1.0, 0.0, 0.3], np.float32))


def _fastest_ms(fn, repeat: int) -> float:
    """The fastest of ``repeat`` runs: what the kernel costs when no other process holds a core."""
    import time

    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append((time.perf_counter() - t0) * 1e3)
    return min(times)


def _row(name, guides, binding, bind_ms, repeat, clump) -> dict:
    import numpy as np

    from hairtool.guides.children import build_points, build_points_reference

    moved = _moved(guides)
    out = np.empty((binding.vertex_count, 3), np.float32)
    row = {
        "case": name,
        "guides": guides.strand_count,
        "children": binding.child_count,
        "vertices": binding.vertex_count,
        "interpolate_ms": median_ms(lambda: build_points(binding, moved, out=out), repeat),
        "fastest_ms": _fastest_ms(lambda: build_points(binding, moved, out=out), repeat),
        "reference_ms": median_ms(
            lambda: build_points_reference(binding, moved), max(1, min(repeat, 3)), warmup=0
        ),
        "bind_ms": bind_ms,
    }
    row["speedup"] = row["reference_ms"] / row["interpolate_ms"]
    if clump:
        from hairtool.frozen.clump import ClumpWorkspace, clump_points
        from hairtool.frozen.strand_clumps import auto_clump_radius

        kids = binding.build(moved)
        h = auto_clump_radius(binding.build())
        ws = ClumpWorkspace()
        row["clump_ms"] = median_ms(lambda: clump_points(kids, h, 3, None, "printed", 0, ws, True), 3)
    row["threads"] = threads()
    return row


def _stroke(guides, share: float = 0.1):
    """Two poses a stroke apart: the ``share`` of the guides nearest guide 0's root swung."""
    import numpy as np

    count = max(1, int(share * len(guides)))
    near = np.argsort(np.linalg.norm(guides.roots - guides.roots[0], axis=1))[:count]
    moved = _moved(guides).points
    pts = guides.points.copy()
    for s in near:
        a, b = guides.offsets[s], guides.offsets[s + 1]
        pts[a:b] = moved[a:b]
    return guides.with_points(pts)


def _alternating(guides, pose, update):
    """A call that gives ``update`` the rest guides and ``pose`` by turns (each call a move)."""
    poses, flip = [guides, pose], [0]

    def call():
        flip[0] ^= 1
        update(poses[flip[0]])

    return call


def _release_rows(guides, binding, repeat: int) -> list[dict]:
    from hairtool.frozen.clump import ClumpWorkspace, clump_points
    from hairtool.guides.children import build_points, moved_guides
    from hairtool.guides.render import ChildClump, RenderHair

    rows = []
    clump = ChildClump()
    h = RenderHair(binding, clump).clump_radius
    for case, pose in (("stroke", _stroke(guides)), ("all", _moved(guides))):
        plain_out = build_points(binding, guides)
        last = [guides.points.copy()]

        def plain(g, out=plain_out, last=last):  # the studio's unclumped release
            build_points(binding, g, out=out, moved=moved_guides(g, last[0]))
            last[0] = g.points.copy()

        rh = RenderHair(binding, clump)
        rh.update_points(guides)
        kids = binding.build(pose)
        ws = ClumpWorkspace()

        def whole(kids=kids, ws=ws):
            ws.invalidate()
            clump_points(kids, h, clump.iterations, None, clump.gap_mode, 0, ws, True)

        row = {"case": f"release, {case}", "children": binding.child_count, "vertices": binding.vertex_count}
        row["release_ms"] = median_ms(_alternating(guides, pose, plain), repeat)
        row["clumped_ms"] = median_ms(_alternating(guides, pose, rh.update_points), repeat)
        row["ratio"] = row["clumped_ms"] / row["release_ms"]
        row["clumps_run"] = rh.clumps.clumps_run
        row["whole_ms"] = median_ms(whole, max(1, min(repeat, 3)))
        row["threads"] = threads()
        rows.append(row)
    return rows


def run(args: argparse.Namespace) -> list[dict]:
    import time

    from hairtool import io, samples
    from hairtool.guides.binding import bind_dense, bind_roots, bind_scalp
    from hairtool.io.obj import read_mesh

    repeat = setup(args, quick_repeat=3)
    rows = []
    if args.release:
        res = _resources()
        sintel, head = io.read_groom(res / "sintel_hair.tfx"), read_mesh(res / "sintel_head.obj")
        for n in [10_000] if args.quick else [30_000, 100_000]:
            rows += _release_rows(sintel, bind_scalp(sintel, head, n, seed=1), max(3, min(repeat, 5)))
        return rows

    def timed(fn):
        t0 = time.perf_counter()
        result = fn()
        return result, (time.perf_counter() - t0) * 1e3

    count = min(args.children, 10_000) if args.quick else args.children
    guides = samples.scalp(args.guides, args.vertices, seed=0)
    binding, ms = timed(lambda: bind_roots(guides, count=count, seed=1))
    rows.append(_row(f"scalp {args.guides}x{args.vertices}", guides, binding, ms, repeat, args.clump))

    res = _resources()
    sintel, head = io.read_groom(res / "sintel_hair.tfx"), read_mesh(res / "sintel_head.obj")
    for n in [10_000] if args.quick else [20_000, 50_000]:
        binding, ms = timed(lambda n=n: bind_scalp(sintel, head, n, seed=1))
        rows.append(_row("sintel on her head", sintel, binding, ms, repeat, args.clump))

    if not args.quick:
        for name, guide_count in (("ratboy_mohawk", 200), ("bear", 1000)):
            path = GROOMS_DIR / f"{name}.tfx"
            if not path.is_file():
                continue
            dense = io.read_groom(path)
            (guides, binding), ms = timed(lambda d=dense, g=guide_count: bind_dense(d, g, seed=0))
            rows.append(_row(f"{name} from dense", guides, binding, ms, repeat, args.clump))
    return rows
