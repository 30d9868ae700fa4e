"""Data files the studio ships (installed as ``app.resources``)."""

from __future__ import annotations

import importlib.resources
from pathlib import Path

SINTEL_HAIR = "sintel_hair.tfx"  # the default scene: Sintel's guide hair (CREDITS-sintel.txt)
SINTEL_HEAD = "sintel_head.obj"  # and the head it was groomed on


def path(name: str) -> Path:
    """A shipped file as a filesystem path (wheels install unzipped, so it is a real file)."""
    return Path(str(importlib.resources.files(__name__).joinpath(name)))

# Render hair of the bundled sample: children interpolated from Sintel's 228 guides on her
# scalp. 30,000 × 32 vertices (960,000) draws at full density in about a tenth of a second on
# the CPU rasterizer, and at the studio's 10 % while dragging well inside a 33 ms frame.
SINTEL_CHILDREN = 30_000
SINTEL_CHILD_SEED = 1
