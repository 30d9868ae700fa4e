"""USD BasisCurves: bit-exact round trips in .usda/.usdc/.usd, animations as time samples, merging."""

from __future__ import annotations

import numpy as np
import pytest

from hairtool.errors import FormatError, ParameterError
from hairtool.groom import Animation, Groom
from hairtool.io import read, usd, write

EXTENSIONS = ("usda", "usdc", "usd")


def _stage(path):
    from pxr import Usd

    return Usd.Stage.Open(str(path))


@pytest.mark.parametrize("ext", EXTENSIONS)
def test_groom_round_trip_is_bit_exact(tmp_path, groom, ext):
    p = tmp_path / f"g.{ext}"
    write(p, groom)
    back = read(p)
    assert isinstance(back, Groom)
    np.testing.assert_array_equal(back.counts, groom.counts)
    assert back.points.tobytes() == groom.points.tobytes()
    assert back.thickness.tobytes() == groom.thickness.tobytes()
    assert back.colors.tobytes() == groom.colors.tobytes()
    np.testing.assert_allclose(back.transparency, groom.transparency, atol=1e-6)


@pytest.mark.parametrize("ext", EXTENSIONS)
def test_animation_round_trip_and_pxr_sees_every_time_sample(tmp_path, animation, ext):
    from pxr import Usd, UsdGeom

    p = tmp_path / f"a.{ext}"
    write(p, animation)
    back = read(p)
    assert isinstance(back, Animation)
    assert back.fps == animation.fps
    assert back.frames.tobytes() == animation.frames.tobytes()

    stage = _stage(p)
    assert stage.GetTimeCodesPerSecond() == animation.fps
    assert (stage.GetStartTimeCode(), stage.GetEndTimeCode()) == (0, animation.n_frames - 1)
    assert UsdGeom.GetStageUpAxis(stage) == UsdGeom.Tokens.y
    curves = UsdGeom.BasisCurves(stage.GetPrimAtPath(usd.PRIM_PATH))
    assert curves.GetTypeAttr().Get() == UsdGeom.Tokens.linear
    assert list(curves.GetCurveVertexCountsAttr().Get()) == animation.counts.tolist()
    attr = curves.GetPointsAttr()
    assert attr.GetTimeSamples() == list(range(animation.n_frames))
    for f in range(animation.n_frames):
        got = np.asarray(attr.Get(Usd.TimeCode(f)), dtype=np.float32)
        assert got.tobytes() == animation.frames[f].tobytes()


def test_keys_only_export_writes_exactly_the_given_time_codes(tmp_path, animation):
    from pxr import Usd, UsdGeom

    keys = [0, 4, 5, 11, 30]
    p = tmp_path / "keys.usda"
    usd.write(p, animation, time_codes=keys)
    stage = _stage(p)
    attr = UsdGeom.BasisCurves(stage.GetPrimAtPath(usd.PRIM_PATH)).GetPointsAttr()
    assert attr.GetTimeSamples() == keys
    assert (stage.GetStartTimeCode(), stage.GetEndTimeCode()) == (0, 30)
    for f, t in enumerate(keys):
        assert np.asarray(attr.Get(Usd.TimeCode(t)), np.float32).tobytes() == animation.frames[f].tobytes()
    # Between keys a USD reader interpolates linearly.
    mid = np.asarray(attr.Get(Usd.TimeCode(8)), np.float64)
    expect = animation.frames[2] + (animation.frames[3].astype(np.float64) - animation.frames[2]) * 3 / 6
    np.testing.assert_allclose(mid, expect, rtol=1e-5, atol=1e-5)
    assert usd.time_codes(p) == keys
    assert read(p).n_frames == len(keys)


@pytest.mark.parametrize("codes", [[0, 1, 2], [0, 2, 1, 3, 4], [0, 1, 1, 2, 3], [0, 1, 2, 3, float("nan")]])
def test_bad_time_codes_are_refused(tmp_path, animation, codes):
    with pytest.raises(ParameterError, match="time_codes"):
        usd.write(tmp_path / "x.usda", animation, time_codes=codes)
    assert not (tmp_path / "x.usda").exists()


def test_time_codes_need_an_animation(tmp_path, groom):
    with pytest.raises(ParameterError):
        usd.write(tmp_path / "x.usda", groom, time_codes=[0])


def _curves(stage, path, counts, points, xform=None):
    from pxr import Gf, UsdGeom, Vt

    c = UsdGeom.BasisCurves.Define(stage, path)
    c.CreateCurveVertexCountsAttr(Vt.IntArray(counts))
    c.CreatePointsAttr(Vt.Vec3fArray.FromNumpy(np.asarray(points, np.float32)))
    if xform is not None:
        c.AddTranslateOp().Set(Gf.Vec3d(*xform))
    return c


def test_several_prims_merge_in_world_space(tmp_path):
    from pxr import Usd, UsdGeom

    p = tmp_path / "two.usda"
    stage = Usd.Stage.CreateNew(str(p))
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.z)
    _curves(stage, "/A", [2], [[0, 0, 0], [0, 0, 1]])
    _curves(stage, "/B/C", [3], [[1, 0, 0], [1, 0, 1], [1, 0, 2]], xform=(10, 0, 0))
    stage.GetRootLayer().Save()
    g = read(p)
    np.testing.assert_array_equal(g.counts, [2, 3])
    np.testing.assert_array_equal(g.points[2:], [[11, 0, 0], [11, 0, 1], [11, 0, 2]])
    np.testing.assert_array_equal(g.points[:2, 2], [0, 1])  # z-up kept as authored


def test_sampled_and_static_prims_merge_into_an_animation(tmp_path):
    from pxr import Usd, Vt

    p = tmp_path / "mixed.usda"
    stage = Usd.Stage.CreateNew(str(p))
    _curves(stage, "/Static", [2], [[0, 0, 0], [0, 1, 0]])
    moving = _curves(stage, "/Moving", [2], [[0, 0, 0], [0, 1, 0]])
    for t in (1.0, 3.0):
        moving.GetPointsAttr().Set(Vt.Vec3fArray.FromNumpy(np.full((2, 3), t, np.float32)), Usd.TimeCode(t))
    stage.SetTimeCodesPerSecond(12)
    stage.GetRootLayer().Save()
    a = read(p)
    assert isinstance(a, Animation) and a.n_frames == 2 and a.fps == 12
    np.testing.assert_array_equal(a.frames[:, :2], [[[0, 0, 0], [0, 1, 0]]] * 2)
    np.testing.assert_array_equal(a.frames[1, 2:], np.full((2, 3), 3.0))


def test_bad_stages_raise_format_error(tmp_path):
    from pxr import Usd, UsdGeom

    garbage = tmp_path / "garbage.usda"
    garbage.write_text("#usda 1.0\ndef Xform 'broken' {{{")
    with pytest.raises(FormatError, match="cannot open"):
        read(garbage)

    crate = tmp_path / "crate.usdc"
    crate.write_bytes(b"PXR-USDC" + b"\xff" * 200)
    with pytest.raises(FormatError):
        read(crate)

    empty = tmp_path / "empty.usda"
    s = Usd.Stage.CreateNew(str(empty))
    UsdGeom.Xform.Define(s, "/Nothing")
    s.GetRootLayer().Save()
    with pytest.raises(FormatError, match="no BasisCurves"):
        read(empty)

    mismatch = tmp_path / "mismatch.usda"
    s = Usd.Stage.CreateNew(str(mismatch))
    _curves(s, "/C", [2, 2], [[0, 0, 0], [0, 1, 0], [0, 2, 0]])
    s.GetRootLayer().Save()
    with pytest.raises(FormatError, match="add up to 4"):
        read(mismatch)

    short = tmp_path / "short.usda"
    s = Usd.Stage.CreateNew(str(short))
    _curves(s, "/C", [1], [[0, 0, 0]])
    s.GetRootLayer().Save()
    with pytest.raises(FormatError, match="at least 2"):
        read(short)

    (tmp_path / "zero.usda").write_bytes(b"")
    with pytest.raises(FormatError):
        read(tmp_path / "zero.usda")


def test_rewritten_file_is_read_fresh(tmp_path, groom):
    p = tmp_path / "again.usdc"
    write(p, groom)
    assert read(p).strand_count == groom.strand_count
    write(p, groom.subset([0, 1]))
    assert read(p).strand_count == 2


def test_a_stage_held_open_elsewhere_does_not_hide_a_rewrite(tmp_path, groom):
    from pxr import Usd

    p = tmp_path / "held.usda"
    write(p, groom)
    held = Usd.Stage.Open(str(p))  # keeps the layer in usd-core's registry
    write(p, groom.subset([3, 4, 5]))
    assert read(p).strand_count == 3
    del held
