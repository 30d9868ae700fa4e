"""Data files the studio ships (installed as ``app.resources``)."""

from __future__ import annotations

import importlib.resources
from pathlib import Path

SINTEL_HAIR = "sintel_hair.tfx"  # the default scene: Sintel's guide hair (CREDITS-sintel.txt)
SINTEL_HEAD = "sintel_head.obj"  # and the head it was groomed on


def path(name: str) -> Path:
    """A shipped file as a filesystem path (wheels install unzipped, so it is a real file)."""
    return Path(str(importlib.resources.files(__name__).joinpath(name)))
