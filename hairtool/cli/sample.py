"""Write a procedural sample groom (portrait 2-D, scalp 3-D or comb grid) to any writable format."""

from __future__ import annotations

import argparse

HELP = "write a seeded sample groom (portrait, scalp, comb)"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("kind", help="portrait (2-D), scalp (3-D) or comb (straight grid)")
    parser.add_argument("output", help="output file; the extension picks the format")
    parser.add_argument("--strands", type=int, default=None, help="number of strands (sample default)")
    parser.add_argument("--vertices", type=int, default=None, help="vertices per strand (sample default)")
    parser.add_argument("--seed", type=int, default=0, help="random seed (default 0)")


def run(args: argparse.Namespace) -> int:
    from hairtool.io import format_for, write
    from hairtool.samples import sample

    format_for(args.output, writing=True)
    groom = sample(args.kind, strands=args.strands, vertices=args.vertices, seed=args.seed)
    write(args.output, groom)
    print(f"wrote {args.output} ({groom.strand_count} strands, {groom.vertex_count} vertices)")
    return 0
