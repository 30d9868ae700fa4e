"""A character's skinned meshes on the GPU, posed by linear blend skinning in a vertex shader
(``shaders/character.glsl``), the same sums as :mod:`hairtool.character.skinning`'s kernel.

The bind-time vertices are uploaded once; a pose uploads only each skin's joint matrices (a
float texture, one row per joint). :meth:`CharacterLayer.captured` reads back, by transform
feedback through the same shader code, the positions the last pose drew, so a test can hold the
GPU to the CPU path vertex by vertex.
"""

from __future__ import annotations

from dataclasses import dataclass

import moderngl
import numpy as np
from numpy.typing import NDArray

from app.render.gl_objects import alive
from app.render.shaders import load_program, stage_sources
from hairtool.character.model import Character, SkinnedMesh
from hairtool.character.skinning import skin_matrices


@dataclass
class _Skin:
    """One skinned mesh on the GPU: its buffers, its joint texture and its vertex arrays."""

    mesh: SkinnedMesh
    joints: moderngl.Texture
    draw: moderngl.VertexArray
    capture: moderngl.VertexArray
    objects: list


class CharacterLayer:
    """GPU copy of a character's meshes; ``set_character(None)`` frees it."""

    def __init__(self, ctx: moderngl.Context) -> None:
        self.ctx = ctx
        self.program = load_program(ctx, "character")
        self.capture_program = ctx.program(**stage_sources("character_capture"), varyings=["v_skinned"])
        self._skins: list[_Skin] = []
        self._tiny: moderngl.Framebuffer | None = None  # bound while capturing, where none is
        self.bounds: tuple[NDArray, NDArray] | None = None

    @property
    def drawn(self) -> bool:
        return bool(self._skins)

    def set_character(self, character: Character | None) -> None:
        """Upload ``character``'s meshes, posed at rest (None: nothing drawn)."""
        self._free()
        if character is None:
            return
        for mesh in character.meshes:
            if len(mesh.triangles) == 0:
                continue
            v = len(mesh.positions)
            position = self.ctx.buffer(np.ascontiguousarray(mesh.positions, dtype="f4").tobytes())
            normals = mesh.normals if mesh.normals is not None else np.zeros((v, 3))
            normal = self.ctx.buffer(np.ascontiguousarray(normals, dtype="f4").tobytes())
            joint = self.ctx.buffer(np.ascontiguousarray(mesh.joint_slots, dtype="i4").tobytes())
            weight = self.ctx.buffer(np.ascontiguousarray(mesh.weights, dtype="f4").tobytes())
            index = self.ctx.buffer(np.ascontiguousarray(mesh.triangles, dtype="u4").tobytes())
            texture = self.ctx.texture((4, len(mesh.skin_joints)), 4, dtype="f4")
            texture.filter = (moderngl.NEAREST, moderngl.NEAREST)
            skinned = [
                (position, "3f", "in_position"),
                (joint, "4i", "in_joints"),
                (weight, "4f", "in_weights"),
            ]
            draw = self.ctx.vertex_array(
                self.program,
                [*skinned, (normal, "3f", "in_normal")],
                index_buffer=index,
                index_element_size=4,
            )
            capture = self.ctx.vertex_array(self.capture_program, skinned)
            objects = [draw, capture, texture, position, normal, joint, weight, index]
            self._skins.append(_Skin(mesh, texture, draw, capture, objects))
        self.pose(character.nodes.world())

    def pose(self, world: NDArray[np.float64]) -> None:
        """Pose the meshes for node world matrices ``(J, 4, 4)`` (``Nodes.world`` of a pose)."""
        lo, hi = [], []
        for s in self._skins:
            m = skin_matrices(s.mesh, world)
            s.joints.write(
                np.ascontiguousarray(m.transpose(0, 2, 1), dtype="f4").tobytes()
            )  # texel c = column c
            joints = np.unique(s.mesh.joint_slots[s.mesh.weights > 0])
            origins = world[s.mesh.skin_joints[joints], :3, 3]  # the joints, padded by the mesh's reach
            lo.append(np.min(origins, axis=0) - _reach(s.mesh))
            hi.append(np.max(origins, axis=0) + _reach(s.mesh))
        self.bounds = (np.min(lo, axis=0), np.max(hi, axis=0)) if lo else None

    def render(self, mvp: NDArray[np.float32], view: NDArray[np.float32]) -> None:
        if not self._skins:
            return
        self.program["u_mvp"].write(np.ascontiguousarray(mvp, dtype="f4").tobytes())
        self.program["u_view"].write(np.ascontiguousarray(view, dtype="f4").tobytes())
        self.program["u_joints"].value = 0
        for s in self._skins:
            self.program["u_color"].value = tuple(s.mesh.base_color[:3])
            s.joints.use(0)
            s.draw.render(moderngl.TRIANGLES)

    def captured(self) -> list[NDArray[np.float32]]:
        """``(V, 3)`` float32 positions of each mesh as the last pose skinned them on the GPU."""
        out = []
        if "u_joints" in self.capture_program:
            self.capture_program["u_joints"].value = 0
        # a draw call, even with no fragments, needs a complete framebuffer bound
        before = self.ctx.fbo
        if self._tiny is None:
            self._tiny = self.ctx.simple_framebuffer((1, 1))
        self._tiny.use()
        for s in self._skins:
            v = len(s.mesh.positions)
            buffer = self.ctx.buffer(reserve=v * 12)
            s.joints.use(0)
            s.capture.transform(buffer, mode=moderngl.POINTS, vertices=v)
            out.append(np.frombuffer(buffer.read(), dtype="f4").reshape(v, 3).copy())
            buffer.release()
        if alive(before) and before is not self._tiny:
            before.use()  # (a framebuffer released while bound, e.g. on a resize, is left alone)
        return out

    def _free(self) -> None:
        for s in self._skins:
            for obj in s.objects:
                obj.release()
        self._skins = []
        self.bounds = None

    def release(self) -> None:
        self._free()
        self.program.release()
        self.capture_program.release()
        if self._tiny is not None:
            if self.ctx.fbo is self._tiny:
                self.ctx.fbo = None  # nothing else may "restore" a framebuffer released here
            self._tiny.release()


def _reach(mesh: SkinnedMesh) -> float:
    """How far a vertex lies from the joints at bind time, at most (pads the posed bounds)."""
    bind = np.linalg.inv(mesh.inverse_bind)[:, :3, 3]
    near = bind[mesh.joint_slots[:, 0]]
    return float(np.max(np.linalg.norm(mesh.positions - near, axis=1), initial=0.0))
