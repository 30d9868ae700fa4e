"""Where children's roots go when their guides' roots move (a head that nods, a parent that
turns, a simulation's head motion), as Blender's interpolated children stay on their moving
surface: the best rigid motion of the guide roots (Kabsch, in float64) carries every child
root, and what is left of each guide root's move after it is blended in with the child's
guide weights. A head moved rigidly carries its children exactly; guide roots that stay where
they were at rest leave the children's roots as bound, bit for bit.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from hairtool.groom import Groom
from hairtool.rotation import rigid_fit


def following_roots(binding, guides: Groom) -> np.ndarray:
    """``(N, 3)`` float64: the children's roots for the guides' pose ``guides`` (the binding's
    own array where the guide roots are the rest guides', bit for bit)."""
    g0 = binding.rest_guides.roots
    gf = guides.roots
    if np.array_equal(g0, gf):
        return binding.roots
    g0, gf = g0.astype(np.float64), gf.astype(np.float64)
    rot, t = rigid_fit(g0, gf)
    left = gf - (g0 @ rot.T + t)
    blend = np.einsum("nk,nkc->nc", binding.weights, left[binding.guide_ids])
    return binding.roots @ rot.T + t + blend


def following(binding, guides: Groom):
    """The binding with its children's roots moved with the guides' (:func:`following_roots`);
    the binding itself where they have not moved. Its caches are shared."""
    roots = following_roots(binding, guides)
    if roots is binding.roots:
        return binding
    return replace(binding, roots=roots, _tangents=binding._tangents, _attributes=binding._attributes)
