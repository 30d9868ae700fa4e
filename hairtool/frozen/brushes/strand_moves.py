"""What the brushes that move vertices share: the check that a sample is theirs, and the
float32 groom a kernel's float64 points make."""

from __future__ import annotations

import numpy as np

from hairtool.errors import ParameterError
from hairtool.frozen.brushes.sample import BrushSample, check_sample
from hairtool.groom import Groom


def checked(sample: BrushSample, brush: str) -> BrushSample:
    """``sample``, checked (:func:`~hairtool.frozen.brushes.sample.check_sample`) and of ``brush``
    (ParameterError naming ``brush`` otherwise)."""
    check_sample(sample)
    if sample.brush != brush:
        raise ParameterError("brush", sample.brush, brush)
    return sample


def moved_groom(groom: Groom, out: np.ndarray) -> Groom:
    """``groom`` with the float64 points ``out`` a kernel wrote, as float32."""
    return groom.with_points(out.astype(np.float32))
