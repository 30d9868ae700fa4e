"""Groom shapes the bundled grooms lack, generated from a seed: where a brush's cost could follow
the groom instead of the brush.

- :func:`ponytail`: every strand runs over the scalp into one tie behind the head, then hangs
  as one lock (strands converging: the densest neighbourhoods a groom has);
- :func:`curls`: helical strands, each turning around its own falling centre line;
- :func:`straight_cut`: long straight strands falling to one blunt cut (Cem Yuksel's straight
  models are 10,000 × 16 of these);
- :func:`hair_systems`: several hair systems in one groom (hair, brows and a beard), each a
  curve prim of its own, as a DCC scene holds them.

All on the samples' unit head (radius 1, Y up, a tenth of a metre a unit), roots on the head.
"""

from __future__ import annotations

import numpy as np

from hairtool.errors import ParameterError
from hairtool.groom import Groom
from hairtool.metadata import CurvesPrim, Metadata
from hairtool.samples import HEAD_RADIUS, SAMPLE_METADATA

#: The shapes by name, with the size ``hairtool bench freeze`` measures each at (strands, vertices).
SIZES = {"ponytail": (3066, 16), "curls": (2000, 32), "straight": (10_000, 16), "systems": (4000, 16)}


def _check(strands: int, vertices: int, least: int = 1) -> None:
    if isinstance(strands, bool) or int(strands) != strands or not least <= strands <= 10_000_000:
        raise ParameterError("strands", strands, f"a whole number in [{least}, 10000000]")
    if isinstance(vertices, bool) or int(vertices) != vertices or not 4 <= vertices <= 256:
        raise ParameterError("vertices", vertices, "a whole number in [4, 256]")


def _cap(rng: np.random.Generator, n: int, y_low: float, z_max: float = 1.0) -> np.ndarray:
    """``n`` unit normals area-uniform on the sphere cap y ≥ ``y_low`` with z ≤ ``z_max``
    (drawn over, the excess dropped, so the count is exact)."""
    out = np.empty((0, 3))
    while len(out) < n:
        y = rng.uniform(y_low, 1.0, 2 * n)
        phi = rng.uniform(0.0, 2.0 * np.pi, 2 * n)
        r = np.sqrt(1.0 - y * y)
        nrm = np.column_stack([r * np.cos(phi), y, r * np.sin(phi)])
        out = np.concatenate([out, nrm[nrm[:, 2] <= z_max]])
    return out[:n]


def _bezier(a: np.ndarray, c: np.ndarray, b: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Quadratic Bézier points ``(S, len(t), 3)`` from ``a`` through control ``c`` to ``b``."""
    t = t[None, :, None]
    return (1 - t) ** 2 * a[:, None] + 2 * (1 - t) * t * c[:, None] + t * t * b[:, None]


def _outside_head(pts: np.ndarray) -> np.ndarray:
    """The points below the scalp (all but roots) moved out onto it with a small clearance."""
    r = np.linalg.norm(pts, axis=2, keepdims=True)
    inside = r < HEAD_RADIUS * 1.02
    inside[:, 0] = False
    return np.where(inside, pts / np.maximum(r, 1e-9) * HEAD_RADIUS * 1.02, pts)


def _groom(pts: np.ndarray, metadata: Metadata = SAMPLE_METADATA) -> Groom:
    pts = _outside_head(pts)
    s, v, _ = pts.shape
    return Groom(pts.reshape(-1, 3).astype(np.float32), np.full(s, v), metadata=metadata)


def ponytail(strands: int = 3066, vertices: int = 16, seed: int = 0, tie_radius: float = 0.08) -> Groom:
    """Strands from the crown and the back of the head gathered into one tie behind the head
    (each at its own place in a disk of ``tie_radius``), then hanging as one lock that opens
    toward its end. Half the vertices run to the tie, half hang below it."""
    _check(strands, vertices)
    rng = np.random.default_rng(seed)
    roots = _cap(rng, strands, 0.05, z_max=0.3) * HEAD_RADIUS
    tie = np.array([0.0, 0.55, -1.15]) * HEAD_RADIUS
    a = rng.uniform(0.0, 2.0 * np.pi, strands)
    rad = tie_radius * np.sqrt(rng.uniform(0.0, 1.0, strands))
    disk = np.column_stack([rad * np.cos(a), rad * np.sin(a), np.zeros(strands)])
    at_tie = tie + disk
    mid = 0.5 * (roots + at_tie)
    control = mid / np.linalg.norm(mid, axis=1, keepdims=True) * 1.25 * HEAD_RADIUS  # over the scalp
    up = vertices // 2
    over = _bezier(roots, control, at_tie, np.linspace(0.0, 1.0, up))
    length = 1.8 * HEAD_RADIUS * rng.uniform(0.9, 1.1, strands)
    t = np.linspace(0.0, 1.0, vertices - up + 1)[1:]
    spread = 1.0 + 3.0 * t  # the lock opens to four times the tie's width
    down = (
        tie[None, None]
        + disk[:, None] * spread[None, :, None]
        + np.array([0.0, -1.0, -0.25])[None, None] * (length[:, None, None] * t[None, :, None])
    )
    return _groom(np.concatenate([over, down], axis=1))


def curls(
    strands: int = 2000, vertices: int = 32, seed: int = 0, turns: float = 4.0, radius: float = 0.08
) -> Groom:
    """Helical strands: each turns ``turns`` times, ``radius`` head radii around a centre line
    that leaves the scalp along its normal and falls; its phase and length drawn per strand."""
    _check(strands, vertices)
    rng = np.random.default_rng(seed)
    normals = _cap(rng, strands, 0.1)
    roots = normals * HEAD_RADIUS
    length = 1.2 * HEAD_RADIUS * rng.uniform(0.8, 1.2, strands)
    t = np.linspace(0.0, 1.0, vertices)[None, :, None]
    fall = np.array([0.0, -1.0, 0.0])
    centre = roots[:, None] + 0.15 * normals[:, None] * np.sqrt(t) + fall * length[:, None, None] * t
    # a frame across the fall: u away from the head (horizontally), w = fall × u
    u = normals * np.array([1.0, 0.0, 1.0])
    u /= np.maximum(np.linalg.norm(u, axis=1, keepdims=True), 1e-9)
    u[np.linalg.norm(normals * np.array([1.0, 0.0, 1.0]), axis=1) < 1e-6] = (1.0, 0.0, 0.0)
    w = np.cross(fall, u)
    phase = rng.uniform(0.0, 2.0 * np.pi, strands)[:, None, None]
    ang = 2.0 * np.pi * turns * t + phase
    grow = np.minimum(t * 4.0, 1.0)  # the curl opens within the first quarter, so the root stays put
    pts = centre + radius * grow * (np.cos(ang) * u[:, None] + np.sin(ang) * w[:, None])
    pts[:, 0] = roots
    return _groom(pts)


def straight_cut(strands: int = 10_000, vertices: int = 16, seed: int = 0, cut: float = -1.6) -> Groom:
    """Long straight hair: each strand leaves the scalp along its normal, then falls straight
    down outside the head to one blunt cut at height ``cut``."""
    _check(strands, vertices)
    rng = np.random.default_rng(seed)
    normals = _cap(rng, strands, 0.1)
    roots = normals * HEAD_RADIUS
    side = normals * np.array([1.0, 0.0, 1.0])
    reach = np.linalg.norm(side, axis=1, keepdims=True)
    side = np.where(reach > 1e-6, side / np.maximum(reach, 1e-9), np.array([1.0, 0.0, 0.0]))
    out = roots + normals * 0.05
    ring = np.maximum(np.linalg.norm(out * np.array([1.0, 0.0, 1.0]), axis=1, keepdims=True), 1.04)
    top = out * np.array([0.0, 1.0, 0.0]) + side * ring  # just outside the head at the root's height
    bottom = top * np.array([1.0, 0.0, 1.0]) + np.array([0.0, cut, 0.0]) * HEAD_RADIUS
    # vertices evenly along root → top → bottom, by length
    legs = np.stack([roots, top, bottom], axis=1)
    seg = np.linalg.norm(np.diff(legs, axis=1), axis=2)
    along = np.concatenate([np.zeros((strands, 1)), np.cumsum(seg, axis=1)], axis=1)
    s = np.linspace(0.0, 1.0, vertices)[None] * along[:, -1:]
    first = (s <= along[:, 1:2])[..., None]
    t0 = (s / np.maximum(seg[:, 0:1], 1e-12))[..., None]
    t1 = ((s - along[:, 1:2]) / np.maximum(seg[:, 1:2], 1e-12))[..., None]
    pts = np.where(
        first, roots[:, None] + t0 * (top - roots)[:, None], top[:, None] + t1 * (bottom - top)[:, None]
    )
    return _groom(pts)


def hair_systems(strands: int = 4000, vertices: int = 16, seed: int = 0) -> Groom:
    """Three hair systems, each its own curve prim: the hair (four fifths of ``strands``, from
    the scalp), the brows (two short rows above the eyes) and a beard (short strands on the
    chin), in that order."""
    _check(strands, vertices, least=10)
    rng = np.random.default_rng(seed)
    n_brows = max(2, strands // 20)
    n_hair = strands * 4 // 5
    n_beard = strands - n_hair - n_brows
    hair = straight_cut(n_hair, vertices, seed, cut=-0.9).points.reshape(n_hair, vertices, 3)
    # brows: roots along two arcs on the forehead, strands combed outward along the arc
    x = rng.uniform(0.12, 0.45, n_brows) * np.where(np.arange(n_brows) % 2 == 0, 1.0, -1.0)
    y = 0.22 + 0.08 * np.cos(np.pi * (np.abs(x) - 0.12) / 0.33) + rng.normal(0.0, 0.01, n_brows)
    z = np.sqrt(np.maximum(1.0 - x * x - y * y, 0.0))
    broot = np.column_stack([x, y, z]) * HEAD_RADIUS
    bdir = np.column_stack([np.sign(x), 0.3 * np.ones(n_brows), 0.4 * np.ones(n_brows)])
    bdir /= np.linalg.norm(bdir, axis=1, keepdims=True)
    t = np.linspace(0.0, 1.0, vertices)[None, :, None]
    brows = broot[:, None] + bdir[:, None] * 0.08 * HEAD_RADIUS * t
    # beard: roots on the lower front of the head, strands down and out
    nrm = _cap(rng, n_beard, 0.1)
    nrm = nrm * np.array([0.7, -0.45, 1.0])
    nrm[:, 2] = np.abs(nrm[:, 2]) + 0.4
    nrm /= np.linalg.norm(nrm, axis=1, keepdims=True)
    droot = nrm * HEAD_RADIUS
    ddir = nrm + np.array([0.0, -0.8, 0.0])
    ddir /= np.linalg.norm(ddir, axis=1, keepdims=True)
    beard = (
        droot[:, None]
        + ddir[:, None] * 0.25 * HEAD_RADIUS * rng.uniform(0.8, 1.2, n_beard)[:, None, None] * t
    )
    meta = Metadata(
        up_axis=SAMPLE_METADATA.up_axis,
        meters_per_unit=SAMPLE_METADATA.meters_per_unit,
        curves=(
            CurvesPrim("/Head/Hair", n_hair),
            CurvesPrim("/Head/Brows", n_brows),
            CurvesPrim("/Head/Beard", n_beard),
        ),
    )
    return _groom(np.concatenate([hair, brows, beard]), meta)


SHAPES = {"ponytail": ponytail, "curls": curls, "straight": straight_cut, "systems": hair_systems}


def shape(name: str, strands: int | None = None, vertices: int | None = None, seed: int = 0) -> Groom:
    """The shape ``name`` (a key of :data:`SHAPES`) at the given size (None: its :data:`SIZES`)."""
    if name not in SHAPES:
        raise ParameterError("shape", name, " or ".join(SHAPES))
    s, v = SIZES[name]
    return SHAPES[name](s if strands is None else strands, v if vertices is None else vertices, seed)
