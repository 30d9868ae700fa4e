"""Videos of render hair are drawn off screen at the size asked for: the frames' children are
made in the export's worker, each frame is drawn into an offscreen framebuffer, and the window's
viewport is not repainted for them. No timings here (``python -m app.bench_timeline --sintel``
measures the 22-frame GIF)."""

from __future__ import annotations

import imageio.v2 as imageio
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from app.ui.animation_export import even_size, sequence_paths
from hairtool import samples
from hairtool.simulate.sway import sway_animation

pytestmark = pytest.mark.gui

FRAMES = 8


@pytest.fixture
def hair_window(make_window):
    """20 guides with 300 grown children (clumped) and a sway of the guides, every frame other."""
    from hairtool.guides.binding import bind_roots

    guides = samples.scalp(20, 6, seed=4)
    w = make_window(groom=guides, size=(640, 420))
    w.scene.set_binding(bind_roots(guides, count=300, seed=1))
    w.animation.load_animation(sway_animation(guides, FRAMES, flick_frame=5), "sway")
    w.jobs.wait()
    return w


def _stills(w, size) -> list[np.ndarray]:
    """Each frame drawn alone at ``size`` (in the view's context, as a still of it is)."""
    anim = w.animation.animation
    r = w.exporter.renderer(anim, size, render_hair=True)
    with w.viewport.current_context() as ctx:
        return [r.render(i, ctx)[..., :3] for i in range(anim.n_frames)]


def _export(w, path, size):
    paints = []
    w.viewport.frame_drawn.connect(lambda: paints.append(1))
    job = w.exporter.export_animation(path, size)
    assert job is not False, w.errors
    assert w.jobs.wait(120) and job.state == "done", (job.state, w.errors)
    return len(paints)


def test_a_gif_at_another_size_has_every_frame_at_that_size_and_never_repaints_the_view(
    ui, hair_window, tmp_path
):
    w = hair_window
    ui.grab(w.viewport)  # (the view is drawn once before)
    size = (150, 96)
    assert w.viewport_pixel_size() != size
    paints = _export(w, tmp_path / "shot.gif", size)
    assert paints <= 1  # not one repaint per frame (at most one the event loop had anyway)
    frames = [np.asarray(f)[..., :3] for f in imageio.mimread(tmp_path / "shot.gif")]
    assert len(frames) == FRAMES
    stills = _stills(w, size)
    for i, (frame, still) in enumerate(zip(frames, stills, strict=True)):
        assert frame.shape == (96, 150, 3)
        # GIF keeps a palette of 256 colours: the frame is its still, to a palette step
        assert np.abs(frame.astype(int) - still).mean() < 2.0, i
    assert np.abs(frames[0].astype(int) - frames[5]).mean() > 0.2  # the flick shows
    assert w.errors == []


@settings(max_examples=2, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(width=st.integers(17, 200), height=st.integers(17, 140))
def test_a_png_sequence_is_the_stills_of_its_frames_at_any_size(hair_window, tmp_path_factory, width, height):
    w = hair_window
    out = tmp_path_factory.mktemp("png")
    paints = _export(w, out / "shot.png", (width, height))
    assert paints <= 1
    want = even_size((width, height))
    stills = _stills(w, want)
    for i, path in enumerate(sequence_paths(out / "shot.png", FRAMES)):
        image = imageio.imread(path)[..., :3]
        assert image.shape == (want[1], want[0], 3)
        np.testing.assert_array_equal(image, stills[i])


def test_the_export_dialog_offers_the_viewport_720p_1080p_and_custom(qtbot):
    from app.ui.dialogs import PictureDialog

    video = PictureDialog((500, 300))
    qtbot.addWidget(video)
    assert video.options().size == (500, 300)  # the viewport's by default
    sizes = {}
    for key in ("720p", "1080p"):
        video.size_form.set_choice(key)
        sizes[key] = video.options().size
    assert sizes == {"720p": (1280, 720), "1080p": (1920, 1080)}
    video.size_form.set_choice("custom")
    video.size_form.width_box.setValue(333)
    assert video.options().size == (333, 1080)


def test_each_frames_cpu_raster_is_made_in_the_worker_while_the_window_keeps_ticking(
    hair_window, tmp_path, monkeypatch
):
    """Strands rasterized on the CPU (software GL): the export's worker rasters every frame and
    the GUI thread only composites, so its timer keeps ticking; the frames are the stills."""
    import threading

    from PySide6.QtCore import QTimer

    from app.render.soft_raster import StrandRaster

    monkeypatch.setenv("HAIRTOOL_STRAND_RASTER", "cpu")
    w = hair_window
    gui = threading.get_ident()
    rasters: list[int] = []
    draw = StrandRaster.draw

    def traced(self, *args, **kwargs):
        rasters.append(threading.get_ident())
        return draw(self, *args, **kwargs)

    monkeypatch.setattr(StrandRaster, "draw", traced)
    ticks = []  # the GUI thread's timer, while the export runs
    timer = QTimer()
    timer.timeout.connect(lambda: w.jobs.busy and ticks.append(1))
    timer.start(1)
    try:
        paints = _export(w, tmp_path / "shot.png", (64, 48))
    finally:
        timer.stop()
    assert paints <= 1
    assert len(rasters) == FRAMES and gui not in rasters  # every frame's raster, none on the GUI thread
    assert len(ticks) > FRAMES  # the GUI thread answered its timer all along
    stills = _stills(w, (64, 48))  # (drawn the way every frame was before: on the GUI thread)
    assert rasters.count(gui) == FRAMES
    for i, path in enumerate(sequence_paths(tmp_path / "shot.png", FRAMES)):
        np.testing.assert_array_equal(imageio.imread(path)[..., :3], stills[i])
