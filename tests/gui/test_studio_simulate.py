"""Animation → Simulate…: the dialog's options, the background job, and cancelling it."""

from __future__ import annotations

import numpy as np
import pytest

from hairtool import samples
from hairtool.simulate.dynamics import simulate

pytestmark = pytest.mark.gui


def test_dialog_round_trips_options_and_refuses_a_bad_motion(qtbot):
    from app.ui.simulate_dialog import SimulateDialog
    from hairtool.simulate.options import SimulateOptions

    o = SimulateOptions(motion="nod,hop", frames=30, fps=30.0, wind=(5.0, 0.0, -2.0), gusts=2, seed=4)
    dialog = SimulateDialog(None, o)
    qtbot.addWidget(dialog)
    assert dialog.options() == o
    assert dialog.duration.text() == "0.967 s"
    dialog.motion.setText("nod,twirl")
    dialog._accept()
    assert "motion" in dialog.error_label.text() and dialog.result() == 0


def test_simulation_runs_as_a_job_and_loads_the_result(make_window):
    from app.ui.simulate_dialog import SOURCE
    from hairtool.simulate.options import SimulateOptions

    groom = samples.scalp(12, 6, seed=1)
    w = make_window(groom=groom)
    options = SimulateOptions(motion="shake", frames=8, substeps=2, gusts=1, seed=3)
    w.ask_simulate_options = lambda o: options
    job = w.sources.simulate_dialog()
    assert w.jobs.wait(60) and job.state == "done", w.errors
    anim = w.animation.animation
    assert w.animation.source == SOURCE and anim.n_frames == 8
    expect = simulate(w.scene.result, **options.kwargs())
    np.testing.assert_array_equal(anim.frames, expect.frames)
    assert w.project.has_unsaved_changes()


def test_cancelled_simulation_keeps_the_previous_animation(make_window):
    from hairtool.simulate.options import SimulateOptions

    groom = samples.scalp(12, 6, seed=1)
    w = make_window(groom=groom)
    w.ask_simulate_options = lambda o: None  # the dialog's Cancel: nothing starts
    assert w.sources.simulate_dialog() is None and w.animation.animation is None
    assert w.sources.start_simulation(SimulateOptions(frames=4, substeps=1)) is not None
    assert w.jobs.wait(60)
    previous = w.animation.animation
    job = w.sources.start_simulation(SimulateOptions(frames=40, substeps=2, motion="hop"))
    w.jobs.cancel(job)
    assert w.jobs.wait(60) and job.state == "cancelled"
    assert w.animation.animation is previous


def test_the_dialog_opens_fitted_to_a_real_groom_and_fits_on_demand(make_window, grooms_dir, qtbot):
    from app.ui.simulate_dialog import SimulateDialog
    from hairtool.simulate.head_motion import fit_head
    from hairtool.simulate.options import SimulateOptions

    w = make_window()
    assert w.open_path(grooms_dir / "sintel_hair.tfx"), w.errors
    seen = []
    w.ask_simulate_options = lambda o: seen.append(o)  # the dialog's Cancel, after a look
    assert w.sources.simulate_dialog() is None
    centre, radius = fit_head(w.scene.result.roots)
    shown = seen[0]
    assert shown.head_radius == pytest.approx(radius, abs=1e-3) and 5.0 < radius < 15.0
    np.testing.assert_allclose(shown.head_center, centre, atol=1e-3)
    base = SimulateOptions()
    assert shown.gravity == base.gravity  # m/s², converted by the groom's unit, not scaled
    assert shown.gust_strength == pytest.approx(base.gust_strength * shown.head_radius)
    # options the user chose are kept as they are
    chosen = SimulateOptions(frames=12)
    w.sources.simulate_options = chosen
    w.sources.simulate_dialog()
    assert seen[-1] == chosen
    dialog = SimulateDialog(None, chosen, w.scene.result)
    qtbot.addWidget(dialog)
    dialog.fit_button.click()
    assert dialog.options().head_radius == pytest.approx(radius, abs=1e-3)
    assert not SimulateDialog(None, chosen).fit_button.isEnabled()  # no groom, nothing to fit
