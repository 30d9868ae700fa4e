"""Front faces only by sight in the studio (issue 47): on Sintel's head, seen from a camera
level with her face, a Mask press on the crown starts on the crown's hair and paints most of
the strands under it, though their roots tilt away from the camera; the stroke says so in its
samples (``visible``), so its log replays the same."""

from __future__ import annotations

import numpy as np
import pytest

pytestmark = pytest.mark.gui


def test_a_mask_press_on_the_crown_seen_from_the_face_paints_the_crown(ui, make_window):
    w = make_window()
    assert w.open_bundled_sample(), w.errors
    s, v = w.scene, w.viewport
    v.frame_all()  # yaw = pitch = 0: the eye level with her face
    w.brush_actions["mask"].trigger()
    g = s.result
    crown = g.roots[np.argsort(g.roots[:, 1])[-5]].astype(np.float64)
    pos = v.project(crown[None])[0]
    ui.drag(v, pos, pos + np.array([2.0, 0.0]), steps=2)
    dabs = [x for x in s.pipeline.strokes if x.brush == "mask"]
    assert dabs and all(x.visible and x.view is not None for x in dabs)
    first = dabs[0]
    assert np.linalg.norm(np.asarray(first.cursor) - crown) < first.radius  # on the crown's hair
    top = g.topology
    near = np.linalg.norm(g.points.astype(np.float64) - np.asarray(first.cursor), axis=1) < first.radius
    under = np.logical_or.reduceat(near, top.offsets[:-1])
    assert under.sum() >= 5
    assert s.pipeline.locked[under].mean() >= 0.5
