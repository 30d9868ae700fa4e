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
