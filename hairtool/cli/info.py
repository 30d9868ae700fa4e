"""Print what a groom, animation or motion capture file holds: format, sizes, bounds, frames,
attributes; for USD its up axis, unit, time codes and curve prims; for BVH its skeleton."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

HELP = "summarise a groom, animation or BVH file (strands, vertices, bounds, frames, attributes)"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("file", help="a .hair, .tfx, .usda/.usdc/.usd, .npz, .obj or .bvh file")
    parser.add_argument("--json", action="store_true", help="print one JSON object")


def _bvh_summary(path: str) -> dict:
    from hairtool.mocap.bvh import read_bvh

    motion = read_bvh(path)
    return {
        "file": str(path),
        "format": "BVH motion capture",
        "kind": "motion",
        "joints": motion.n_joints,
        "channels": motion.n_channels,
        "frames": motion.n_frames,
        "frame_time": motion.frame_time,
        "fps": motion.fps,
        "root": motion.joint_names[0],
    }


def _usd_summary(obj) -> dict:
    """What the stage said about its space, time code range and curves."""
    m = obj.metadata
    out: dict = {"up_axis": m.up_axis, "meters_per_unit": m.meters_per_unit}
    if m.start_time_code is not None or m.end_time_code is not None:
        out["time_code_range"] = [m.start_time_code, m.end_time_code]  # (null: that end not authored)
    out["curves"] = [
        {
            "path": c.path,
            "strands": c.strands,
            "basis": c.basis,
            "wrap": c.wrap,
            "purpose": c.purpose,
            "drawn": c.description,
        }
        for c in m.curves
    ]
    return out


def summary(path: str) -> dict:
    """The facts ``hairtool info`` prints, as plain JSON-ready values."""
    import numpy as np

    from hairtool.groom import Animation
    from hairtool.io import format_for, read

    suffix = Path(path).suffix.lower()
    if suffix == ".bvh":
        return _bvh_summary(path)
    fmt = format_for(path)
    obj = read(path)
    counts = obj.counts
    lo, hi = obj.bounds
    out: dict = {
        "file": str(path),
        "format": fmt.name,
        "kind": "animation" if isinstance(obj, Animation) else "groom",
        "strands": obj.strand_count,
        "vertices": obj.vertex_count,
        "vertices_per_strand": {
            "min": int(counts.min()),
            "mean": round(float(counts.mean()), 3),
            "max": int(counts.max()),
        },
        "bounds": {"min": [float(x) for x in lo], "max": [float(x) for x in hi]},
        "attributes": [name for name, a in obj.attributes.items() if a is not None],
    }
    prims = obj.metadata.for_strands(obj.strand_count).curves
    guide_prims = [c for c in prims if c.purpose == "guide"]
    if guide_prims:  # render hair and its guides, counted apart
        guides = sum(c.strands for c in guide_prims)
        is_guide = np.repeat([c.purpose == "guide" for c in prims], [c.strands for c in prims])
        out["render_hair"] = {"strands": obj.strand_count - guides, "vertices": int(counts[~is_guide].sum())}
        out["guides"] = {"strands": guides, "vertices": int(counts[is_guide].sum())}
    if isinstance(obj, Animation):
        out["frames"] = obj.n_frames
        out["fps"] = obj.fps
        out["time_codes"] = {"first": float(obj.time_codes[0]), "last": float(obj.time_codes[-1])}
    if fmt.module == "usd":
        out["usd"] = _usd_summary(obj)
    if suffix == ".hair":
        from hairtool.io.hairfile import read_header

        out["hair_info"] = read_header(path).info
    return out


def _bvh_text(s: dict) -> str:
    return "\n".join(
        [
            f"file        {s['file']}",
            f"format      {s['format']}",
            f"joints      {s['joints']}  (root {s['root']})",
            f"channels    {s['channels']}",
            f"frames      {s['frames']} at {s['fps']:g} fps (frame time {s['frame_time']:g} s)",
        ]
    )


def _usd_text(u: dict) -> list[str]:
    lines = [f"space       {u['up_axis']}-up, {u['meters_per_unit']:g} m per unit"]
    for c in u["curves"]:
        purpose = "" if c["purpose"] == "default" else f", purpose {c['purpose']}"
        lines.append(f"curves      {c['path']}: {c['strands']} strands, {c['drawn']}{purpose}")
    return lines


def _text(s: dict) -> str:
    if s["kind"] == "motion":
        return _bvh_text(s)
    vps = s["vertices_per_strand"]
    lo, hi = s["bounds"]["min"], s["bounds"]["max"]
    lines = [
        f"file        {s['file']}",
        f"format      {s['format']} ({s['kind']})",
        f"strands     {s['strands']}",
        f"vertices    {s['vertices']}  (per strand min {vps['min']}, mean {vps['mean']:g}, max {vps['max']})",
        *(
            [
                f"render hair {s['render_hair']['strands']} strands, {s['render_hair']['vertices']} vertices",
                f"guides      {s['guides']['strands']} strands, {s['guides']['vertices']} vertices",
            ]
            if "guides" in s
            else []
        ),
        f"bounds      min ({', '.join(f'{x:.6g}' for x in lo)})  max ({', '.join(f'{x:.6g}' for x in hi)})",
    ]
    if "frames" in s:
        first, last = s["time_codes"]["first"], s["time_codes"]["last"]
        lines.append(f"frames      {s['frames']} at {s['fps']:g} fps, time codes {first:g} … {last:g}")
    if "usd" in s:
        lines.extend(_usd_text(s["usd"]))
    lines.append(f"attributes  {', '.join(s['attributes']) or 'none'}")
    if s.get("hair_info"):
        lines.append(f"info        {s['hair_info']}")
    return "\n".join(lines)


def run(args: argparse.Namespace) -> int:
    s = summary(args.file)
    print(json.dumps(s, indent=1) if args.json else _text(s))
    return 0
