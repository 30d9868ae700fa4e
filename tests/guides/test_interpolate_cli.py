"""`hairtool interpolate`, `hairtool freeze` with render hair, and `hairtool bench interpolate`."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from hairtool import io, samples
from hairtool.cli import main
from hairtool.guides.files import split_guides

RESOURCES = Path(__file__).resolve().parents[2] / "resources"
GUIDES = str(RESOURCES / "sintel_hair.tfx")
HEAD = str(RESOURCES / "sintel_head.obj")


def test_interpolate_on_the_scalp_writes_children_and_reports_json(tmp_path, capsys):
    out = tmp_path / "kids.npz"
    rc = main(["interpolate", GUIDES, str(out), "--count", "2000", "--scalp", HEAD, "--seed", "3", "--json"])
    assert rc == 0
    report = json.loads(capsys.readouterr().out)
    assert report["children"] == 2000 and report["guides"] == 228 and report["vertices"] == 2000 * 32
    kids = io.read_groom(out)
    assert kids.strand_count == 2000
    again = tmp_path / "again.npz"
    assert main(["interpolate", GUIDES, str(again), "--count", "2000", "--scalp", HEAD, "--seed", "3"]) == 0
    assert io.read_groom(again).points.tobytes() == kids.points.tobytes()


def test_from_dense_writes_render_strands_and_guides(tmp_path, grooms_dir):
    src = grooms_dir / "ponytail_tail.tfx"
    out = tmp_path / "hair.usda"
    assert (
        main(["interpolate", str(src), str(out), "--from-dense", "--guides", "30", "--guides-per-child", "3"])
        == 0
    )
    dense = io.read_groom(src)
    hair, guide_prim = split_guides(io.read_groom(out))  # USD: the guides are a prim of the file too
    assert hair.points.tobytes() == dense.points.tobytes()
    guides = io.read_groom(tmp_path / "hair.guides.usda")
    assert guides.strand_count == 30
    assert guide_prim.points.tobytes() == guides.points.tobytes()
    assert hair.thickness is not None  # render strands have widths
    chosen = tmp_path / "chosen.npz"
    assert (
        main(
            ["interpolate", str(src), str(out), "--from-dense", "--guides", "30", "--guides-out", str(chosen)]
        )
        == 0
    )
    assert io.read_groom(chosen).strand_count == 30


@pytest.mark.slow(seconds=18)
def test_freeze_outputs_render_hair(tmp_path, capsys):
    out = tmp_path / "render.npz"
    args = [
        "freeze",
        GUIDES,
        str(out),
        "--count",
        "1500",
        "--scalp",
        HEAD,
        "--keep-lengths",
        "--clump-children",
    ]
    assert main([*args, "--align", "0,50,10", "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["children"] == 1500 and report["guides"] == 228
    hair = io.read_groom(out)
    assert hair.strand_count == 1500
    plain = tmp_path / "plain.npz"
    assert main(["interpolate", GUIDES, str(plain), "--count", "1500", "--scalp", HEAD]) == 0
    assert np.abs(io.read_groom(plain).points - hair.points).max() > 0.1  # the frozen guides moved them


@pytest.mark.parametrize(
    ("extra", "name"),
    [
        (["--count", "0"], "count"),
        (["--count", "10", "--guides-per-child", "229"], "guides_per_child"),
        (["--from-dense"], "guides"),
        (["--count", "10", "--from-dense", "--guides", "5"], "from-dense"),
        (["--from-dense", "--guides", "5", "--region", "scalp"], "from-dense"),
        (["--count", "10", "--region", "nowhere.txt"], "region"),
        (["--count", "10", "--length-variation", "nan"], "length_variation"),
    ],
)
def test_bad_options_give_one_line_and_exit_2(tmp_path, capsys, extra, name):
    out = tmp_path / "x.npz"
    assert main(["interpolate", GUIDES, str(out), *extra]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and name in err
    assert not out.exists()


def test_a_mesh_without_faces_and_a_bad_region_file(tmp_path, capsys):
    mesh = tmp_path / "points.obj"
    mesh.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\n")
    out = tmp_path / "x.npz"
    assert main(["interpolate", GUIDES, str(out), "--count", "10", "--scalp", str(mesh)]) == 2
    assert "no faces" in capsys.readouterr().err
    region = tmp_path / "faces.txt"
    region.write_text("1 2 banana\n")
    assert (
        main(["interpolate", GUIDES, str(out), "--count", "10", "--scalp", HEAD, "--region", str(region)])
        == 2
    )
    assert "faces.txt" in capsys.readouterr().err
    assert main(["interpolate", GUIDES, str(out), "--count", "10", "--scalp", HEAD, "--region", "hat"]) == 2
    assert "GEO-body" in capsys.readouterr().err  # the face sets there are
    region.write_text("0 1 2\n")  # three tiny triangles of her body, far from any guide: still hair
    assert (
        main(["interpolate", GUIDES, str(out), "--count", "10", "--scalp", HEAD, "--region", str(region)])
        == 0
    )


def test_bench_interpolate_rows(capsys):
    assert main(["bench", "interpolate", "--quick", "--json", "--children", "2000", "--guides", "100"]) == 0
    rows = json.loads(capsys.readouterr().out)
    assert len(rows) == 2
    for r in rows:
        assert {"guides", "children", "vertices", "interpolate_ms", "reference_ms", "threads"} <= set(r)
        assert r["interpolate_ms"] > 0 and r["reference_ms"] > 0
    assert rows[0]["guides"] == 100


def test_sample_guides_without_a_mesh(tmp_path):
    src = tmp_path / "g.npz"
    io.write(src, samples.scalp(50, 8, seed=0))
    out = tmp_path / "kids.obj"
    assert (
        main(["interpolate", str(src), str(out), "--count", "500", "--vertices", "12", "--frizz", "0"]) == 0
    )
    kids = io.read_groom(out)
    assert kids.strand_count == 500 and set(kids.counts) == {12}


def test_a_file_of_render_hair_and_guides_is_read_as_such(tmp_path, capsys):
    """This tool's own USD (the hair, then the guides as a prim of purpose guide): --count grows
    new children from its guides, --from-dense picks guides among its render hair, and without
    either the command works on the guides with the render hair following them, never on the
    two merged."""
    both = tmp_path / "both.usda"
    assert main(["interpolate", GUIDES, str(both), "--count", "300", "--scalp", HEAD]) == 0
    hair, guides = split_guides(io.read_groom(both))
    assert (hair.strand_count, guides.strand_count) == (300, 228)
    again = tmp_path / "again.usda"
    assert main(["interpolate", str(both), str(again), "--count", "300", "--scalp", HEAD, "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["guides"] == 228
    assert split_guides(io.read_groom(again))[0].points.tobytes() == hair.points.tobytes()  # same guides
    dense = tmp_path / "dense.usda"
    assert main(["interpolate", str(both), str(dense), "--from-dense", "--guides", "20", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["children"] == 300
    assert split_guides(io.read_groom(dense))[0].points.tobytes() == hair.points.tobytes()
    frozen = tmp_path / "frozen.usda"
    assert main(["freeze", str(both), str(frozen), "--count", "300", "--scalp", HEAD, "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["guides"] == 228
    # Otherwise the command works on the guides, the render hair bound to them exactly.
    same = tmp_path / "same.usda"
    assert main(["freeze", str(both), str(same), "--no-freeze", "--no-clump"]) == 0
    back, back_guides = split_guides(io.read_groom(same))
    assert back.points.tobytes() == hair.points.tobytes()
    assert back_guides.points.tobytes() == guides.points.tobytes()
    moved = tmp_path / "moved.usda"
    assert main(["freeze", str(both), str(moved), "--no-clump", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["children"] == 300
    hair2, guides2 = split_guides(io.read_groom(moved))
    assert np.abs(guides2.points - guides.points).max() > 1e-3  # the guides froze …
    assert np.abs(hair2.points - hair.points).max() > 1e-3  # … and the render hair followed
    np.testing.assert_array_equal(hair2.roots, hair.roots)
    anim = tmp_path / "sim.usda"
    assert main(["simulate", str(both), str(anim), "--frames", "3"]) == 0
    sim_hair, sim_guides = split_guides(io.read(anim))
    assert (sim_hair.strand_count, sim_guides.strand_count) == (300, 228)


@pytest.mark.parametrize(
    ("command", "extra", "name"),
    [
        ("interpolate", ["--count", "10", "--guides", "5"], "guides"),
        ("interpolate", ["--count", "10", "--density", "d.txt"], "density"),
        ("interpolate", ["--from-dense", "--guides", "5", "--frizz", "0.2"], "frizz"),
        ("interpolate", ["--from-dense", "--guides", "5", "--length-variation", "0.2"], "length-variation"),
        ("freeze", ["--guides", "5"], "guides"),
        ("freeze", ["--scalp", HEAD], "scalp"),
        ("freeze", ["--clump-children"], "clump-children"),
        ("freeze", ["--frizz", "0.1"], "frizz"),
        ("simulate", ["--frames", "3", "--guides-per-child", "3"], "guides-per-child"),
        ("anime", ["--vertices", "8"], "vertices"),
    ],
)
def test_options_that_would_do_nothing_are_refused(tmp_path, capsys, command, extra, name):
    out = tmp_path / "x.npz"
    assert main([command, GUIDES, str(out), *extra]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and err.split("=")[0].endswith(name), err
    assert not out.exists()


def test_freeze_from_dense_gives_the_groom_back_when_nothing_moves(tmp_path, grooms_dir):
    src = grooms_dir / "ponytail_tail.tfx"
    out = tmp_path / "back.npz"
    args = ["freeze", str(src), str(out), "--from-dense", "--guides", "40", "--no-freeze", "--no-clump"]
    assert main(args) == 0
    assert io.read_groom(out).points.tobytes() == io.read_groom(src).points.tobytes()
    assert io.read_groom(tmp_path / "back.guides.npz").strand_count == 40


def test_clumped_children_follow_freezes_length_rule(tmp_path):
    """--clump-children with freeze's --keep-lengths keeps every child's segment lengths; as
    printed (without it) ClumpWithGaps stretches them, as it does the guides."""
    base = ["--count", "800", "--scalp", HEAD, "--clump-children", "--no-freeze", "--no-clump"]
    outs = {}
    for keep in (False, True):
        outs[keep] = tmp_path / f"keep{keep}.npz"
        assert main(["freeze", GUIDES, str(outs[keep]), *base, *(["--keep-lengths"] if keep else [])]) == 0
    plain = tmp_path / "plain.npz"
    assert main(["interpolate", GUIDES, str(plain), "--count", "800", "--scalp", HEAD]) == 0
    rest = io.read_groom(plain).segment_lengths
    kept, printed = (io.read_groom(outs[k]).segment_lengths for k in (True, False))
    np.testing.assert_allclose(kept, rest, rtol=1e-4)
    assert np.abs(printed / rest - 1.0).max() > 0.05
