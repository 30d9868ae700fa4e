"""The density brush: under the brush the roots end up a given spacing apart, Poisson-disk
style (no two roots closer than the spacing, no point of the region farther than twice it from a
root), by removing strands where they are too dense and planting where they are too sparse.

Within the brush's disc around the head's point nearest the cursor:

1. thinning: the strands whose roots lie in the disc are taken in their order; one is kept if
   its root is at least the spacing from every root kept so far, where the roots outside the
   disc (up to a spacing beyond it), masked strands and back-facing ones are kept from the
   start; the others leave the groom (as delete removes them);
2. darts: candidates drawn uniformly over the disc (from ``seed`` and the cursor, as the add
   brush draws) and moved onto the head are accepted in turn when at least the spacing from
   every root and every accepted candidate; then every point of a grid of step spacing / 2 over
   the disc (on the head) that is still farther than the spacing from all roots is accepted the
   same way, so no point of the disc is farther than about 1.35 × the spacing from a root;
3. the accepted roots grow strands shaped like their neighbours (the surface's ``grow``, as the
   add brush's children).

The two sequential loops (thinning, acceptance) are numba kernels with numpy twins.
"""

from __future__ import annotations

import numpy as np
from numba import njit
from numpy.typing import NDArray

from hairtool import budget

F64 = NDArray[np.float64]

DARTS = 30  # candidates drawn per spacing-sized square of the disc's area


@njit(cache=True, nogil=True)
def _thin_kernel(roots, fixed, spacing, keep):  # pragma: no cover - compiled
    s2 = spacing * spacing
    for i in range(roots.shape[0]):
        keep[i] = fixed[i]
    for i in range(roots.shape[0]):
        if fixed[i]:
            continue
        ok = True
        for j in range(roots.shape[0]):
            if keep[j] and j != i:
                dx, dy, dz = roots[i, 0] - roots[j, 0], roots[i, 1] - roots[j, 1], roots[i, 2] - roots[j, 2]
                if dx * dx + dy * dy + dz * dz < s2:
                    ok = False
                    break
        keep[i] = ok


def thin(roots: np.ndarray, fixed: np.ndarray, spacing: float) -> np.ndarray:
    """``(R,)`` the roots kept (step 1 of the module docstring) (numba).

    Parameters
    ----------
    roots : ndarray
        ``(R, 3)`` float64 roots under the brush, in the order they are taken.
    fixed : ndarray
        ``(R,)`` bool, roots kept whatever their spacing (masked, back-facing).
    spacing : float
        The least distance between kept roots, > 0.

    Returns
    -------
    ndarray
        ``(R,)`` bool.
    """
    n = float(len(roots))
    budget.check("steps", n * n, f"thinning {len(roots)} roots within the brush (spacing={spacing:g})")
    keep = np.empty(len(roots), np.bool_)
    _thin_kernel(np.ascontiguousarray(roots, np.float64), np.asarray(fixed, np.bool_), float(spacing), keep)
    return keep


def thin_reference(roots: np.ndarray, fixed: np.ndarray, spacing: float) -> np.ndarray:
    """Numpy twin of :func:`thin`.

    Parameters
    ----------
    roots, fixed, spacing
        As :func:`thin` takes them.

    Returns
    -------
    ndarray
        ``(R,)`` bool, as :func:`thin` gives it.
    """
    r = np.asarray(roots, np.float64)
    keep = np.asarray(fixed, bool).copy()
    for i in np.flatnonzero(~keep):
        d = r[keep] - r[i]
        keep[i] = not np.any(d[:, 0] * d[:, 0] + d[:, 1] * d[:, 1] + d[:, 2] * d[:, 2] < spacing * spacing)
    return keep


@njit(cache=True, nogil=True)
def _accept_kernel(candidates, roots, spacing, out):  # pragma: no cover - compiled
    s2 = spacing * spacing
    for i in range(candidates.shape[0]):
        ok = True
        for j in range(roots.shape[0]):
            dx, dy = candidates[i, 0] - roots[j, 0], candidates[i, 1] - roots[j, 1]
            dz = candidates[i, 2] - roots[j, 2]
            if dx * dx + dy * dy + dz * dz < s2:
                ok = False
                break
        if ok:
            for j in range(i):
                if out[j]:
                    dx, dy = candidates[i, 0] - candidates[j, 0], candidates[i, 1] - candidates[j, 1]
                    dz = candidates[i, 2] - candidates[j, 2]
                    if dx * dx + dy * dy + dz * dz < s2:
                        ok = False
                        break
        out[i] = ok


def accept(candidates: np.ndarray, roots: np.ndarray, spacing: float) -> np.ndarray:
    """``(C,)`` the candidates accepted in turn: at least ``spacing`` from every root and every
    candidate accepted before (numba).

    Parameters
    ----------
    candidates : ndarray
        ``(C, 3)`` float64 candidate roots, in the order they are tried.
    roots : ndarray
        ``(R, 3)`` float64 roots kept.
    spacing : float
        The least distance, > 0.

    Returns
    -------
    ndarray
        ``(C,)`` bool.
    """
    out = np.zeros(len(candidates), np.bool_)
    c, r = np.ascontiguousarray(candidates, np.float64), np.ascontiguousarray(roots, np.float64)
    _accept_kernel(c, r, float(spacing), out)
    return out


def accept_reference(candidates: np.ndarray, roots: np.ndarray, spacing: float) -> np.ndarray:
    """Numpy twin of :func:`accept`.

    Parameters
    ----------
    candidates, roots, spacing
        As :func:`accept` takes them.

    Returns
    -------
    ndarray
        ``(C,)`` bool, as :func:`accept` gives it.
    """
    c, r = np.asarray(candidates, np.float64), np.asarray(roots, np.float64)
    out = np.zeros(len(c), bool)
    s2 = spacing * spacing
    for i in range(len(c)):
        others = np.concatenate([r, c[:i][out[:i]]])
        d = others - c[i]
        out[i] = not np.any(d[:, 0] * d[:, 0] + d[:, 1] * d[:, 1] + d[:, 2] * d[:, 2] < s2)
    return out


def candidate_count(radius: float, spacing: float) -> float:
    """How many candidates :func:`disc_candidates` draws: the darts, and the grid's square
    before it is cut to the disc (a float: inf or nan where the ratio overflows).

    Parameters
    ----------
    radius : float
        The brush radius.
    spacing : float
        The spacing asked for.

    Returns
    -------
    float
        The candidates' count.
    """
    with np.errstate(all="ignore"):
        ratio = np.float64(radius) / np.float64(spacing)
        return float(DARTS * np.pi * ratio * ratio + (4.0 * ratio + 1.0) ** 2)


def check_candidates(radius: float, spacing: float) -> None:
    """Refuse (:class:`~hairtool.budget.BudgetError`) a radius and spacing whose candidates
    would not fit the budget, before any is drawn: their points, and the acceptance loop, which
    tests each candidate against those accepted before it (about candidates² / 2 steps).

    Parameters
    ----------
    radius : float
        The brush radius.
    spacing : float
        The spacing asked for.

    Raises
    ------
    BudgetError
        Naming both, where the candidates or the loop over them would not fit.
    """
    what = f"density radius={radius:g}, spacing={spacing:g}"
    c = candidate_count(radius, spacing)
    budget.check("points", c, what)
    budget.check_bytes(c * 8 * 3 * 4, what)  # uv, their 3-D points, projected, with normals
    budget.check("steps", c * c / 2, what)


def disc_candidates(centre: F64, normal: F64, radius: float, spacing: float, rng: np.random.Generator) -> F64:
    """Darts (uniform over the disc) then the grid of step spacing / 2, in the tangent plane at
    ``centre`` (to be moved onto the head).

    Parameters
    ----------
    centre : ndarray
        ``(3,)`` the head's point under the cursor.
    normal : ndarray
        ``(3,)`` the head's unit normal there.
    radius : float
        The brush radius.
    spacing : float
        The spacing asked for.
    rng : numpy.random.Generator
        The darts' generator (seeded from the sample's seed and cursor).

    Returns
    -------
    ndarray
        ``(C, 3)`` float64 candidates.
    """
    a = np.eye(3)[int(np.argmin(np.abs(normal)))]
    u = np.cross(normal, a)
    u /= np.linalg.norm(u)
    v = np.cross(normal, u)
    check_candidates(radius, spacing)
    n_darts = int(np.ceil(DARTS * np.pi * radius * radius / (spacing * spacing)))
    r = radius * np.sqrt(rng.random(n_darts))
    t = 2.0 * np.pi * rng.random(n_darts)
    darts = np.column_stack([r * np.cos(t), r * np.sin(t)])
    step = 0.5 * spacing
    k = np.arange(-np.floor(radius / step), np.floor(radius / step) + 1) * step
    gx, gy = np.meshgrid(k, k, indexing="ij")
    grid = np.column_stack([gx.ravel(), gy.ravel()])
    grid = grid[np.einsum("ij,ij->i", grid, grid) <= radius * radius]
    uv = np.concatenate([darts, grid])
    return centre + uv[:, :1] * u + uv[:, 1:] * v
