"""Print what a groom or animation file holds: format, sizes, bounding box, frames, attributes."""

from __future__ import annotations

import argparse
import json

HELP = "summarise a groom or animation file (strands, vertices, bounds, frames, attributes)"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("file", help="a .hair, .tfx, .usda/.usdc/.usd, .npz or .obj file")
    parser.add_argument("--json", action="store_true", help="print one JSON object")


def summary(path: str) -> dict:
    """The facts ``hairtool info`` prints, as plain JSON-ready values."""
    from pathlib import Path

    from hairtool.groom import Animation
    from hairtool.io import format_for, read

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
    if isinstance(obj, Animation):
        out["frames"] = obj.n_frames
        out["fps"] = obj.fps
    if Path(path).suffix.lower() == ".hair":
        from hairtool.io.hairfile import read_header

        out["hair_info"] = read_header(path).info
    return out


def _text(s: dict) -> str:
    vps = s["vertices_per_strand"]
    lo, hi = s["bounds"]["min"], s["bounds"]["max"]
    lines = [
        f"file        {s['file']}",
        f"format      {s['format']} ({s['kind']})",
        f"strands     {s['strands']}",
        f"vertices    {s['vertices']}  (per strand min {vps['min']}, mean {vps['mean']:g}, max {vps['max']})",
        f"bounds      min ({', '.join(f'{x:.6g}' for x in lo)})  max ({', '.join(f'{x:.6g}' for x in hi)})",
    ]
    if "frames" in s:
        lines.append(f"frames      {s['frames']} at {s['fps']:g} fps")
    lines.append(f"attributes  {', '.join(s['attributes']) or 'none'}")
    if s.get("hair_info"):
        lines.append(f"info        {s['hair_info']}")
    return "\n".join(lines)


def run(args: argparse.Namespace) -> int:
    s = summary(args.file)
    print(json.dumps(s, indent=1) if args.json else _text(s))
    return 0
