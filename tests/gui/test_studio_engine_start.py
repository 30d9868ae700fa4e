"""A first start: the window shows before the kernels are compiled, says so when a stroke comes
too early, keeps parameter edits for the engine, and starts it when the warm-up reports."""

from __future__ import annotations

import json
import sys

import numpy as np
import pytest
from PySide6.QtCore import QProcess

from app.ui import kernel_warmup
from app.ui.engine_start import WAIT_MESSAGE
from hairtool import samples

pytestmark = pytest.mark.gui


def test_before_the_engine_the_groom_shows_as_it_is_and_strokes_wait(ui, make_window):
    groom = samples.scalp(strands=60, vertices=8)
    w = make_window(groom=groom, engine_ready=False)
    s, v = w.scene, w.viewport
    assert not s.engine_ready and s.pipeline is None and s.result is groom
    assert v.renderer.strand_raster == "gl"  # the CPU rasterizer's kernels may be compiling
    assert ui.hair_mask(ui.grab(v)).sum() > 0  # drawn all the same
    centre = v.project(s.centre[None])[0]
    ui.drag(v, centre, centre + np.array([40.0, 10.0]))
    assert w.statusBar().currentMessage() == WAIT_MESSAGE
    assert w.undo_stack.count() == 0 and s.pipeline is None
    w.dock.params["stretch_stiffness"].spin.setValue(20.0)  # kept for the engine
    assert s.params.stretch_stiffness == 20.0 and w.undo_stack.count() == 1
    s.set_colour_mode("clump")  # no clumps yet: grey, no error
    assert not w.errors

    s.start_engine()
    assert s.engine_ready and s.pipeline is not None and s.pipeline.params.stretch_stiffness == 20.0
    assert not np.array_equal(s.result.points, groom.points)  # the frozen look, at last
    from app.render.strands import default_strand_raster

    assert v.renderer.strand_raster == default_strand_raster()
    ui.drag(v, centre, centre + np.array([40.0, 10.0]))
    assert w.undo_stack.count() == 2


def test_the_warm_up_reports_progress_and_starts_the_engine(make_window, qtbot, monkeypatch):
    """The engine starts when its own step is cached, whatever else is still compiling; the CPU
    strand rasterizer takes over from GL's lines only once its step is cached too."""
    labels = [kernel_warmup.ENGINE_STEP, kernel_warmup.RENDER_HAIR_STEP, kernel_warmup.RASTER_STEP]
    _fake_warm_up(monkeypatch, labels, 0.4)
    w = make_window(groom=samples.comb(strands=10, vertices=6), engine_ready=False)
    v = w.viewport
    at_start = []  # what the engine's start found
    w.scene.engine_started.connect(lambda: at_start.append((set(es.done), v.renderer.strand_raster)))
    w.start_warmup()
    es = w.engine_start
    qtbot.waitUntil(lambda: w.scene.engine_ready, timeout=10_000)
    # started on its own step, drawn with GL's lines while the rasterizer's kernels may compile
    assert at_start == [({kernel_warmup.ENGINE_STEP}, "gl")]
    qtbot.waitUntil(lambda: v.raster_ready, timeout=10_000)
    from app.render.strands import default_strand_raster

    assert es.step == 3 and v.renderer.strand_raster == default_strand_raster()
    qtbot.waitUntil(lambda: not es.running and es.label is None, timeout=10_000)
    assert w.scene.pipeline is not None


def test_a_first_start_runs_the_serial_twins_until_the_parallel_kernels_are_cached(
    ui, make_window, qtbot, monkeypatch
):
    """Strokes work on either; the switch comes once both parallel steps are cached."""
    from hairtool import serial_twins

    labels = [kernel_warmup.ENGINE_STEP, kernel_warmup.PARALLEL_ENGINE_STEP, kernel_warmup.RENDER_HAIR_STEP,
              kernel_warmup.PARALLEL_RENDER_HAIR_STEP, "more"]  # fmt: skip
    _fake_warm_up(monkeypatch, labels, 0.4)
    w = make_window(groom=samples.comb(strands=10, vertices=6), engine_ready=False)
    modes = []
    w.scene.engine_started.connect(lambda: modes.append(serial_twins.parallel_in_use()))
    w.start_warmup()
    es = w.engine_start
    assert not serial_twins.parallel_in_use()
    qtbot.waitUntil(lambda: kernel_warmup.PARALLEL_ENGINE_STEP in es.done, timeout=10_000)
    assert modes == [False] and not serial_twins.parallel_in_use()  # one of the two is not enough
    v = w.viewport
    centre = v.project(w.scene.centre[None])[0]
    ui.drag(v, centre, centre + np.array([30.0, 10.0]))  # on the serial twins
    qtbot.waitUntil(lambda: kernel_warmup.PARALLEL_RENDER_HAIR_STEP in es.done, timeout=10_000)
    assert serial_twins.parallel_in_use()
    ui.drag(v, centre + np.array([30.0, 10.0]), centre)  # on the parallel kernels
    assert w.undo_stack.count() == 2 and not w.errors
    serial_twins.use_parallel(False)
    w.close()  # a start ended early leaves the process on the parallel kernels, as by default
    assert serial_twins.parallel_in_use()


def test_two_lanes_start_the_engine_from_either_and_end_together(make_window, qtbot, monkeypatch):
    """Each warm-up lane reports its own steps (numbered in the whole warm-up); the progress counts
    both, the engine starts on its step, and ``ended`` comes once, after the slower lane."""
    from app.ui.engine_start import EngineStart

    scripts = [
        "import time\ntime.sleep(2.0)\nprint('step 1 3 hair engine', flush=True)",
        "print('step 2 3 render hair', flush=True)\nprint('step 3 3 strand drawing', flush=True)",
    ]

    def start(self):
        for process, script in zip(self.processes, scripts, strict=True):
            process.start(sys.executable, ["-c", script])

    monkeypatch.setattr(EngineStart, "start", start)
    w = make_window(groom=samples.comb(strands=10, vertices=6), engine_ready=False)
    ended = []
    w.start_warmup()
    es = w.engine_start
    es.ended.connect(lambda: ended.append(es.step))
    qtbot.waitUntil(lambda: w.viewport.raster_ready, timeout=10_000)
    assert not w.scene.engine_ready  # the rasterizer's lane was first
    qtbot.waitUntil(lambda: w.scene.engine_ready, timeout=10_000)
    qtbot.waitUntil(lambda: not es.running, timeout=10_000)
    qtbot.waitUntil(lambda: bool(ended), timeout=10_000)
    assert ended == [3]


def _fake_warm_up(monkeypatch, labels: list[str], pause_s: float = 0.2) -> None:
    """The warm-up replaced by a process that reports ``labels`` as its steps."""
    from app.ui.engine_start import EngineStart

    lines = [f"step {i + 1} {len(labels)} {label}" for i, label in enumerate(labels)]
    script = f"import time\nfor line in {lines!r}:\n    print(line, flush=True)\n    time.sleep({pause_s})"
    monkeypatch.setattr(EngineStart, "start", lambda self: self.process.start(sys.executable, ["-c", script]))


@pytest.mark.slow(seconds=12)
def test_a_first_start_shows_sintels_guides_and_binds_her_render_hair_when_its_kernels_are_ready(
    make_window, qtbot, monkeypatch
):
    _fake_warm_up(monkeypatch, ["hair engine", "strand drawing", kernel_warmup.RENDER_HAIR_STEP, "more"], 0.3)
    w = make_window(engine_ready=False)
    assert w.open_bundled_sample(), w.errors
    s = w.scene
    assert not s.has_children and s.colour_mode == "root-to-tip"  # nothing compiled on this thread
    assert s.rest.strand_count == 228 and "render hair" in w.statusBar().currentMessage()
    w.start_warmup()
    qtbot.waitUntil(lambda: s.has_children, timeout=10_000)
    assert w.engine_start.step >= 3 and s.colour_mode == "hair"
    assert s.binding.child_count > 1000


def test_a_groom_opened_before_the_render_hair_step_keeps_no_children(make_window, qtbot, monkeypatch):
    _fake_warm_up(monkeypatch, ["hair engine", "strand drawing", kernel_warmup.RENDER_HAIR_STEP])
    w = make_window(engine_ready=False)
    assert w.open_bundled_sample(), w.errors
    w.set_groom(samples.comb(strands=10, vertices=6))  # the artist's own groom, first
    w.start_warmup()
    qtbot.waitUntil(lambda: not w.engine_start.running, timeout=10_000)
    assert not w.scene.has_children and w.scene.rest.strand_count == 10


def test_a_failed_warm_up_still_starts_the_engine(make_window, qtbot, monkeypatch):
    from app.ui.engine_start import EngineStart

    monkeypatch.setattr(
        EngineStart, "start", lambda self: self.process.start(sys.executable, ["-c", "raise SystemExit(3)"])
    )
    w = make_window(groom=samples.comb(strands=10, vertices=6), engine_ready=False)
    w.start_warmup()
    qtbot.waitUntil(lambda: w.scene.engine_ready, timeout=10_000)
    assert w.engine_start.process.state() == QProcess.ProcessState.NotRunning


def test_kernels_cached_reads_the_warm_up_record(tmp_path, monkeypatch):
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    assert not kernel_warmup.kernels_cached()  # no record: a first start
    assert samples.comb(strands=4, vertices=3).bounds is not None  # compiles or loads bounds' kernel
    every = [label for label, _ in kernel_warmup.STEPS]
    record = kernel_warmup.record_path()
    record.parent.mkdir(parents=True)
    record.write_text(json.dumps({"steps": every, "kernels": ["hairtool.bounds:_box"]}))
    assert kernel_warmup.kernels_cached()
    record.write_text(json.dumps({"steps": every[:-1], "kernels": ["hairtool.bounds:_box"]}))
    assert not kernel_warmup.kernels_cached()  # a warm-up stopped before its end
    gone = ["hairtool.bounds:_box", "hairtool.frozen.nothing:_here"]
    record.write_text(json.dumps({"steps": every, "kernels": gone}))
    assert not kernel_warmup.kernels_cached()
    record.write_text("not json")
    assert not kernel_warmup.kernels_cached()
    # the studio's lanes record apart: cached when their records together cover every step
    for lane, labels in enumerate(kernel_warmup.LANES, start=1):
        lane_record = {"steps": list(labels), "kernels": ["hairtool.bounds:_box"]}
        kernel_warmup.record_path(lane).write_text(json.dumps(lane_record))
        assert kernel_warmup.kernels_cached() == (lane == len(kernel_warmup.LANES))


def test_the_lanes_share_out_every_step_once_the_first_screen_first():
    lanes = kernel_warmup.LANES
    flat = [label for lane in lanes for label in lane]
    assert sorted(flat) == sorted(label for label, _ in kernel_warmup.STEPS)
    assert lanes[0][0] == kernel_warmup.ENGINE_STEP  # the engine's lane starts at once
    for lane in lanes:  # no step of the rest before one of the first screen
        ranks = [label in kernel_warmup.FIRST_SCREEN for label in lane]
        assert ranks == sorted(ranks, reverse=True), lane
    for lane in lanes:  # the serial twins first: the parallel kernels are the later starts'
        quick = [label in kernel_warmup.QUICK_STEPS for label in lane]
        assert quick == sorted(quick, reverse=True), lane
    # every start after the first: the steps it needs leave the serial twins out
    assert not set(kernel_warmup.QUICK_STEPS) & set(kernel_warmup.lane_labels(None, quick=False))
    with pytest.raises(SystemExit, match="--lane takes"):
        kernel_warmup.main(["--lane", "9"])


def test_the_warm_up_runs_its_steps_and_records_the_kernels(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    assert kernel_warmup.main() == 0
    lines = capsys.readouterr().out.splitlines()
    n = len(kernel_warmup.STEPS)
    assert lines == [f"step {i + 1} {n} {label}" for i, (label, _) in enumerate(kernel_warmup.STEPS)]
    names = json.loads(kernel_warmup.record_path().read_text())["kernels"]
    assert "app.render.soft_raster:draw_bands" in names and "hairtool.frozen.clump:_clump_run" in names
    # what an artist reaches after the first groom: other brushes, render hair, keys, waves, sims,
    # a character's springs, clump colours, picked guides, a price per key
    for kernel in (
        "hairtool.frozen.brushes.comb:_comb_kernel",
        "hairtool.guides.children:_children_kernel",
        "hairtool.guides.children:_moved_kernel",
        "app.render.hair_shading:_shade_kernel",
        "hairtool.keys.dp:_layer_block",
        "hairtool.keys.segment_fit:_fit_kernel",
        "hairtool.anime.pose:_pose_kernel",
        "hairtool.simulate.dynamics:_frame_kernel",
        "hairtool.character.springs_kernel:spring_step_kernel",
        "hairtool.frozen.strand_clumps:_basins",
        "hairtool.guides.nearest:_fps_kernel",
        "hairtool.keys.dp:_penalty_kernel",
    ):
        assert kernel in names
    assert kernel_warmup.kernels_cached()


def test_the_head_step_compiles_the_drags_closest_points_kernel():
    """The other lane takes the align drag's head kernel off the engine's lane: its step must
    reach it (its types are float64 whatever the groom, so the drag then loads it)."""
    from hairtool import serial_twins
    from hairtool.frozen.brushes import first_hit
    from hairtool.guides import surface

    dict(kernel_warmup.STEPS)[kernel_warmup.HEAD_STEP]()
    # the step runs on the serial twins (a first start's), so it is the twin that has them (the
    # parallel kernel's signatures came only from tests run before this one in the process)
    grid_closest = serial_twins.serial(serial_twins.parallel_of(surface._grid_closest_kernel))
    assert grid_closest.signatures and surface._bin_faces.signatures
    assert first_hit._first_hit_kernel.signatures  # the head under the mouse


def test_clump_children_on_a_first_start_waits_for_its_kernels_and_the_parallel_ones(
    make_window, qtbot, monkeypatch
):
    """On before the warm-up has cached the children's clumping (grown children, on by default;
    a project saved with it), the render hair shows unclumped rather than the window compiling;
    it clumps once that step is cached and the studio runs on the parallel kernels it compiled."""
    from hairtool import serial_twins
    from hairtool.guides.binding import bind_roots

    k = kernel_warmup
    labels = [k.ENGINE_STEP, k.RENDER_HAIR_STEP, k.CLUMPED_HAIR_STEP, k.PARALLEL_ENGINE_STEP,
              k.PARALLEL_RENDER_HAIR_STEP, "more"]  # fmt: skip
    _fake_warm_up(monkeypatch, labels, 0.4)
    w = make_window(groom=samples.scalp(strands=60, vertices=12, seed=4), engine_ready=False)
    w.start_warmup()
    s = w.scene
    qtbot.waitUntil(lambda: s.engine_ready, timeout=10_000)
    s.set_binding(bind_roots(s.rest, count=300, seed=2))
    assert s.clump_children  # grown children: on by default
    plain = s.binding.build(s.result).points
    drawn = lambda: s.drawn_points[: s.binding.vertex_count]  # noqa: E731
    np.testing.assert_array_equal(drawn(), plain)  # not yet cached
    qtbot.waitUntil(lambda: k.CLUMPED_HAIR_STEP in w.engine_start.done, timeout=10_000)
    assert not serial_twins.parallel_in_use() and not s.children_clump_ready  # its kernels are parallel
    np.testing.assert_array_equal(drawn(), plain)
    qtbot.waitUntil(lambda: s.children_clump_ready, timeout=10_000)
    assert serial_twins.parallel_in_use()
    clumped = s.render_hair().points
    assert np.abs(clumped - plain).max() > 1e-4
    np.testing.assert_array_equal(drawn(), clumped)


def test_the_clumped_hair_step_compiles_clump_children_as_the_studio_runs_it():
    """In a process of its own (nothing else compiled there): the step reaches the children's
    clumping and its length pass, with the types the studio's Clump children gives them."""
    import subprocess

    code = (
        "from app.ui import kernel_warmup as k; dict(k.STEPS)[k.CLUMPED_HAIR_STEP]()\n"
        "from hairtool.guides import child_clumps; from hairtool.frozen import lengths\n"
        "print(len(child_clumps._clumps_kernel.signatures), "
        "sum('float32' in str(s) for s in lengths._restore_kernel.signatures))"
    )
    run = [sys.executable, "-c", code]
    out = subprocess.run(run, capture_output=True, text=True, check=True, timeout=600)
    clumps, restores = map(int, out.stdout.split())
    assert clumps >= 1 and restores >= 1
