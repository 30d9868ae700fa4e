"""Exporting the animation (MP4, GIF, PNG sequence, USD, npz) and its keys from the window."""

from __future__ import annotations

import json

import imageio.v2 as imageio
import numpy as np
import pytest
from PySide6.QtCore import Qt

from hairtool import io, samples
from hairtool.simulate.sway import sway_animation

pytestmark = pytest.mark.gui

FRAMES = 10


@pytest.fixture
def window(make_window):
    """A window with a short animation whose every frame differs (a GIF merges equal ones)."""
    groom = samples.scalp(20, 6, seed=4)
    w = make_window(groom=groom, size=(640, 420))
    anim = sway_animation(groom, FRAMES, flick_frame=6)
    w.animation.load_animation(anim, "sway")
    w.jobs.wait()
    return w


@pytest.fixture
def out(tmp_path):
    """Exports go here, apart from the settings file the window keeps in ``tmp_path``."""
    d = tmp_path / "out"
    d.mkdir()
    return d


def _wait(w, job):
    assert job is not False, w.errors
    assert w.jobs.wait(60)
    assert job.state == "done", (job.state, w.errors)


def test_mp4_and_gif_have_one_frame_per_animation_frame(window, out):
    w = window
    for name in ("shot.mp4", "shot.gif"):
        _wait(w, w.exporter.export_animation(out / name))
        reader = imageio.get_reader(out / name)
        frames = [np.asarray(f) for f in reader]
        reader.close()
        assert len(frames) == FRAMES, name
        h, wd = frames[0].shape[:2]
        assert h % 2 == 0 and wd % 2 == 0 and h > 100 and wd > 100
        assert not np.array_equal(frames[0], frames[6])  # the flick shows
    assert sorted(p.name for p in out.iterdir()) == ["shot.gif", "shot.mp4"]
    assert w.errors == []


def test_cancelled_video_export_leaves_no_file(window, out):
    w = window
    target = out / "old.mp4"
    target.write_bytes(b"previous export")
    job = w.exporter.export_animation(target)
    w.jobs.cancel(job)
    assert w.jobs.wait(60)
    assert job.state == "cancelled"
    assert target.read_bytes() == b"previous export"
    assert [p.name for p in out.iterdir()] == ["old.mp4"]  # no temporary file left


def test_png_sequence_and_data_formats(window, out):
    w = window
    (out / "seq").mkdir()
    _wait(w, w.exporter.export_animation(out / "seq" / "f.png", size=(121, 81)))
    names = sorted(p.name for p in (out / "seq").iterdir())
    assert names == [f"f_{i:04d}.png" for i in range(FRAMES)]
    assert imageio.imread(out / "seq" / "f_0003.png").shape[:2] == (80, 120)
    for name in ("a.usda", "a.npz"):
        assert w.exporter.export_animation(out / name) is True
        back = io.read(out / name)
        np.testing.assert_array_equal(back.frames, w.animation.animation.frames)
    assert w.exporter.export_animation(out / "a.obj") is False
    assert "a.obj" in w.errors[-1][1]


def test_exported_keys_read_back_as_json_csv_and_usd(window, out):
    from pxr import Usd, UsdGeom

    from hairtool.keys.export import read_keys_json

    w = window
    keys = w.animation.dp_keys.tolist()
    assert len(keys) >= 2
    assert w.exporter.export_keys(out / "k.json"), w.errors
    record = read_keys_json(out / "k.json")
    assert [k["frame"] for k in record["keys"]] == keys and record["fps"] == w.animation.animation.fps
    assert record["uniform"]["keys"] == w.animation.uniform_keys.tolist()
    assert record["params"]["mode"] == "count" and record["cost"] >= 0.0
    assert w.exporter.export_keys(out / "k.csv")
    assert len((out / "k.csv").read_text().splitlines()) == FRAMES + 1
    assert w.exporter.export_keys(out / "k.usda")
    stage = Usd.Stage.Open(str(out / "k.usda"))
    curves = next(UsdGeom.BasisCurves(p) for p in stage.Traverse() if p.IsA(UsdGeom.BasisCurves))
    assert curves.GetPointsAttr().GetTimeSamples() == [float(k) for k in keys]
    assert json.loads((out / "k.json").read_text())["input"] == "sway"


def test_exported_keys_carry_the_pins_and_exclusions(window, out):
    import csv

    from hairtool.keys.export import read_keys_json

    w = window
    m = w.animation
    pin = next(f for f in range(1, FRAMES - 1) if f not in m.dp_keys)
    excluded = next(f for f in range(1, FRAMES - 1) if f != pin)
    steer = w.animation_ui.steer_keys
    assert steer("Pin", pin=pin) and steer("Exclude", exclude=excluded)
    assert w.exporter.export_keys(out / "k.json") and w.exporter.export_keys(out / "k.csv"), w.errors
    record = read_keys_json(out / "k.json")
    assert record["params"]["pins"] == [pin] and record["params"]["excludes"] == [excluded]
    assert record["uniform"]["ignores"] == {"pins": 1, "excludes": 1}
    with open(out / "k.csv", newline="", encoding="utf-8") as f:
        keyed = {int(r["frame"]): r["pinned"] for r in csv.DictReader(f) if r["key"] == "1"}
    assert list(keyed) == m.dp_keys.tolist() and excluded not in keyed
    assert {f for f, pinned in keyed.items() if pinned == "1"} == {pin}
    assert "the uniform keys ignore the pins" in w.timeline.controls.summary.text()


def test_keys_without_an_animation_are_one_clear_error(make_window, out):
    w = make_window()
    assert not w.exporter.export_keys(out / "k.json")
    assert "no keys" in w.errors[-1][1] and not (out / "k.json").exists()


def test_the_export_entries_are_greyed_out_saying_why_until_there_is_something_to_write(make_window):
    from app.ui import animation_export as ae

    w = make_window(groom=samples.scalp(20, 6, seed=4), size=(640, 420))
    entries = {a.text(): a for a in w.menuBar().actions()[0].menu().actions()}
    animation, keys = entries["Export &Animation…"], entries["Export &Keys…"]
    assert not animation.isEnabled() and animation.toolTip() == ae.NO_ANIMATION
    assert not keys.isEnabled() and keys.toolTip() == ae.NO_KEYS
    w.animation.load_animation(sway_animation(w.scene.rest, FRAMES, flick_frame=6), "sway")
    assert animation.isEnabled() and animation.toolTip() == ae.ANIMATION_TIP
    w.jobs.wait()
    assert keys.isEnabled() and keys.toolTip() == ae.KEYS_TIP
    w.animation.clear()
    assert not animation.isEnabled() and not keys.isEnabled() and keys.toolTip() == ae.NO_KEYS
    remove = next(a for a in w.menuBar().actions() if a.text() == "&Groom").menu().actions()[1]
    assert not remove.isEnabled() and "No render hair" in remove.toolTip()


def test_write_video_cancelled_mid_way_and_bad_frames(tmp_path):
    from app.ui.animation_export import write_video
    from hairtool.errors import Cancelled, FormatError, ParameterError

    frames = [np.full((32, 48, 3), i * 20, np.uint8) for i in range(8)]
    seen = []
    with pytest.raises(Cancelled):
        write_video(
            tmp_path / "c.gif",
            frames,
            8,
            12.0,
            progress=lambda f, t="": seen.append(f),
            cancelled=lambda: len(seen) >= 3,
        )
    assert list(tmp_path.iterdir()) == [] and len(seen) == 3
    with pytest.raises(ParameterError, match="frames"):
        write_video(tmp_path / "short.mp4", frames[:5], 8, 12.0)
    with pytest.raises(FormatError, match="avi"):
        write_video(tmp_path / "v.avi", frames, 8, 12.0)
    assert list(tmp_path.iterdir()) == []


@pytest.fixture
def render_hair_window(make_window):
    """A groom with 300 children and an animation of its guides."""
    from hairtool.guides.binding import bind_roots

    guides = samples.scalp(20, 6, seed=4)
    w = make_window(groom=guides, size=(640, 420))
    w.scene.set_binding(bind_roots(guides, count=300, seed=1))
    w.animation.load_animation(sway_animation(guides, FRAMES, flick_frame=6), "sway")
    w.jobs.wait()
    return w


def test_animation_export_writes_render_hair_when_the_groom_has_children(render_hair_window, out):
    from hairtool.guides.files import split_guides

    w = render_hair_window
    anim, binding = w.animation.animation, w.scene.binding
    assert w.exporter.render_hair_binding() is binding
    _wait(w, w.exporter.export_animation(out / "hair.usdc"))  # render hair by default: a job
    children, guides = split_guides(io.read(out / "hair.usdc"))
    assert (children.strand_count, guides.strand_count, children.n_frames) == (300, 20, FRAMES)
    assert guides.frames.tobytes() == anim.frames.tobytes()
    # clumped on every frame, as the view draws them (Clump children: on for grown children)
    from hairtool.guides.render import RenderHair

    clump = w.scene.children_clump()
    assert clump is not None
    clumped = RenderHair(binding, clump, follow_roots=True).update(anim.frame(6)).points
    assert children.frames[6].tobytes() == clumped.tobytes()
    w.scene.set_clump_children(False)  # off: the interpolation itself
    _wait(w, w.exporter.export_animation(out / "plain.usdc"))
    plain = split_guides(io.read(out / "plain.usdc"))[0]
    from hairtool.guides.root_motion import following

    pose = anim.frame(6)  # the children's roots carried by the guides' (the head moves)
    assert plain.frames[6].tobytes() == following(binding, pose).build(pose).points.tobytes()
    assert np.abs(plain.frames[6] - clumped).max() > 1e-4
    _wait(w, w.exporter.export_animation(out / "hair.npz"))
    assert io.read(out / "hair.npz").strand_count == 300
    assert io.read(out / "hair.guides.npz").frames.tobytes() == anim.frames.tobytes()
    assert w.exporter.export_animation(out / "g.usda", render_hair=False) is True  # the guides alone
    assert io.read(out / "g.usda").frames.tobytes() == anim.frames.tobytes()
    assert w.errors == []


def test_the_export_dialog_asks_for_render_hair_first(render_hair_window, out, monkeypatch):
    from app.ui.animation_export import RenderHairDialog

    w = render_hair_window
    dialog = RenderHairDialog(300, 20, w)
    assert dialog.render_hair.isChecked() and "300" in dialog.render_hair.text()
    dialog.deleteLater()
    monkeypatch.setattr(w, "ask_save_path", lambda *a, **k: str(out / "guides.npz"))
    monkeypatch.setattr(w.exporter, "ask_render_hair", lambda binding: False)
    assert w.exporter.export_animation_dialog()
    assert io.read(out / "guides.npz").strand_count == 20 and not (out / "guides.guides.npz").exists()
    monkeypatch.setattr(w.exporter, "ask_render_hair", lambda binding: None)  # cancelled: no file asked
    monkeypatch.setattr(w, "ask_save_path", lambda *a, **k: pytest.fail("asked for a file"))
    assert not w.exporter.export_animation_dialog()


def test_an_animation_of_other_strands_has_no_render_hair(render_hair_window, out):
    w = render_hair_window
    w.animation.load_animation(sway_animation(samples.scalp(7, 5, seed=1), FRAMES), "other")
    w.jobs.wait()
    assert w.exporter.render_hair_binding() is None
    assert w.exporter.export_animation(out / "o.usda") is True  # written as it is
    assert io.read(out / "o.usda").strand_count == 7
    assert w.exporter.export_animation(out / "x.usda", render_hair=True) is False
    assert "guides" in w.errors[-1][1] and not (out / "x.usda").exists()


def test_a_video_of_render_hair_draws_the_children(render_hair_window, out):
    w = render_hair_window
    anim = w.animation.animation
    hair = w.exporter.renderer(anim, (96, 64), render_hair=True)
    guides = w.exporter.renderer(anim, (96, 64), render_hair=False)
    drawn = hair.frame_groom(6)
    assert drawn.strand_count == w.scene.drawn_topology.strand_count
    from hairtool.guides.render import RenderHair

    clumped = RenderHair(w.scene.binding, w.scene.children_clump(), follow_roots=True).update(anim.frame(6))
    assert drawn.points[: w.scene.binding.vertex_count].tobytes() == clumped.points.tobytes()
    again = hair.frame_groom(6)  # (the frames' clumper keeps its runs: the same bytes again)
    assert again.points.tobytes() == drawn.points.tobytes()
    assert guides.frame_groom(6).strand_count == 20
    _wait(w, w.exporter.export_animation(out / "hair.gif", size=(96, 64)))
    _wait(w, w.exporter.export_animation(out / "guides.gif", size=(96, 64), render_hair=False))
    frames = {n: np.asarray(imageio.mimread(out / f"{n}.gif")[0])[..., :3] for n in ("hair", "guides")}
    background = frames["guides"][0, 0]
    covered = {n: int(np.any(f != background, axis=2).sum()) for n, f in frames.items()}
    assert covered["hair"] > covered["guides"]  # 300 children fill more pixels than 20 guides


def test_a_playing_animation_draws_its_children_unclumped_and_the_frame_it_stops_on_clumped(
    ui, qtbot, render_hair_window, monkeypatch
):
    """Clumping every child on every frame would hold playback to a few frames a second on
    Sintel: while it plays the view draws them as interpolated, the frame it stops on (and any
    exported frame, even during playback) clumped, as the groom's are (the children's roots
    carried by their guides' on every frame)."""
    from hairtool.guides.render import RenderHair
    from hairtool.guides.root_motion import following

    w = render_hair_window
    s, v, model = w.scene, w.viewport, w.animation
    anim, b = model.animation, s.binding
    n = b.vertex_count
    clumped = RenderHair(b, s.children_clump(), follow_roots=True).update(anim.frame(6)).points
    model.set_frame(6)
    ui.grab(v)
    np.testing.assert_array_equal(v.drawn().points[:n], clumped)
    model.play()
    assert s.frames_live
    model.set_frame(6)
    ui.grab(v)
    np.testing.assert_array_equal(
        v.drawn().points[:n], following(b, anim.frame(6)).build(anim.frame(6)).points
    )
    frame = w.exporter.renderer(anim, (96, 64), render_hair=True).frame_groom(6)
    np.testing.assert_array_equal(frame.points[:n], clumped)  # exported: clumped all the same
    model.pause()
    assert not s.frames_live
    np.testing.assert_array_equal(v.drawn().points[:n], clumped)
    view = w.timeline.view  # the timeline's frame dragged with the mouse: as while playing …
    left = Qt.MouseButton.LeftButton
    y = view.height() - 4  # (the ruler, below the key rows)
    ui.send_mouse(view, "press", (view.frame_to_x(3), y), left, left)
    ui.send_mouse(view, "move", (view.frame_to_x(5), y), None, left)
    assert s.frames_live and model.frame == 5
    frames = w.animation_ui.frames  # (the drag's share of the children, built in its worker)
    qtbot.waitUntil(lambda: not frames.busy and v.frame_children is not None, timeout=30_000)
    share = s.drawn_binding()
    assert share.child_count == 30
    np.testing.assert_array_equal(
        v.drawn().points[: share.vertex_count], following(share, anim.frame(5)).build(anim.frame(5)).points
    )
    ui.send_mouse(view, "release", (view.frame_to_x(5), y), left, None)  # … let go: clumped …
    qtbot.waitUntil(lambda: not s.frames_live, timeout=30_000)  # … once the worker has them
    want = RenderHair(b, s.children_clump(), follow_roots=True).update(anim.frame(5)).points
    np.testing.assert_array_equal(v.drawn().points[:n], want)
    model.play()  # a press while it plays: it pauses and stays live until the release
    live = []
    monkeypatch.setattr(s, "set_frames_live", lambda on: live.append(on) or setattr(s, "frames_live", on))
    ui.send_mouse(view, "press", (view.frame_to_x(4), y), left, left)
    assert not model.playing and s.frames_live and live == []
    ui.send_mouse(view, "release", (view.frame_to_x(4), y), left, None)
    qtbot.waitUntil(lambda: live == [False], timeout=30_000)  # (when its clumped frame lands)
