"""A groom's source record: defaults, checks, and which operations carry it."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from hairtool.errors import GroomError, ParameterError
from hairtool.groom import Animation, Groom
from hairtool.metadata import DEFAULT_METERS_PER_UNIT, CurvesPrim, Metadata


def _groom(meta: Metadata | None = None) -> Groom:
    pts = np.arange(27, dtype=np.float32).reshape(9, 3)
    return Groom(pts, [2, 3, 4], metadata=meta)


def test_defaults_when_absent():
    g = Groom(np.zeros((2, 3)), [2])
    assert g.metadata == Metadata()
    assert (g.metadata.up_axis, g.metadata.meters_per_unit) == ("Y", DEFAULT_METERS_PER_UNIT) == ("Y", 0.01)
    a = Animation(np.zeros((3, 2, 3)), [2])
    np.testing.assert_array_equal(a.time_codes, [0, 1, 2])


@pytest.mark.parametrize(
    ("changes", "name"),
    [
        ({"up_axis": "X"}, "up axis"),
        ({"meters_per_unit": 0.0}, "meters per unit"),
        ({"meters_per_unit": float("nan")}, "meters per unit"),
        ({"time_codes_per_second": -24}, "time codes per second"),
        ({"start_time_code": 5, "end_time_code": 1}, "end time code"),
        ({"time_codes": (1, 1, 2)}, "time codes"),
        ({"time_codes": (0, float("inf"))}, "time codes"),
        ({"curves": (CurvesPrim("/A", 1), CurvesPrim("/A", 2))}, "prim paths"),
        ({"color_primvar": "Cd"}, "colour primvar"),
    ],
)
def test_bad_values_name_the_field(changes, name):
    with pytest.raises(ParameterError, match=name):
        Metadata(**changes)


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [({"path": "A"}, "prim path"), ({"strands": 0}, "prim strands"), ({"basis": "hermite"}, "basis")],
)
def test_bad_prims_name_the_field(kwargs, name):
    with pytest.raises(ParameterError, match=name):
        CurvesPrim(**{"path": "/A", "strands": 1, **kwargs})


def test_up_axis_is_case_blind_and_prims_must_hold_the_strands():
    assert Metadata(up_axis="z").up_axis == "Z"
    with pytest.raises(GroomError, match="hold 2 strands, not 3"):
        _groom(Metadata(curves=(CurvesPrim("/A", 2),)))


def test_what_carries_the_record():
    meta = Metadata(
        up_axis="Z", meters_per_unit=1.0, curves=(CurvesPrim("/A", 1), CurvesPrim("/B", 2, "bspline"))
    )
    g = _groom(meta)
    assert g.with_points(g.points + 1).metadata == meta
    sub = g.subset([2, 0])
    assert sub.metadata.curves == () and sub.metadata.up_axis == "Z"  # across prims, backwards
    assert g.subset([0, 2]).metadata.curves == (CurvesPrim("/A", 1), CurvesPrim("/B", 1, "bspline"))
    a = Animation.from_grooms([g, g.with_points(g.points * 2), g], fps=24)
    assert a.metadata == meta
    a = a.with_metadata(meta.with_(time_codes=(1, 2, 3)))
    np.testing.assert_array_equal(a.time_codes, [1, 2, 3])
    assert a.with_frames(a.frames + 1).metadata.time_codes == (1, 2, 3)
    assert a.with_frames(a.frames[:2]).metadata.time_codes is None  # another frame count
    assert a.with_frames(a.frames[[0, 2]], time_codes=[1, 3]).metadata.time_codes == (1, 3)
    assert a.frame(1).metadata == meta  # a pose has no time codes
    with pytest.raises(GroomError, match="2 time codes for 3 frames"):
        a.with_metadata(meta.with_(time_codes=(1, 2)))
    assert meta.for_strands(4).curves == () and meta.for_strands(3) is meta


_PRIMS = st.lists(
    st.tuples(st.integers(1, 6), st.sampled_from(("linear", "catmullRom", "bspline"))), min_size=1, max_size=4
)


@given(prims=_PRIMS, data=st.data())
@settings(max_examples=80, deadline=None)
def test_a_subset_holds_each_prims_chosen_strands(prims, data):
    curves = tuple(CurvesPrim(f"/G{k}/Hair", n, basis) for k, (n, basis) in enumerate(prims))
    scaled = (2, 0, 0, 0, 0, 2, 0, 0, 0, 0, 2, 0, 1, 2, 3, 1)
    meta = Metadata(up_axis="Z", curves=curves, xforms=(("/G0", scaled),))
    total = sum(n for n, _ in prims)
    ids = sorted(data.draw(st.sets(st.integers(0, total - 1), min_size=1)))
    sub = meta.subset(ids)
    owner = meta.prim_of(ids)
    assert [c.path for c in sub.curves] == [curves[k].path for k in sorted(set(owner.tolist()))]
    assert [c.strands for c in sub.curves] == [int((owner == k).sum()) for k in sorted(set(owner.tolist()))]
    assert all(c.basis == curves[int(c.path[2:].split("/")[0])].basis for c in sub.curves)
    assert (sub.up_axis, sub.xforms) == (meta.up_axis, meta.xforms)
    back = list(reversed(ids))
    if len(set(owner.tolist())) > 1:  # a reordering across prims: one default prim
        assert meta.subset(back).curves == ()
    grown = sub.extended([len(sub.curves) - 1] * 3)
    assert grown.curves[-1].strands == sub.curves[-1].strands + 3 and grown.curves[:-1] == sub.curves[:-1]
    if len(sub.curves) > 1:
        assert sub.extended([0]).curves == ()


def test_a_groom_subset_keeps_the_prims_it_draws_from():
    meta = Metadata(curves=(CurvesPrim("/A", 1), CurvesPrim("/B", 2, "bspline", "pinned")))
    sub = _groom(meta).subset([1, 2])
    assert sub.metadata.curves == (CurvesPrim("/B", 2, "bspline", "pinned"),)
    with pytest.raises(ParameterError, match="strand ids"):
        meta.subset([3])
