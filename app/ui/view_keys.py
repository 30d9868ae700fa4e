"""Blender's view keys: the numpad's front (1), right (3) and top (7) views, Ctrl for the
opposite side (on the numpad only: Ctrl+1…4 of the main row pick the animation's view mode),
and the numpad's period to frame the selection.

The views are the DCCs' own: front looks along the groom's forward axis (−z of a Y-up groom, +y
of a Z-up one), right looks at the groom's right side, top looks down. A view keeps the camera's
target, distance and projection; only its direction changes. Qt finds a shortcut "1" for the
numpad's 1 too, so the keys work with or without a numpad.
"""

from __future__ import annotations

import math

import numpy as np

from app.render.camera import PITCH_LIMIT, Camera

#: name → (yaw, pitch) of the orbit camera (its docstring's frame); top and bottom stop at the
#: orbit's pitch limit, so the view's up stays defined.
VIEWS = {
    "front": (0.0, 0.0),
    "back": (math.pi, 0.0),
    "right": (math.pi / 2.0, 0.0),
    "left": (-math.pi / 2.0, 0.0),
    "top": (0.0, PITCH_LIMIT),
    "bottom": (0.0, -PITCH_LIMIT),
}
#: (menu label, view, key), in the order of the View menu: Blender's numpad keys.
VIEW_KEYS = (
    ("&Front", "front", "1"),
    ("Bac&k", "back", "Ctrl+Num+1"),
    ("&Right", "right", "3"),
    ("&Left", "left", "Ctrl+Num+3"),
    ("&Top", "top", "7"),
    ("&Bottom", "bottom", "Ctrl+Num+7"),
)


def look_from(camera: Camera, view: str) -> None:
    """Turn ``camera`` to look from ``view`` (a key of :data:`VIEWS`) at its target."""
    camera.yaw, camera.pitch = VIEWS[view]


def selected_bounds(scene) -> tuple[np.ndarray, np.ndarray] | None:
    """``(lo, hi)`` of the selected, shown strands' points; None when all are (frame all then)
    or none is."""
    chosen = scene.selected & ~scene.hidden
    if chosen.all() or not chosen.any():
        return None
    g = scene.result
    pts = g.points[chosen[g.topology.strand_index]]
    return pts.min(axis=0), pts.max(axis=0)


def frame_selected(viewport) -> None:
    """Fit the selected strands in view (Blender's View Selected); with every strand selected,
    or none, the whole groom and its head."""
    box = selected_bounds(viewport.scene)
    if box is None:
        viewport.frame_all()
        return
    cam = viewport.camera
    centre, radius = cam.scene_center, cam.scene_radius  # the clip range stays the whole scene's
    cam.frame(*box, aspect=viewport._aspect())
    cam.scene_center, cam.scene_radius = centre, radius
    viewport._auto_frame = False
    viewport.update()


def set_view(viewport, view: str) -> None:
    """The numpad's view ``view`` in ``viewport`` (a 2-D view keeps its fixed front)."""
    if viewport.camera.ortho and viewport.scene.is_planar:
        return
    look_from(viewport.camera, view)
    viewport._auto_frame = False
    viewport.update()


def add_view_actions(window, menu) -> dict[str, object]:
    """The numpad views and Frame selected in ``menu`` (the View menu), by view name."""
    from app.ui.qt_utils import add_action

    v = window.viewport
    actions = {"selected": add_action(window, menu, "Frame &selected", lambda: frame_selected(v), "Num+.")}
    views = menu.addMenu("&Numpad views")
    for label, name, key in VIEW_KEYS:
        actions[name] = add_action(window, views, label, lambda _=False, n=name: set_view(v, n), key)
    return actions
