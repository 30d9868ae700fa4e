"""Hermite with fitted tangents: the O(D)-per-segment kernel equals a least-squares solve per
segment, never costs more than seed 003's data tangents, reproduces a Hermite curve exactly from
its two ends, and its key curve's error is the table's cost at the chosen keys."""

from __future__ import annotations

from itertools import combinations

import numpy as np
import pytest

from hairtool.errors import ParameterError
from hairtool.keys.costs import cost_table
from hairtool.keys.dp import keys_cost, select_keys
from hairtool.keys.gram import HERMITE_BASIS, frame_curvature
from hairtool.keys.reconstruct import interpolate_keys, key_poses
from hairtool.keys.segment_fit import fit_table, fit_table_reference


def walk(n: int, d: int, seed: int) -> np.ndarray:
    return np.cumsum(np.random.default_rng(seed).normal(size=(n, d)), axis=0)


@pytest.mark.parametrize(("n", "d", "lam"), [(20, 3, 0.0), (24, 5, 0.4), (12, 40, 0.0), (9, 1, 1.0)])
def test_kernel_equals_a_least_squares_solve_per_segment(n, d, lam):
    x = walk(n, d, n + d)
    curv = frame_curvature(x)
    got, want = fit_table(x, curv, lam), fit_table_reference(x, curv, lam)
    np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-9 * np.abs(want).max())


@pytest.mark.parametrize("seed", range(4))
def test_fitted_tangents_never_cost_more_than_the_data_tangents(seed):
    x = walk(40, 6, seed) + np.sin(np.arange(40) / 3.0)[:, None] * 4.0
    fitted, data = cost_table(x, "hermite-fit", 0.2), cost_table(x, "hermite", 0.2)
    iu = np.triu_indices(40, 2)
    assert np.all(fitted[iu] <= data[iu] * (1 + 1e-9) + 1e-9)
    assert fitted[iu].sum() < 0.8 * data[iu].sum()


def test_a_hermite_curve_is_rebuilt_exactly_from_its_two_ends():
    n, rng = 31, np.random.default_rng(3)
    p0, p1, a, b = rng.normal(size=(4, 5)) * [[1], [1], [20], [20]]
    s = np.linspace(0.0, 1.0, n)
    basis = HERMITE_BASIS @ np.stack([np.ones_like(s), s, s**2, s**3])
    x = basis[0][:, None] * p0 + basis[1][:, None] * a + basis[2][:, None] * p1 + basis[3][:, None] * b
    table = cost_table(x, "hermite-fit")
    assert table[0, n - 1] == pytest.approx(0.0, abs=1e-9 * np.sum(x**2))
    assert cost_table(x, "hermite")[0, n - 1] > 0.1  # the data tangents miss the handles
    sel = select_keys(table, keys=2)
    rebuilt = interpolate_keys(key_poses(x, sel.keys, "hermite-fit"))
    np.testing.assert_allclose(rebuilt, x, atol=1e-9 * np.abs(x).max())


def test_the_key_curve_error_is_the_tables_cost_and_the_dp_is_exact_over_it():
    x = walk(14, 3, 7)
    table = cost_table(x, "hermite-fit")
    for k in (3, 4, 5):
        sel = select_keys(table, keys=k)
        best = min(
            keys_cost(table, np.array((0, *inner, 13))) for inner in combinations(range(1, 13), k - 2)
        )
        assert sel.cost == pytest.approx(best, rel=1e-12)
        rebuilt = interpolate_keys(key_poses(x, sel.keys, "hermite-fit"))
        assert np.sum((rebuilt - x) ** 2) == pytest.approx(sel.cost, rel=1e-8)
        kp = key_poses(x, sel.keys, "hermite-fit")
        assert kp.tangents.shape == kp.tangents_in.shape == (k, 3)


def test_fitted_tangents_need_the_total_objective():
    x = walk(10, 2, 0)
    with pytest.raises(ParameterError, match="objective"):
        cost_table(x, "hermite-fit", objective="worst")


def test_the_command_line_writes_the_handles_and_a_baked_curve(tmp_path, capsys):
    import json

    from hairtool import io, samples
    from hairtool.cli import main
    from hairtool.simulate.sway import sway_animation

    x = walk(30, 4, 1)
    np.savez(tmp_path / "x.npz", X=x)
    assert main(["keys", str(tmp_path / "x.npz"), "--keys", "6", "--interp", "hermite-fit", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    kp = key_poses(x, out["keys"], "hermite-fit")
    np.testing.assert_allclose(out["tangents"]["out"], kp.tangents)
    np.testing.assert_allclose(out["tangents"]["in"], kp.tangents_in)
    assert out["tangents"]["space"] == "X columns"
    anim = sway_animation(samples.comb(strands=6, vertices=5), 24, flick_frame=12)
    io.write(tmp_path / "a.npz", anim)
    argv = ["keys", str(tmp_path / "a.npz"), "--keys", "5", "--interp", "hermite-fit"]
    assert main([*argv, "--export", str(tmp_path / "baked.npz"), "--bake"]) == 0
    baked = io.read(tmp_path / "baked.npz")
    assert baked.n_frames == 24
    assert main(["keys", str(tmp_path / "x.npz"), "--bake"]) == 2
    assert main(["keys", str(tmp_path / "x.npz"), "--interp", "hermite-fit", "--objective", "worst"]) == 2
