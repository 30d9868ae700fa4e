"""Convert between any readable and any writable format (chosen by the file extensions).

An animation written to a format without time samples keeps its first frame only; a warning
on stderr says how many frames were dropped.
"""

from __future__ import annotations

import argparse
import sys

HELP = "convert a groom or animation between formats (by extension)"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("input", help="any readable file: .hair, .tfx, .usda/.usdc/.usd, .npz, .obj")
    parser.add_argument("output", help="any writable file: .hair, .usda/.usdc/.usd, .npz, .obj")


def run(args: argparse.Namespace) -> int:
    from pathlib import Path

    from hairtool.errors import FormatError
    from hairtool.groom import Animation
    from hairtool.io import format_for, read, write

    out_fmt = format_for(args.output, writing=True)  # fail before reading a large input
    obj = read(args.input)
    if isinstance(obj, Animation) and not out_fmt.animated and obj.n_frames > 1:
        print(
            f"hairtool convert: warning: {out_fmt.name} holds one pose; keeping frame 0 "
            f"and dropping {obj.n_frames - 1} of {obj.n_frames} frames",
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
    kept = obj if out_fmt.animated or not isinstance(obj, Animation) else obj.rest
    frames = f", {kept.n_frames} frames" if isinstance(kept, Animation) else ""
    print(f"wrote {args.output} ({kept.strand_count} strands, {kept.vertex_count} vertices{frames})")
    return 0
