"""The character drawn skinned: the GPU's vertex shader poses the meshes as the library's numpy
reference and numba kernel do (positions read back by transform feedback, within float32), the
posed mesh is drawn, and a click on a chain's bones selects that chain."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from app.render.camera import Camera
from app.render.character_bones import chain_lines, chains_groom, pick_chain
from app.render.character_skin import CharacterLayer
from hairtool.character import load_character
from hairtool.character.cycle import character_cycle
from hairtool.character.skinning import skin, skin_matrices, skin_reference
from hairtool.character.springs import head_shake

CHARACTER = load_character(Path(__file__).resolve().parents[1] / "data" / "characters" / "bunches.vrm")
CYCLE = character_cycle(CHARACTER)
SHAKE = head_shake(CHARACTER, 12, 24.0, turn_deg=40.0, period=0.5)


@pytest.fixture
def layer(gl_ctx):
    lay = CharacterLayer(gl_ctx)
    lay.set_character(CHARACTER)
    yield lay
    lay.release()


def _check(layer: CharacterLayer, rotations: np.ndarray) -> None:
    world = CHARACTER.nodes.world(rotations)
    layer.pose(world)
    gpu = layer.captured()
    assert len(gpu) == len(CHARACTER.meshes)
    for mesh, got in zip(CHARACTER.meshes, gpu, strict=True):
        want = skin_reference(mesh.positions, mesh.joint_slots, mesh.weights, skin_matrices(mesh, world))
        scale = float(np.max(np.abs(want)))
        np.testing.assert_allclose(got, want, rtol=0, atol=4e-6 * scale)  # float32 sums of a metre-sized body
        np.testing.assert_allclose(skin(mesh, world), want, rtol=0, atol=1e-12 * scale)  # the CPU path


@settings(
    max_examples=8, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)  # posing replaces all it reads
@given(picture=st.integers(0, CYCLE.schedule.n_pictures - 1), frame=st.integers(0, len(SHAKE) - 1))
def test_the_gpu_skins_as_the_reference_does(layer, picture, frame):
    rotations = CYCLE.pictures[picture].copy()
    head = CHARACTER.nodes.names.index("Head")
    rotations[head] = SHAKE[frame, head]  # the cycle's drawing on a turned head
    _check(layer, rotations)


def test_the_rest_pose_gives_back_the_bind_positions(layer):
    layer.pose(CHARACTER.nodes.world())
    for mesh, got in zip(CHARACTER.meshes, layer.captured(), strict=True):
        np.testing.assert_allclose(got, mesh.positions, rtol=0, atol=4e-6)


def test_the_posed_character_is_drawn_and_framed(gl_ctx, layer):
    world = CHARACTER.nodes.world(CYCLE.pictures[2])
    layer.pose(world)
    lo, hi = layer.bounds
    for got in layer.captured():
        assert np.all(got >= lo - 1e-6) and np.all(got <= hi + 1e-6)
    cam = Camera.for_bounds(lo, hi)
    size = (96, 96)
    fbo = gl_ctx.simple_framebuffer(size)
    fbo.use()
    fbo.clear(0.0, 0.0, 0.0, 1.0, depth=1.0)
    gl_ctx.enable(gl_ctx.DEPTH_TEST)
    view = cam.view_matrix()
    mvp = (view @ cam.projection_matrix(1.0)).astype(np.float32)
    layer.render(mvp, view)
    image = np.frombuffer(fbo.read(components=3), dtype=np.uint8).reshape(96, 96, 3)
    fbo.release()
    covered = np.any(image > 0, axis=2).mean()
    assert 0.01 < covered < 0.9  # the body and hair fill part of the frame (padded bounds), not all of it


def test_a_click_on_a_chains_bones_selects_it():
    world = CHARACTER.nodes.world(CYCLE.pictures[1])
    lines = chain_lines(CHARACTER, world)
    groom = chains_groom(CHARACTER, world)
    assert len(groom) == len(CHARACTER.chains)
    cam = Camera.for_bounds(*groom.bounds)
    size = (400, 300)
    for c, line in enumerate(lines):
        mid = cam.project(line[1:3], *size).mean(axis=0)  # the middle of the chain's second bone
        got = pick_chain(cam, size, lines, tuple(mid))
        near = cam.project(lines[got][1:3], *size).mean(axis=0)
        assert got == c or np.linalg.norm(near - mid) < 1.0  # or a chain drawn over it there
    assert pick_chain(cam, size, lines, (-50.0, -50.0)) is None


def test_a_capture_after_the_bound_framebuffer_was_released(gl_ctx, layer):
    """Another drawing released the framebuffer it left bound (a resize does): the capture still
    runs, and leaves its own bound."""
    gone = gl_ctx.simple_framebuffer((4, 4))
    gone.use()
    gone.release()
    layer.pose(CHARACTER.nodes.world())
    for mesh, got in zip(CHARACTER.meshes, layer.captured(), strict=True):
        np.testing.assert_allclose(got, mesh.positions, rtol=0, atol=4e-6)
