"""One simulation's options as a value (no Qt): JSON round trip, the keyword arguments of
simulate, the head fitted to a groom, and a run that stops at the first frame after a cancel."""

from __future__ import annotations

import json

import numpy as np
import pytest

from hairtool import samples
from hairtool.errors import Cancelled, ParameterError
from hairtool.simulate.dynamics import simulate
from hairtool.simulate.head_motion import fit_head
from hairtool.simulate.options import SimulateOptions, run_simulation


def test_options_round_trip_and_give_simulates_arguments():
    o = SimulateOptions(motion="nod,hop", frames=30, fps=30.0, wind=(5.0, 0.0, -2.0), gusts=2, seed=4)
    assert SimulateOptions.from_dict(json.loads(json.dumps(o.to_dict()))) == o
    kw = o.kwargs()
    assert kw["motion"] == ["nod", "hop"] and kw["wind"][1] == pytest.approx(np.hypot(5.0, 2.0))
    assert SimulateOptions().kwargs()["wind"] is None
    with pytest.raises(ParameterError, match="simulate options"):
        SimulateOptions.from_dict({"frames": 3, "viscosity": 1.0})
    with pytest.raises(ParameterError, match="motion"):
        SimulateOptions(motion="nod,twirl").kwargs()


def test_run_is_the_engines_simulation_and_stops_after_a_cancel():
    groom = samples.scalp(12, 6, seed=1)
    options = SimulateOptions(motion="shake", frames=8, substeps=2, gusts=1, seed=3)
    seen = []
    anim = run_simulation(groom, options, lambda *a: seen.append(a), lambda: False)
    np.testing.assert_array_equal(anim.frames, simulate(groom, **options.kwargs()).frames)
    assert seen[0] == (0.0, "preparing") and seen[-1][0] == pytest.approx(1.0)
    done = []
    with pytest.raises(Cancelled):
        run_simulation(groom, SimulateOptions(frames=20), lambda *a: done.append(a), lambda: len(done) > 2)
    assert len(done) == 3


def test_fitted_to_a_groom_scales_wind_and_gusts_with_the_head_not_gravity():
    groom = samples.scalp(200, 8, seed=2)
    centre, radius = fit_head(groom.roots)
    base = SimulateOptions()
    fitted = base.fitted_to(groom)
    assert fitted.head_radius == pytest.approx(radius, abs=1e-3)
    np.testing.assert_allclose(fitted.head_center, centre, atol=1e-3)
    scale = fitted.head_radius / base.head_radius
    assert fitted.gravity == base.gravity == 9.81  # m/s²: the groom's unit converts it
    assert fitted.gust_strength == pytest.approx(base.gust_strength * scale)


def test_gravity_of_a_project_saved_in_scene_units_is_converted():
    """Before gravity was in m/s² a project stored scene units/s² (98.1 by default, no unit);
    reopened, it must fall as it did, not ten times harder."""
    o = SimulateOptions(gravity=4.0)
    assert o.to_dict()["gravity_unit"] == "m/s²"
    assert SimulateOptions.from_dict(o.to_dict(), units_per_meter=10.0) == o  # marked: kept as is
    old = {k: v for k, v in o.to_dict().items() if k != "gravity_unit"} | {"gravity": 98.1}
    assert SimulateOptions.from_dict(old, units_per_meter=10.0).gravity == pytest.approx(9.81)
    assert SimulateOptions.from_dict(old, units_per_meter=100.0).gravity == pytest.approx(0.981)
    with pytest.raises(ParameterError, match="gravity_unit"):
        SimulateOptions.from_dict(o.to_dict() | {"gravity_unit": "ft/s²"})
