"""What front faces only by sight costs a mask drag: per move, the pipeline's time with the
root-normal rule and with the sight rule (hairtool.frozen.brushes.sight), and the sight
kernel's own time, on a groom and an occluder.

    PYTHONPATH=. python benchmarks/front_by_sight.py [--groom tests/data/grooms/bear.tfx]
        [--head MESH.obj] [--moves 30] [--radius 0.1]

Without ``--head`` the occluder is an ellipsoid of 64 × 32 quads (3,968 triangles, about a
head mesh's count) inside the roots' box, centred on them: a groom without its head still
gets a head-sized mesh for the rays to walk. The drag crosses the groom's front, the camera
looking along −z, as the studio's default view does. Last, a box select over the whole view:
every vertex traced along the view (the 2-D view's rays) and to an eye (the 3-D view's).
"""

from __future__ import annotations

import argparse
import time
from dataclasses import replace

import numpy as np

from app.ui.brush_tool import BrushTool
from hairtool import io
from hairtool.frozen.brushes.sight import hidden_points, hidden_strands
from hairtool.frozen.pipeline import FrozenParams, FrozenPipeline
from hairtool.guides.planting import HeadSurface
from hairtool.io.obj import Mesh, read_mesh


def ellipsoid(centre: np.ndarray, axes: np.ndarray, rings: int = 32, sides: int = 64) -> Mesh:
    """A closed UV ellipsoid mesh."""
    theta = np.linspace(0.0, np.pi, rings + 1)[1:-1]
    phi = np.linspace(0.0, 2.0 * np.pi, sides, endpoint=False)
    t, p = (a.ravel() for a in np.meshgrid(theta, phi, indexing="ij"))
    unit = np.column_stack([np.sin(t) * np.cos(p), np.cos(t), np.sin(t) * np.sin(p)])
    unit = np.vstack([[0.0, 1.0, 0.0], unit, [0.0, -1.0, 0.0]])

    def ring(i: int, j: int) -> int:
        return 1 + i * sides + j % sides

    faces = [(0, ring(0, j + 1), ring(0, j)) for j in range(sides)]
    for i in range(rings - 2):
        for j in range(sides):
            a, b, c, d = ring(i, j), ring(i, j + 1), ring(i + 1, j), ring(i + 1, j + 1)
            faces += [(a, b, c), (b, d, c)]
    last = len(unit) - 1
    faces += [(last, ring(rings - 2, j), ring(rings - 2, j + 1)) for j in range(sides)]
    v = (centre + unit * axes).astype(np.float32)
    return Mesh(v, np.array(faces, np.int32), unit.astype(np.float32))


def drag(pipe: FrozenPipeline, samples: list, visible: bool) -> np.ndarray:
    """Milliseconds per move of the drag (the first move is a warm-up, not counted)."""
    out = []
    for k, move in enumerate(samples):
        t = time.perf_counter()
        pipe.apply_samples([replace(s, visible=visible) for s in move])
        if k:
            out.append(1000.0 * (time.perf_counter() - t))
    pipe.settle()
    return np.array(out)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--groom", default="tests/data/grooms/bear.tfx")
    ap.add_argument("--head", default=None, help="an OBJ head mesh (default: an ellipsoid inside the roots)")
    ap.add_argument("--moves", type=int, default=30)
    ap.add_argument("--radius", type=float, default=0.1, help="brush radius, a share of the largest side")
    a = ap.parse_args()
    groom = io.read_groom(a.groom)
    roots = groom.roots.astype(np.float64)
    lo, hi = (b.astype(np.float64) for b in groom.bounds)
    if a.head:
        mesh = read_mesh(a.head)
    else:
        mesh = ellipsoid(roots.mean(axis=0), 0.35 * np.ptp(roots, axis=0).clip(1e-6))
    head = HeadSurface(mesh)
    tool = BrushTool()
    tool.reset_radius(a.radius * float(np.max(hi - lo)))
    tool.set_brush("mask")
    r = tool.radius["mask"]
    start = np.array([0.5 * (lo[0] + hi[0]) - 2.0 * r, 0.5 * (lo[1] + hi[1]), hi[2] - 0.5 * r])
    step = np.array([4.0 * r / max(a.moves - 1, 1), 0.0, 0.0])
    moves = [
        tool.samples(start + i * step, step, (0.0, 0.0, -1.0), 0.0, start=i == 0) for i in range(a.moves + 1)
    ]
    print(f"{a.groom}: {groom.strand_count} strands, {groom.vertex_count} vertices; "
          f"occluder {len(mesh.faces)} faces; brush radius {r:.4g}; {a.moves} moves")  # fmt: skip
    for visible in (False, True, False, True):  # twice each: the second pair is warm
        pipe = FrozenPipeline(groom, FrozenParams(keep_lengths=True), head)
        ms = drag(pipe, moves, visible)
        rule = "sight      " if visible else "root normal"
        print(f"  {rule}: median {np.median(ms):7.2f} ms, p90 {np.percentile(ms, 90):7.2f} ms per move; "
              f"{int(pipe.locked.sum())} strands masked")  # fmt: skip
    kernel = []  # the least of five calls per move: the kernel's own cost
    for move in moves[1:]:
        s, best = move[0], np.inf
        for _ in range(5):
            t = time.perf_counter()
            hidden_strands(groom.points, groom.offsets, s.cursor, s.radius, s.view, head.face_grid)
            best = min(best, time.perf_counter() - t)
        kernel.append(1000.0 * best)
    med, top = np.median(kernel), np.max(kernel)
    print(f"  sight kernel alone, whole groom: median {med:.2f} ms, max {top:.2f} ms per move")
    # a box over the whole view traces every vertex: along the view (2-D), to the eye (3-D)
    eye = np.array([0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), hi[2] + 3.0 * (hi[2] - lo[2])])
    for name, at in (("along the view", None), ("to the eye", eye)):
        hidden_points(groom.points[:1], (0.0, 0.0, -1.0), head.face_grid, at)  # compiled
        best = np.inf
        for _ in range(3):
            t = time.perf_counter()
            hidden = hidden_points(groom.points, (0.0, 0.0, -1.0), head.face_grid, at)
            best = min(best, time.perf_counter() - t)
        print(f"  every vertex traced {name}: {1000.0 * best:.1f} ms, {int(hidden.sum())} hidden")


if __name__ == "__main__":
    main()
