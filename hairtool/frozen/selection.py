"""Selecting and hiding strands, as a Blender artist does with hair curves.

Each strand of the stroked state is selected or not, and shown or hidden (two ``(S,)`` bool
arrays the pipeline keeps beside the mask). A new groom has every strand selected and none
hidden, as a Blender curves object without a ``.selection`` attribute counts as all selected.

The selection is a bool per strand, not Blender sculpt mode's soft float: the pipeline locks
strands for a brush sample by one bool path (the mask, front-facing, and now "only the
selection" and hidden), every brush honours it unchanged, and box select, select all and the
selection brush (touched or not, as the mask brush) only ever make whole values.

The steps that change them (:class:`SelectionSample`) are part of the stroke log like brush
samples, so undo, projects and a replayed log see the same selection at every stroke:

- ``all``: every shown strand selected (hidden ones stay unselected); ``none``: none;
  ``invert``: the shown strands flip.
- ``box``: the shown strands with a vertex inside a screen rectangle (``rect`` x0, y0, x1, y1
  in normalised device coordinates, −1 … 1, y up) of a camera (``matrix``: its 4×4
  world-to-clip matrix, row-major); ``mode`` "set" (only those), "add" or "subtract"; with a
  ``view``, only the strands facing that camera (the brushes' front faces only): with
  ``visible`` and a head mesh, those with a vertex inside the rectangle that the head does not
  hide from the camera (:mod:`~hairtool.frozen.brushes.sight`, the studio's rule), else those
  whose root normal faces it (the rule of every log written before ``visible``, so its
  default, and the rule without a head mesh). By sight, the rays go against ``view`` (one
  direction for the whole box, as a camera without perspective sees), or with ``to_eye`` from
  each vertex to the eye of ``matrix`` (:func:`matrix_eye`): a perspective camera sees a wide
  box's corners along their own lines of sight, not the view's centre line.
- ``hide_selected``: the selected strands hidden (and deselected, as Blender hides);
  ``hide_unselected``: the unselected shown strands hidden; ``reveal``: every hidden strand
  shown again, selected.

Hidden strands are locked for every brush, whatever "only the selection" says. The selection
brush itself (``BrushSample`` of brush "select") is :func:`~hairtool.frozen.brushes.paint_mask`
with hidden strands skipped: > 0 selects what it touches, < 0 deselects.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from hairtool.errors import ParameterError
from hairtool.frozen.brushes.sample import check_flag
from hairtool.frozen.brushes.sight import FaceGrid, hidden_points
from hairtool.groom import Groom

OPS = ("all", "none", "invert", "box", "hide_selected", "hide_unselected", "reveal")
BOX_MODES = ("set", "add", "subtract")


class SelectionSample(NamedTuple):
    """One selection step (module docstring); ``matrix`` (16 floats), ``rect`` and ``mode``
    only for ``box``; ``view`` and ``visible`` as a brush sample's (None: every strand; with
    ``visible`` front faces only by sight, else by root normal); ``to_eye``: by sight, each
    ray goes to the eye of a perspective ``matrix`` (else along ``view``, as before it)."""

    op: str
    matrix: tuple[float, ...] | None = None
    rect: tuple[float, float, float, float] | None = None
    mode: str = "set"
    view: tuple[float, float, float] | None = None
    visible: bool = False
    to_eye: bool = False


def check_selection(sample: SelectionSample) -> SelectionSample:
    """The sample, or a ParameterError naming its bad field.

    Parameters
    ----------
    sample : SelectionSample
        A selection step.

    Returns
    -------
    SelectionSample
        The same sample.
    """
    if sample.op not in OPS:
        raise ParameterError("selection", sample.op, "one of " + ", ".join(OPS))
    if sample.op != "box":
        return sample
    check_flag("visible", sample.visible)
    check_flag("to_eye", sample.to_eye)
    if sample.mode not in BOX_MODES:
        raise ParameterError("mode", sample.mode, " or ".join(BOX_MODES))
    m = np.asarray(sample.matrix if sample.matrix is not None else (), dtype=np.float64)
    if m.shape != (16,) or not np.all(np.isfinite(m)):
        raise ParameterError("matrix", "box", "16 finite numbers (a 4×4 world-to-clip matrix, row-major)")
    r = np.asarray(sample.rect if sample.rect is not None else (), dtype=np.float64)
    if r.shape != (4,) or not np.all(np.isfinite(r)):
        raise ParameterError("rect", sample.rect, "four finite numbers [x0, y0, x1, y1]")
    return sample


def matrix_eye(matrix) -> np.ndarray | None:
    """``(3,)`` the eye of a perspective camera's world-to-clip ``matrix`` (16 numbers,
    row-major): the point its x, y and w rows all send to 0. None for a camera without
    perspective (w does not depend on the point: its eye is at infinity) or a degenerate one.
    Plain 3 × 3 determinants (Cramer's rule), the same bits on every machine."""
    m = np.asarray(matrix, np.float64).reshape(4, 4)[[0, 1, 3]]
    if not m[2, :3].any():
        return None
    a, b = m[:, :3], -m[:, 3]

    def det(c0: np.ndarray, c1: np.ndarray, c2: np.ndarray) -> float:
        return float(
            c0[0] * (c1[1] * c2[2] - c1[2] * c2[1])
            - c1[0] * (c0[1] * c2[2] - c0[2] * c2[1])
            + c2[0] * (c0[1] * c1[2] - c0[2] * c1[1])
        )

    d = det(a[:, 0], a[:, 1], a[:, 2])
    if d == 0.0 or not np.isfinite(d):
        return None
    eye = np.array([det(b, a[:, 1], a[:, 2]), det(a[:, 0], b, a[:, 2]), det(a[:, 0], a[:, 1], b)]) / d
    return eye if np.all(np.isfinite(eye)) else None


def in_box(
    groom: Groom, matrix, rect, view=None, grid: FaceGrid | None = None, to_eye: bool = False
) -> np.ndarray:
    """``(S,)`` the strands with a vertex in front of the camera whose projection lies inside
    ``rect`` (either corner order); with ``view`` and ``grid``, a vertex there the head does not
    hide from a camera looking along ``view``, or with ``to_eye`` from the eye of a perspective
    ``matrix`` (only the vertices inside are traced).

    Parameters
    ----------
    groom : Groom
        The strands.
    matrix : array_like
        16 numbers: the camera's projection × view, row-major.
    rect : array_like
        ``(x0, y0, x1, y1)`` in normalised device coordinates.
    view : array_like, optional
        ``(3,)`` the camera's viewing direction (with ``grid``: front faces only by sight).
    grid : FaceGrid, optional
        The head's faces.
    to_eye : bool, default False
        By sight, each ray goes from its vertex to the eye of ``matrix`` where it has one
        (perspective; :func:`matrix_eye`), else against ``view``.

    Returns
    -------
    ndarray
        ``(S,)`` bool.
    """
    m = np.asarray(matrix, np.float64).reshape(4, 4)
    p = groom.points.astype(np.float64)
    with np.errstate(all="ignore"):  # a huge camera overflows: inf and NaN fall outside the box
        clip = p @ m[:3, :3].T + m[:3, 3]
        w = p @ m[3, :3] + m[3, 3]
        x0, y0, x1, y1 = (float(v) for v in rect)
        ok = w > 1e-12
        safe = np.where(ok, w, 1.0)
        x, y = clip[:, 0] / safe, clip[:, 1] / safe
    inside = ok & (x >= min(x0, x1)) & (x <= max(x0, x1)) & (y >= min(y0, y1)) & (y <= max(y0, y1))
    if view is not None and grid is not None:
        at = np.flatnonzero(inside)
        eye = matrix_eye(m) if to_eye else None
        inside[at[hidden_points(p[at], view, grid, eye)]] = False
    if groom.strand_count == 0:
        return np.zeros(0, bool)
    return np.maximum.reduceat(inside, groom.offsets[:-1]).astype(bool)


def apply_selection(
    groom: Groom,
    sample: SelectionSample,
    selected: np.ndarray,
    hidden: np.ndarray,
    away: np.ndarray | None = None,
    grid: FaceGrid | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """``(selected, hidden)`` after one step (new arrays); ``away``: the strands facing away
    from the sample's camera (a box leaves them as they are); ``grid``: the head, which a box
    that says ``visible`` judges by sight instead (``away`` then unused).

    Parameters
    ----------
    groom : Groom
        The strands.
    sample : SelectionSample
        The step.
    selected, hidden : ndarray
        ``(S,)`` bool, before the step.
    away : ndarray, optional
        ``(S,)`` bool, the strands facing away.
    grid : FaceGrid, optional
        The head's faces.

    Returns
    -------
    tuple of (ndarray, ndarray)
        ``selected`` and ``hidden`` after it.
    """
    check_selection(sample)
    sel, hid = np.array(selected, dtype=bool), np.array(hidden, dtype=bool)
    op = sample.op
    if op == "all":
        sel = ~hid
    elif op == "none":
        sel[:] = False
    elif op == "invert":
        sel = ~sel & ~hid
    elif op == "box":
        if sample.visible and sample.view is not None and grid is not None:
            touched = in_box(groom, sample.matrix, sample.rect, sample.view, grid, sample.to_eye) & ~hid
            away = None
        else:
            touched = in_box(groom, sample.matrix, sample.rect) & ~hid
        if away is not None:
            touched &= ~np.asarray(away, dtype=bool)
        if sample.mode == "set":
            sel = touched
        elif sample.mode == "add":
            sel |= touched
        else:
            sel &= ~touched
    elif op == "hide_selected":
        hid |= sel
        sel[:] = False
    elif op == "hide_unselected":
        hid |= ~sel
    else:  # reveal
        sel |= hid
        hid[:] = False
    return sel, hid
