"""hairtool's keys against Blender's Graph Editor Decimate, on real motion captures.

Run it with hairtool's Python and point it at a Python that imports ``bpy`` (the Blender module)::

    .venv/bin/python benchmarks/blender_decimate.py --bpy /work/bpyvenv/bin/python \
        [CAPTURE.bvh ...] [--ratios 0.9,0.95,0.98] [--errors 0.5,2] [--out decimate.json]

Captures default to every BVH in ``shared/data/motion``. Not part of the package or of CI.

For each capture, every channel of the file (the BVH's own numbers: rotations in degrees,
positions in scene units) becomes one F-curve in Blender with a Bezier key on every frame
(auto-clamped handles, as Blender keys a baked capture). Blender's Decimate
(``bpy.ops.graph.decimate``, run in the Graph Editor through a context override) then removes
keys, by ratio (each F-curve keeps the same share of its keys) or by error margin (each F-curve
keeps what its own curve needs). The script reads back Blender's key frames per F-curve and
evaluates Blender's own curves (``FCurve.evaluate``) at every frame.

Decimate works per F-curve, so hairtool is run per channel too, at Blender's key count for that
channel: the exact DP of ``hairtool.keys`` on that one channel, with each segment's handles
fitted (``hermite-fit``), seed 003's data tangents (``hermite``) and straight lines
(``linear``). Every channel thus has the same number of keys in both tools, and so has the
total. For the ratio runs, where every channel keeps the same count K, the table also gives
``hermite-fit`` with K keys shared by all channels (one key pose per frame, the harder case).

The error is the root-mean-square difference from the capture over all frames, separately for
rotation channels (degrees) and position channels (scene units). Blender stores keys in
float32; hairtool's curves are float64.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

WORKER_FLAG = "--blender-worker"


# ---------------------------------------------------------------------------------------
# The Blender side (runs in the bpy Python; numpy and bpy only)
# ---------------------------------------------------------------------------------------
def _blender_decimate(values: np.ndarray, mode: str, amount: float) -> tuple[list[np.ndarray], np.ndarray]:
    """Keys every channel on every frame, decimates, returns the kept frames per channel and
    Blender's curves evaluated at every frame ``(F, C)``."""
    import bpy

    bpy.ops.wm.read_factory_settings(use_empty=False)
    scene = bpy.context.scene
    ob = bpy.data.objects.new("capture", None)
    scene.collection.objects.link(ob)
    ob.animation_data_create()
    action = bpy.data.actions.new("capture")
    ob.animation_data.action = action
    n, n_ch = values.shape
    bezier = bpy.types.Keyframe.bl_rna.properties["interpolation"].enum_items["BEZIER"].value
    frames = np.arange(n, dtype=np.float64)
    curves = []
    for c in range(n_ch):
        ob[f"c{c}"] = 0.0
        fc = action.fcurve_ensure_for_datablock(ob, f'["c{c}"]')
        fc.keyframe_points.add(n)
        fc.keyframe_points.foreach_set("co", np.column_stack([frames, values[:, c]]).ravel())
        fc.keyframe_points.foreach_set("interpolation", [bezier] * n)
        fc.keyframe_points.foreach_set("select_control_point", [True] * n)
        fc.update()  # auto-clamped handles from the neighbouring keys
        curves.append(fc)
    ob.select_set(True)
    bpy.context.view_layer.objects.active = ob
    window = bpy.context.window_manager.windows[0]
    area = max(window.screen.areas, key=lambda a: a.width * a.height)
    area.type = "GRAPH_EDITOR"
    region = next(r for r in area.regions if r.type == "WINDOW")
    with bpy.context.temp_override(window=window, area=area, region=region):
        if mode == "ratio":
            result = bpy.ops.graph.decimate(mode="RATIO", factor=amount)
        else:
            result = bpy.ops.graph.decimate(mode="ERROR", remove_error_margin=amount)
    if result != {"FINISHED"}:
        raise RuntimeError(f"Blender's decimate returned {result}")
    kept = []
    evaluated = np.empty((n, n_ch))
    for c, fc in enumerate(curves):
        co = np.empty(2 * len(fc.keyframe_points))
        fc.keyframe_points.foreach_get("co", co)
        kept.append(np.rint(co[0::2]).astype(np.int64))
        evaluated[:, c] = [fc.evaluate(float(f)) for f in range(n)]
    return kept, evaluated


def _worker(argv: list[str]) -> None:
    """``--blender-worker IN.npz OUT.npz``: every (mode, amount) run of IN's channels into OUT."""
    src, dst = argv
    data = np.load(src)
    values, runs = data["values"], json.loads(str(data["runs"]))
    out = {}
    for r, (mode, amount) in enumerate(runs):
        t0 = time.perf_counter()
        kept, evaluated = _blender_decimate(values, mode, amount)
        out[f"seconds_{r}"] = np.array(time.perf_counter() - t0)
        out[f"curve_{r}"] = evaluated
        out[f"counts_{r}"] = np.array([k.size for k in kept])
        out[f"keys_{r}"] = np.concatenate(kept)
    np.savez(dst, **out)


# ---------------------------------------------------------------------------------------
# The hairtool side
# ---------------------------------------------------------------------------------------
def _hairtool_curve(x: np.ndarray, k: int, interp: str) -> np.ndarray:
    """The exact DP's K keys on the columns of ``x`` together, rebuilt at every frame."""
    from hairtool.keys.costs import cost_table
    from hairtool.keys.dp import select_keys
    from hairtool.keys.reconstruct import interpolate_keys, key_poses

    if k >= x.shape[0]:
        return x.copy()
    sel = select_keys(cost_table(x, interp), keys=k, curve_keys=k)
    return interpolate_keys(key_poses(x, sel.keys, interp))


def _per_channel(values: np.ndarray, counts: np.ndarray, interp: str) -> np.ndarray:
    return np.column_stack(
        [_hairtool_curve(values[:, [c]], int(counts[c]), interp)[:, 0] for c in range(values.shape[1])]
    )


def _rms(a: np.ndarray, b: np.ndarray, columns: np.ndarray) -> float | None:
    if not columns.any():
        return None
    return float(np.sqrt(np.mean((a[:, columns] - b[:, columns]) ** 2)))


def compare(path: Path, bpy_python: str, runs: list[tuple[str, float]]) -> list[dict]:
    """One row per (capture, Blender run, method)."""
    from hairtool.mocap.bvh import read_bvh

    motion = read_bvh(path)
    values = np.ascontiguousarray(motion.values, dtype=np.float64)
    names = [c for chans in motion.channels for c in chans]
    rot = np.array([c.endswith("rotation") for c in names])
    pos = ~rot
    with tempfile.TemporaryDirectory() as tmp:
        src, dst = Path(tmp) / "in.npz", Path(tmp) / "out.npz"
        np.savez(src, values=values, runs=np.array(json.dumps(runs)))
        done = subprocess.run(
            [bpy_python, os.path.abspath(__file__), WORKER_FLAG, str(src), str(dst)],
            capture_output=True,
            text=True,
        )
        if done.returncode != 0:
            raise SystemExit(f"Blender's side failed on {path.name}:\n{done.stderr[-2000:]}")
        blender = dict(np.load(dst))
    rows = []
    for r, (mode, amount) in enumerate(runs):
        counts = blender[f"counts_{r}"]
        curves = {"blender decimate": blender[f"curve_{r}"]}
        seconds = {"blender decimate": float(blender[f"seconds_{r}"])}
        for interp in ("hermite-fit", "hermite", "linear"):
            t0 = time.perf_counter()
            curves[f"hairtool {interp}"] = _per_channel(values, counts, interp)
            seconds[f"hairtool {interp}"] = time.perf_counter() - t0
        if counts.min() == counts.max():  # ratio runs: one count K for every channel
            t0 = time.perf_counter()
            shared = _hairtool_curve(values, int(counts[0]), "hermite-fit")
            curves["hairtool hermite-fit, shared keys"] = shared
            seconds["hairtool hermite-fit, shared keys"] = time.perf_counter() - t0
        for method, curve in curves.items():
            worst = np.abs(curve - values)
            rows.append(
                {
                    "capture": path.stem,
                    "frames": motion.n_frames,
                    "channels": len(names),
                    "blender_mode": mode,
                    "blender_amount": amount,
                    "method": method,
                    "keys_total": int(counts.sum()),
                    "keys_per_channel_mean": float(counts.mean()),
                    "rms_rotation_deg": _rms(curve, values, rot),
                    "rms_position": _rms(curve, values, pos),
                    "max_abs_rotation_deg": float(worst[:, rot].max()) if rot.any() else None,
                    "seconds": seconds[method],
                }
            )
    return rows


def _print_table(rows: list[dict]) -> None:
    head = f"{'capture':<15} {'run':<12} {'keys':>6} {'method':<34} {'rms rot (deg)':>13} {'rms pos':>10}"
    head += f" {'s':>7}"
    print(head)
    print("-" * len(head))
    for r in rows:
        run = f"{r['blender_mode']} {r['blender_amount']:g}"
        rot = "—" if r["rms_rotation_deg"] is None else f"{r['rms_rotation_deg']:.4f}"
        pos = "—" if r["rms_position"] is None else f"{r['rms_position']:.4f}"
        print(
            f"{r['capture']:<15} {run:<12} {r['keys_total']:>6} {r['method']:<34} {rot:>13} {pos:>10} "
            f"{r['seconds']:>7.2f}"
        )


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument(
        "captures", nargs="*", type=Path, help="BVH files (default: shared/data/motion/*.bvh)"
    )
    parser.add_argument(
        "--bpy", default=os.environ.get("HAIRTOOL_BPY_PYTHON"), help="a Python that imports bpy (Blender 5)"
    )
    parser.add_argument("--ratios", default="0.9,0.95,0.98", help="Decimate ratios (share of keys removed)")
    parser.add_argument("--errors", default="", help="Decimate error margins (channel units), e.g. 0.5,2")
    parser.add_argument("--out", type=Path, default=Path("decimate.json"), help="the table as JSON")
    args = parser.parse_args(argv)
    if not args.bpy:
        parser.error("--bpy PYTHON (or HAIRTOOL_BPY_PYTHON): a Python that imports bpy")
    runs = [("ratio", float(v)) for v in args.ratios.split(",") if v]
    runs += [("error", float(v)) for v in args.errors.split(",") if v]
    captures = args.captures
    if not captures:
        from hairtool.bench import MOTION_DIR

        captures = sorted(MOTION_DIR.glob("*.bvh"))
    rows = []
    for path in captures:
        rows += compare(path, args.bpy, runs)
    _print_table(rows)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(rows, indent=1) + "\n")
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1] == WORKER_FLAG:
        _worker(sys.argv[2:])
    else:
        sys.exit(main())
