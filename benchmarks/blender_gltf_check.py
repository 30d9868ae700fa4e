"""What Blender 5 plays from a character animation hairtool wrote, against hairtool's own reader.

Run it with hairtool's Python and point it at a Python that imports ``bpy`` (the Blender module,
``pip install bpy==5.0.1`` in a venv of its own; not a dependency, not in CI)::

    .venv/bin/python benchmarks/blender_gltf_check.py --bpy /work/bpy-venv/bin/python \
        [FILE.glb|FILE.vrm ...] [--out blender_gltf.json]

Without files it writes the bundled character's three kinds of animation first, with the
command line: the anime cycle (``STEP`` keys at the drawings, .glb and .vrm), the spring bones
on a head shake (``LINEAR`` keys on every frame) and their optimal keys with fitted tangents
(``CUBICSPLINE``). Blender imports each file with ``bpy.ops.import_scene.gltf`` (the rest pose
from the nodes, not a guessed bind pose) and is sampled at every frame of the clip.

Blender turns each bone to point along its length and the scene from +Y up to +Z up, so a bone's
matrix there is ``A · M · C`` (``A`` the fixed axis change, ``C`` the bone's own fixed turn) for
our world matrix ``M``. Its turn away from rest in world space, ``R_f · R_rest⁻¹``, is then ours
conjugated by ``A``, whatever ``C`` is: that is what is compared, bone by bone and frame by frame
(the angle of the rotation between the two, radians), with the bone heads' positions (metres).
A row per file gives the largest of each over the hair chains' bones.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

WORKER_FLAG = "--blender-worker"
ROOT = Path(__file__).resolve().parents[1]
# glTF (+Y up) to Blender (+Z up): x → x, y → z, z → −y
AXES = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])


# ---------------------------------------------------------------------------------------
# The Blender side (runs in the bpy Python; numpy and bpy only)
# ---------------------------------------------------------------------------------------
def blender_worker(path: str, bones: list[str], fps: float, frames: int, out: str) -> None:
    import bpy

    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.fps, scene.render.fps_base = round(fps), round(fps) / fps
    bpy.ops.import_scene.gltf(filepath=path, guess_original_bind_pose=False)
    arm = next(o for o in scene.objects if o.type == "ARMATURE")
    missing = [b for b in bones if b not in arm.pose.bones]
    if missing:
        raise SystemExit(f"{path}: Blender made no bone of {missing[0]}")
    rest = {b: [list(r) for r in arm.matrix_world @ arm.data.bones[b].matrix_local] for b in bones}
    action = arm.animation_data.action if arm.animation_data else None
    start = round(action.frame_range[0]) if action is not None else 0
    posed = []
    for f in range(frames):
        scene.frame_set(start + f)
        posed.append({b: [list(r) for r in arm.matrix_world @ arm.pose.bones[b].matrix] for b in bones})
    Path(out).write_text(json.dumps({"rest": rest, "posed": posed, "first_frame": start}))


# ---------------------------------------------------------------------------------------
# hairtool's side
# ---------------------------------------------------------------------------------------
def _rotation(m: np.ndarray) -> np.ndarray:
    r = np.asarray(m, dtype=np.float64)[:3, :3]
    return r / np.linalg.norm(r, axis=0)  # no scale: Blender's bones and our nodes may differ in it


def _angle(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.arccos(np.clip((np.trace(a.T @ b) - 1.0) / 2.0, -1.0, 1.0)))


def compare(path: Path, python: str) -> dict:
    from hairtool.character import load_character

    character = load_character(path)
    if not character.clips:
        raise SystemExit(f"{path}: no animation to compare")
    clip = character.clips[-1]
    fps = clip.frame_rate()
    count = round(clip.duration * fps) + 1
    ours = character.nodes.world(np.stack([clip.sample(character.nodes, f / fps) for f in range(count)]))
    rest = character.nodes.world()
    hair = sorted({j for chain in character.chains for j in chain.nodes})
    names = [character.nodes.names[j] for j in hair]
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "blender.json"
        subprocess.run(
            [python, __file__, WORKER_FLAG, str(path), json.dumps(names), repr(fps), str(count), str(out)],
            check=True,
        )
        theirs = json.loads(out.read_text())
    keys = sorted({round(float(t) * fps) for times, _ in clip.rotations.values() for t in times})
    worst_angle = worst_position = at_keys = 0.0
    worst_frame = 0
    for j, name in zip(hair, names, strict=True):
        b_rest = _rotation(theirs["rest"][name])
        g_rest = _rotation(rest[j])
        for f in range(count):
            b = np.asarray(theirs["posed"][f][name])
            turn_b = _rotation(b) @ b_rest.T
            turn_g = AXES @ (_rotation(ours[f, j]) @ g_rest.T) @ AXES.T
            angle = _angle(turn_b, turn_g)
            if angle > worst_angle:
                worst_angle, worst_frame = angle, f
            if f in keys:
                at_keys = max(at_keys, angle)
            worst_position = max(worst_position, float(np.linalg.norm(b[:3, 3] - AXES @ ours[f, j, :3, 3])))
    kinds = {"STEP" if clip.step else "CUBICSPLINE" if clip.cubic else "LINEAR"}
    return {
        "file": str(path),
        "interpolation": "/".join(sorted(kinds)),
        "bones": len(hair),
        "frames": count,
        "fps": fps,
        "blender_first_frame": theirs["first_frame"],
        "max_rotation_rad": worst_angle,
        "worst_frame": worst_frame,
        "max_rotation_at_keys_rad": at_keys,
        "max_position_m": worst_position,
    }


def bundled_exports(folder: Path) -> list[Path]:
    """The bundled character's cycle, springs and their optimal keys, written by the command line."""
    from hairtool.cli import main

    vrm = str(ROOT / "resources" / "bunches.vrm")
    runs = {
        "cycle.glb": ["anime", vrm, str(folder / "cycle.glb")],
        "cycle.vrm": ["anime", vrm, str(folder / "cycle.vrm")],
        "springs.glb": [
            "simulate",
            vrm,
            str(folder / "springs.glb"),
            "--springs",
            "--motion",
            "shake",
            "--frames",
            "48",
        ],
        "keys.glb": [
            "keys",
            str(folder / "springs.glb"),
            "--keys",
            "8",
            "--interp",
            "hermite-fit",
            "--export",
            str(folder / "keys.glb"),
        ],
        "keys.vrm": [
            "keys",
            str(folder / "springs.glb"),
            "--keys",
            "8",
            "--interp",
            "hermite-fit",
            "--export",
            str(folder / "keys.vrm"),
        ],
    }
    for argv in runs.values():
        if main([*argv, "--json"] if argv[0] != "keys" else argv) != 0:
            raise SystemExit(f"hairtool {' '.join(argv)} failed")
    return [folder / name for name in runs]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "files", nargs="*", type=Path, help="animated .glb/.vrm (default: the bundled character's)"
    )
    parser.add_argument("--bpy", required=True, help="a Python that imports bpy")
    parser.add_argument("--out", type=Path, help="also write the rows here as JSON")
    parser.add_argument("--keep", type=Path, help="write the bundled character's files here (kept)")
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp) if args.keep is None else args.keep
        folder.mkdir(parents=True, exist_ok=True)
        files = args.files or bundled_exports(folder)
        rows = [compare(path, args.bpy) for path in files]
    for row in rows:
        print(
            f"{Path(row['file']).name:12s} {row['interpolation']:12s} {row['bones']:3d} bones "
            f"{row['frames']:3d} frames at {row['fps']:g} fps: rotation ≤ {row['max_rotation_rad']:.2e} rad, "
            f"position ≤ {row['max_position_m']:.2e} m; worst on frame {row['worst_frame']}, "
            f"on the keys ≤ {row['max_rotation_at_keys_rad']:.2e} rad (Blender's first frame "
            f"{row['blender_first_frame']})"
        )
    if args.out is not None:
        args.out.write_text(json.dumps(rows, indent=2) + "\n")
    return 0


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1] == WORKER_FLAG:
        blender_worker(
            sys.argv[2], json.loads(sys.argv[3]), float(sys.argv[4]), int(sys.argv[5]), sys.argv[6]
        )
    else:
        sys.exit(main())
