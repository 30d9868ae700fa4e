"""Where children grow: roots scattered on a scalp mesh, or around the guide roots without one.

On a mesh the roots are uniform by area (or by a density per face or per vertex) over the
region where hair grows. The default region is the faces whose corners lie on average within
:data:`DEFAULT_REACH` guide spacings (the median distance between neighbouring guide roots) of a
guide root along the surface: the scalp the guides cover, not the face or the neck (on Sintel's
head: 579 of 5,952 triangles, 677 of 2,858 square units, none below her hairline or on her
neck). Any face set (the name of a group of the mesh's file, triangle indices or a mask over
the triangles) replaces it. Without a mesh each
child takes a guide at random and a point in the disc of one guide spacing around its root,
across its root tangent.

Randomness: numpy generators seeded with (seed, channel), so the roots depend on the seed only.
"""

from __future__ import annotations

import numpy as np

from hairtool.errors import ParameterError
from hairtool.frozen.strand_clumps import median_root_spacing
from hairtool.groom import Groom
from hairtool.guides.surface import nearest_guide_distance
from hairtool.io.obj import Mesh

DEFAULT_REACH = 1.5  # the default region: faces within this many guide spacings of a guide root
CH_SCATTER = 1
CH_VARIATION = 2


def generator(seed: int, channel: int) -> np.random.Generator:
    """The random generator of one ``channel`` (scatter, lengths, frizz) of ``seed``.

    Parameters
    ----------
    seed : int
        The user's seed.
    channel : int
        Which draws.

    Returns
    -------
    numpy.random.Generator
        Seeded by the pair.
    """
    return np.random.default_rng((int(seed), int(channel)))


def check_mesh(mesh: Mesh) -> None:
    """A ParameterError for a scalp with no faces or non-finite vertices.

    Parameters
    ----------
    mesh : Mesh
        The scalp.
    """
    if len(mesh.faces) == 0:
        raise ParameterError("scalp", "a mesh without faces", "a mesh with at least one triangle")
    if not np.all(np.isfinite(mesh.vertices)):
        raise ParameterError("scalp", "a mesh with non-finite vertices", "finite vertex coordinates")


def guide_spacing(guides: Groom) -> float:
    """The median distance between neighbouring guide roots (the groom's extent / √G if the
    roots give none).

    Parameters
    ----------
    guides : Groom
        The guides.

    Returns
    -------
    float
        The spacing, in the groom's units.
    """
    s = median_root_spacing(guides)
    if s > 0:
        return s
    lo, hi = guides.bounds
    return max(float(np.linalg.norm(hi - lo)) / np.sqrt(guides.strand_count), 1e-6)


def face_areas(mesh: Mesh) -> np.ndarray:
    """``(F,)`` float64 area of each face.

    Parameters
    ----------
    mesh : Mesh
        The mesh.

    Returns
    -------
    ndarray
        ``(F,)`` float64.
    """
    v = mesh.vertices.astype(np.float64)
    f = mesh.faces
    return 0.5 * np.linalg.norm(np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]]), axis=1)


def default_region(
    mesh: Mesh, guides: Groom, reach: float = DEFAULT_REACH, near: np.ndarray | None = None
) -> np.ndarray:
    """``(F,)`` bool: the faces whose three corners lie on average within ``reach`` guide
    spacings of a guide root along the surface (of the guides flagged in ``near`` only, e.g.
    those the artist painted, when given).

    Parameters
    ----------
    mesh : Mesh
        The scalp.
    guides : Groom
        The guides.
    reach : float, default DEFAULT_REACH
        How many guide spacings from a root.
    near : ndarray, optional
        ``(G,)`` bool, the guides that count.

    Returns
    -------
    ndarray
        ``(F,)`` bool.
    """
    check_mesh(mesh)
    if not np.isfinite(reach) or reach <= 0:
        raise ParameterError("reach", reach, "a positive number of guide spacings")
    roots = guides.roots.astype(np.float64)
    if near is not None:
        near = np.asarray(near, bool)
        if near.shape != (guides.strand_count,) or not near.any():
            raise ParameterError("region", f"{int(near.sum())} guides", "at least one guide to grow near")
        roots = roots[near]
    d = nearest_guide_distance(mesh, roots)
    return d[mesh.faces].mean(axis=1) <= reach * guide_spacing(guides)


def _face_mask(mesh: Mesh, region: np.ndarray | str) -> np.ndarray:
    if isinstance(region, str):
        if region not in mesh.groups:
            names = ", ".join(sorted(mesh.groups)) or "none"
            raise ParameterError("region", region, f"a face set of the mesh ({names})")
        region = mesh.groups[region]
    r = np.asarray(region)
    nf = len(mesh.faces)
    if r.dtype == bool:
        if r.shape != (nf,):
            raise ParameterError("region", f"a mask of {r.size}", f"a mask of the mesh's {nf} triangles")
        return r
    if r.size and (not np.issubdtype(r.dtype, np.integer) or r.min() < 0 or r.max() >= nf):
        raise ParameterError("region", "face indices", f"triangle indices in [0, {nf})")
    mask = np.zeros(nf, bool)
    mask[r.astype(np.int64)] = True
    return mask


def _face_density(mesh: Mesh, density: np.ndarray) -> np.ndarray:
    d = np.asarray(density, np.float64)
    nf, nv = len(mesh.faces), len(mesh.vertices)
    if d.shape not in ((nf,), (nv,)):
        raise ParameterError(
            "density", f"shape {d.shape}", f"one value per triangle ({nf}) or per vertex ({nv})"
        )
    if not np.all(np.isfinite(d)) or np.any(d < 0):
        raise ParameterError("density", "non-finite or negative values", "finite values ≥ 0")
    return d if d.shape == (nf,) else d[mesh.faces].mean(axis=1)


def scatter_on_mesh(
    mesh: Mesh,
    count: int,
    seed: int,
    region: np.ndarray | str,
    density: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """``count`` roots on the ``region`` faces (mask, indices or a face set's name), uniform by
    area × density (a per-vertex density is averaged over each triangle's corners): ``(N, 3)``
    float64 points and ``(N,)`` their faces.

    Parameters
    ----------
    mesh : Mesh
        The scalp.
    count : int
        Roots.
    seed : int
        The draws' seed.
    region : ndarray or str
        Face mask, face indices or a face set's name.
    density : ndarray, optional
        ``(Vm,)`` per-vertex density.

    Returns
    -------
    tuple of (ndarray, ndarray)
        Roots and their faces.
    """
    check_mesh(mesh)
    weight = face_areas(mesh) * _face_mask(mesh, region)
    if density is not None:
        weight = weight * _face_density(mesh, density)
    total = float(weight.sum())
    if not total > 0:
        raise ParameterError("region", "no area", "faces of positive area (and density) where hair grows")
    rng = generator(seed, CH_SCATTER)
    cdf = np.cumsum(weight) / total
    faces = np.minimum(np.searchsorted(cdf, rng.random(count), side="right"), len(cdf) - 1)
    faces = np.where(weight[faces] > 0, faces, np.flatnonzero(weight)[0])  # (rounding at the very end)
    r = rng.random((count, 2))
    s = np.sqrt(r[:, 0])
    bary = np.column_stack([1.0 - s, s * (1.0 - r[:, 1]), s * r[:, 1]])
    v = mesh.vertices.astype(np.float64)[mesh.faces[faces]]  # (N, 3 corners, 3)
    return np.einsum("nc,ncx->nx", bary, v), faces.astype(np.int64)


def scatter_around(guides: Groom, count: int, seed: int) -> np.ndarray:
    """``(N, 3)`` float64 roots without a mesh: around random guide roots, in the disc of one
    guide spacing across each root's tangent. The disc's axes start from the scene's axis
    least along the tangent (in the groom's frame, :attr:`hairtool.metadata.Metadata.frame`),
    so the same groom in Y-up or Z-up gets the same roots.

    Parameters
    ----------
    guides : Groom
        The guides.
    count : int
        Roots.
    seed : int
        The draws' seed.

    Returns
    -------
    ndarray
        ``(N, 3)`` float64.
    """
    rng = generator(seed, CH_SCATTER)
    g = rng.integers(0, guides.strand_count, count)
    radius = guide_spacing(guides) * np.sqrt(rng.random(count))
    angle = 2.0 * np.pi * rng.random(count)
    pts = guides.points.astype(np.float64)
    root = pts[guides.offsets[:-1]]
    t = pts[guides.offsets[:-1] + 1] - root
    t /= np.maximum(np.linalg.norm(t, axis=1, keepdims=True), 1e-30)
    axes = guides.metadata.frame
    e = axes.T[np.argmin(np.abs(t @ axes), axis=1)]  # a column of the frame: a scene axis
    n = e - np.einsum("ij,ij->i", e, t)[:, None] * t
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    b = np.cross(t, n)
    return root[g] + radius[:, None] * (np.cos(angle)[:, None] * n[g] + np.sin(angle)[:, None] * b[g])
