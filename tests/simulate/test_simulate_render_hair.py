"""`hairtool simulate` with render hair: the guides are simulated, OUT receives the children
following them (USD: with the guides as a prim of purpose guide; elsewhere the guides beside),
and `hairtool keys` keys a render-hair animation as it keys any other."""

from __future__ import annotations

import json

import pytest

from hairtool import io
from hairtool.cli import main
from hairtool.guides.binding import bind_roots
from hairtool.guides.files import split_guides
from hairtool.guides.render import ChildClump, RenderHair
from hairtool.samples import scalp

SIM = ["--frames", "8", "--gusts", "1", "--substeps", "2", "--seed", "2"]


@pytest.fixture
def guides_file(tmp_path):
    src = tmp_path / "guides.npz"
    io.write(src, scalp(30, 6, seed=1))
    return src


def test_usd_holds_children_and_the_guide_prim_frame_for_frame(guides_file, tmp_path, capsys):
    out = tmp_path / "shot.usdc"
    argv = ["simulate", str(guides_file), str(out), *SIM, "--count", "400", "--seed", "5", "--json"]
    assert main(argv) == 0
    report = json.loads(capsys.readouterr().out)
    assert (report["children"], report["guides"], report["frames"]) == (400, 30, 8)
    assert "guides_output" not in report  # the guides are in the file
    hair, guides = split_guides(io.read(out))
    assert (hair.n_frames, hair.strand_count, guides.strand_count) == (8, 400, 30)
    plain = tmp_path / "guides_only.npz"
    assert main(["simulate", str(guides_file), str(plain), *SIM, "--seed", "5"]) == 0
    sim = io.read(plain)
    assert guides.frames.tobytes() == sim.frames.tobytes()  # the guides move as they do alone
    binding = bind_roots(io.read_groom(guides_file), count=400, seed=5)
    render = RenderHair(binding, ChildClump(seed=5))  # grown children: clumped by default
    for f in (0, 7):  # the children are that frame's guides' interpolation, clumped
        assert hair.frames[f].tobytes() == render.update(sim.frame(f)).points.tobytes()


def test_other_formats_write_the_guides_beside_and_keys_work_on_the_children(guides_file, tmp_path, capsys):
    out = tmp_path / "shot.npz"
    assert main(["simulate", str(guides_file), str(out), *SIM, "--count", "300"]) == 0
    assert "300 render strands following 30 guides" in capsys.readouterr().out
    hair, guides = io.read(out), io.read(tmp_path / "shot.guides.npz")
    assert (hair.strand_count, guides.strand_count, hair.n_frames, guides.n_frames) == (300, 30, 8, 8)
    for target in (out, tmp_path / "shot.guides.npz"):
        assert main(["keys", str(target), "--keys", "3", "--json"]) == 0
        result = json.loads(capsys.readouterr().out)
        assert len(result["keys"]) == 3 and result["keys"][0] == 0 and result["keys"][-1] == 7


def test_from_dense_and_bad_render_options(tmp_path, capsys):
    dense = tmp_path / "dense.npz"
    io.write(dense, scalp(200, 6, seed=3))
    out = tmp_path / "d.usda"
    argv = ["simulate", str(dense), str(out), "--frames", "3", "--from-dense", "--guides", "20"]
    assert main(argv) == 0
    hair, guides = split_guides(io.read(out))
    assert (hair.strand_count, guides.strand_count) == (200, 20)
    assert io.read(tmp_path / "d.guides.usda").strand_count == 20
    capsys.readouterr()
    for extra, name in ((["--count", "0"], "count"), (["--from-dense"], "guides")):
        bad = tmp_path / "bad.npz"
        assert main(["simulate", str(dense), str(bad), "--frames", "3", *extra]) == 2
        err = capsys.readouterr().err.strip()
        assert "\n" not in err and name in err
        assert not bad.exists()


def test_guides_out_also_writes_the_guides_beside_a_usd_file(guides_file, tmp_path, capsys):
    out, side = tmp_path / "shot.usda", tmp_path / "side.npz"
    argv = ["simulate", str(guides_file), str(out), "--frames", "3", "--count", "50"]
    assert main([*argv, "--guides-out", str(side), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["guides_output"] == str(side)
    _, guides = split_guides(io.read(out))
    assert io.read(side).frames.tobytes() == guides.frames.tobytes()
