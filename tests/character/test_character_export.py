"""Files out: the character's own bytes kept, STEP keys at the drawings with safe float32 times,
the same rotations read back, and the command line's character paths."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from hairtool.character import load_character
from hairtool.character.accessors import buffers, read
from hairtool.character.cycle import character_cycle
from hairtool.character.export import key_times, write_animated
from hairtool.character.glb import unpack
from hairtool.character.read import _gltf, load_document
from hairtool.cli import main
from hairtool.mocap.bvh import read_bvh

DATA = Path(__file__).resolve().parents[1] / "data" / "characters"
VRM = DATA / "bunches.vrm"


@settings(max_examples=60, deadline=None)
@given(fps=st.sampled_from([24.0, 25.0, 30.0, 60.0, 24000 / 1001, 12.0]), frame=st.integers(0, 200_000))
def test_key_times_never_round_above_their_frame(fps, frame):
    t = key_times(np.array([frame]), fps)[0]
    assert t.dtype == np.float32 and float(t) <= frame / fps
    assert float(np.nextafter(t, np.float32(np.inf))) > frame / fps  # the largest such float32


def _sampled(path, frame, fps, step):
    """(J, 4) wxyz each channel gives at frame/fps, sampled as three.js does (doubles, STEP or LINEAR)."""
    doc, binary = load_document(path)
    gltf = _gltf(str(path), doc)
    data = buffers(str(path), gltf, binary)
    c = load_character(path)
    out = c.nodes.rotation.copy()
    anim = doc["animations"][-1]
    t = frame / fps
    for ch in anim["channels"]:
        s = anim["samplers"][ch["sampler"]]
        times = read(str(path), gltf, data, s["input"], "t").astype(np.float64)
        q = read(str(path), gltf, data, s["output"], "q").astype(np.float64)
        i = max(int(np.searchsorted(times, t, side="right")) - 1, 0)
        assert s["interpolation"] == ("STEP" if step else "LINEAR")
        if step or i + 1 >= len(times):
            v = q[i]
        else:
            u = (t - times[i]) / (times[i + 1] - times[i])
            v = (1 - u) * q[i] + u * q[i + 1]
        out[ch["target"]["node"]] = np.roll(v / np.linalg.norm(v), 1)
    return out


def test_the_cycle_written_keeps_the_characters_bytes_and_plays_every_frame(tmp_path):
    c = load_character(VRM)
    cyc = character_cycle(c)
    frames = cyc.frames(2 * cyc.schedule.n_frames)
    out = tmp_path / "cycle.vrm"
    report = write_animated(VRM, out, frames, c.nodes.rotation, 24.0, name="cycle", step=True, loop_frames=22)
    assert report["interpolation"] == "STEP"
    old_doc, old_bin = unpack("a", VRM.read_bytes())
    new_doc, new_bin = unpack("b", out.read_bytes())
    assert new_bin[: len(old_bin)] == old_bin
    for key, value in old_doc.items():
        if key in ("accessors", "bufferViews"):
            assert new_doc[key][: len(value)] == value
        elif key != "buffers":
            assert new_doc[key] == value, key
    anim = new_doc["animations"][0]
    times = read("b", _gltf("b", new_doc), [new_bin], anim["samplers"][0]["input"], "t")
    assert len(times) == 2 * 6 + 1  # a key at each drawing, and one closing the loop
    for f in range(len(frames)):
        got = _sampled(out, f, 24.0, step=True)
        dots = np.abs(np.sum(got * frames[f], axis=1))
        assert dots.min() > 1 - 1e-6, f


def test_simulate_springs_writes_linear_keys_on_every_frame(tmp_path, capsys):
    out, bvh = tmp_path / "springs.glb", tmp_path / "hair.bvh"
    args = [
        "simulate",
        str(VRM),
        str(out),
        "--springs",
        "--frames",
        "6",
        "--motion",
        "shake",
        "--bvh",
        str(bvh),
    ]
    assert main([*args, "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert read_bvh(bvh).n_frames == 6
    assert report["written"]["frames"] == 6 and report["written"]["interpolation"] == "LINEAR"
    assert load_character(out).clips[0].rotations


def test_anime_on_a_character_and_its_comparison_with_the_springs(tmp_path, capsys):
    out = tmp_path / "cycle.glb"
    args = ["anime", str(VRM), str(out), "--period", "0.45", "--hold", "2", "--compare", "springs", "--json"]
    assert main(args) == 0
    report = json.loads(capsys.readouterr().out)
    assert (report["n_pictures"], report["n_frames"]) == (6, 11)
    cmp = report["compare_springs"]
    assert cmp["frames"] == 11 and len(cmp["chains"]) == 14 and cmp["angular_error_deg"] > 0
    assert main(args) == 0  # reproducible: the same numbers again
    assert json.loads(capsys.readouterr().out)["compare_springs"] == cmp


def test_a_broken_character_is_one_line_and_exit_2(tmp_path, capsys):
    bad = tmp_path / "bad.vrm"
    bad.write_bytes(VRM.read_bytes()[:500])
    assert main(["anime", str(bad), str(tmp_path / "o.glb")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "bad.vrm" in err
    assert not (tmp_path / "o.glb").exists()
    assert main(["simulate", str(bad), str(tmp_path / "o.glb"), "--springs"]) == 2
    assert capsys.readouterr().err.count("\n") == 1


def test_character_options_on_a_groom_are_refused(tmp_path, capsys):
    assert main(["simulate", "sample:portrait:4:4", str(tmp_path / "o.npz"), "--springs"]) == 2
    assert "springs" in capsys.readouterr().err


def test_groom_options_on_a_character_are_refused_not_ignored(tmp_path, capsys):
    out = str(tmp_path / "o.glb")
    assert main(["anime", str(VRM), out, "--sway", "0,1,0"]) == 2
    assert "sway" in capsys.readouterr().err
    assert main(["simulate", str(VRM), out, "--springs", "--wind", "1,0,0"]) == 2
    assert "wind" in capsys.readouterr().err
    assert not (tmp_path / "o.glb").exists()
    sheet = tmp_path / "sheet.csv"
    assert main(["anime", str(VRM), out, "--export-sheet", str(sheet)]) == 0
    assert sheet.read_text().splitlines()[0] == "frame,picture,time"


def test_keys_on_a_characters_animation(tmp_path, capsys):
    out = tmp_path / "springs.glb"
    assert main(["simulate", str(VRM), str(out), "--springs", "--frames", "12", "--motion", "shake"]) == 0
    capsys.readouterr()
    assert main(["keys", str(out), "--keys", "4", "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["frames"] == 12 and report["fps"] == 24.0
    assert len(report["keys"]) == 4 and report["keys"][0] == 0 and report["keys"][-1] == 11
    keyed = tmp_path / "keys.vrm"
    assert main(["keys", str(out), "--keys", "4", "--export", str(keyed)]) == 0
    clip = load_character(keyed).clips[-1]
    for times, _ in clip.rotations.values():
        np.testing.assert_allclose(
            times * 24.0, report["keys"], atol=1e-4
        )  # LINEAR keys at the optimal frames
    assert (
        main(
            [
                "keys",
                str(out),
                "--keys",
                "4",
                "--export",
                str(tmp_path / "x.glb"),
                "--bvh-features",
                "positions",
            ]
        )
        == 0
    )


def test_a_step_clip_holds_its_drawings_when_read_back(tmp_path):
    c = load_character(VRM)
    cyc = character_cycle(c)
    out = tmp_path / "cycle.glb"
    write_animated(VRM, out, cyc.frames(), c.nodes.rotation, 24.0, name="cycle", step=True, loop_frames=11)
    clip = load_character(out).clips[0]
    assert clip.frame_rate() == 24.0  # drawings two frames apart, and the last one held one frame
    frames = clip.frames(c.nodes, 24.0)
    np.testing.assert_allclose(np.abs(np.sum(frames[:11] * cyc.frames(), axis=-1)), 1.0, atol=1e-6)
