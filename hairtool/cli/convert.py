"""Convert between any readable and any writable format (chosen by the file extensions).

An animation written to a format without time samples keeps its first frame only; a warning on
stderr says how many frames were dropped. Render hair and its guides (a prim of purpose ``guide``)
stay apart in USD and ``.npz``; elsewhere a warning says the guides join the hair. USD and
``.npz`` outputs keep the input's scene description (up axis, unit, time codes, curve prims
with their basis, purposes and colour primvar); HAIR and OBJ cannot, and one warning names what
is dropped; ``--up-axis`` and
``--meters-per-unit`` say what the points are in where the input cannot (HAIR, OBJ, TressFX) or
is wrong — they relabel, they do not move the points.
"""

from __future__ import annotations

import argparse
import math
import sys

HELP = "convert a groom or animation between formats (by extension)"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("input", help="any readable file: .hair, .tfx, .usda/.usdc/.usd, .npz, .obj")
    parser.add_argument("output", help="any writable file: .hair, .usda/.usdc/.usd, .npz, .obj")
    parser.add_argument(
        "--up-axis",
        type=str.upper,
        choices=("Y", "Z"),
        help="the up axis a USD or .npz output declares (default: the input's; Y for formats without one)",
    )
    parser.add_argument(
        "--meters-per-unit",
        type=float,
        metavar="M",
        help="metres per unit a USD or .npz output declares (default: the input's; 0.01, centimetres, "
        "for formats without one)",
    )


def _override(args: argparse.Namespace, obj):
    """The groom with the up axis / unit the command line declares (USD and .npz outputs)."""
    from hairtool.errors import ParameterError
    from hairtool.io import format_for

    changes = {}
    if args.up_axis is not None:
        changes["up_axis"] = args.up_axis
    if args.meters_per_unit is not None:
        changes["meters_per_unit"] = args.meters_per_unit
    if not changes:
        return obj
    if format_for(args.output, writing=True).module not in ("usd", "npz"):
        name = "up-axis" if "up_axis" in changes else "meters-per-unit"
        expected = "a USD output or an .npz cache (.usda, .usdc, .usd, .npz)"
        raise ParameterError(name, next(iter(changes.values())), expected)
    return obj.with_metadata(obj.metadata.with_(**changes))


def _scene_lost(obj) -> list[str]:
    """What of the scene description a format without one drops (empty when it held nothing
    beyond the defaults these formats read back as)."""
    from hairtool.io.usd import PRIM_PATH
    from hairtool.metadata import DEFAULT_METERS_PER_UNIT, DEFAULT_UP_AXIS, CurvesPrim

    m = obj.metadata
    lost = []
    if m.up_axis != DEFAULT_UP_AXIS:
        lost.append(f"{m.up_axis}-up")
    if m.meters_per_unit != DEFAULT_METERS_PER_UNIT:
        lost.append(f"{m.meters_per_unit:g} m per unit")
    prims = m.for_strands(obj.strand_count).curves
    if prims == (CurvesPrim(PRIM_PATH, obj.strand_count),):
        prims = ()  # hairtool's own default prim: nothing to lose
    if prims:
        lost.append("prims " + ", ".join(f"{c.path} ({c.description})" for c in prims))
    return lost


def run(args: argparse.Namespace) -> int:
    from pathlib import Path

    from hairtool.errors import FormatError, ParameterError
    from hairtool.groom import Animation
    from hairtool.io import format_for, read, write

    out_fmt = format_for(args.output, writing=True)  # fail before reading a large input
    mpu = args.meters_per_unit
    if mpu is not None and not (math.isfinite(mpu) and mpu > 0):
        raise ParameterError("meters-per-unit", mpu, "a positive number of metres")  # before reading
    obj = _override(args, read(args.input))
    if isinstance(obj, Animation) and not out_fmt.animated and obj.n_frames > 1:
        print(
            f"hairtool convert: warning: {out_fmt.name} holds one pose; keeping frame 0 "
            f"and dropping {obj.n_frames - 1} of {obj.n_frames} frames",
            file=sys.stderr,
        )
    guides = [c for c in obj.metadata.for_strands(obj.strand_count).curves if c.purpose == "guide"]
    if guides and out_fmt.module not in ("usd", "npz"):
        held = sum(c.strands for c in guides)
        print(
            f"hairtool convert: warning: {out_fmt.name} cannot mark guides; the {held} guide strands "
            f"({', '.join(c.path for c in guides)}) are written as hair with the others",
            file=sys.stderr,
        )
    lost = _scene_lost(obj) if out_fmt.module not in ("usd", "npz") else []
    if lost:
        print(
            f"hairtool convert: warning: {out_fmt.name} cannot hold the scene description; dropping "
            f"{'; '.join(lost)} (it reads back as Y-up, 0.01 m per unit, one linear prim)",
            file=sys.stderr,
        )
    if Path(args.input).suffix.lower() == ".hair" and Path(args.output).suffix.lower() == ".hair":
        from hairtool.io import hairfile

        header = hairfile.read_header(args.input)  # carry the info string and header defaults over
        groom = obj.rest if isinstance(obj, Animation) else obj
        try:
            hairfile.write(Path(args.output), groom, info=header.info, defaults=header.defaults)
        except OSError as e:
            raise FormatError(args.output, f"cannot write: {e}") from None
    else:
        write(args.output, obj)
        from hairtool.io.usd_carry import carry_between

        carry_between(args.input, args.output)  # USD to USD: the scene beside the hair
    kept = obj if out_fmt.animated or not isinstance(obj, Animation) else obj.rest
    frames = f", {kept.n_frames} frames" if isinstance(kept, Animation) else ""
    print(f"wrote {args.output} ({kept.strand_count} strands, {kept.vertex_count} vertices{frames})")
    return 0
