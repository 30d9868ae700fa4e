"""UserAlign (Kim 2026, eqs. 8–13): turn the strands near a cursor about their roots toward it.

Strand s takes part when its tip lies within r of the cursor c (10). Its representative direction
v = tip − mean (8) is turned onto u = c − root (9) by the rotation R(â, phi) (11), weighted along
the strand by w(t) = t(1 − x) + x (12). Two modes:

- ``"paper"``: (13) as printed, p'' = root + w·R·(p − root) + (1 − w)·(p − root). The linear blend
  shortens a strand where 0 < w < 1 and phi is large.
- ``"preserve-length"``: every segment vector p[i] − p[i−1] is turned by w(t_i)·phi instead and the
  strand rebuilt from its root, which keeps every segment length (so the strand length) exactly.

Both are a rigid rotation about the root for x = 1. Degenerate strands are left alone: a cursor on
the root (u ≈ 0), a strand with v ≈ 0, or v already along u (phi < 1e-7 rad, which also makes
repeated alignment toward one cursor a fixed point). v opposite to u turns by pi about any axis
perpendicular to v (the plane normal for 2-D grooms). For 2-D grooms (z = 0) the cursor is
projected onto the plane, so strands stay in it. phi is computed as atan2(|v × u|, v·u), the
same angle as (11)'s arccos but accurate near 0 and pi.
"""

from __future__ import annotations

import numpy as np
from numba import prange
from numpy.typing import ArrayLike

from hairtool.errors import ParameterError
from hairtool.groom import Groom
from hairtool.rotation import any_perpendicular, perpendicular_axis, rotate
from hairtool.serial_twins import twin_njit

MODES = ("paper", "preserve-length")
PHI_MIN = 1e-7  # radians: below this a strand counts as aligned
REL_EPS = 1e-6  # |u| ≤ REL_EPS·|v|: the cursor sits on the root
PAR_EPS = 1e-12  # |v × u| ≤ PAR_EPS·|v||u|: v ∥ u


def check_align_params(cursor: ArrayLike, radius: float, intensity: float, mode: str) -> np.ndarray:
    """Validate one align sample; returns the cursor as a float64 (3,) (a 2-D cursor gets z = 0).

    Parameters
    ----------
    cursor : array_like
        The cursor, 2 or 3 finite numbers.
    radius : float
        The brush radius, > 0.
    intensity : float
        The strength, in [0, 1].
    mode : str
        ``"paper"`` or ``"preserve-length"``.

    Returns
    -------
    ndarray
        ``(3,)`` float64 cursor.
    """
    c = np.asarray(cursor, dtype=np.float64).reshape(-1)
    if c.shape not in ((2,), (3,)):
        raise ParameterError("cursor", cursor, "a point (x, y) or (x, y, z)")
    if not np.all(np.isfinite(c)):
        raise ParameterError("cursor", cursor, "finite coordinates")
    if c.size == 2:
        c = np.append(c, 0.0)
    r = float(radius)
    if not np.isfinite(r) or r <= 0:
        raise ParameterError("radius", radius, "a positive finite distance")
    x = float(intensity)
    if not np.isfinite(x) or not 0.0 <= x <= 1.0:
        raise ParameterError("intensity", intensity, "a number in [0, 1]")
    if mode not in MODES:
        raise ParameterError("mode", mode, " or ".join(MODES))
    return c


@twin_njit(nogil=True, parallel=True)
def _align_kernel(p, offsets, c, radius, x, preserve, planar, out):
    s_count = offsets.size - 1
    for s in prange(s_count):
        o = offsets[s]
        n = offsets[s + 1] - o
        for i in range(n):
            out[o + i, 0], out[o + i, 1], out[o + i, 2] = p[o + i, 0], p[o + i, 1], p[o + i, 2]
        ex, ey, ez = np.float64(p[o + n - 1, 0]), np.float64(p[o + n - 1, 1]), np.float64(p[o + n - 1, 2])
        if (ex - c[0]) ** 2 + (ey - c[1]) ** 2 + (ez - c[2]) ** 2 > radius * radius:  # (10)
            continue  # most strands, while a brush drags: nothing more to compute
        mx = my = mz = 0.0
        for i in range(n):
            mx += p[o + i, 0]
            my += p[o + i, 1]
            mz += p[o + i, 2]
        mx, my, mz = mx / n, my / n, mz / n  # p̄ (8)
        bx, by, bz = np.float64(p[o, 0]), np.float64(p[o, 1]), np.float64(p[o, 2])
        vx, vy, vz = ex - mx, ey - my, ez - mz  # v (8)
        ux, uy, uz = c[0] - bx, c[1] - by, c[2] - bz  # u (9)
        nv = np.sqrt(vx * vx + vy * vy + vz * vz)
        nu = np.sqrt(ux * ux + uy * uy + uz * uz)
        if nv == 0.0 or nu <= REL_EPS * nv:
            continue
        ax, ay, az = vy * uz - vz * uy, vz * ux - vx * uz, vx * uy - vy * ux
        cn = np.sqrt(ax * ax + ay * ay + az * az)
        phi = np.arctan2(cn, vx * ux + vy * uy + vz * uz)  # (11)
        if phi < PHI_MIN:
            continue
        if cn > PAR_EPS * nv * nu:
            ax, ay, az = ax / cn, ay / cn, az / cn
        elif planar:
            ax, ay, az = 0.0, 0.0, 1.0
        else:
            ax, ay, az = perpendicular_axis(vx, vy, vz)
        qx, qy, qz = bx, by, bz  # running position (preserve-length)
        for i in range(1, n):
            w = (i / (n - 1)) * (1.0 - x) + x  # (12)
            if preserve:
                dx = np.float64(p[o + i, 0]) - np.float64(p[o + i - 1, 0])
                dy = np.float64(p[o + i, 1]) - np.float64(p[o + i - 1, 1])
                dz = np.float64(p[o + i, 2]) - np.float64(p[o + i - 1, 2])
                th = w * phi
            else:
                dx, dy, dz = p[o + i, 0] - bx, p[o + i, 1] - by, p[o + i, 2] - bz
                th = phi
            cs, sn = np.cos(th), np.sin(th)
            ad = ax * dx + ay * dy + az * dz
            rx = dx * cs + (ay * dz - az * dy) * sn + ax * ad * (1.0 - cs)
            ry = dy * cs + (az * dx - ax * dz) * sn + ay * ad * (1.0 - cs)
            rz = dz * cs + (ax * dy - ay * dx) * sn + az * ad * (1.0 - cs)
            if preserve:
                qx, qy, qz = qx + rx, qy + ry, qz + rz
            else:  # (13)
                qx = bx + w * rx + (1.0 - w) * dx
                qy = by + w * ry + (1.0 - w) * dy
                qz = bz + w * rz + (1.0 - w) * dz
            out[o + i, 0], out[o + i, 1], out[o + i, 2] = qx, qy, qz


def align(
    groom: Groom,
    cursor: ArrayLike,
    radius: float,
    intensity: float = 0.8,
    mode: str = "paper",
    planar: bool | None = None,
) -> Groom:
    """UserAlign: one align sample (one mouse move) applied to ``groom``; roots stay fixed.

    ``cursor``: (3,) point (the mouse unprojected), ``radius``: the tips within it take part,
    ``intensity`` x ∈ [0, 1]: 1 turns a strand like a rod, 0 mostly its tip. ``planar``: whether
    the groom counts as 2-D (None: :attr:`~hairtool.groom.Groom.is_planar`; the brush-local
    pipeline passes the whole groom's for the strands it runs on).

    Parameters
    ----------
    groom
        The groom to turn (in the pipeline, the frozen groom or the last sample's result).
    cursor
        ``(3,)`` the cursor c of eq. 9, in groom units.
    radius
        r of eq. 10, > 0: a strand takes part when its tip is within it of the cursor.
    intensity
        x of eq. 12, in [0, 1].
    mode
        ``"paper"``: eq. 13's blend of rotated and unrotated offsets, which shortens strands at
        large angles; ``"preserve-length"``: each offset rotated by the weighted angle instead.
    planar
        Whether the groom is 2-D (its turning axis then the plane's normal); None: the groom's own.

    Returns
    -------
    Groom
        A new groom; strands out of reach keep their points bit for bit.

    Raises
    ------
    ParameterError
        A parameter is out of range or not finite.
    """
    c = check_align_params(cursor, radius, intensity, mode)
    planar = groom.is_planar if planar is None else bool(planar)
    if planar:
        c[2] = 0.0
    out = np.empty_like(groom.points)
    _align_kernel(
        groom.points, groom.offsets, c, float(radius), float(intensity), mode != "paper", planar, out
    )
    return groom.with_points(out)


def align_reference(
    groom: Groom, cursor: ArrayLike, radius: float, intensity: float = 0.8, mode: str = "paper"
) -> Groom:
    """Plain numpy twin of :func:`align`.

    Parameters
    ----------
    groom : Groom
        The groom.
    cursor : array_like
        The cursor.
    radius : float
        The brush radius.
    intensity : float, default 0.8
        The strength, in [0, 1].
    mode : str, default "paper"
        ``"paper"`` or ``"preserve-length"``.

    Returns
    -------
    Groom
        What :func:`align` gives.
    """
    c = check_align_params(cursor, radius, intensity, mode)
    planar = groom.is_planar
    if planar:
        c[2] = 0.0
    top = groom.topology
    p = groom.points.astype(np.float64)
    root, tip = p[top.root_indices], p[top.tip_indices]
    mean = np.add.reduceat(p, top.offsets[:-1], axis=0) / top.counts[:, None]  # (8)
    v, u = tip - mean, c - root  # (8), (9)
    nv, nu = np.linalg.norm(v, axis=1), np.linalg.norm(u, axis=1)
    cross = np.cross(v, u)
    cn = np.linalg.norm(cross, axis=1)
    phi = np.arctan2(cn, np.einsum("ij,ij->i", v, u))  # (11)
    active = (np.linalg.norm(tip - c, axis=1) <= radius) & (nv > 0) & (nu > REL_EPS * nv) & (phi >= PHI_MIN)
    fallback = np.tile([0.0, 0.0, 1.0], (len(v), 1)) if planar else any_perpendicular(v)
    has_axis = cn > PAR_EPS * nv * nu
    axis = np.where(has_axis[:, None], cross / np.where(has_axis, cn, 1.0)[:, None], fallback)
    s = top.strand_index
    w = top.index_in_strand / (top.counts[s] - 1) * (1.0 - intensity) + intensity  # (12)
    out = p.copy()
    if mode == "paper":
        off = p - root[s]
        turned = rotate(off, axis[s], phi[s])
        new = root[s] + w[:, None] * turned + (1.0 - w[:, None]) * off  # (13)
    else:
        end = top.segment_end
        seg = np.zeros_like(p)
        seg[end] = rotate(p[end] - p[end - 1], axis[s[end]], w[end] * phi[s[end]])
        new = root[s] + _strand_cumsum(seg, top)
    sel = active[s] & (top.index_in_strand > 0)
    out[sel] = new[sel]
    return groom.with_points(out)


def _strand_cumsum(values: np.ndarray, top) -> np.ndarray:
    """Running sums along each strand (values at roots included)."""
    cs = np.cumsum(values, axis=0)
    first = top.root_indices
    return cs - (cs[first] - values[first])[top.strand_index]
