"""Shared pieces of the frozen-brush tests: the flat head the comb of :func:`hairtool.samples.comb`
hangs under (the plane y = 0 over [−1, 1.5]² as a grid of triangles, normals along −y, so the
head is the side y > 0 and the comb grows away from it)."""

from __future__ import annotations

import numpy as np
import pytest

from hairtool.io.obj import Mesh

PLANE_LO, PLANE_HI = -1.0, 1.5  # the square the plane covers in x and z
PLANE_CELLS = 5  # squares along each side, two triangles each


def plane_mesh(lo: float = PLANE_LO, hi: float = PLANE_HI, n: int = PLANE_CELLS + 1) -> Mesh:
    """The plane y = 0 over [lo, hi]² with n × n vertices, normals along −y."""
    t = np.linspace(lo, hi, n)
    x, z = np.meshgrid(t, t, indexing="ij")
    v = np.column_stack([x.ravel(), np.zeros(n * n), z.ravel()])
    f = [(i * n + j, (i + 1) * n + j, (i + 1) * n + j + 1) for i in range(n - 1) for j in range(n - 1)]
    f += [(i * n + j, (i + 1) * n + j + 1, i * n + j + 1) for i in range(n - 1) for j in range(n - 1)]
    normals = np.tile([0.0, -1.0, 0.0], (n * n, 1))
    return Mesh(v.astype(np.float32), np.array(f, np.int32), normals.astype(np.float32))


@pytest.fixture(scope="session")
def plane() -> Mesh:
    """The flat head (module docstring): a mesh, to wrap in a MeshSurface or HeadSurface."""
    return plane_mesh()
