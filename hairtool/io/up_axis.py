"""The up axis of hair from a format that does not say (HAIR, TressFX, USC-HairSalon ``.data``):
hair falls, so its roots lie above its tips along the up axis. Of the axes a groom may have up
(Y or Z), the one along which the roots stand highest above the tips, measured against the
groom's size, is up; where neither does (hair standing up, a flat cut), the format's default
stays, and the caller says which it chose."""

from __future__ import annotations

import numpy as np

from hairtool.groom import Groom
from hairtool.metadata import UP_AXES

#: File suffixes whose formats carry no up axis.
UNSAID = (".hair", ".tfx", ".data")
#: The mean root-over-tip drop, of the groom's largest side, that counts as hair hanging.
MIN_DROP = 0.02


def root_drops(groom: Groom) -> dict[str, float]:
    """Per axis of :data:`~hairtool.metadata.UP_AXES`: the strands' mean (root − tip) along it,
    of the groom's largest side (positive: the roots are above the tips).

    Parameters
    ----------
    groom : Groom
        The strands.

    Returns
    -------
    dict of str to float
        The drop per axis name.
    """
    lo, hi = groom.bounds
    size = max(float(np.max(hi.astype(np.float64) - lo)), 1e-30)
    drop = (groom.roots.astype(np.float64) - groom.tips).mean(axis=0) / size
    return {"Y": float(drop[1]), "Z": float(drop[2])}


def infer_up_axis(groom: Groom, default: str = "Y") -> tuple[str, bool]:
    """``(axis, inferred)``: the axis the hair hangs along (``inferred`` True), or ``default``
    (False) where it hangs along neither.

    Parameters
    ----------
    groom : Groom
        The strands.
    default : str, default "Y"
        The axis where the hair hangs along neither.

    Returns
    -------
    tuple of (str, bool)
        The axis and whether it was inferred.
    """
    drops = root_drops(groom)
    axis = max(UP_AXES, key=lambda a: drops[a])
    if drops[axis] < MIN_DROP:
        return default, False
    return axis, True
