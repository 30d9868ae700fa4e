"""``hairtool bench keys --quick`` runs and reports every column the lead reads."""

from __future__ import annotations

import json

import pytest

from hairtool.cli import main


def test_quick_bench_rows(capsys):
    assert main(["bench", "keys", "--quick", "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)
    main_rows = [r for r in rows if "gram_s" in r]
    assert [(r["frames"], r["dims"]) for r in main_rows] == [(40, 6), (120, 48)]
    modes = {(r["frames"], r["objective"], r["interp"], r["constrained"]) for r in rows if "gram_s" not in r}
    assert modes == {
        (n, o, i, c)
        for n in (40, 120)
        for o, i, c in (
            ("worst", "linear", False),
            ("worst", "hermite", False),
            ("total", "hermite-fit", False),
            ("total", "linear", True),
            ("worst", "linear", True),
            ("quaternion", "slerp", False),
        )
    }
    assert all(r["dims"] == 23 for r in rows if r["objective"] == "quaternion")
    assert all(r["select_s"] > 0 for r in rows)
    for r in rows:  # the constrained rows say what the constraints add, against their own table
        assert ("constraint_overhead" in r) == r["constrained"]
        if r["constrained"]:
            assert r["dp_unconstrained_s"] > 0
            assert r["constraint_overhead"] == pytest.approx(
                (r["table_s"] + r["dp_s"]) / (r["table_s"] + r["dp_unconstrained_s"]) - 1.0
            )
    for r in main_rows:
        for key in ("select_s", "gram_s", "table_s", "dp_s", "direct_s", "features_s"):
            assert key in r
        assert r["select_s"] > 0 and r["gram_s"] > 0
        assert r["direct_s"] is not None and r["table_rel_diff"] < 1e-9


def test_sizes_option(capsys):
    assert main(["bench", "keys", "--sizes", "20x3", "--no-direct", "--max-keys", "5"]) == 0
    assert "frames" in capsys.readouterr().out
    assert main(["bench", "keys", "--sizes", "20by3"]) == 2
