"""What a brush sample's aim costs under a perspective camera: per call, the head's first hit
along the line from the eye through the cursor (``MeshSurface.ray_hit``, the grid walk of
hairtool.frozen.brushes.first_hit) against its numpy twin that tries every face, on each head.

    PYTHONPATH=. python benchmarks/ray_hit.py [--calls 400] [--dense 256]

Heads: Sintel's (tests/data/grooms/sintel_head.obj); for the bear and ratboy, whose files come
without a head, the ellipsoid of 3,968 faces inside their roots that front_by_sight.py uses;
and a dense ellipsoid of ``--dense`` × ``--dense``/2 quads. The eyes lie 1.5-4 head sizes from
the head's centre, each aimed at a random vertex (a hit) or, one in eight, away (a miss), as the
studio's camera orbits. Each line prints the median and the 90th percentile over the calls.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from front_by_sight import ellipsoid

from hairtool import io
from hairtool.guides.surface import MeshSurface
from hairtool.io.obj import Mesh, read_mesh

GROOMS = Path(__file__).resolve().parent.parent / "tests" / "data" / "grooms"


def heads(dense: int) -> dict[str, Mesh]:
    out = {"sintel head": read_mesh(GROOMS / "sintel_head.obj")}
    for name in ("bear", "ratboy_mohawk"):
        roots = io.read_groom(GROOMS / f"{name}.tfx").roots.astype(np.float64)
        out[f"{name} ellipsoid"] = ellipsoid(roots.mean(axis=0), 0.35 * np.ptp(roots, axis=0).clip(1e-6))
    out["dense ellipsoid"] = ellipsoid(np.zeros(3), np.array([1.0, 1.2, 0.9]), dense // 2, dense)
    return out


def rays(surface: MeshSurface, calls: int, seed: int = 0) -> list[tuple[np.ndarray, np.ndarray]]:
    v = surface.face_grid.vertices
    lo, hi = v.min(axis=0), v.max(axis=0)
    centre, size = 0.5 * (lo + hi), float((hi - lo).max())
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(calls):
        u = rng.normal(size=3)
        eye = centre + rng.uniform(1.5, 4.0) * size * u / np.linalg.norm(u)
        target = v[rng.integers(len(v))]
        out.append((eye, target - eye if rng.random() >= 0.125 else eye - centre))
    return out


def per_call(call, samples) -> np.ndarray:
    ms = []
    for o, d in samples:
        t = time.perf_counter()
        call(o, d)
        ms.append(1000.0 * (time.perf_counter() - t))
    return np.array(ms)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--calls", type=int, default=400)
    ap.add_argument("--dense", type=int, default=256, help="the dense ellipsoid's quads around")
    a = ap.parse_args()
    for name, mesh in heads(a.dense).items():
        surface = MeshSurface(mesh)
        samples = rays(surface, a.calls)
        surface.ray_hit(*samples[0]), surface.ray_hit_reference(*samples[0])  # compiled, corners kept
        same = all(
            (p is None and q is None) or (p is not None and q is not None and (p == q).all())
            for p, q in ((surface.ray_hit(o, d), surface.ray_hit_reference(o, d)) for o, d in samples)
        )
        print(f"{name}: {len(mesh.faces)} faces, grid {'×'.join(map(str, surface.dims))}; "
              f"{a.calls} calls, the same points: {same}")  # fmt: skip
        for label, call in (("grid walk", surface.ray_hit), ("every face", surface.ray_hit_reference)):
            ms = per_call(call, samples)
            print(f"  {label:10}: median {np.median(ms):7.3f} ms, p90 {np.percentile(ms, 90):7.3f} ms")


if __name__ == "__main__":
    main()
