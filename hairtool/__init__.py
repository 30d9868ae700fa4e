"""hairtool: strand grooms, frozen-hair shaping, anime hair cycles and optimal keyframes.

The core library never imports Qt or OpenGL; ``app`` is the desktop view over it.
"""

from hairtool.errors import FormatError, GroomError, HairtoolError, ParameterError
from hairtool.groom import Animation, Groom

__all__ = [
    "Animation",
    "FormatError",
    "Groom",
    "GroomError",
    "HairtoolError",
    "ParameterError",
]
__version__ = "0.1.0"
