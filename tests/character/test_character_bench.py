"""``hairtool bench character``: skinning and springs per frame against their numpy twins."""

from __future__ import annotations

import pytest

TIMES = ("skin_ms", "skin_numpy_ms", "springs_ms_per_frame", "springs_numpy_ms_per_frame", "cycle_ms")


def test_quick_rows(quick_bench):
    rows = quick_bench("character", times=())
    skins, springs = rows[:-1], rows[-1]
    assert [r["what"] for r in skins] == ["skin Body", "skin Hair"]
    for r in skins:
        assert r["numpy_over_numba"] == pytest.approx(r["skin_numpy_ms"] / r["skin_ms"])
        assert r["skin_ms"] > 0 and r["skin_numpy_ms"] > 0
    assert (springs["joints"], springs["frames"]) == (56, 6)
    for key in TIMES[2:]:
        assert springs[key] > 0
