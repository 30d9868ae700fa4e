"""``simulate`` on an animated groom: the source's own root motion drives the hair (roots on
the source's roots every frame, the head moving with them), said in one line, at the source's
time codes; the driven kernel against its numpy twin. On generated stages animated by points
and by a parent's transform."""

from __future__ import annotations

import numpy as np
import pytest

from hairtool import io
from hairtool.cli import main
from hairtool.groom import Animation
from hairtool.simulate.driver import RootDriver
from hairtool.simulate.dynamics import simulate, simulate_reference

from .test_animated_interpolate import two_prims
from .usd_scenes import write_stage


@pytest.mark.parametrize("animated", ["points", "transform"])
def test_the_roots_follow_the_source_at_its_time_codes(tmp_path, animated, capsys):
    write_stage(tmp_path / "s.usda", two_prims(animated))
    src = io.read(tmp_path / "s.usda")
    out = tmp_path / "sim.usda"
    assert main(["simulate", str(tmp_path / "s.usda"), str(out), "--fit-head", "--substeps", "2"]) == 0
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "info" in err[0] and "roots follow" in err[0]
    sim = io.read(out)
    assert isinstance(sim, Animation) and list(sim.time_codes) == list(src.time_codes) == [1.0, 2.0, 3.0]
    assert [c.path for c in sim.metadata.curves] == [c.path for c in src.metadata.curves]
    idx = src.topology.root_indices
    scale = float(np.abs(src.frames).max())
    np.testing.assert_allclose(sim.frames[:, idx], src.frames[:, idx], rtol=0, atol=1e-6 * scale)
    assert main(["simulate", str(tmp_path / "s.usda"), str(out), "--motion", "nod"]) == 2
    err = capsys.readouterr().err
    assert "motion" in err and "animated" in err and len(err.strip().splitlines()) == 1


def test_the_driven_kernel_equals_its_numpy_twin(tmp_path):
    write_stage(tmp_path / "s.usda", two_prims("transform"))
    src = io.read(tmp_path / "s.usda")
    kw = dict(frames=4, fps=src.fps, substeps=3, driver=RootDriver(src), head_radius=0.05)
    a = simulate(src.rest, **kw)
    b = simulate_reference(src.rest, **kw)
    np.testing.assert_allclose(a.frames, b.frames, rtol=0, atol=1e-6)
    idx = src.topology.root_indices
    assert np.array_equal(a.frames[3][idx], src.frames[2][idx])  # held after the source's last frame
