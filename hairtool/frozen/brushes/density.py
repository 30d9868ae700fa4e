"""Density: under the brush the roots end up a given spacing apart, by removing strands where
they are too dense and planting where they are too sparse (:mod:`hairtool.frozen.density`
holds the thinning and the dart throwing, with their numpy twins). Front faces only: a sample
that says ``visible`` keeps (as if locked) the strands the head hides under the brush and plants
no root the head hides from the camera; one that does not (every log before it) does nothing
where the head under the cursor faces away and plants only where the surface faces the camera.
Under a perspective camera (a sample's ``eye``) the brush works around the head's point on the
line from the eye through the cursor (:meth:`~hairtool.guides.planting.HeadSurface.aimed`), and
by sight each dart's ray goes to the eye."""

from __future__ import annotations

import numpy as np

from hairtool.errors import ParameterError
from hairtool.frozen.brushes.add import SEED, append_strands
from hairtool.frozen.brushes.delete import remove
from hairtool.frozen.brushes.sight import hidden_points
from hairtool.frozen.brushes.spec import Brush, BrushSpec, Param, StrokeContext, Studio
from hairtool.frozen.density import accept, accept_reference, disc_candidates, thin, thin_reference
from hairtool.groom import Groom

SPACING = Param(
    "spacing",
    float,
    0.0,
    np.inf,
    0.0,
    "spacing",
    "a positive distance between roots (groom units)",
    open_low=True,
)

SPEC = BrushSpec(
    name="density",
    order=12,
    moves_points=False,
    changes_strands=True,
    needs_surface=True,
    takes_strength=False,
    follows_selection=False,
    params=(SPACING, SEED),
    studio=Studio(
        "Density",
        "D",
        "Removes or plants strands under the brush until the roots are the spacing "
        "apart (needs the head mesh)",
        1.0,
        place=12,
    ),
)


def _density(ctx: StrokeContext, g: Groom, sample, thin_, accept_) -> Groom:
    """One density sample: thinned, then planted (``thin_``, ``accept_``: the kernels or their twins)."""
    surface = ctx.surface
    if surface is None or not hasattr(surface, "aimed"):
        raise ParameterError("scalp", None, "a head mesh for the density brush (--scalp MESH.obj)")
    if sample.strength <= 0:
        return g
    locked = ctx.lock(sample)
    q, n = surface.aimed(sample.cursor, sample.eye)
    q, n = q[0], n[0]
    grid = getattr(surface, "face_grid", None) if sample.view is not None and sample.visible else None
    if sample.view is not None and grid is None and float(n @ np.asarray(sample.view, np.float64)) > 0:
        return g
    spacing, r = float(sample.spacing), float(sample.radius)
    roots = g.roots.astype(np.float64)
    dist = np.linalg.norm(roots - q, axis=1)
    near = np.flatnonzero(dist < r + spacing)
    keep = thin_(roots[near], (dist[near] >= r) | locked[near], spacing)
    gone = np.zeros(g.strand_count, bool)
    gone[near[~keep]] = True
    g = remove(ctx, g, gone, "density")
    bits = np.asarray(sample.cursor, np.float64).view(np.uint32)
    rng = np.random.default_rng([int(sample.seed), *(int(b) for b in bits), 0xDE5])
    cands, cn = surface.project(disc_candidates(q, n, r, spacing, rng))
    ok = np.linalg.norm(cands - q, axis=1) < r
    if grid is not None:  # front faces only by sight: the darts the head hides are not thrown
        ok[ok] = ~hidden_points(cands[ok], sample.view, grid, sample.eye)
    elif sample.view is not None:  # by the normal, as every log before visible
        ok &= cn @ np.asarray(sample.view, np.float64) <= 0
    cands = cands[ok]
    roots = g.roots.astype(np.float64)
    around = roots[np.linalg.norm(roots - q, axis=1) < r + spacing]
    new_roots = cands[accept_(cands, around, spacing)]
    if len(new_roots) == 0:
        return g
    new = surface.grow(g, new_roots)
    ctx.planted(new.strand_count)
    return append_strands(g, new)


class Density(Brush):
    spec = SPEC

    def apply(self, ctx: StrokeContext, g: Groom, sample) -> Groom:
        return _density(ctx, g, sample, thin, accept)

    def reference(self, ctx: StrokeContext, g: Groom, sample) -> Groom:
        return _density(ctx, g, sample, thin_reference, accept_reference)


BRUSH = Density()
