"""Render hair and guides in one USD file (the guides a prim of purpose "guide"), and the child
definition in the project file: exact round trips, bad input named."""

from __future__ import annotations

import json
import zipfile

import numpy as np
import pytest

from hairtool import io, project, samples
from hairtool.errors import FormatError, GroomError, ParameterError
from hairtool.guides.binding import bind_dense, bind_roots
from hairtool.guides.files import GUIDES_PRIM, HAIR_PRIM, split_guides, tapered_widths, with_guides
from hairtool.metadata import CurvesPrim


def _write_project(path, manifest: dict, arrays: dict) -> None:
    """A project file written by hand, as a damaged or older one would be."""
    with zipfile.ZipFile(path, "w") as zf:
        zf.writestr("manifest.json", json.dumps(manifest))
        for name, a in arrays.items():
            with zf.open(name, "w") as f:
                np.lib.format.write_array(f, np.ascontiguousarray(a), allow_pickle=False)


@pytest.fixture(scope="module")
def hair_and_guides():
    guides = samples.scalp(40, 10, seed=3)
    binding = bind_roots(guides, count=500, seed=4)
    return binding.build(guides), guides, binding


@pytest.mark.parametrize("suffix", [".usda", ".usdc"])
def test_usd_round_trip_keeps_the_guide_prim(tmp_path, hair_and_guides, suffix):
    hair, guides, _b = hair_and_guides
    path = tmp_path / f"hair{suffix}"
    io.write(path, with_guides(hair, guides))
    back = io.read(path)
    assert [(c.path, c.strands, c.purpose) for c in back.metadata.curves] == [
        (HAIR_PRIM, 500, "default"),
        (GUIDES_PRIM, 40, "guide"),
    ]
    h, g = split_guides(back)
    np.testing.assert_array_equal(h.points, hair.points)
    np.testing.assert_array_equal(h.counts, hair.counts)
    np.testing.assert_array_equal(g.points, guides.points)
    np.testing.assert_array_equal(h.thickness, tapered_widths(hair))
    # and written again, the same two prims
    io.write(tmp_path / f"again{suffix}", back)
    assert io.read(tmp_path / f"again{suffix}").metadata.curves == back.metadata.curves


def test_the_guide_prim_is_marked_with_usd_purpose(tmp_path, hair_and_guides):
    from pxr import Usd, UsdGeom

    hair, guides, _b = hair_and_guides
    path = tmp_path / "hair.usda"
    io.write(path, with_guides(hair, guides))
    stage = Usd.Stage.Open(str(path))
    assert UsdGeom.Imageable(stage.GetPrimAtPath(GUIDES_PRIM)).GetPurposeAttr().Get() == "guide"
    curves = UsdGeom.BasisCurves(stage.GetPrimAtPath(HAIR_PRIM))
    assert len(curves.GetWidthsAttr().Get()) == hair.vertex_count
    assert curves.GetWidthsInterpolation() == "vertex"


def test_a_groom_without_guide_prims_splits_into_itself():
    g = samples.scalp(10, 5)
    assert split_guides(g) == (g, None)


def test_bad_purposes_and_widths_are_refused():
    with pytest.raises(ParameterError, match="purpose"):
        CurvesPrim("/Groom/Hair", 3, purpose="guides")
    with pytest.raises(ParameterError, match="tip width"):
        tapered_widths(samples.scalp(5, 4), 0.01, -1.0)


def test_a_unknown_purpose_in_a_file_is_one_format_error(tmp_path, hair_and_guides):
    hair, guides, _b = hair_and_guides
    path = tmp_path / "hair.usda"
    io.write(path, with_guides(hair, guides))
    text = path.read_text().replace('uniform token purpose = "guide"', 'uniform token purpose = "nonsense"')
    path.write_text(text)
    with pytest.raises(FormatError, match="purpose"):
        io.read(path)


@pytest.mark.parametrize("dense", [False, True])
def test_a_project_stores_the_child_definition_exactly(tmp_path, dense):
    if dense:
        guides, binding = bind_dense(samples.scalp(300, 8, seed=1), 30, seed=2)
    else:
        guides = samples.scalp(30, 8, seed=1)
        binding = bind_roots(guides, count=700, seed=5, frizz=0.05)
    path = tmp_path / "p.hairproj"
    project.save(path, project.Project(rest=guides, children=binding))
    back = project.load(path).children
    for name in ("counts", "roots", "guide_ids", "weights", "scale", "local", "exact_points", "exact_blend"):
        a, b = getattr(binding, name), getattr(back, name)
        assert (a is None) == (b is None), name
        if a is not None:
            np.testing.assert_array_equal(a, b)
            assert a.dtype == b.dtype, name
    np.testing.assert_array_equal(back.build().points, binding.build().points)
    moved = guides.with_points(guides.points + guides.topology.vertex_param[:, None].astype(np.float32))
    np.testing.assert_array_equal(back.build(moved).points, binding.build(moved).points)
    with zipfile.ZipFile(path) as zf:  # the definition, not the children's points
        names = zf.namelist()
    assert not any("children/points" in n for n in names)
    # Per-vertex offsets are made again on loading: a dense groom's from its points (stored
    # once), the frizz from its amplitude and each child's phase and turns.
    assert "children/local.npy" not in names and "children/exact_blend.npy" not in names
    assert ("children/frizz_phase.npy" in names) != dense and ("children/roots.npy" in names) != dense
    with zipfile.ZipFile(path) as zf, zf.open("children/guide_ids.npy") as f:
        assert np.lib.format.read_array(f).dtype == np.uint16  # indices in the smallest type
    assert project.load(path).rest.strand_count == guides.strand_count


def _drop_turns(manifest: dict, arrays: dict) -> None:
    manifest["children"]["arrays"].remove("frizz_turns")
    del arrays["children/frizz_turns.npy"]


def _drop_roots(manifest: dict, arrays: dict) -> None:  # only a dense groom's follow from its points
    manifest["children"]["arrays"].remove("roots")
    del arrays["children/roots.npy"]


@pytest.mark.parametrize(
    ("change", "match"),
    [
        (lambda m, a: m["children"].update(frizz=7.0), "frizz"),
        (lambda m, a: m["children"].update(frizz="curly"), "frizz"),
        (_drop_turns, "turns"),
        (_drop_roots, "roots"),
    ],
)
def test_a_bad_frizz_recipe_is_one_format_error(tmp_path, change, match):
    guides = samples.scalp(20, 6, seed=1)
    binding = bind_roots(guides, count=50, seed=5, frizz=0.1)
    manifest, arrays = project.manifest_and_arrays(project.Project(rest=guides, children=binding))
    change(manifest, arrays)
    manifest["arrays"] = sorted(arrays)
    path = tmp_path / "bad.hairproj"
    _write_project(path, manifest, arrays)
    with pytest.raises(FormatError, match=match):
        project.load(path)


def test_a_dense_project_stored_in_full_by_an_earlier_hairtool_still_loads(tmp_path):
    guides, binding = bind_dense(samples.scalp(200, 8, seed=1), 20, seed=2)
    manifest, arrays = project.manifest_and_arrays(project.Project(rest=guides, children=binding))
    arrays["children/local.npy"] = binding.local
    arrays["children/exact_blend.npy"] = binding.exact_blend
    manifest["children"]["arrays"] += ["local", "exact_blend"]
    manifest["arrays"] = sorted(arrays)
    path = tmp_path / "old.hairproj"
    _write_project(path, manifest, arrays)
    back = project.load(path).children
    np.testing.assert_array_equal(back.local, binding.local)
    np.testing.assert_array_equal(back.exact_blend, binding.exact_blend)


def test_a_project_without_children_has_none(tmp_path):
    path = tmp_path / "p.hairproj"
    project.save(path, project.Project(rest=samples.scalp(10, 5)))
    assert project.load(path).children is None


def test_children_naming_a_missing_guide_are_one_format_error(tmp_path):
    guides = samples.scalp(20, 6, seed=1)
    binding = bind_roots(guides, count=50, seed=5)
    manifest, arrays = project.manifest_and_arrays(project.Project(rest=guides, children=binding))
    arrays["children/guide_ids.npy"] = arrays["children/guide_ids.npy"] + 20
    path = tmp_path / "bad.hairproj"
    _write_project(path, manifest, arrays)
    with pytest.raises(FormatError, match="guide outside"):
        project.load(path)


def test_children_bound_to_other_guides_are_refused():
    binding = bind_roots(samples.scalp(20, 6, seed=1), count=50, seed=5)
    with pytest.raises(GroomError, match="rest groom"):
        project.manifest_and_arrays(project.Project(rest=samples.scalp(20, 6, seed=2), children=binding))


def test_convert_keeps_guides_apart_where_it_can_and_warns_elsewhere(tmp_path, hair_and_guides, capsys):
    from hairtool.cli import main

    hair, guides, _b = hair_and_guides
    src = tmp_path / "both.usda"
    io.write(src, with_guides(hair, guides))
    for suffix, warned in ((".npz", False), (".usdc", False), (".hair", True), (".obj", True)):
        out = tmp_path / f"out{suffix}"
        assert main(["convert", str(src), str(out)]) == 0
        err = capsys.readouterr().err
        assert ("cannot mark guides" in err) == warned, suffix
        if not warned:
            back_hair, back_guides = split_guides(io.read(out))
            assert (back_hair.strand_count, back_guides.strand_count) == (500, 40)
