"""The head mesh drawn shaded under the hair (program ``shaders/mesh.glsl``)."""

from __future__ import annotations

from typing import Any

import moderngl
import numpy as np
from numpy.typing import NDArray

from app.render.shaders import load_program
from hairtool.errors import ParameterError

MESH_COLOR = (0.78, 0.66, 0.58)


def vertex_normals(vertices: NDArray, faces: NDArray) -> NDArray[np.float32]:
    """Area-weighted vertex normals ``(n, 3)`` (float64 sums), for meshes that come without them."""
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    face_n = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    n = np.zeros_like(v)
    for k in range(3):
        np.add.at(n, f[:, k], face_n)
    length = np.linalg.norm(n, axis=1, keepdims=True)
    return (n / np.where(length > 0, length, 1.0)).astype(np.float32)


def mesh_arrays(mesh: Any) -> tuple[NDArray[np.float32], NDArray[np.float32], NDArray[np.uint32]]:
    """``(vertices, normals, faces)`` from anything with ``vertices``, ``faces`` and maybe ``normals``."""
    try:
        v = np.ascontiguousarray(mesh.vertices, dtype=np.float32)
        f = np.ascontiguousarray(mesh.faces, dtype=np.int64)
    except AttributeError:
        raise ParameterError("mesh", type(mesh).__name__, "an object with vertices and faces") from None
    if v.ndim != 2 or v.shape[1] != 3 or f.ndim != 2 or f.shape[1] != 3:
        raise ParameterError("mesh", f"vertices {v.shape}, faces {f.shape}", "(n, 3) vertices, (m, 3) faces")
    if f.size and (f.min() < 0 or f.max() >= len(v)):
        raise ParameterError("mesh.faces", f"indices up to {f.max()}", f"indices in [0, {len(v)})")
    if not np.all(np.isfinite(v)):
        raise ParameterError("mesh.vertices", "non-finite", "finite coordinates")
    n = getattr(mesh, "normals", None)
    n = None if n is None else np.asarray(n, dtype=np.float32)
    if n is None or n.shape != v.shape or not np.all(np.isfinite(n)):
        n = vertex_normals(v, f)
    return v, np.ascontiguousarray(n), np.ascontiguousarray(f, dtype=np.uint32)


class MeshLayer:
    """GPU copy of one mesh; ``set_mesh(None)`` frees it."""

    def __init__(self, ctx: moderngl.Context) -> None:
        self.ctx = ctx
        self.program = load_program(ctx, "mesh")
        self.color = MESH_COLOR
        self._objects: list = []
        self.vao: moderngl.VertexArray | None = None
        self.bounds: tuple[NDArray, NDArray] | None = None

    def set_mesh(self, mesh: Any | None) -> None:
        self._free()
        if mesh is None:
            return
        v, n, f = mesh_arrays(mesh)
        if len(f) == 0:
            return
        vbo = self.ctx.buffer(np.hstack([v, n]).astype(np.float32).tobytes())
        ibo = self.ctx.buffer(f.tobytes())
        self.vao = self.ctx.vertex_array(
            self.program, [(vbo, "3f 3f", "in_position", "in_normal")], index_buffer=ibo, index_element_size=4
        )
        self._objects = [self.vao, vbo, ibo]
        self.bounds = (v.min(axis=0), v.max(axis=0))

    def render(self, mvp: NDArray[np.float32], view: NDArray[np.float32]) -> None:
        if self.vao is None:
            return
        self.program["u_mvp"].write(mvp.tobytes())
        self.program["u_view"].write(view.tobytes())
        self.program["u_color"].value = self.color
        self.vao.render(moderngl.TRIANGLES)

    def _free(self) -> None:
        for obj in self._objects:
            obj.release()
        self._objects = []
        self.vao = None
        self.bounds = None

    def release(self) -> None:
        self._free()
        self.program.release()
