"""Colour ramps and palettes for strands (RGB in [0, 1], float32).

A ramp is a list of evenly spaced stops, interpolated linearly in RGB. "root-tip" is the default
strand colouring (dark brown roots, light blonde tips); "red-blue" is the frozen-hair paper's
Fig. 1 colouring (red root, blue tip); "heat" is for displacement magnitudes.
"""

from __future__ import annotations

import colorsys

import numpy as np
from numba import njit
from numpy.typing import ArrayLike, NDArray

from hairtool.errors import ParameterError
from hairtool.kernel_arrays import readonly

F32 = NDArray[np.float32]


def _hex(*codes: str) -> F32:
    return np.array([[int(c[i : i + 2], 16) / 255.0 for i in (1, 3, 5)] for c in codes], dtype=np.float32)


RAMPS: dict[str, F32] = {
    "root-tip": _hex("#2e1a0e", "#6b4423", "#b08850", "#f3e3a8"),
    "viridis": _hex("#440154", "#3b528b", "#21918c", "#5ec962", "#fde725"),
    "heat": _hex("#000000", "#8b0000", "#ff4500", "#ffd700", "#ffffff"),
    "grey": _hex("#404040", "#d0d0d0"),
    "red-blue": _hex("#d62728", "#9467bd", "#1f5fd6"),
}
DEFAULT_RAMP = "root-tip"

# Ten well-separated hues for clump ids, selections and other categories.
CATEGORICAL: F32 = _hex(
    "#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd",
    "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf",
)  # fmt: skip


def ramp_stops(name: str) -> F32:
    try:
        return RAMPS[name]
    except KeyError:
        raise ParameterError("ramp", name, f"one of {', '.join(RAMPS)}") from None


def ramp_colors(values: ArrayLike, name: str = DEFAULT_RAMP) -> F32:
    """``(n,)`` values in [0, 1] (clipped) → ``(n, 3)`` float32 colours of the ramp."""
    stops = ramp_stops(name)
    v = np.asarray(values, dtype=np.float64).reshape(-1)
    if not np.all(np.isfinite(v)):
        raise ParameterError("values", "non-finite", "finite numbers in [0, 1]")
    x = np.linspace(0.0, 1.0, len(stops))
    v = np.clip(v, 0.0, 1.0)
    return np.column_stack([np.interp(v, x, stops[:, c]) for c in range(3)]).astype(np.float32)


def ramp_texture(name: str, width: int = 256) -> F32:
    """``(width, 3)`` samples of the ramp, for a 1-D lookup texture."""
    return ramp_colors(np.linspace(0.0, 1.0, width), name)


@njit(cache=True, nogil=True)
def _sample_kernel(tex, t, out):  # pragma: no cover - compiled
    """:func:`sample_linear_reference`'s arithmetic per coordinate, in the same order (float64,
    then rounded to float32 once): the same bytes."""
    w = tex.shape[0]
    for k in range(t.shape[0]):  # (on one thread: memory-bound, 5-8 ms a million)
        x = t[k]
        if x == x:  # NaN stays NaN, as np.clip leaves it
            x = min(max(x, 0.0), 1.0)
        x = x * w - 0.5
        i = np.floor(x)
        f = x - i
        i0 = min(max(int(i), 0), w - 1)
        i1 = min(max(int(i) + 1, 0), w - 1)
        for c in range(3):
            out[k, c] = np.float32(tex[i0, c] * (1.0 - f) + tex[i1, c] * f)


def sample_linear(texels: ArrayLike, t: ArrayLike) -> F32:
    """``(n, 3)`` colours of a ``(width, 3)`` 1-D texture at coordinates ``t`` (clamped to [0, 1]),
    as GL samples it with LINEAR filtering and CLAMP_TO_EDGE: between texel centres (i + ½)/width.
    Compiled: a million render-hair vertices took 0.23 s in numpy at every colouring."""
    tex = readonly(np.asarray(texels, dtype=np.float64))
    if tex.ndim != 2 or tex.shape[0] < 1 or tex.shape[1] != 3:
        raise ParameterError("texels", tex.shape, "(width, 3) colours, width at least 1")
    x = readonly(np.asarray(t, dtype=np.float64).reshape(-1))
    out = np.empty((x.size, 3), np.float32)
    _sample_kernel(tex, x, out)
    return out


def sample_linear_reference(texels: ArrayLike, t: ArrayLike) -> F32:
    """Numpy twin of :func:`sample_linear`."""
    tex = np.asarray(texels, dtype=np.float64)
    x = np.clip(np.asarray(t, dtype=np.float64).reshape(-1), 0.0, 1.0) * len(tex) - 0.5
    i = np.floor(x)
    f = (x - i)[:, None]
    i0 = np.clip(i.astype(np.int64), 0, len(tex) - 1)
    i1 = np.clip(i.astype(np.int64) + 1, 0, len(tex) - 1)
    return (tex[i0] * (1.0 - f) + tex[i1] * f).astype(np.float32)


def per_strand_random_colors(strand_count: int, seed: int = 0) -> F32:
    """``(S, 3)`` bright colours with random hues, reproducible from ``seed``."""
    if int(strand_count) != strand_count or strand_count < 0:
        raise ParameterError("strand_count", strand_count, "a whole number >= 0")
    rng = np.random.default_rng(seed)
    hue = rng.uniform(0.0, 1.0, int(strand_count))
    sat = rng.uniform(0.55, 0.85, int(strand_count))
    val = rng.uniform(0.75, 1.0, int(strand_count))
    rgb = [colorsys.hsv_to_rgb(h, s, v) for h, s, v in zip(hue, sat, val, strict=True)]
    return np.array(rgb, dtype=np.float32).reshape(-1, 3)


def categorical_colors(ids: ArrayLike) -> F32:
    """``(n,)`` integer ids → ``(n, 3)`` colours, cycling through ten hues; ids < 0 are grey."""
    i = np.asarray(ids).reshape(-1)
    if i.size and not np.issubdtype(i.dtype, np.integer):
        raise ParameterError("ids", i.dtype, "integer ids")
    out = CATEGORICAL[np.mod(i, len(CATEGORICAL))].copy()
    out[i < 0] = 0.5
    return out


def strand_to_vertex_colors(strand_colors: ArrayLike, topology) -> F32:
    """Repeat ``(S, 3)`` per-strand colours over each strand's vertices → ``(V, 3)``."""
    c = np.asarray(strand_colors, dtype=np.float32)
    if c.shape != (topology.strand_count, 3):
        raise ParameterError("strand_colors", c.shape, f"shape ({topology.strand_count}, 3)")
    return c[topology.strand_index]
