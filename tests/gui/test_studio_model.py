"""The scene model and its document steps without a window: signals only on change, clear errors."""

from __future__ import annotations

import json

import numpy as np
import pytest

from app.ui.scene import Scene
from hairtool import samples
from hairtool.errors import ParameterError
from hairtool.frozen.pipeline import FrozenParams


def _deleted(scene: Scene) -> None:
    """Delete a window-less scene on this thread: left to the garbage collector, its Qt objects
    could be deleted on whichever thread collects them (a later window's worker)."""
    from PySide6.QtCore import QCoreApplication, QEvent

    scene.moves.shutdown()
    scene.deleteLater()
    QCoreApplication.sendPostedEvents(None, QEvent.Type.DeferredDelete)


@pytest.fixture
def scene(qapp):
    made = Scene(samples.portrait(strands=20, vertices=8))
    yield made
    _deleted(made)


def test_setters_emit_only_when_the_value_changes(ui, scene):
    tool, display, params = (
        ui.record(scene.tool_changed),
        ui.record(scene.display_changed),
        ui.record(scene.params_changed),
    )
    scene.set_radius(scene.radius)
    scene.set_intensity(scene.intensity)
    scene.set_colour_mode(scene.colour_mode)
    scene.set_params(scene.params)
    assert tool == [] and display == [] and params == []
    scene.set_radius(0.5)
    scene.set_align_mode("preserve-length")
    scene.set_colour_mode("clump")
    scene.set_params(scene.with_param("seed", 3))
    assert len(tool) == 2 and len(display) == 1 and len(params) == 1


@pytest.mark.parametrize(
    ("setter", "value"),
    [("set_radius", 0.0), ("set_radius", float("nan")), ("set_intensity", 1.5), ("set_align_mode", "x"),
     ("set_colour_mode", "rainbow"), ("set_line_width", 0.0)],
)  # fmt: skip
def test_bad_values_raise_parameter_errors(scene, setter, value):
    with pytest.raises(ParameterError):
        getattr(scene, setter)(value)


def test_bad_engine_parameter_is_named(scene):
    with pytest.raises(ParameterError, match="stretch_stiffness"):
        scene.with_param("stretch_stiffness", 0.5)


def test_a_stroke_is_one_document_step_recorded_on_release(qapp):
    """The drag runs on the document's engine; the release records it once, without applying it
    again; Undo and Redo land back through the document."""
    loose = FrozenParams(freeze=False, clump=False, keep_lengths=True)  # (the tips follow the cursor)
    scene = Scene(samples.portrait(strands=20, vertices=8), loose)
    stack = scene.hair.stack
    before_points = scene.result.points.copy()
    before = scene.snapshot()
    tip = scene.result.tips[0].astype(np.float64)
    scene.align(tip + np.array([0.6, 0.0, 0.0]))
    scene.align(tip + np.array([0.6, 0.3, 0.0]))
    assert stack.count == 0  # nothing recorded mid-stroke
    scene.end_stroke(before)
    after_points = scene.result.points.copy()
    assert stack.count == 1 and stack.undo_text == "Align stroke"
    assert not np.array_equal(after_points, before_points)
    stack.undo()
    assert np.array_equal(scene.result.points, before_points)
    stack.redo()
    assert np.array_equal(scene.result.points, after_points)
    scene.end_stroke(scene.snapshot())  # a release with nothing applied: no step
    assert stack.count == 1
    _deleted(scene)


def test_param_edits_merge_within_one_drag_only(scene):
    stack = scene.hair.stack
    p0 = scene.params
    for i, k in enumerate((8.0, 9.0, 10.0)):
        scene.set_params(scene.with_param("bend_stiffness", k), "bend_stiffness", drag=1)
        assert stack.count == 1, i
    scene.set_params(scene.with_param("bend_stiffness", 11.0), "bend_stiffness", drag=2)
    scene.set_params(scene.with_param("seed", 5), "seed")
    assert stack.count == 3 and scene.params.seed == 5 and stack.undo_text == "Change seed"
    stack.undo()
    stack.undo()
    assert scene.params.bend_stiffness == 10.0
    stack.undo()
    assert scene.params == p0


def test_displacement_is_zero_at_rest_and_grows_with_a_stroke(scene):
    scene.set_params(scene.params.replace(freeze=False, clump=False))
    assert np.all(scene.displacement() == 0.0)
    scene.align(scene.result.tips[0].astype(np.float64) + np.array([0.6, 0.0, 0.0]))
    d = scene.displacement()
    assert d.max() > 0.01 and np.all(d[scene.rest.topology.root_indices] == 0.0)


def test_cli_help_and_bad_arguments(capsys):
    from app.main import main

    with pytest.raises(SystemExit) as e:
        main(["--help"])
    assert e.value.code == 0
    assert main(["groom.hair", "--nonsense"]) == 2
    assert "unrecognised" in capsys.readouterr().err


@pytest.mark.gui
def test_benchmark_runs_and_reports_the_breakdown(qapp, capsys):
    from app.main import main

    argv = ["--bench", "--only", "large", "--strands", "30", "--vertices", "6", "--moves", "3", "--json"]
    assert main(argv) == 0
    rows = json.loads(capsys.readouterr().out)
    assert len(rows) == 1 and rows[0]["strands"] == 30 and rows[0]["moves"] == 3
    for key in ("total_ms", "pipeline_ms", "upload_ms", "draw_ms"):
        assert rows[0][key] >= 0.0
    assert rows[0]["total_ms"] >= rows[0]["draw_ms"]
    assert rows[0]["lines"] == "cpu/quads"  # llvmpipe: strands rasterized on the CPU
    assert main([*argv, "--strand-raster", "gl", "--line-width", "1"]) == 0
    assert json.loads(capsys.readouterr().out)[0]["lines"] == "thin"


@pytest.mark.gui
def test_the_splash_shows_until_the_window_is_up(qapp, make_window):
    from app.main import show_splash

    splash = show_splash(qapp)  # a second or two: kernels compile after the window is up
    assert splash.isVisible() and "Starting" in splash.message()
    window = make_window()
    splash.finish(window)
    assert not splash.isVisible()
