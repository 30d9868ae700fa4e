"""A groom opened from a format without an up axis takes the one its hair hangs along
(:mod:`hairtool.io.up_axis`), and the status bar says so; View ▸ Up axis changes it."""

from __future__ import annotations

import os
from pathlib import Path

from hairtool.groom import Groom
from hairtool.io.up_axis import UNSAID, infer_up_axis


def with_inferred_up_axis(path: str | os.PathLike[str], groom: Groom) -> tuple[Groom, str | None]:
    """``groom`` with the up axis its hair gives where ``path``'s format says none, and the
    status bar's words (None where the format says one)."""
    if Path(path).suffix.lower() not in UNSAID:
        return groom, None
    fmt = Path(path).suffix.lower()
    axis, inferred = infer_up_axis(groom, groom.metadata.up_axis)
    if inferred:
        said = f"{axis} up: {fmt} files do not say, and the roots lie above the tips along {axis}"
    else:
        said = f"{axis} up: {fmt} files do not say, and the hair hangs along no axis (the default)"
    return groom.with_metadata(groom.metadata.with_(up_axis=axis)), said + " (View ▸ Up axis changes it)"
