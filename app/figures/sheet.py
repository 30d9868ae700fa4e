"""Shared pieces of the figure scripts: output folder, labelled panels side by side, contact sheets."""

from __future__ import annotations

import argparse
import math
import sys
from collections.abc import Sequence
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from app.render.offscreen import save_png
from hairtool.errors import HairtoolError

LABEL_HEIGHT = 26
GAP = 6
SHEET_BACKGROUND = (255, 255, 255, 255)
LABEL_COLOR = (20, 20, 20, 255)


def label(image: NDArray[np.uint8], text: str) -> NDArray[np.uint8]:
    """The image with a white caption band of ``text`` under it."""
    from PIL import Image, ImageDraw, ImageFont  # pillow comes with imageio

    h, w = image.shape[:2]
    canvas = Image.new("RGBA", (w, h + LABEL_HEIGHT), SHEET_BACKGROUND)
    canvas.paste(Image.fromarray(np.ascontiguousarray(image[..., :4])), (0, 0))
    draw = ImageDraw.Draw(canvas)
    font = ImageFont.load_default(size=15)
    box = draw.textbbox((0, 0), text, font=font)
    draw.text(((w - (box[2] - box[0])) / 2, h + 4), text, fill=LABEL_COLOR, font=font)
    return np.asarray(canvas)


def grid(images: Sequence[NDArray[np.uint8]], columns: int | None = None) -> NDArray[np.uint8]:
    """Equal-sized RGBA images in rows of ``columns`` (default: one row), with white gaps."""
    if not images:
        raise HairtoolError("a sheet needs at least one image")
    h, w = images[0].shape[:2]
    cols = len(images) if columns is None else max(1, int(columns))
    rows = math.ceil(len(images) / cols)
    sheet = np.empty((rows * h + (rows + 1) * GAP, cols * w + (cols + 1) * GAP, 4), dtype=np.uint8)
    sheet[:] = SHEET_BACKGROUND
    for i, img in enumerate(images):
        r, c = divmod(i, cols)
        y, x = GAP + r * (h + GAP), GAP + c * (w + GAP)
        sheet[y : y + h, x : x + w] = img[..., :4]
    return sheet


def out_dir(description: str, argv: Sequence[str] | None = None) -> tuple[Path, argparse.Namespace]:
    parser = argparse.ArgumentParser(description=description)
    parser.add_argument("outdir", type=Path, help="folder for the PNGs (made if missing)")
    parser.add_argument("--size", type=int, default=480, help="pixels per panel side (default 480)")
    args = parser.parse_args(argv)
    if not 64 <= args.size <= 4096:
        parser.error("--size must be in [64, 4096]")
    args.outdir.mkdir(parents=True, exist_ok=True)
    return args.outdir, args


def write(path: Path, image: NDArray[np.uint8]) -> Path:
    save_png(path, image)
    print(path)
    return path


def main_guard(run) -> int:
    """Run a figure script; a HairtoolError becomes a one-line message and exit status 2."""
    try:
        run()
    except HairtoolError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    return 0
