"""Read and write speed of every file format, on the real grooms and a 50,000-strand sample.

One row per groom and format: the file's size, the median write and read times through
``hairtool.io`` (validation included) and the rates in MB/s of file (10⁶ bytes). TressFX is
read only, from the original file. The floor in the same run: ``npy`` rows save and load the
raw points and counts with numpy (no header, no checks); ``read_over_npy`` is a format's read
time over that floor's. Files go to a temporary folder (``--dir`` to measure another disk).
"""

from __future__ import annotations

import argparse
import os
import tempfile
from collections.abc import Callable
from pathlib import Path

from hairtool.bench import GROOMS_DIR, add_common_arguments

HELP = "read/write time and MB/s of every format on the real grooms and a 50k-strand sample"

WRITABLE = ("hair", "npz", "usdc", "usda", "obj")
DEFAULT_GROOMS = ["real", "50000x24"]
QUICK_GROOMS = [str(GROOMS_DIR / "ponytail_tail.tfx"), "200x8"]
QUICK_FORMATS = ("hair", "npz", "usda", "obj")
#: Slow text formats on a big groom: stop repeating a number after this many seconds.
BUDGET_S = 10.0


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--formats",
        nargs="+",
        choices=WRITABLE,
        metavar="EXT",
        help=f"of {', '.join(WRITABLE)} (default all)",
    )
    parser.add_argument("--dir", type=Path, help="write the files here (default: a temporary folder)")
    add_common_arguments(
        parser, quick="one small real groom and a 200x8 sample, one run", repeat=5, grooms=DEFAULT_GROOMS
    )


def _npy_io(points, counts, folder: Path) -> tuple[Callable[[], None], Callable[[], None], Path]:
    import numpy as np

    path = folder / "points.npy"

    def write() -> None:
        with open(path, "wb") as f:
            np.save(f, points)
            np.save(f, counts)

    def read() -> None:
        with open(path, "rb") as f:
            np.load(f)
            np.load(f)

    return write, read, path


def _row(name: str, groom, fmt: str, path: Path, write_ms: float | None, read_ms: float) -> dict:
    mb = os.path.getsize(path) / 1e6
    return {
        "groom": name,
        "strands": groom.strand_count,
        "vertices": groom.vertex_count,
        "format": fmt,
        "file_mb": mb,
        "write_ms": write_ms,
        "write_mb_s": None if write_ms is None else mb / (write_ms / 1e3),
        "read_ms": read_ms,
        "read_mb_s": mb / (read_ms / 1e3),
    }


def _groom_rows(name: str, groom, source: Path | None, formats, folder: Path, repeat: int) -> list[dict]:
    from hairtool import io
    from hairtool.bench import median_ms, ratio

    write_npy, read_npy, npy_path = _npy_io(groom.points, groom.counts, folder)
    npy_row = _row(name, groom, "npy", npy_path, median_ms(write_npy, repeat), median_ms(read_npy, repeat))
    npy_path.unlink()
    rows = [npy_row]
    if source is not None:  # the original file (TressFX is read only)
        read_ms = median_ms(lambda: io.read(source), repeat, max_time=BUDGET_S)
        rows.append(_row(name, groom, source.suffix.lower().lstrip("."), source, None, read_ms))
    for fmt in formats:
        path = folder / f"groom.{fmt}"
        write_ms = median_ms(lambda p=path: io.write(p, groom), repeat, max_time=BUDGET_S)
        read_ms = median_ms(lambda p=path: io.read(p), repeat, max_time=BUDGET_S)
        rows.append(_row(name, groom, fmt, path, write_ms, read_ms))
        path.unlink()
    for r in rows:
        r["read_over_npy"] = ratio(r["read_ms"], npy_row["read_ms"])
    return rows


def run(args: argparse.Namespace) -> list[dict]:
    from hairtool.bench import grooms, setup

    repeat = setup(args)
    specs = args.grooms or (QUICK_GROOMS if args.quick else DEFAULT_GROOMS)
    formats = args.formats or (QUICK_FORMATS if args.quick else WRITABLE)
    rows: list[dict] = []
    with tempfile.TemporaryDirectory(prefix="hairtool-bench-io-", dir=args.dir) as tmp:
        for name, groom, source in grooms(specs):
            rows += _groom_rows(name, groom, source, formats, Path(tmp), repeat)
    return rows
