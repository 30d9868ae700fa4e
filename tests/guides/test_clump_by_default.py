"""Clump children by default: grown children are clumped, authored hair is not (the library's
rule, and `hairtool interpolate` / `freeze` following it unless told otherwise)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from hairtool import io, samples
from hairtool.cli import main
from hairtool.guides.binding import bind_dense, bind_roots, bind_scalp, bind_to_guides, clumps_by_default
from hairtool.guides.files import split_guides
from hairtool.guides.render import ChildClump, RenderHair
from hairtool.io.obj import read_mesh

RESOURCES = Path(__file__).resolve().parents[2] / "resources"
GUIDES = str(RESOURCES / "sintel_hair.tfx")
HEAD = str(RESOURCES / "sintel_head.obj")


def test_grown_children_clump_by_default_and_authored_hair_does_not():
    guides = samples.scalp(strands=40, vertices=8, seed=1)
    grown = bind_roots(guides, count=300, seed=2)
    assert not grown.authored and clumps_by_default(grown)
    on_scalp = bind_scalp(io.read_groom(GUIDES), read_mesh(HEAD), 200, seed=1)
    assert clumps_by_default(on_scalp)
    dense = samples.scalp(strands=400, vertices=8, seed=3)
    picked, from_dense = bind_dense(dense, 20)
    assert from_dense.authored and not clumps_by_default(from_dense)
    read_beside = bind_to_guides(dense, picked)
    assert read_beside.authored and not clumps_by_default(read_beside)
    # a subset (the drawn share while dragging) is what its binding is
    assert not clumps_by_default(from_dense.subset(np.arange(10)))
    assert clumps_by_default(grown.subset(np.arange(10)))


def test_interpolate_clumps_grown_children_unless_told_not_to(tmp_path):
    common = ["--count", "1500", "--scalp", HEAD, "--seed", "3"]
    default, on, off = (tmp_path / f"{n}.npz" for n in ("default", "on", "off"))
    assert main(["interpolate", GUIDES, str(default), *common]) == 0
    assert main(["interpolate", GUIDES, str(on), *common, "--clump-children"]) == 0
    assert main(["interpolate", GUIDES, str(off), *common, "--no-clump-children"]) == 0
    d, c, o = (io.read_groom(p).points for p in (default, on, off))
    assert d.tobytes() == c.tobytes()
    binding = bind_scalp(io.read_groom(GUIDES), read_mesh(HEAD), 1500, seed=3)
    np.testing.assert_array_equal(o, binding.build().points)  # off: the interpolation itself
    np.testing.assert_array_equal(d, RenderHair(binding, ChildClump(seed=3)).update().points)
    assert np.abs(d - o).max() > 1e-3


def test_render_hair_read_beside_its_guides_is_not_clumped_again(tmp_path):
    """A file the studio (or this CLI) wrote with clumped children: a command on it keeps the
    children as written, instead of clumping them a second time."""
    clumped = tmp_path / "clumped.usda"
    assert main(["interpolate", GUIDES, str(clumped), "--count", "800", "--scalp", HEAD]) == 0
    again = tmp_path / "again.usda"
    assert main(["freeze", str(clumped), str(again), "--no-freeze", "--no-clump"]) == 0
    hair, guides = split_guides(io.read_groom(again))
    want, _ = split_guides(io.read_groom(clumped))
    assert guides is not None and hair.points.tobytes() == want.points.tobytes()
    twice = tmp_path / "twice.usda"
    assert main(["freeze", str(clumped), str(twice), "--no-freeze", "--no-clump", "--clump-children"]) == 0
    assert np.abs(split_guides(io.read_groom(twice))[0].points - want.points).max() > 1e-4


def test_clump_children_without_render_hair_is_refused_naming_the_option(tmp_path, capsys):
    out = tmp_path / "x.npz"
    for argv in (["anime", "--clump-children"], ["freeze", GUIDES, str(out), "--clump-children"]):
        assert main(argv) == 2
        err = capsys.readouterr().err.strip()
        assert len(err.splitlines()) == 1 and "clump-children" in err, err
    assert not out.exists()
