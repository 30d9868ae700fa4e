"""Exporting the animation (MP4, GIF, PNG sequence, USD, npz) and its keys from the window."""

from __future__ import annotations

import json

import imageio.v2 as imageio
import numpy as np
import pytest

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


def test_keys_without_an_animation_are_one_clear_error(make_window, out):
    w = make_window()
    assert not w.exporter.export_keys(out / "k.json")
    assert "no keys" in w.errors[-1][1] and not (out / "k.json").exists()


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
