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


@njit(cache=True, nogil=True, inline="always")
def _power(x, e, whole):
    """x**e for x in [0, 1]; by squarings when e is a whole number ``whole`` ≥ 0 (the default
    highlight's 24: a pow() call per vertex was half the shading's time), else pow()."""
    if whole < 0:
        return x**e
    r = 1.0
    while whole > 0:
        if whole & 1:
            r *= x
        x *= x
        whole >>= 1
    return r


# fastmath (1.4x here): a strand's vertices are shaded by one thread in one loop, so each
# vertex gets the same instructions whatever the thread count (the bytes stay deterministic);
# the tests hold the kernel to its numpy twin.
@njit(cache=True, nogil=True, parallel=True, fastmath=True)
def _shade_kernel(points, offsets, base, light, half, ambient, kd, ks, exponent, out):
    e = 0.5 * exponent
    whole = int(e) if e == np.floor(e) and 0.0 <= e <= 1024.0 else -1
    for s in prange(offsets.size - 1):
        a, b = offsets[s], offsets[s + 1]
        for v in range(a, b):
            lo = v - 1 if v > a else v
            hi = v + 1 if v < b - 1 else v
            tx = np.float64(points[hi, 0]) - np.float64(points[lo, 0])
            ty = np.float64(points[hi, 1]) - np.float64(points[lo, 1])
            tz = np.float64(points[hi, 2]) - np.float64(points[lo, 2])
            n = np.sqrt(tx * tx + ty * ty + tz * tz)
            if n > 0.0:
                inv = 1.0 / n
                tx, ty, tz = tx * inv, ty * inv, tz * inv
            tl = tx * light[0] + ty * light[1] + tz * light[2]
            th = tx * half[0] + ty * half[1] + tz * half[2]
            diffuse = np.sqrt(max(1.0 - tl * tl, 0.0))
            spec = _power(max(1.0 - th * th, 0.0), e, whole)
            k = ambient + kd * diffuse
            for c in range(3):
                out[v, c] = min(max(np.float64(base[v, c]) * k + ks * spec, 0.0), 1.0)


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
    _shade_kernel(
        points, np.ascontiguousarray(offsets, np.int64), base,
        np.asarray(light, np.float64), _half(light, eye), float(look.ambient), float(look.diffuse),
        float(look.specular), float(look.exponent), out,
    )  # fmt: skip
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
