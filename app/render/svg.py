"""Vector export: each strand one ``<polyline>`` in pixel coordinates of :meth:`Camera.project`.

Colour along a strand is a ``linearGradient`` in user space from the root's pixel to the tip's,
with one stop per vertex at its position projected on that root→tip axis (clamped to be
non-decreasing): exact for straight strands, a close match for the bent ones of 2-D drawings.
Strands with one colour get a plain stroke. 3-D grooms are drawn back to front (painter's order
by mean depth); every polyline carries ``data-strand`` with its index in the groom.
"""

from __future__ import annotations

import io
import os

import numpy as np
from numpy.typing import ArrayLike

from app.render.camera import Camera
from app.render.ramps import DEFAULT_RAMP, ramp_colors
from hairtool.errors import FormatError, ParameterError
from hairtool.groom import Groom
from hairtool.io.atomic import atomic_open

STOP_TOLERANCE = 1.0 / 255.0  # colours closer than this count as one colour


def _hex(rgb: np.ndarray) -> str:
    r, g, b = (round(float(np.clip(c, 0.0, 1.0)) * 255) for c in rgb)
    return f"#{r:02x}{g:02x}{b:02x}"


def _num(x: float) -> str:
    return f"{x:.2f}".rstrip("0").rstrip(".") if np.isfinite(x) else "0"


def _gradient_offsets(px: np.ndarray) -> np.ndarray | None:
    """Each vertex's position along the root→tip pixel axis in [0, 1]; None when root ≈ tip."""
    axis = px[-1] - px[0]
    length2 = float(axis @ axis)
    if length2 < 1e-6:
        return None
    u = np.clip((px - px[0]) @ axis / length2, 0.0, 1.0)
    return np.maximum.accumulate(u)


def groom_svg(
    groom: Groom,
    camera: Camera,
    size: tuple[int, int],
    *,
    ramp: str = DEFAULT_RAMP,
    colors: ArrayLike | None = None,
    line_width: float = 2.0,
    background: tuple[float, ...] | None = None,
) -> str:
    """SVG text of the groom as seen by ``camera`` in a ``size`` = (width, height) pixel picture."""
    w, h = (int(v) for v in size)
    if w <= 0 or h <= 0:
        raise ParameterError("size", size, "positive (width, height) in pixels")
    if not np.isfinite(line_width) or line_width <= 0:
        raise ParameterError("line_width", line_width, "a positive width in pixels")
    top = groom.topology
    if colors is None:
        colors = groom.colors
    if colors is None:
        vcol = ramp_colors(top.vertex_param, ramp)
    else:
        vcol = np.asarray(colors, dtype=np.float32)
        if vcol.shape != (top.vertex_count, 3):
            raise ParameterError("colors", vcol.shape, f"shape ({top.vertex_count}, 3)")
    px = camera.project(groom.points, w, h)
    in_front = camera.depth(groom.points) > 0
    off = top.offsets
    order = np.arange(top.strand_count)
    if not groom.is_planar:
        mean_depth = np.add.reduceat(camera.depth(groom.points), off[:-1]) / top.counts
        order = np.argsort(-mean_depth, kind="stable")

    out = io.StringIO()
    out.write(f'<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}">\n')
    if background is not None:
        bg = np.asarray(background, dtype=np.float64)
        opacity = f' fill-opacity="{_num(bg[3])}"' if len(bg) > 3 and bg[3] < 1 else ""
        out.write(f'<rect width="{w}" height="{h}" fill="{_hex(bg[:3])}"{opacity}/>\n')
    # Format every vertex once (the per-strand loop only joins slices): big grooms stay fast.
    xs = [f"{x:.2f}" for x in np.nan_to_num(px[:, 0]).tolist()]
    ys = [f"{y:.2f}" for y in np.nan_to_num(px[:, 1]).tolist()]
    coords = [f"{x},{y}" for x, y in zip(xs, ys, strict=True)]
    rgb = np.round(np.clip(vcol, 0.0, 1.0) * 255).astype(np.int64)
    hexes = [f"#{r:02x}{g:02x}{b:02x}" for r, g, b in rgb.tolist()]
    uniform = np.abs(np.diff(vcol, axis=0)).max(axis=1) <= STOP_TOLERANCE  # (V−1,) same as the next
    defs = io.StringIO()
    body = io.StringIO()
    for s in order.tolist():
        a, b = int(off[s]), int(off[s + 1])
        if not in_front[a:b].all():
            continue  # a strand through the eye plane has no picture in this view
        p = px[a:b]
        offsets = _gradient_offsets(p)
        if offsets is None or uniform[a : b - 1].all():
            stroke = _hex(vcol[a:b].mean(axis=0))
        else:
            defs.write(
                f'<linearGradient id="g{s}" gradientUnits="userSpaceOnUse" '
                f'x1="{xs[a]}" y1="{ys[a]}" x2="{xs[b - 1]}" y2="{ys[b - 1]}">'
            )
            defs.write(
                "".join(
                    f'<stop offset="{u:.4f}" stop-color="{c}"/>'
                    for u, c in zip(offsets.tolist(), hexes[a:b], strict=True)
                )
            )
            defs.write("</linearGradient>\n")
            stroke = f"url(#g{s})"
        body.write(f'<polyline data-strand="{s}" points="{" ".join(coords[a:b])}" stroke="{stroke}"/>\n')
    if defs.tell():
        out.write(f"<defs>\n{defs.getvalue()}</defs>\n")
    out.write(
        f'<g fill="none" stroke-width="{_num(float(line_width))}" '
        f'stroke-linecap="round" stroke-linejoin="round">\n'
    )
    out.write(body.getvalue())
    out.write("</g>\n</svg>\n")
    return out.getvalue()


def save_svg(path: str | os.PathLike[str], groom: Groom, camera: Camera, size: tuple[int, int], **kw) -> None:
    """Write :func:`groom_svg` to ``path`` atomically (keywords as for :func:`groom_svg`)."""
    text = groom_svg(groom, camera, size, **kw)
    try:
        with atomic_open(path, "w", encoding="utf-8") as f:
            f.write(text)
    except OSError as e:
        raise FormatError(path, f"cannot write: {e}") from None
