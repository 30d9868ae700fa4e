"""What the renderers ask of a moderngl object they did not make (a framebuffer left bound)."""

from __future__ import annotations

from typing import Any


def alive(obj: Any) -> bool:
    """False for None and for released moderngl objects (whose ``mglo`` is an InvalidObject)."""
    return obj is not None and type(obj.mglo).__name__ != "InvalidObject"
