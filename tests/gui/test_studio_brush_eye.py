"""A brush stroke in the studio records the camera's eye in its samples in the 3-D
(perspective) view, where lines of sight spread from it, and none in the orthographic 2-D view,
whose lines of sight all run along the view (what the eye changes: hairtool's
tests/frozen/test_sight_brush_perspective.py)."""

from __future__ import annotations

import numpy as np
import pytest

from hairtool import samples

pytestmark = pytest.mark.gui


def test_a_perspective_stroke_records_the_eye_and_an_orthographic_one_does_not(ui, make_window):
    w = make_window(groom=samples.comb(16, 6))
    s, v = w.scene, w.viewport
    s.set_params(s.params.replace(freeze=False, clump=False))
    w.brush_actions["mask"].trigger()
    s.set_radius(float(np.ptp(s.result.points, axis=0).max()))  # the brush covers the comb
    recorded = []
    for ortho in (False, True):
        v.set_ortho(ortho)
        v.frame_all()
        eye = v.camera.eye()
        at = v.project(s.result.points.mean(axis=0, keepdims=True))[0]
        before = len(s.pipeline.strokes)
        ui.drag(v, at, at + np.array([3.0, 0.0]), steps=2)
        dabs = [x for x in s.pipeline.strokes[before:] if x.brush == "mask"]
        assert dabs
        recorded.append((eye, [x.eye for x in dabs]))
    (eye, persp), (_, flat) = recorded
    assert all(e is not None and np.allclose(e, eye) for e in persp)
    assert all(e is None for e in flat)
