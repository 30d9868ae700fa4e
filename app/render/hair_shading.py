"""Hair shading from the strand direction (Kajiya & Kay 1989), per vertex.

A strand is a thin cylinder, so its lighting depends on its tangent T alone, not on a normal:

    diffuse  = sin(T, L) = √(1 − (T·L)²)
    specular = sin(T, H)^p = (1 − (T·H)²)^(p/2),   H = (L + E)/|L + E|
    colour   = base · (ambient + k_d · diffuse) + k_s · specular          (clamped to [0, 1])

with L toward the light and E toward the eye, both fixed relative to the camera (a key light
above and to the left of the viewer, turning with the view, as a DCC's viewport lamp), and
T the central difference of the strand's points (one-sided at root and tip). The shade is a
per-vertex colour: the GL draws and the CPU rasterizer interpolate the very same colours along
each segment, so both paths give the same picture. :func:`shade` is the kernel,
:func:`shade_reference` its numpy twin.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit, prange
from numpy.typing import NDArray

from hairtool.kernel_arrays import readonly
from hairtool.serial_twins import twin_njit

LIGHT_IN_VIEW = (-0.35, 0.6, 0.72)  # toward the key light: (right, up, toward the viewer)
HAIR_TAPER = 0.75  # shaded hair narrows to a quarter of its width at the tip (StrandRenderer.taper)


@dataclass(frozen=True)
class HairLook:
    """Kajiya-Kay weights: ambient, diffuse k_d, specular k_s and exponent p."""

    ambient: float = 0.3
    diffuse: float = 0.75
    specular: float = 0.3
    exponent: float = 48.0


DEFAULT_LOOK = HairLook()


def light_and_eye(right: NDArray, up: NDArray, forward: NDArray) -> tuple[NDArray, NDArray]:
    """World-space unit L (the camera's key light) and E (toward the eye) from the view basis."""
    r, u, f = (np.asarray(a, np.float64) for a in (right, up, forward))
    lx, ly, lz = LIGHT_IN_VIEW
    light = lx * r + ly * u - lz * f
    return light / np.linalg.norm(light), -f / np.linalg.norm(f)


_SQUARINGS = 6  # whole exponents p/2 below 2**6 (the default look's 24) by a fixed run of squarings


@njit(cache=True, nogil=True, inline="always")
def _power(x, e, bits, whole):
    """x**e for x in [0, 1]: with ``whole`` from ``bits``, e's binary digits as 0.0 or 1.0, by a
    fixed run of squarings, which vectorises (pow() did not, and was half the shading's time)."""
    if not whole:
        return x**e
    r = 1.0 + bits[0] * (x - 1.0)
    x *= x
    r *= 1.0 + bits[1] * (x - 1.0)
    x *= x
    r *= 1.0 + bits[2] * (x - 1.0)
    x *= x
    r *= 1.0 + bits[3] * (x - 1.0)
    x *= x
    r *= 1.0 + bits[4] * (x - 1.0)
    x *= x
    return r * (1.0 + bits[5] * (x - 1.0))


@njit(cache=True, nogil=True, inline="always")
def _vertex(pf, bf, of, v, lo, hi, light, half, ambient, kd, ks, e, bits, whole):
    """Vertex v's shade, its tangent from the points lo and hi (flat arrays; unsigned indices, so
    numba adds no wrap-around for negative ones, which had kept the loop from vectorising)."""
    one, two = np.uint64(1), np.uint64(2)
    u, a, b = np.uint64(3) * v, np.uint64(3) * lo, np.uint64(3) * hi
    tx = np.float64(pf[b]) - np.float64(pf[a])
    ty = np.float64(pf[b + one]) - np.float64(pf[a + one])
    tz = np.float64(pf[b + two]) - np.float64(pf[a + two])
    n = np.sqrt(tx * tx + ty * ty + tz * tz)
    inv = 1.0 / n if n > 0.0 else 0.0
    tx, ty, tz = tx * inv, ty * inv, tz * inv
    tl = tx * light[0] + ty * light[1] + tz * light[2]
    th = tx * half[0] + ty * half[1] + tz * half[2]
    k = ambient + kd * np.sqrt(max(1.0 - tl * tl, 0.0))
    s = ks * _power(max(1.0 - th * th, 0.0), e, bits, whole)
    of[u] = min(max(np.float64(bf[u]) * k + s, 0.0), 1.0)
    of[u + one] = min(max(np.float64(bf[u + one]) * k + s, 0.0), 1.0)
    of[u + two] = min(max(np.float64(bf[u + two]) * k + s, 0.0), 1.0)


@njit(cache=True, nogil=True, inline="always")
def _strand(pf, bf, of, a, b, light, half, ambient, kd, ks, e, bits, whole):
    """The vertices a … b − 1 of one strand: central differences inside, one-sided at the ends."""
    one = np.uint64(1)
    if b == a:
        return
    for v in range(a + one, b - one):
        _vertex(pf, bf, of, v, v - one, v + one, light, half, ambient, kd, ks, e, bits, whole)
    _vertex(pf, bf, of, a, a, min(a + one, b - one), light, half, ambient, kd, ks, e, bits, whole)
    if b - a >= 2:
        _vertex(pf, bf, of, b - one, b - one - one, b - one, light, half, ambient, kd, ks, e, bits, whole)


# fastmath (1.4x here): a strand's vertices are shaded by one thread in one loop, so each
# vertex gets the same instructions whatever the thread count (the bytes stay deterministic);
# the tests hold the kernels to their numpy twin. Two kernels, so that the common one's loop has
# no pow() call in it (a branch between the two, even on an argument, kept it scalar).
@twin_njit(nogil=True, parallel=True, fastmath=True)
def _shade_kernel(points, offsets, base, light, half, ambient, kd, ks, bits, out):
    """Shades for a whole exponent e < 2**_SQUARINGS given by its binary digits ``bits``."""
    pf, bf, of = points.reshape(-1), base.reshape(-1), out.reshape(-1)
    for s in prange(offsets.size - 1):
        a, b = np.uint64(offsets[s]), np.uint64(offsets[s + 1])
        _strand(pf, bf, of, a, b, light, half, ambient, kd, ks, 0.0, bits, True)


@njit(cache=True, nogil=True, parallel=True, fastmath=True)
def _shade_kernel_pow(points, offsets, base, light, half, ambient, kd, ks, e, out):
    """Shades for any exponent e, by pow()."""
    pf, bf, of = points.reshape(-1), base.reshape(-1), out.reshape(-1)
    no_bits = np.zeros(0)
    for s in prange(offsets.size - 1):
        a, b = np.uint64(offsets[s]), np.uint64(offsets[s + 1])
        _strand(pf, bf, of, a, b, light, half, ambient, kd, ks, e, no_bits, False)


def _half(light: NDArray, eye: NDArray) -> NDArray[np.float64]:
    h = np.asarray(light, np.float64) + np.asarray(eye, np.float64)
    n = np.linalg.norm(h)
    return h / n if n > 0 else np.asarray(light, np.float64)


def shade(
    points: NDArray,
    offsets: NDArray,
    base: NDArray,
    light: NDArray,
    eye: NDArray,
    look: HairLook = DEFAULT_LOOK,
    out: NDArray[np.float32] | None = None,
) -> NDArray[np.float32]:
    """``(V, 3)`` float32 shaded colours of strands ``points`` (``offsets``: the topology's
    S + 1 strand starts) with per-vertex ``base`` colours, unit ``light`` and ``eye`` directions."""
    if out is None or out.shape != (len(points), 3):
        out = np.empty((len(points), 3), np.float32)
    points, base = readonly(points), np.ascontiguousarray(base)
    offsets = readonly(np.asarray(offsets, np.int64))
    light, half = np.asarray(light, np.float64), _half(light, eye)
    terms = (float(look.ambient), float(look.diffuse), float(look.specular))
    e = 0.5 * float(look.exponent)
    if e == np.floor(e) and 0.0 <= e < 2.0**_SQUARINGS:
        bits = np.array([float((int(e) >> k) & 1) for k in range(_SQUARINGS)])
        _shade_kernel(points, offsets, base, light, half, *terms, bits, out)
    else:
        _shade_kernel_pow(points, offsets, base, light, half, *terms, e, out)
    return out


def shade_reference(
    points: NDArray,
    offsets: NDArray,
    base: NDArray,
    light: NDArray,
    eye: NDArray,
    look: HairLook = DEFAULT_LOOK,
) -> NDArray[np.float32]:
    """Numpy twin of :func:`shade`: tangents by whole-array differences within each strand."""
    p = np.asarray(points, np.float64)
    v = np.arange(len(p))
    strand = np.searchsorted(offsets, v, side="right") - 1
    lo = np.where(v > offsets[strand], v - 1, v)
    hi = np.where(v < offsets[strand + 1] - 1, v + 1, v)
    t = p[hi] - p[lo]
    n = np.linalg.norm(t, axis=1, keepdims=True)
    t = np.where(n > 0, t / np.where(n > 0, n, 1.0), t)
    tl = t @ np.asarray(light, np.float64)
    th = t @ _half(light, eye)
    diffuse = np.sqrt(np.maximum(1.0 - tl * tl, 0.0))
    spec = np.maximum(1.0 - th * th, 0.0) ** (0.5 * look.exponent)
    c = (
        np.asarray(base, np.float64) * (look.ambient + look.diffuse * diffuse)[:, None]
        + look.specular * spec[:, None]
    )
    return np.clip(c, 0.0, 1.0).astype(np.float32)
