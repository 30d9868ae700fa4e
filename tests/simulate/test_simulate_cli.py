"""`hairtool simulate`: writes an animation, reports JSON, refuses bad input with exit code 2."""

from __future__ import annotations

import json

import numpy as np
import pytest

from hairtool.cli import main
from hairtool.io import read, write
from hairtool.samples import scalp


def test_simulates_a_sample_to_an_animated_file(tmp_path, capsys):
    out = tmp_path / "sim.npz"
    rc = main(
        [
            "simulate",
            "sample:scalp:40:8",
            str(out),
            "--motion",
            "turn,nod",
            "--frames",
            "10",
            "--wind",
            "30,0,0",
            "--gusts",
            "2",
            "--seed",
            "3",
            "--substeps",
            "4",
            "--json",
        ]
    )
    assert rc == 0
    report = json.loads(capsys.readouterr().out)
    assert report["frames"] == 10 and report["strands"] == 40 and report["motion"] == ["turn", "nod"]
    anim = read(out)
    assert anim.frames.shape == (10, 320, 3)
    np.testing.assert_allclose(anim.frames[0], scalp(40, 8).points)


def test_reads_a_groom_file_and_is_deterministic(tmp_path, capsys):
    src = tmp_path / "g.npz"
    write(src, scalp(30, 6, seed=1))
    outs = []
    for name in ("a.npz", "b.npz"):
        assert main(["simulate", str(src), str(tmp_path / name), "--frames", "6", "--gusts", "1"]) == 0
        outs.append(read(tmp_path / name).frames)
    np.testing.assert_array_equal(outs[0], outs[1])
    assert "wrote" in capsys.readouterr().out


@pytest.mark.parametrize(
    "argv",
    [
        ["sample:scalp:10:4", "OUT.npz", "--motion", "jump"],
        ["sample:scalp:10:4", "OUT.npz", "--frames", "0"],
        ["sample:scalp:10:4", "OUT.npz", "--wind", "1,2"],
        ["sample:scalp:10:4", "OUT.npz", "--head-center", "a,b,c"],
        ["sample:scalp:10:4", "OUT.npz", "--fit-head", "--head-radius", "2"],
        ["sample:blob", "OUT.npz"],
        ["sample:scalp:x", "OUT.npz"],
        ["sample:scalp:10:4", "OUT.xyz"],
        ["missing.npz", "OUT.npz"],
    ],
)
def test_bad_input_exits_2_with_one_line(tmp_path, capsys, argv):
    argv = [a.replace("OUT", str(tmp_path / "out")) for a in argv]
    assert main(["simulate", *argv]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("hairtool simulate: error:") and "\n" not in err
    assert not (tmp_path / "out.npz").exists()


def test_help_describes_the_motions(capsys):
    with pytest.raises(SystemExit) as e:
        main(["simulate", "--help"])
    assert e.value.code == 0
    assert "follow-the-leader" in capsys.readouterr().out


def test_fit_head_moves_a_scaled_groom_as_the_sample_moves(tmp_path, capsys):
    """A groom 10× larger and moved away, simulated with --fit-head, is the sample's motion
    scaled and moved the same way (to float32 rounding of the solver's positions)."""
    import json

    groom = scalp(30, 6)  # = sample:scalp:30:6
    offset = np.array([5.0, 30.0, -3.0])
    big = groom.with_points(groom.points * 10.0 + offset)
    src = tmp_path / "big.npz"
    write(src, big)
    common = ["--frames", "8", "--motion", "turn,hop", "--gusts", "1", "--wind", "3,0,1", "--json"]
    assert main(["simulate", "sample:scalp:30:6", str(tmp_path / "unit.npz"), *common]) == 0
    capsys.readouterr()
    assert main(["simulate", str(src), str(tmp_path / "big_out.npz"), "--fit-head", *common]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["head_radius"] == pytest.approx(10.0, rel=1e-6)
    np.testing.assert_allclose(report["head_center"], offset, atol=1e-5)
    big_frames = read(tmp_path / "big_out.npz").frames.astype(np.float64)
    unit_frames = read(tmp_path / "unit.npz").frames.astype(np.float64)
    rel = np.abs((big_frames - offset) / 10.0 - unit_frames).max() / np.ptp(unit_frames)
    assert rel < 1e-4  # the sample's own fitted head is its unit head to 1e-8
    assert np.abs(big_frames[-1] - big_frames[0]).max() > 1.0  # and it does move
