"""The timeline's numbers (no window, no GL): keys traced from one solve equal the engine's own
selection, chunked reconstructions and errors equal the core's, a ranged key edit equals
editing the whole animation."""

from __future__ import annotations

import numpy as np
import pytest

from hairtool import samples
from hairtool.errors import ParameterError
from hairtool.keys import session as ks
from hairtool.keys.costs import cost_table
from hairtool.keys.dp import select_keys, uniform_keys
from hairtool.keys.edit import edit_animation
from hairtool.keys.features import hair_features
from hairtool.keys.reconstruct import (
    interpolate_at,
    interpolate_keys,
    key_poses,
    motion_speed,
    position_errors,
    reconstruct,
)
from hairtool.simulate.sway import sway_animation


@pytest.fixture(scope="module")
def anim():
    return sway_animation(samples.comb(strands=12, vertices=8), 40, 24.0, flick_frame=27)


@pytest.mark.parametrize("interp", ["linear", "hermite"])
@pytest.mark.parametrize("objective", ["total", "worst"])
def test_keys_for_every_count_equal_the_engines_selection(anim, interp, objective):
    settings = ks.KeySettings(interp=interp, objective=objective, tip_weight=3.0, samples=6)
    solved = ks.solve(anim, settings)
    table = cost_table(hair_features(anim, settings.feature_options()), interp, 0.0, objective)
    np.testing.assert_array_equal(solved.table, table)
    assert solved.kmax == anim.n_frames
    for k in (2, 3, 5, 9, 17, 40):
        want = select_keys(table, keys=k, objective=objective)
        np.testing.assert_array_equal(solved.keys_for_count(k), want.keys)
        assert solved.curve[k - 2, 1] == pytest.approx(want.cost, rel=1e-12, abs=1e-12)


def test_tau_and_budget_keys_equal_the_engines(anim):
    solved = ks.solve(anim, ks.KeySettings())
    e2 = solved.table[0, -1]  # tau is a share of the two-key error
    assert solved.two_key_error == e2 > 0
    for tau in (0.0, 1e-4, 0.01, 1.0):
        want = select_keys(solved.table, penalty=tau * e2).keys
        np.testing.assert_array_equal(solved.keys_for(ks.KeySettings(mode="tau", tau=tau)), want)
        np.testing.assert_array_equal(solved.keys_for_tau(tau * e2, relative=False), want)
    for budget in (0.0, 0.05, 1.0, 1e6):
        want = select_keys(solved.table, budget=budget).keys
        got = solved.keys_for(ks.KeySettings(mode="budget", budget=budget))
        np.testing.assert_array_equal(got, want)


def test_default_count_is_the_knee_of_the_error_curve(anim):
    solved = ks.solve(anim, ks.KeySettings())
    knee = solved.knee
    assert solved.keys_for(ks.KeySettings()).size == knee == ks.knee_count(solved.curve)
    curve = solved.curve
    x = (curve[:, 0] - 2) / (curve[-1, 0] - 2)
    y = (curve[:, 1] - curve[-1, 1]) / (curve[0, 1] - curve[-1, 1])
    assert knee == curve[np.argmax(1 - x - y), 0]
    assert 2 < knee < 40


def test_knee_rule():
    k = np.arange(2, 30)
    assert ks.knee_count(np.column_stack([k, 1.0 / (k - 1.0) ** 2])) < 6  # a sharp elbow, early
    assert ks.knee_count(np.column_stack([k, 30.0 - k])) == 2  # a straight line: no knee, fewest
    assert ks.knee_count(np.column_stack([k, np.zeros(k.size)])) == 2  # nothing to save
    assert ks.knee_count(np.column_stack([k, np.where(k < 12, 1.0, 0.0)])) == 12  # a step
    with pytest.raises(ParameterError, match="curve"):
        ks.knee_count(np.zeros((3, 3)))


def test_settings_are_validated():
    with pytest.raises(ParameterError, match="tau"):
        ks.KeySettings(mode="tau", objective="worst").validate()
    with pytest.raises(ParameterError, match="samples"):
        ks.KeySettings(samples=1).validate()
    with pytest.raises(ParameterError, match="interpolation"):
        ks.KeySettings().replace(interp="cubic")


@pytest.mark.parametrize("interp", ["linear", "hermite"])
def test_rebuilt_frames_and_errors_equal_the_core(anim, interp):
    keys = np.array([0, 7, 12, 30, 39])
    kp = key_poses(anim.frames, keys, interp)
    full = interpolate_keys(kp)
    np.testing.assert_array_equal(interpolate_at(kp, np.arange(40)), full)
    err = ks.frame_errors(anim, kp)
    ref = position_errors(anim, reconstruct(anim, keys, interp))
    np.testing.assert_allclose(err.mean, ref.per_frame_mean, rtol=1e-4, atol=1e-6)
    np.testing.assert_allclose(err.tip, ref.per_frame_tip, rtol=1e-4, atol=1e-6)
    np.testing.assert_allclose(err.max, ref.per_frame_max, rtol=1e-4, atol=1e-6)
    assert np.all(err.mean[keys] == 0)
    d = ks.vertex_errors(anim, ks.key_poses_of(anim, keys, interp), 20)
    np.testing.assert_allclose(d.mean(), ref.per_frame_mean[20], rtol=1e-4)


def test_speed_equals_the_cores(anim):
    np.testing.assert_allclose(ks.speed(anim), motion_speed(anim.frames, anim.fps), rtol=1e-5)


def test_analysis_compares_with_uniform_keys_of_the_same_count(anim):
    keys = np.array([0, 20, 26, 29, 39])
    a = ks.analyse(anim, keys, "linear")
    np.testing.assert_array_equal(a.uniform.keys, uniform_keys(40, 5))
    np.testing.assert_array_equal(a.dp.keys, keys)
    assert a.speed.shape == (40,)


def test_cancelled_work_returns_none(anim):
    assert ks.solve(anim, ks.KeySettings(), cancelled=lambda: True) is None
    assert ks.analyse(anim, [0, 39], "linear", cancelled=lambda: True) is None


@pytest.mark.parametrize("interp", ["linear", "hermite"])
@pytest.mark.parametrize("key_frame", [0, 7, 12, 39])
def test_ranged_key_edit_equals_editing_the_whole_animation(anim, interp, key_frame):
    keys = np.array([0, 7, 12, 30, 39])
    pose = anim.frames[key_frame] + np.float32(0.1)
    start, block = ks.key_edit_block(anim.frames, keys, interp, key_frame, pose)
    whole = edit_animation(anim, keys, {key_frame: pose}, interp).frames
    np.testing.assert_array_equal(whole[start : start + len(block)], block)
    outside = np.ones(40, bool)
    outside[start : start + len(block)] = False
    np.testing.assert_array_equal(whole[outside], anim.frames[outside])
    with pytest.raises(ParameterError, match="key frame"):
        ks.key_edit_block(anim.frames, keys, interp, 8, pose)


def test_constraints_steer_every_mode_of_a_session_and_match_the_engine(anim):
    from hairtool.keys.constraints import KeyConstraints

    cons = KeyConstraints(pins=(5, 30), excludes=(26, 27, 28))
    base = ks.KeySettings(pins=[30, 5], excludes=(28, 26, 27))  # as a project file lists them
    assert base.constraints == cons
    solved = ks.solve(anim, base)
    table = solved.table
    assert solved.key_range == (4, 37)
    for k in (4, 6, 9):
        got = solved.keys_for_count(k)
        np.testing.assert_array_equal(got, select_keys(table, keys=k, constraints=cons).keys)
        assert cons.allows(got)
    assert solved.curve[0, 0] == 4 and np.all(np.isfinite(solved.curve[:, 1]))
    for tau in (1e-4, 1e-2):
        assert cons.allows(solved.keys_for(base.replace(mode="tau", tau=tau)))
    budget = float(solved.curve[3, 1])
    got = solved.keys_for(base.replace(mode="budget", budget=budget))
    np.testing.assert_array_equal(got, select_keys(table, budget=budget, constraints=cons).keys)
    # the default count is the knee of the unconstrained curve, never fewer keys than the pins need
    assert solved.knee == ks.solve(anim, ks.KeySettings()).knee
    assert solved.keys_for(base).size == max(solved.knee, 4)
    with pytest.raises(ParameterError, match="with these pins"):
        solved.keys_for_count(3)
    # new constraints reuse the table: no features, no cost table
    assert solved.keys_for(ks.KeySettings(count=5)).size == 5 and not solved.constraints
    assert solved.key_range == (2, 40) and not solved.constraints
    np.testing.assert_array_equal(solved.keys_for_count(5), select_keys(table, keys=5).keys)


@pytest.mark.parametrize("objective", ["total", "worst"])
def test_the_default_count_holds_while_the_animator_steers(anim, objective):
    """The knee is the unconstrained curve's, as a key reducer's count: pinning keys or excluding
    frames that are not keys changes nothing, moving a key keeps the count."""
    settings = ks.KeySettings(objective=objective)
    solved = ks.solve(anim, settings)
    keys, knee = solved.keys_for(settings), solved.knee
    assert keys.size == knee > 3
    inner = keys[1:-1].tolist()
    others = [f for f in range(1, 39) if f not in keys]
    for pins, excludes in (([inner[0]], ()), (inner[:2], others[:3]), (inner, others[::2])):
        got = solved.keys_for(settings.replace(pins=pins, excludes=excludes))
        np.testing.assert_array_equal(got, keys)
    for old in inner:
        for new in others[::4]:
            got = solved.keys_for(settings.replace(pins=(new,), excludes=(old,)))
            assert got.size == knee and new in got and old not in got
    assert solved.knee == knee
    # a fresh session under pins (a reopened project) gives the same default count
    assert ks.solve(anim, settings.replace(pins=(others[0],))).keys_for(settings).size == knee
