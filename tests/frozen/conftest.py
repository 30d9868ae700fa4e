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


FOLD_SLOPE = 4.0  # the fold's walls rise 4 in y per 1 in x: the outside is a wedge of about 28°


def fold_mesh(n: int = 9, hard: bool = True) -> Mesh:
    """A harsh fold: the surface y = −FOLD_SLOPE·|x| over x, z in [−1, 1], the head above it
    (y > −FOLD_SLOPE·|x|), so the outside is a narrow wedge below the crease x = 0; normals
    point out of the head, into the wedge. ``hard``: a hard crease, its vertices given the
    x > 0 wall's normal (as a file with split normals gives one of them), else their mean."""
    t = np.linspace(-1.0, 1.0, n)  # (n odd: the crease is a row of vertices)
    x, z = np.meshgrid(t, t, indexing="ij")
    v = np.column_stack([x.ravel(), -FOLD_SLOPE * np.abs(x.ravel()), z.ravel()])
    f = [(i * n + j, (i + 1) * n + j, (i + 1) * n + j + 1) for i in range(n - 1) for j in range(n - 1)]
    f += [(i * n + j, (i + 1) * n + j + 1, i * n + j + 1) for i in range(n - 1) for j in range(n - 1)]
    side = np.sign(v[:, 0]) + (hard & (v[:, 0] == 0))
    normals = np.column_stack([-FOLD_SLOPE * side, -np.ones(n * n), np.zeros(n * n)])
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    return Mesh(v.astype(np.float32), np.array(f, np.int32), normals.astype(np.float32))


@pytest.fixture(scope="session")
def fold() -> Mesh:
    """:func:`fold_mesh` with a hard crease: walls a brush pushes strands into."""
    return fold_mesh()
