"""A character in the studio (Xvfb): File ▸ Open draws it skinned on the GPU exactly as the
library's numpy reference poses it, its chains as bones that a click or the list selects; the
anime dock's Apply makes the cycle its animation, the timeline scrubs it, the springs show
beside it with the Table-1 measure, and the export writes what the library's reader reads."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest
from PySide6.QtCore import QPoint, Qt

from app.render.character_bones import chain_lines
from hairtool.character import load_character
from hairtool.character.skinning import skin_matrices, skin_reference

VRM = Path(__file__).resolve().parents[1] / "data" / "characters" / "bunches.vrm"


@pytest.fixture
def studio(make_window, tmp_path):
    path = tmp_path / "bunches.vrm"
    shutil.copy(VRM, path)
    window = make_window(str(path))
    assert window.errors == [] and window.character.doc is not None
    return window


def _gpu_matches_reference(window, rotations) -> None:
    """The positions the viewport's vertex shader made for the frame shown, against numpy."""
    window.viewport.draw_now()  # a frame rendered with this pose
    c = window.character.doc.character
    world = c.nodes.world(rotations)
    vp = window.viewport
    vp.makeCurrent()
    try:
        gpu = vp.renderer.character.captured()
    finally:
        vp.doneCurrent()
    for mesh, got in zip(c.meshes, gpu, strict=True):
        want = skin_reference(mesh.positions, mesh.joint_slots, mesh.weights, skin_matrices(mesh, world))
        np.testing.assert_allclose(got, want, rtol=0, atol=4e-6 * float(np.max(np.abs(want))))


def test_a_character_opens_skinned_with_its_chains_as_bones(studio):
    doc = studio.character.doc
    assert len(studio.scene.result) == len(doc.character.chains) == studio.character.dock.chains.count()
    assert studio.viewport.renderer.character.drawn
    _gpu_matches_reference(studio, doc.character.nodes.rotation)


def test_apply_makes_the_cycle_the_animation_and_the_timeline_scrubs_it(studio, qtbot):
    doc = studio.character.doc
    assert studio.sources.dock.apply_button.text() == "Apply to character"
    studio.sources.dock.apply_button.click()
    assert doc.state.applied is not None
    model = studio.animation
    n = doc.cycle().schedule.n_frames
    assert model.animation.n_frames == n * studio.character.cycles
    # the character's motion is its own document's: no step (nor unsaved work) of the window's
    assert studio.undo_stack.count() == 0 and not studio.project.has_unsaved_changes()
    for frame in (3, n + 4):
        model.set_frame(frame)
        _gpu_matches_reference(studio, doc.pose(frame, "cycle"))
    assert "Drawings on frames 0, 2, 4" in studio.character.dock.measure.text()
    qtbot.waitUntil(lambda: model.dp_keys is not None, timeout=60_000)
    drawings = [f + c * n for c in range(studio.character.cycles) for f in doc.drawing_frames()]
    assert model.dp_keys.tolist() == sorted({*drawings, model.animation.n_frames - 1})  # keys at the drawings
    assert doc.undo() and doc.state.applied is None  # Apply is one step of the document
    studio.new_from_sample("portrait")  # another groom: the character is closed
    assert studio.character.doc is None and not studio.viewport.renderer.character.drawn
    assert studio.sources.dock.apply_button.text() == "Apply to groom"


def test_the_springs_show_beside_the_cycle_with_the_papers_measure(studio):
    dock = studio.character.dock
    dock.view.activated.emit(list(dock.view.itemData(i) for i in range(dock.view.count())).index("both"))
    doc = studio.character.doc
    assert doc.state.view == "both"
    assert len(studio.animation.animation.frames[0]) == 2 * sum(len(ch.nodes) for ch in doc.character.chains)
    assert "mean angular error" in dock.measure.text()


def test_a_click_on_a_chain_selects_it_in_the_list(studio, qtbot):
    doc = studio.character.doc
    vp = studio.viewport
    size = (vp.width(), vp.height())
    lines = chain_lines(doc.character, doc.character.nodes.world())
    mids = [vp.camera.project(line[1:3], *size).mean(axis=0) for line in lines]
    clear = [
        c for c, xy in enumerate(mids) if studio.character.chain_at(tuple(xy)) == c
    ]  # not behind another
    assert len(clear) >= 2
    for c in clear[:2]:
        qtbot.mouseClick(vp, Qt.MouseButton.LeftButton, pos=QPoint(round(mids[c][0]), round(mids[c][1])))
        assert doc.state.selected == c and studio.character.dock.chains.currentRow() == c
    assert studio.character.chain_at((-50.0, -50.0)) is None
    dock = studio.character.dock
    dock.chains.setCurrentRow(2)
    assert doc.state.selected == 2
    dock.axis.activated.emit(2)  # the selected chain bends about the world's up axis
    dock.amplitude.edited.emit(1.5, "drag")
    dock.amplitude.edited.emit(0.5, "drag")  # one drag: one step
    assert (
        doc.state.cycle.chains[2].axis == (0.0, 1.0, 0.0) and doc.state.cycle.chains[2].amplitude_scale == 0.5
    )
    dock.undo_button.click()
    assert doc.state.cycle.chains[2].amplitude_scale != 0.5 and doc.state.cycle.chains[2].axis == (
        0.0,
        1.0,
        0.0,
    )


def test_export_writes_the_cycle_and_the_chains(studio, tmp_path):
    studio.sources.apply_anime()
    out = tmp_path / "cycle.vrm"
    assert studio.character.export(out, "cycle")
    clip = load_character(out).clips[-1]
    assert clip.step and clip.frame_rate() == 24.0
    assert studio.character.export(tmp_path / "keys.glb", "springs keys")
    keyed = load_character(tmp_path / "keys.glb").clips[-1]
    assert keyed.cubic and 2 <= len(next(iter(keyed.rotations.values()))[0]) < len(
        studio.character.doc.springs()
    )
    assert studio.character.export(tmp_path / "springs.bvh", "springs bvh")
    assert (tmp_path / "springs.bvh").read_text().startswith("HIERARCHY")
    assert not studio.character.export(tmp_path / "x.txt", "cycle")  # one line in a dialog
    assert studio.errors and "output" in studio.errors[-1][1]
