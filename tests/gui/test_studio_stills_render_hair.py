"""Stills and videos of what the view draws: the bundled Sintel sample with her 30,000 render
strands (967,296 drawn vertices, where a still once paired the guides' 7,296 points with every
child's colours), at the viewport's size or another, without the working overlays unless asked."""

from __future__ import annotations

import imageio.v2 as imageio
import imageio.v3 as iio
import numpy as np
import pytest

from app.render.camera import Camera
from app.render.drawn import Drawn
from app.render.offscreen import render_drawn
from hairtool.errors import ParameterError
from hairtool.groom import Animation

pytestmark = pytest.mark.gui


@pytest.fixture
def sintel(make_window):
    w = make_window(size=(420, 320))
    assert w.open_bundled_sample(), w.errors
    assert w.scene.binding.child_count == 30_000
    w.viewport.frame_all()
    return w


def _covered(image, background) -> int:
    return int(np.any(np.abs(image[..., :3].astype(int) - background[:3].astype(int)) > 24, axis=2).sum())


def test_a_still_of_sintel_shows_her_render_hair_at_full_density_and_no_overlay(ui, sintel, tmp_path):
    w, v = sintel, sintel.viewport
    w.scene.set_symmetry(True)  # the mirror plane is drawn in the view …
    centre = np.array([v.width() / 2.0, v.height() / 2.0])
    ui.send_mouse(v, "move", centre)  # … and the brush circle under the cursor
    ui.grab(v)
    d = v.drawn(mask=False)
    assert d.vertex_count == 30_000 * 32 + 7_296 and d.colors.shape == (d.vertex_count, 3)
    assert d.shaded and d.taper > 0  # shaded hair, tapered, as on screen

    still = tmp_path / "sintel.png"
    assert w.export_still(still), w.errors
    image = iio.imread(still)
    size = w.viewport_pixel_size()
    assert image.shape[:2] == size[::-1]
    with v.current_context() as ctx:  # the same Drawn rendered again: the still is exactly it
        again = render_drawn(d, size=size, camera=v.camera, mesh=w.scene.mesh, ctx=ctx, strand_raster="gl")
        close = Camera.for_bounds(*w.scene.result.bounds, aspect=4 / 3)  # the hair alone, filling it
        hair, guides = (  # 228 guides leave gaps there that 30,000 children fill
            render_drawn(x, size=(320, 240), camera=close, ctx=ctx, strand_raster="gl")
            for x in (d, Drawn.of_groom(w.scene.result, ramp=d.ramp, line_width=d.line_width))
        )
    np.testing.assert_array_equal(image, again)
    background = image[0, 0]
    assert _covered(hair, background) > 1.25 * _covered(guides, background)  # the children fill in

    with_overlays = tmp_path / "overlays.png"
    assert w.export_still(with_overlays, overlays=True), w.errors
    over = iio.imread(with_overlays)
    changed = np.any(over[..., :3] != image[..., :3], axis=2)
    assert changed.sum() > 200  # the circle and the mirror plane's outline, only when asked

    hd = tmp_path / "custom.png"
    assert w.export_still(hd, size=(192, 108)), w.errors
    assert iio.imread(hd).shape == (108, 192, 4)

    wrong = np.zeros((w.scene.result.vertex_count, 3), np.float32)  # the guides' colours …
    with pytest.raises(ParameterError, match="colors"):  # … never pass for every drawn vertex
        Drawn(d.points, d.topology, make_colors=lambda: wrong).colors  # noqa: B018


def test_a_video_of_sintel_draws_her_render_hair(sintel, tmp_path):
    w = sintel
    rest = w.scene.rest
    frames = np.stack([rest.points + np.float32([0.0, 0.0, 0.4 * k]) for k in range(3)])
    w.animation.load_animation(Animation(frames, rest.counts, 24.0), "test")
    w.jobs.wait()
    hair = w.exporter.renderer(w.animation.animation, (160, 120), render_hair=True)
    drawn = hair.frame_drawn(2)
    assert drawn.vertex_count == 30_000 * 32 + 7_296
    np.testing.assert_array_equal(drawn.points[-rest.vertex_count :], frames[2])
    for name, render_hair in (("hair", True), ("guides", False)):
        job = w.exporter.export_animation(tmp_path / f"{name}.gif", (160, 120), render_hair=render_hair)
        assert job is not False and w.jobs.wait(120) and job.state == "done", w.errors
    read = {n: np.asarray(imageio.mimread(tmp_path / f"{n}.gif")[1])[..., :3] for n in ("hair", "guides")}
    assert read["hair"].shape == (120, 160, 3)
    background = read["guides"][0, 0]
    assert _covered(read["hair"], background) > 1.05 * _covered(read["guides"], background)


def test_the_mask_tint_is_in_stills_and_videos_only_with_overlays(ui, make_window, tmp_path, monkeypatch):
    from app.ui.dialogs import PictureOptions
    from hairtool import samples
    from hairtool.simulate.sway import sway_animation

    groom = samples.scalp(30, 8, seed=4)
    w = make_window(groom=groom, size=(520, 380))
    v = w.viewport
    w.scene.set_brush("mask")
    w.scene.set_radius(0.5)
    tips = v.project(w.scene.result.tips)
    ui.drag(v, tips[0], tips[0] + np.array([40.0, 10.0]), steps=4)
    assert w.scene.locked.any()
    ui.leave(v)
    plain, tinted = tmp_path / "plain.png", tmp_path / "tinted.png"
    assert w.export_still(plain) and w.export_still(tinted, overlays=True), w.errors
    a, b = iio.imread(plain), iio.imread(tinted)
    assert np.any(a != b, axis=2).sum() > 20  # the masked strands' slate blue, only when asked
    size = w.viewport_pixel_size()
    with v.current_context() as ctx:
        untinted = render_drawn(v.drawn(mask=False), size=size, camera=v.camera, ctx=ctx, strand_raster="gl")
    np.testing.assert_array_equal(a, untinted)

    w.animation.load_animation(sway_animation(groom, 4), "sway")
    w.jobs.wait()
    asked = []
    monkeypatch.setattr(w, "ask_save_path", lambda *a, **k: str(tmp_path / "plain.gif"))
    monkeypatch.setattr(w, "ask_picture_options", lambda: asked.append(1) or PictureOptions((100, 80), False))
    assert w.exporter.export_animation_dialog() and asked  # a video asks for its size first
    assert w.jobs.wait(60)
    job = w.exporter.export_animation(tmp_path / "tinted.gif", (100, 80), overlays=True)
    assert job is not False and w.jobs.wait(60) and job.state == "done", w.errors
    frames = {n: np.asarray(imageio.mimread(tmp_path / f"{n}.gif")[0])[..., :3] for n in ("plain", "tinted")}
    assert frames["plain"].shape == (80, 100, 3)
    assert np.any(frames["plain"] != frames["tinted"], axis=2).sum() > 5


def test_the_size_choice_offers_the_viewport_1080p_and_a_custom_size(qtbot):
    from app.ui.dialogs import PictureDialog, StillDialog

    still = StillDialog((640, 360))
    qtbot.addWidget(still)
    assert still.size_px() == (640, 360) and not still.width_box.isEnabled()
    assert not still.overlays.isChecked()  # overlays are left out unless ticked
    still.size_form.set_choice("1080p")
    assert still.size_px() == (1920, 1080)
    still.size_form.set_choice("custom")
    still.width_box.setValue(800)
    assert still.width_box.isEnabled() and still.size_px() == (800, 1080)
    video = PictureDialog((500, 300))
    qtbot.addWidget(video)
    video.size_form.set_choice("1080p")
    video.overlays.setChecked(True)
    assert video.options().size == (1920, 1080) and video.options().overlays
