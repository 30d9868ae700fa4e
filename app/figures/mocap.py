"""Seed 003's Fig. 9 on a bundled walk: a jump added at one key, before and after.

``python -m app.figures.mocap OUTDIR`` keys the bundled walk (pymo's, 1,064 frames at 120 fps:
24 keys, cubic Hermite, exact DP on joint positions), then edits one key pose by IK as an
animator would for a jump: both heels drawn up behind the hips (knee and hip turn) and both
wrists raised forward (elbow, shoulder and collar turn). The root keeps its captured path, so
the lifted feet leave the ground line. The edit
spreads to the frames between the neighbouring keys with the captured detail kept, and the
capture is untouched outside them. Writes ``mocap_fig9_jump.png``: the original frames (top)
and the edited ones (bottom, the original faint behind) from the key before to the key after,
side views of the walk; and ``mocap_fig9_jump.bvh``, the edited capture.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from app.figures.sheet import grid, label, main_guard, out_dir, write
from app.render.camera import Camera
from app.render.offscreen import render_image
from hairtool.groom import Groom
from hairtool.keys.session import find_keys
from hairtool.mocap import ik
from hairtool.mocap.bvh import Motion, read_bvh, write_bvh
from hairtool.mocap.costs import motion_features
from hairtool.mocap.pose_edit import PoseEdit, PoseEditor

CAPTURE = Path(__file__).resolve().parents[2] / "tests" / "data" / "motion" / "pymo_walk.bvh"
KEYS = 24
AFTER_FRAME = 200  # the edited key: the first after this frame, on a straight stretch of the walk
#: (ankle, wrist, shoulder) of each side in the capture's hierarchy
LIMBS = [tuple(f"{side}{part}" for part in ("Foot", "Hand", "Arm")) for side in ("Left", "Right")]
BACKGROUND = (1.0, 1.0, 1.0, 1.0)
INK = np.array([0.12, 0.12, 0.15])
EDITED = np.array([0.80, 0.18, 0.12])
GHOST = np.array([0.80, 0.80, 0.82])
GROUND = np.array([0.45, 0.45, 0.45])


def jump_edits(motion: Motion, frame: int) -> list[PoseEdit]:
    """A tuck jump at ``frame``: heels drawn up behind the hips, wrists reaching up and forward."""
    h = ik.figure_height(motion)
    p = motion.joint_positions()[frame]
    root = motion.root_translation()
    ahead = root[min(frame + 10, motion.n_frames - 1)] - root[max(frame - 10, 0)]
    ahead[1] = 0.0
    ahead /= max(float(np.linalg.norm(ahead)), 1e-12)
    name = motion.joint_names.index
    hips = p[0]
    edits = []
    for ankle_name, _, _ in LIMBS:
        ankle = p[name(ankle_name)]
        tucked = ankle + np.array([0.0, 0.25 * h, 0.0])
        tucked[[0, 2]] = 0.6 * ankle[[0, 2]] + 0.4 * hips[[0, 2]] - 0.1 * h * ahead[[0, 2]]
        edits.append(PoseEdit(frame, ankle_name, tuple(tucked), 2))
    for _, wrist_name, shoulder_name in LIMBS:
        shoulder = p[name(shoulder_name)]
        raised = shoulder + 0.2 * h * np.array([0.0, 1.0, 0.0]) + 0.12 * h * ahead
        edits.append(PoseEdit(frame, wrist_name, tuple(raised), 3))
    return edits


def _side_view(points: np.ndarray, heading: np.ndarray) -> np.ndarray:
    """World points turned so the walk runs along +x and the camera (down −z) sees its side."""
    f = np.array([heading[0], 0.0, heading[1]])
    f /= np.linalg.norm(f)
    up = np.array([0.0, 1.0, 0.0])
    side = np.cross(f, up)
    return np.stack([points @ f, points @ up, points @ side], axis=-1)


def _bones(motion: Motion, frame: int) -> np.ndarray:
    """``(B, 2, 3)`` bone segments of one frame, End Sites included."""
    p = motion.joint_positions(end_sites=True)[frame]
    parent = np.r_[motion.parents[1:], motion.end_parents]
    child = np.r_[np.arange(1, motion.n_joints), motion.n_joints + np.arange(len(motion.end_parents))]
    return np.stack([p[parent], p[child]], axis=1)


def _panel(layers, centre, half, ground_y, size) -> np.ndarray:
    """Bones of each ``(segments, colour)`` layer, later ones on top, and the ground line."""
    segs = [np.array([[centre[0] - half, ground_y, 0.0], [centre[0] + half, ground_y, 0.0]])[None]]
    colours = [GROUND]
    for depth, (s, c) in enumerate(layers):
        s = s.copy()
        s[..., 2] = np.clip(s[..., 2], -half, half) - 3.0 * half + depth * 2.0 * half  # later ones nearer
        segs.append(s)
        colours += [c] * len(s)
    points = np.concatenate([s.reshape(-1, 3) for s in segs])
    groom = Groom(points, np.full(len(colours), 2))
    lo = np.array([centre[0] - half, centre[1] - half, -6.0 * half])
    hi = np.array([centre[0] + half, centre[1] + half, 6.0 * half])
    cam = Camera.for_bounds(lo, hi, ortho=True)
    colors = np.repeat(colours, 2, axis=0)
    return render_image(groom, size=size, camera=cam, colors=colors, line_width=3.0, background=BACKGROUND)


def make(argv: list[str] | None = None) -> None:
    outdir, args = out_dir(__doc__.splitlines()[0], argv)
    size = (args.size, args.size)
    m = read_bvh(CAPTURE)
    keys = find_keys(motion_features(m), keys=KEYS, interp="hermite").keys
    which = int(np.searchsorted(keys, AFTER_FRAME))
    frame = int(keys[which])
    editor = PoseEditor(m, keys, "hermite")
    reports = editor.apply_all(jump_edits(m, frame))
    edited = editor.motion()
    write_bvh(outdir / "mocap_fig9_jump.bvh", edited)
    lo, hi = int(keys[which - 1]), int(keys[which + 1])
    shown = np.r_[np.linspace(lo, frame, 4), np.linspace(frame, hi, 4)]
    frames = np.unique(shown.round().astype(int))  # three steps either side of the key
    root = m.root_translation()
    heading = root[hi, [0, 2]] - root[lo, [0, 2]]
    h = ik.figure_height(m)
    ground = _side_view(m.joint_positions(end_sites=True).reshape(-1, 3), heading)[:, 1].min()
    top, bottom = [], []
    for f in frames:
        before = _side_view(_bones(m, f), heading)
        after = _side_view(_bones(edited, f), heading)
        centre = np.array([before[:, :, 0].mean(), ground + 0.5 * h])
        half = 0.62 * h
        tag = "(key)" if f in keys else ""
        top.append(label(_panel([(before, INK)], centre, half, ground, size), f"frame {f} {tag}".strip()))
        both = _panel([(before, GHOST), (after, EDITED)], centre, half, ground, size)
        bottom.append(label(both, f"edited {f} {tag}".strip()))
    write(outdir / "mocap_fig9_jump.png", grid(top + bottom, columns=len(frames)))
    print(f"jump at the key of frame {frame}: frames {lo + 1}-{hi - 1} follow (keys {lo}, {frame}, {hi})")
    for r in reports:
        where = f"{r.miss_share:.2g} of the figure's height from its target"
        print(f"{r.edit.joint} at frame {r.edit.frame}: {where}")


if __name__ == "__main__":
    sys.exit(main_guard(make))
