"""Drawing grooms: an orbit camera, colour ramps, the GL strand renderer, PNG and SVG export.

``camera``, ``ramps`` and ``svg`` are numpy-only; ``strands``, ``offscreen`` and ``shaders`` need
moderngl. Nothing here imports Qt: the Qt viewport hands its own ``moderngl.Context`` and
framebuffer to :class:`~app.render.strands.StrandRenderer`.
"""

from app.render.camera import Camera
from app.render.ramps import RAMPS, categorical_colors, per_strand_random_colors, ramp_colors

__all__ = ["RAMPS", "Camera", "categorical_colors", "per_strand_random_colors", "ramp_colors"]
