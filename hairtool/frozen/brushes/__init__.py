"""The grooming brushes: one module per brush, found by :mod:`.registry`.

Each brush module declares a :class:`~.spec.BrushSpec` (signed or not, moves points, changes
strands, needs the head's surface, runs brush-locally, its own sample fields, and how the
studio shows it) and holds its operation (:class:`~.spec.Brush`: stroke state, kernel, numpy
twin). What they share lives once: the falloff and its weights (:mod:`.falloff`), the length
constraint (:mod:`.constraints`), the scalp's normals and centre and front-facing strands
(:mod:`.scalp`), the sample and its checks (:mod:`.sample`).

Every brush sample acts on the vertices within its radius of the cursor, weighted by a falloff
curve of the distance times its strength. Masked and hidden strands are locked for every brush,
and with ``only_selected`` the unselected ones. A sample may be mirrored across the plane x = m
(X symmetry): the mirrored cursor and direction act as a second sample of the same stroke. A
sample with a ``view`` leaves the strands whose root normal faces away from that camera as if
locked.

The name lists below are derived from the specs: adding a brush is adding its module.
"""

from hairtool.errors import ParameterError
from hairtool.frozen.brushes import registry
from hairtool.frozen.brushes.clump import paint_clump, paint_clump_reference
from hairtool.frozen.brushes.falloff import EPS, FALLOFFS, LUT_SIZE, MAX_FALLOFF_POINTS, falloff_lut
from hairtool.frozen.brushes.mask import paint_mask
from hairtool.frozen.brushes.sample import (
    MAX_COUNT,
    BrushSample,
    check_eye,
    check_pressure,
    check_sample,
    check_view,
    mirrored_eye,
    mirrored_view,
)
from hairtool.frozen.brushes.scalp import (
    PLANAR_RATIO,
    any_within,
    any_within_reference,
    facing_away,
    facing_away_reference,
    root_normals,
    scalp_centre,
)
from hairtool.frozen.brushes.spec import StrandMove

#: Every brush, in the toolbar's and the stroke logs' order.
BRUSHES = registry.names()
#: The brushes that add or remove strands, and those that need the head's surface.
CHANGE_STRANDS = registry.names_where(changes_strands=True)
NEED_SURFACE = registry.names_where(needs_surface=True)
#: They move no vertex: nothing to collide.
MOVE_NONE = registry.names_where(moves_points=False)
#: Strength in [-1, 1]; the others in [0, 1].
SIGNED = registry.names_where(signed=True)
#: The brushes a move runs on the strands under it only (the others on the whole groom).
LOCAL_BRUSHES = registry.names_where(local=True)


def _strand_move(sample: BrushSample) -> StrandMove:
    check_sample(sample)
    brush = registry.brush_of(sample.brush)
    if not isinstance(brush, StrandMove):
        moves = [s.name for s in registry.specs() if isinstance(registry.brush_of(s.name), StrandMove)]
        raise ParameterError("brush", sample.brush, "one of " + ", ".join(moves))
    return brush


def apply_brush(groom, sample: BrushSample, locked, centre):
    """One sample of a brush that only moves vertices (comb, smooth, length, puff, pinch …), numba.

    Parameters
    ----------
    groom : Groom
        The groom before the sample.
    sample : BrushSample
        The sample.
    locked : array_like, ``(S,)`` bool
        Strands left as they are.
    centre : array_like, ``(3,)``
        The scalp's centre (:func:`scalp_centre`), puff's outward normal.

    Returns
    -------
    Groom
        The groom after the sample.
    """
    return _strand_move(sample).move(groom, sample, locked, centre)


def apply_brush_reference(groom, sample: BrushSample, locked, centre):
    """Numpy twin of :func:`apply_brush`."""
    return _strand_move(sample).move_reference(groom, sample, locked, centre)


__all__ = [
    "BRUSHES", "CHANGE_STRANDS", "EPS", "FALLOFFS", "LOCAL_BRUSHES", "LUT_SIZE", "MAX_COUNT",
    "MAX_FALLOFF_POINTS", "MOVE_NONE", "NEED_SURFACE", "PLANAR_RATIO", "SIGNED", "BrushSample",
    "any_within", "any_within_reference", "apply_brush", "apply_brush_reference", "check_eye",
    "check_pressure", "check_sample", "check_view", "facing_away", "facing_away_reference",
    "falloff_lut", "mirrored_eye", "mirrored_view", "paint_clump", "paint_clump_reference", "paint_mask",
    "registry", "root_normals", "scalp_centre",
]  # fmt: skip
