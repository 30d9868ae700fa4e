"""``hairtool info``, ``convert`` and ``sample``: output, exit codes, one-line errors."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import numpy as np
import pytest

from hairtool.cli import main
from hairtool.groom import Animation
from hairtool.io import hairfile, read, write
from hairtool.samples import scalp


def test_sample_then_info_json(tmp_path, capsys):
    out = tmp_path / "s.hair"
    assert main(["sample", "scalp", str(out), "--strands", "30", "--vertices", "7", "--seed", "3"]) == 0
    assert "30 strands" in capsys.readouterr().out
    np.testing.assert_array_equal(read(out).points, scalp(30, 7, seed=3).points)
    assert main(["info", str(out), "--json"]) == 0
    info = json.loads(capsys.readouterr().out)
    assert info["format"].startswith("HAIR") and info["kind"] == "groom"
    assert (info["strands"], info["vertices"]) == (30, 210)
    assert info["vertices_per_strand"] == {"min": 7, "mean": 7.0, "max": 7}
    g = scalp(30, 7, seed=3)
    assert info["bounds"]["min"] == pytest.approx(g.points.min(axis=0).tolist())
    assert info["attributes"] == [] and "frames" not in info


def test_info_text_for_an_animation_and_a_real_groom(tmp_path, capsys, grooms_dir):
    g = scalp(10, 5)
    a = Animation(np.stack([g.points] * 4), g.topology, 25, thickness=np.ones(g.vertex_count))
    write(tmp_path / "a.npz", a)
    assert main(["info", str(tmp_path / "a.npz")]) == 0
    text = capsys.readouterr().out
    assert "frames      4 at 25 fps" in text and "thickness" in text
    assert main(["info", str(grooms_dir / "ponytail_tail.tfx"), "--json"]) == 0
    info = json.loads(capsys.readouterr().out)
    assert (info["strands"], info["vertices"]) == (474, 474 * 16)


def test_convert_keeps_animations_where_it_can_and_warns_where_it_cannot(tmp_path, capsys):
    g = scalp(10, 5)
    a = Animation(np.stack([g.points, g.points + 1, g.points + 2]), g.topology, 30)
    write(tmp_path / "a.npz", a)
    assert main(["convert", str(tmp_path / "a.npz"), str(tmp_path / "a.usdc")]) == 0
    assert read(tmp_path / "a.usdc").frames.tobytes() == a.frames.tobytes()
    assert capsys.readouterr().err == ""
    assert main(["convert", str(tmp_path / "a.usdc"), str(tmp_path / "a.obj")]) == 0
    captured = capsys.readouterr()
    assert "warning" in captured.err and "dropping 2 of 3 frames" in captured.err
    assert read(tmp_path / "a.obj").points.tobytes() == g.points.tobytes()


def test_convert_hair_to_hair_keeps_the_info_string(tmp_path):
    hairfile.write(tmp_path / "in.hair", scalp(5, 4), info="scanned by hand")
    assert main(["convert", str(tmp_path / "in.hair"), str(tmp_path / "out.hair")]) == 0
    assert hairfile.read_header(tmp_path / "out.hair").info == "scanned by hand"


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["info", "{tmp}/absent.hair"], "no such file"),
        (["info", "{tmp}/x.xyz"], "cannot read '.xyz'"),
        (["info", "{tmp}/bad.hair"], "not a HAIR file"),
        (["convert", "{tmp}/bad.hair", "{tmp}/out.tfx"], "cannot write '.tfx'"),
        (["convert", "{tmp}/absent.npz", "{tmp}/out.obj"], "no such file"),
        (["sample", "braid", "{tmp}/s.hair"], "kind='braid'"),
        (["sample", "scalp", "{tmp}/s.hair", "--vertices", "1"], "vertices=1"),
        (["sample", "scalp", "{tmp}/s.png"], "cannot write '.png'"),
    ],
)
def test_bad_input_exits_2_with_one_line(tmp_path, capsys, argv, message):
    (tmp_path / "bad.hair").write_bytes(b"NOPE" + b"\0" * 200)
    (tmp_path / "x.xyz").write_text("x")
    assert main([a.format(tmp=tmp_path) for a in argv]) == 2
    err = capsys.readouterr().err
    assert message in err
    assert err.count("\n") == 1 and "Traceback" not in err


def test_an_output_in_a_missing_folder_gets_the_folder(tmp_path, capsys):
    """As a render ROP does: a shot's new output folder needs no mkdir first."""
    write(tmp_path / "in.hair", scalp(10, 5))
    out = tmp_path / "shot01" / "hair" / "out.usdc"
    assert main(["convert", str(tmp_path / "in.hair"), str(out)]) == 0
    assert read(out).strand_count == 10
    assert [p.name for p in out.parent.iterdir()] == ["out.usdc"]
    (tmp_path / "taken").write_text("a file, not a folder")
    blocked = tmp_path / "taken" / "out.usdc"
    assert main(["convert", str(tmp_path / "in.hair"), str(blocked)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"hairtool convert: error: {blocked}: cannot write: ") and err.count("\n") == 1
    assert f"'{tmp_path / 'taken'}'" in err and ".tmp" not in err


def test_bad_input_from_a_real_process_has_no_traceback(tmp_path):
    bad = tmp_path / "bad.tfx"
    bad.write_bytes(b"\0\0\x80\x40" + b"\xff" * 300)
    r = subprocess.run(
        [sys.executable, "-m", "hairtool", "info", str(bad)], capture_output=True, text=True, timeout=60
    )
    assert r.returncode == 2
    assert r.stdout == ""
    assert r.stderr.startswith("hairtool info: error: ") and r.stderr.count("\n") == 1


@pytest.mark.parametrize("command", ["info", "convert", "sample"])
def test_help(command, capsys):
    with pytest.raises(SystemExit) as e:
        main([command, "--help"])
    assert e.value.code == 0
    assert "usage: hairtool" in capsys.readouterr().out


def test_shared_input_module_is_not_a_command():
    from hairtool.cli import command_names

    names = command_names()
    assert "_inputs" not in names and {"anime", "simulate", "info"} <= set(names)


def test_groom_input_spec(tmp_path):
    from hairtool.cli._inputs import parse_vector
    from hairtool.errors import FormatError, ParameterError
    from hairtool.io.specs import load_groom

    assert load_groom("sample:scalp:12:5").points.tobytes() == scalp(12, 5).points.tobytes()
    assert load_groom("sample:comb").strand_count > 0
    write(tmp_path / "g.npz", scalp(3, 4))
    assert load_groom(str(tmp_path / "g.npz")).vertex_count == 12
    for bad in ("sample:", "sample:scalp:1:2:3", "sample:scalp:x", "sample:braid"):
        with pytest.raises(ParameterError):
            load_groom(bad)
    with pytest.raises(FormatError):
        load_groom(str(tmp_path / "absent.npz"))
    assert parse_vector("wind", "1,-2.5,3e1") == (1.0, -2.5, 30.0)
    for bad in ("1,2", "a,b,c", "1,2,3,4", ""):
        with pytest.raises(ParameterError, match="three numbers"):
            parse_vector("wind", bad)


@pytest.mark.parametrize(
    "argv",
    [["info", "{groom}"], ["info", "{groom}", "--json"], ["--help"], ["info", "--help"], ["--version"],
     ["convert", "{groom}", "{out}"], ["info", "{missing}"]],
    ids=["info", "info-json", "help", "info-help", "version", "convert", "bad-input"],
)  # fmt: skip
@pytest.mark.skipif(sys.platform == "win32", reason="SIGPIPE and /dev/null as on POSIX")
def test_a_closed_pipe_exits_quietly(tmp_path, argv):
    """``hairtool info F | head -1``: the reader leaves; no BrokenPipeError traceback, status 141
    (as a shell reports for cat), and a file the command wrote is whole."""
    groom = tmp_path / "g.npz"
    write(groom, scalp(10, 5))
    names = {"groom": groom, "out": tmp_path / "out.usda", "missing": tmp_path / "none.npz"}
    raw, argv = argv, [a.format(**names) for a in argv]
    env = {k: v for k, v in os.environ.items() if k != "PYTHONUNBUFFERED"}  # stdout buffered, as usual
    r, w = os.pipe()
    os.close(r)  # the reader has gone before the first write: every write to stdout fails
    try:
        for stderr in (subprocess.PIPE, w):  # stderr apart, and both into the closed pipe (2>&1)
            p = subprocess.run(
                [sys.executable, "-m", "hairtool", *argv], stdout=w, stderr=stderr, env=env, timeout=120
            )
            if "{missing}" in raw and stderr != w:  # nothing for stdout; the error line reaches stderr
                assert p.returncode == 2 and len(p.stderr.splitlines()) == 1, p.stderr
                continue
            assert p.returncode == 141, p.stderr
            assert stderr == w or p.stderr == b"", p.stderr.decode()
    finally:
        os.close(w)
    if "convert" in argv:
        assert read(names["out"]).strand_count == 10
        assert sorted(f.name for f in tmp_path.iterdir()) == ["g.npz", "out.usda"]  # no temporary left
