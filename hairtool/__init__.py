"""hairtool: strand grooms, frozen-hair shaping, anime hair cycles and optimal keyframes.

The core library never imports Qt or OpenGL; ``app`` is the desktop view over it.
``Groom`` and ``Animation`` load numpy and numba on first use, not on ``import hairtool``, so
the command line installs its Ctrl+C handling before anything heavy is imported.
"""

from hairtool.errors import FormatError, GroomError, HairtoolError, ParameterError

__all__ = [
    "Animation",
    "FormatError",
    "Groom",
    "GroomError",
    "HairtoolError",
    "ParameterError",
]
__version__ = "0.1.0"


def __getattr__(name: str):
    if name in ("Animation", "Groom"):
        from hairtool import groom

        return getattr(groom, name)
    raise AttributeError(f"module 'hairtool' has no attribute {name!r}")
