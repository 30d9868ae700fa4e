"""The graph editor: the selected joint's rotation channels as curves over the frames.

For a motion capture (:mod:`app.ui.capture_edit`) the selected joint's rotation angles are drawn
three ways: the capture as it was (faint), the edited capture (the key curve plus the captured
residuals, what is exported) and the key curve alone through the keys; keys are points with
their Hermite handles (the slopes the key curve leaves and enters each key with: the captured
samples' tangents, or the fitted ones of "hermite-fit"; linear keys have none). Dragging a key
moves it in value — one :class:`hairtool.mocap.pose_edit.ChannelEdit`, carried to the frames
around the key with the residuals kept, exactly as an IK drag is, one undo step — and dragging
a handle end sets the slope the key curve passes the key with (a
:class:`~hairtool.mocap.pose_edit.TangentEdit`, both handles aligned on it); the viewport, the
timeline's errors and the curves follow. Dragged sideways a key moves in time, snapped to a
whole frame strictly between its neighbours (a :class:`~hairtool.mocap.pose_edit.RetimeEdit`).
With "Per-channel keys" each rotation channel shows its own keys (seed 003), edited the same way
on that channel alone, and a joint dragged in the viewport keys the channels it turns on their own
keys (:meth:`app.ui.capture_edit.CaptureEditor.commit_pose`). On a hair animation the curves
are a strand vertex's x, y, z (editable the same three ways, :mod:`app.ui.hair_channels`) and
the strand's feature channels, read-only. Navigation as in Blender's Graph Editor: the wheel
zooms about the cursor, middle-drag pans, Ctrl+middle-drag zooms each axis, Home frames every
curve.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from PySide6.QtCore import QPointF, QRectF, Qt, Signal
from PySide6.QtGui import QColor, QKeyEvent, QMouseEvent, QPainter, QPen, QWheelEvent
from PySide6.QtWidgets import (
    QCheckBox,
    QDockWidget,
    QHBoxLayout,
    QLabel,
    QSizePolicy,
    QSpinBox,
    QToolTip,
    QVBoxLayout,
    QWidget,
)

from app.ui import view_range
from app.ui.capture_edit import CaptureEditor
from app.ui.hair_channels import READ_ONLY, HairChannels
from app.ui.timeline_plots import polygon
from hairtool.mocap import ik
from hairtool.mocap.channel_edit import ChannelRetimeEdit
from hairtool.mocap.pose_edit import ChannelEdit, Edit, RetimeEdit, TangentEdit

if TYPE_CHECKING:
    from app.ui.host import StudioHost

AXIS_COLOURS = {"X": QColor(230, 80, 80), "Y": QColor(110, 200, 90), "Z": QColor(80, 140, 240)}
PICK_PX = 8.0
MARGIN = 24.0  # pixels around the plot
ZOOM_STEP = 1.15  # per wheel notch
EMPTY = (
    "Select a joint of a capture (click its dot at a key frame), or open a hair animation, "
    "to see its channels"
)


@dataclass
class Curve:
    """One channel: its name, the capture (original), the edited capture, the key curve alone,
    the key frames with their values and the handle slopes (value per frame) into and out of
    each key (None: linear keys, no handles)."""

    name: str
    colour: QColor
    original: np.ndarray
    result: np.ndarray
    key_curve: np.ndarray
    keys: np.ndarray
    values: np.ndarray
    slope_in: np.ndarray | None
    slope_out: np.ndarray | None
    editable: bool = True  # False: a view (a hair strand's feature channels), keys not dragged


def hair_curves(hair: HairChannels) -> list[Curve]:
    """The chosen strand vertex's x, y, z of a hair animation (none without one), then, when
    shown, the strand's feature channels at the matching sample (read-only, lighter)."""
    if not hair.active:
        return []
    out = [Curve(n, AXIS_COLOURS[n.upper()], *rest) for n, *rest in hair.channels()]
    if hair.features:
        for n, *rest in hair.feature_channels():
            colour = QColor(AXIS_COLOURS[n[-1].upper()]).lighter(160)
            out.append(Curve(n, colour, *rest, editable=False))
    return out


def capture_curves(capture: CaptureEditor) -> list[Curve]:
    """The selected joint's rotation channels of the capture (none when nothing is selected)."""
    if not capture.attached or capture.editor is None or not capture.joint:
        return []
    m, editor = capture.original, capture.editor
    j = m.joint_names.index(capture.joint)
    cols, order = ik.rotation_columns(m, j)
    if not cols:
        return []
    result = capture.motion().values[:, cols]
    key_curve = editor.key_curve(j, result)
    keys = editor.keys
    slopes = editor.key_slopes(j)
    slope_in, slope_out = (None, None) if slopes is None else slopes
    out = []
    for i, c in enumerate(cols):
        name = m.channels[j][c - int(m._starts[j])]
        out.append(
            Curve(
                name,
                AXIS_COLOURS.get(order[i], QColor(200, 200, 200)),
                m.values[:, c],
                result[:, i],
                key_curve[:, i],
                keys,
                key_curve[keys, i],
                None if slope_in is None else slope_in[:, i],
                None if slope_out is None else slope_out[:, i],
            )
        )
    return out


def channel_curves(capture: CaptureEditor) -> list[Curve]:
    """The selected joint's rotation channels with seed 003's per-channel keys: each channel
    keyed on its own (at the timeline's price per key, on the capture as captured, angles
    unwrapped), with its own key points, key curve and handles; their edits lie over the pose
    keys' (:meth:`CaptureEditor.channel_layer`)."""
    if not capture.attached or capture.editor is None or not capture.joint:
        return []
    m = capture.original
    j = m.joint_names.index(capture.joint)
    cols, order = ik.rotation_columns(m, j)
    if not cols:
        return []
    capture.column_keys(cols)
    layer = capture.channel_layer()
    result = layer.motion().values
    out = []
    for i, c in enumerate(cols):
        keys = layer.keys(c)
        curve = layer.key_curve(c)
        slopes = layer.key_slopes(c)
        out.append(
            Curve(
                m.channels[j][c - int(m._starts[j])],
                AXIS_COLOURS.get(order[i], QColor(200, 200, 200)),
                m.values[:, c],
                result[:, c],
                curve,
                keys,
                curve[keys],
                None if slopes is None else slopes[0],
                None if slopes is None else slopes[1],
            )
        )
    return out


class GraphView(QWidget):
    """The plot: curves, keys and handles; key drags, zoom and pan (module docstring)."""

    view_changed = Signal()

    def __init__(self, capture: CaptureEditor, hair: HairChannels, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.capture, self.hair = capture, hair
        self.curves: list[Curve] = []
        self.x_range = (0.0, 1.0)
        self.y_range = (-1.0, 1.0)
        self.last_value: float | None = None  # the value the last key drag asked for
        self.last_frame = 0  # and the frame
        self._drag: tuple | None = None
        self._framed_for: tuple | None = None
        self.per_channel = False  # a capture's channels with their own keys (seed 003)
        self.refused = ""  # why the last press on a read-only curve did not drag
        self.setMinimumSize(240, 120)
        self.setFocusPolicy(Qt.FocusPolicy.StrongFocus)
        self.setMouseTracking(False)

    # -- data --------------------------------------------------------------------------------
    @property
    def on_hair(self) -> bool:
        return not self.capture.attached and self.hair.active

    def refresh(self) -> None:
        if self.on_hair:
            self.curves = hair_curves(self.hair)
        elif self.per_channel:
            self.curves = channel_curves(self.capture)
        else:
            self.curves = capture_curves(self.capture)
        if self.on_hair:
            what = ("hair", self.capture.doc.state.take, self.hair.strand, self.hair.vertex)
        else:
            what = (self.capture.doc.state.take, self.capture.joint)
        if self.curves and what != self._framed_for:
            self._framed_for = what
            self.frame_all()
        self.update()

    # -- view --------------------------------------------------------------------------------
    def _plot(self) -> QRectF:
        return QRectF(
            MARGIN * 2, MARGIN / 2, max(self.width() - MARGIN * 2.5, 1), max(self.height() - MARGIN * 1.5, 1)
        )

    def _axes(self) -> tuple[view_range.Axis, view_range.Axis]:
        r = self._plot()
        return (
            view_range.Axis(self.x_range, r.left(), r.width()),
            view_range.Axis(self.y_range, r.top(), r.height(), flip=True),
        )

    def to_px(self, frame: np.ndarray | float, value: np.ndarray | float) -> tuple:
        ax, ay = self._axes()
        return ax.to_px(frame), ay.to_px(value)

    def from_px(self, px: float, py: float) -> tuple[float, float]:
        ax, ay = self._axes()
        return ax.from_px(px), ay.from_px(py)

    def frame_all(self) -> None:
        """Home: every curve (and every frame) in view, with a little room around."""
        if not self.curves:
            n = max(self.capture.model.n_frames - 1, 1)
            self.x_range, self.y_range = (0.0, float(n)), (-1.0, 1.0)
        else:
            v = np.concatenate([np.r_[c.original, c.result, c.key_curve] for c in self.curves])
            lo, hi = float(v.min()), float(v.max())
            pad = max((hi - lo) * 0.05, 1e-3)
            self.x_range = (0.0, float(max(self.curves[0].original.size - 1, 1)))
            self.y_range = (lo - pad, hi + pad)
        self.view_changed.emit()
        self.update()

    def zoom(self, factor: float, px: float, py: float, axes: str = "xy") -> None:
        """Scale the view by ``factor`` (> 1 zooms in) about the pixel ``(px, py)``."""
        fx, fy = self.from_px(px, py)
        if "x" in axes:
            self.x_range = view_range.zoom(self.x_range, factor, fx)
        if "y" in axes:
            self.y_range = view_range.zoom(self.y_range, factor, fy)
        self.view_changed.emit()
        self.update()

    def pan(self, dx_px: float, dy_px: float) -> None:
        ax, ay = self._axes()
        self.x_range = view_range.pan(self.x_range, -dx_px * ax.per_px)
        self.y_range = view_range.pan(self.y_range, dy_px * ay.per_px)
        self.view_changed.emit()
        self.update()

    # -- picking -----------------------------------------------------------------------------
    def key_at(self, px: float, py: float) -> tuple[int, int] | None:
        """``(curve, key index)`` of the key point under the pixel, or None."""
        best, hit = PICK_PX, None
        for i, c in enumerate(self.curves):
            if not c.editable:
                continue
            kx, ky = self.to_px(c.keys, c.values)
            d = np.hypot(kx - px, ky - py)
            k = int(np.argmin(d))
            if d[k] <= best:
                best, hit = float(d[k]), (i, k)
        return hit

    def _arms(self, c: Curve, k: int) -> tuple[float, float]:
        """Frames from a key to its left and right handle ends (a third of each segment)."""
        gaps = np.diff(c.keys).astype(float)
        return (gaps[k - 1] / 3 if k > 0 else 0.0), (gaps[k] / 3 if k < gaps.size else 0.0)

    def handle_point(self, curve: int, key: int, side: int) -> tuple[float, float]:
        """The pixel position of a key's left (side −1) or right (+1) handle end."""
        c = self.curves[curve]
        left, right = self._arms(c, key)
        f, v = float(c.keys[key]), float(c.values[key])
        if side < 0:
            px, py = self.to_px(f - left, v - c.slope_in[key] * left)
        else:
            px, py = self.to_px(f + right, v + c.slope_out[key] * right)
        return float(px), float(py)

    def handle_at(self, px: float, py: float) -> tuple[int, int, int] | None:
        """``(curve, key index, side)`` of the handle end under the pixel, or None."""
        best, hit = PICK_PX, None
        for i, c in enumerate(self.curves):
            if c.slope_in is None or not c.editable:
                continue
            for k in range(c.keys.size):
                left, right = self._arms(c, k)
                for side, arm in ((-1, left), (1, right)):
                    if arm <= 0:
                        continue
                    hx, hy = self.handle_point(i, k, side)
                    d = float(np.hypot(hx - px, hy - py))
                    if d <= best:
                        best, hit = d, (i, k, side)
        return hit

    def read_only_at(self, px: float, py: float) -> int | None:
        """The read-only curve whose key point is under the pixel (a press there says why it
        does not drag), or None."""
        for i, c in enumerate(self.curves):
            if c.editable:
                continue
            kx, ky = self.to_px(c.keys, c.values)
            if np.min(np.hypot(kx - px, ky - py)) <= PICK_PX:
                return i
        return None

    def key_point(self, curve: int, key: int) -> tuple[float, float]:
        """A key's pixel position (tests press there)."""
        c = self.curves[curve]
        px, py = self.to_px(c.keys[key], c.values[key])
        return float(px), float(py)

    # -- input -------------------------------------------------------------------------------
    def wheelEvent(self, event: QWheelEvent) -> None:
        steps = event.angleDelta().y() / 120.0
        if steps:
            p = event.position()
            self.zoom(ZOOM_STEP**steps, p.x(), p.y())
        event.accept()

    def keyPressEvent(self, event: QKeyEvent) -> None:
        if event.key() == Qt.Key.Key_Home:
            self.frame_all()
            event.accept()
            return
        super().keyPressEvent(event)

    def mousePressEvent(self, event: QMouseEvent) -> None:
        p = event.position()
        if event.button() == Qt.MouseButton.MiddleButton:
            ctrl = bool(event.modifiers() & Qt.KeyboardModifier.ControlModifier)
            self._drag = ("zoom" if ctrl else "pan", p, p)
        elif event.button() == Qt.MouseButton.LeftButton:
            hit = self.key_at(p.x(), p.y())
            handle = None if hit is not None else self.handle_at(p.x(), p.y())
            if hit is not None or handle is not None:
                i, k = hit if hit is not None else handle[:2]
                c = self.curves[i]
                if self.capture.model.frame != int(c.keys[k]):
                    self.capture.model.set_frame(int(c.keys[k]))  # the key's pose in the viewport
                if hit is not None:
                    self._drag = ("key", p, hit, float(c.values[k]), int(c.keys[k]))
                else:
                    self._drag = ("handle", p, handle, 0.0)
            elif self.read_only_at(p.x(), p.y()) is not None:
                self.refused = READ_ONLY
                QToolTip.showText(self.mapToGlobal(p.toPoint()), READ_ONLY, self)
                window = self.window()
                if hasattr(window, "statusBar"):
                    window.statusBar().showMessage(READ_ONLY, 8000)
        event.accept()

    def mouseMoveEvent(self, event: QMouseEvent) -> None:
        if self._drag is None:
            return
        p = event.position()
        kind = self._drag[0]
        if kind == "pan":
            last = self._drag[2]
            self.pan(p.x() - last.x(), p.y() - last.y())
            self._drag = ("pan", self._drag[1], p)
        elif kind == "zoom":
            last = self._drag[2]
            start = self._drag[1]
            self.zoom(ZOOM_STEP ** ((p.x() - last.x()) / 20.0), start.x(), start.y(), "x")
            self.zoom(ZOOM_STEP ** ((last.y() - p.y()) / 20.0), start.x(), start.y(), "y")
            self._drag = ("zoom", start, p)
        elif kind == "key":
            _, start, (i, k), v0, f0 = self._drag
            (fx, fy), (sx, sy) = self.from_px(p.x(), p.y()), self.from_px(start.x(), start.y())
            value, to = v0 + (fy - sy), self.snap(i, k, f0 + (fx - sx))
            if event.modifiers() & Qt.KeyboardModifier.ShiftModifier:  # one axis: the longer move
                if abs(p.x() - start.x()) >= abs(p.y() - start.y()):
                    value = v0
                else:
                    to = f0
            self.last_value, self.last_frame = value, to
            if self.capture.model.frame != to:
                self.capture.model.set_frame(to)  # the key's pose at its new frame in the viewport
            if self.on_hair:
                c = self.curves[i]
                result = self.hair.preview(i, f0, value, to)
                values, keys = c.values.copy(), c.keys.copy()
                values[k], keys[k] = value, to
                self.curves[i] = Curve(
                    c.name, c.colour, c.original, result, c.key_curve, keys, values, c.slope_in, c.slope_out
                )
                self.update()
            else:
                edits = self._edits(i, f0, to, v0, value)
                self._preview(edits)
        elif kind == "handle":
            _, _, (i, k, side), _ = self._drag
            c = self.curves[i]
            frame, value = self.from_px(p.x(), p.y())
            df = frame - float(c.keys[k])
            df = max(df, 0.25) if side > 0 else min(df, -0.25)  # a handle stays on its side
            self.last_value = (value - float(c.values[k])) / df
            if self.on_hair:
                result = self.hair.preview_slope(i, int(c.keys[k]), self.last_value)
                s_in, s_out = np.array(c.slope_in, dtype=float), np.array(c.slope_out, dtype=float)
                s_in[k] = s_out[k] = self.last_value
                self.curves[i] = Curve(
                    c.name, c.colour, c.original, result, c.key_curve, c.keys, c.values, s_in, s_out
                )
                self.update()
            else:
                self._preview([self._tangent(i, k, self.last_value)])
        event.accept()

    def mouseReleaseEvent(self, event: QMouseEvent) -> None:
        drag, self._drag = self._drag, None
        if drag is not None and drag[0] == "key" and self.last_value is not None and self.on_hair:
            _, _, (i, k), v0, f0 = drag
            self.hair.preview(None)
            if self.last_value != v0 or self.last_frame != f0:
                self.hair.commit(i, f0, self.last_value, self.last_frame)
        elif drag is not None and drag[0] == "key" and self.last_value is not None:
            _, _, (i, _k), v0, f0 = drag
            self.capture.preview(None)
            edits = self._edits(i, f0, self.last_frame, v0, self.last_value)
            if edits:
                name = f"{self.capture.joint} {self.curves[i].name}"
                moved = f" to {self.last_frame}" if self.last_frame != f0 else ""
                self._commit(edits, f"Move {name} key at {f0}{moved}")
        elif drag is not None and drag[0] == "handle" and self.last_value is not None and self.on_hair:
            _, _, (i, k, _), _ = drag
            self.hair.commit_slope(i, int(self.curves[i].keys[k]), self.last_value)
        elif drag is not None and drag[0] == "handle" and self.last_value is not None:
            _, _, (i, k, _), _ = drag
            self.capture.preview(None)
            edit = self._tangent(i, k, self.last_value)
            self._commit([edit], f"Turn {edit.joint} {edit.channel} handle at {edit.frame}")
        self.last_value = None
        event.accept()

    def snap(self, curve: int, key: int, frame: float) -> int:
        """The frame a key dragged to ``frame`` lands on: a whole frame strictly between its
        neighbouring keys (the first and last key stay on their frames)."""
        keys = self.curves[curve].keys
        if key == 0 or key == keys.size - 1:
            return int(keys[key])
        return int(min(max(round(frame), int(keys[key - 1]) + 1), int(keys[key + 1]) - 1))

    def _edits(self, i: int, frame: int, to: int, start: float, value: float) -> list[Edit]:
        """A key dragged from ``frame`` and value ``start`` to ``to`` and ``value``: the move in
        time (the key frame after it is ``to``), then the new value there; none when it went
        nowhere."""
        name = self.curves[i].name
        if to == frame:
            out: list[Edit] = []
        elif self.per_channel:  # that channel's key alone
            out = [ChannelRetimeEdit(frame, self.capture.joint, name, to)]
        else:  # the pose key, every channel
            out = [RetimeEdit(frame, to)]
        if value != start:
            out.append(ChannelEdit(int(to), self.capture.joint, self.curves[i].name, float(value)))
        return out

    def _tangent(self, i: int, k: int, slope: float) -> TangentEdit:
        c = self.curves[i]
        return TangentEdit(int(c.keys[k]), self.capture.joint, c.name, float(slope))

    def _preview(self, edits: list[Edit]) -> None:
        """The viewport and the joint's channels as the edits would make them (the capture's
        editor, or its per-channel layer, then undone)."""
        if self.per_channel:
            self.capture.preview_channel(edits or None)
            editor, curves = self.capture.channel_layer(), channel_curves
        else:
            self.capture.preview(edits or None)
            editor, curves = self.capture.editor, capture_curves
        editor.apply_all(edits)
        try:
            self.curves = curves(self.capture)
        finally:
            for _ in edits:
                editor.undo()
        self.update()

    def _commit(self, edits: list[Edit], text: str) -> None:
        if self.per_channel:
            self.capture.preview_channel(None)
            self.capture.commit_channel(edits, text)
        else:
            self.capture.commit(edits, text)

    # -- drawing -----------------------------------------------------------------------------
    def paintEvent(self, event) -> None:
        painter = QPainter(self)
        painter.setRenderHint(QPainter.RenderHint.Antialiasing)
        painter.fillRect(self.rect(), QColor(40, 42, 46))
        r = self._plot()
        painter.setPen(QPen(QColor(70, 72, 78), 1))
        painter.drawRect(r)
        self._grid(painter, r)
        if not self.curves:
            painter.setPen(QColor(170, 170, 170))
            painter.drawText(r, Qt.AlignmentFlag.AlignCenter | Qt.TextFlag.TextWordWrap, EMPTY)
            painter.end()
            return
        painter.setClipRect(r)
        frame = self.capture.model.frame
        fx, _ = self.to_px(frame, 0.0)
        painter.setPen(QPen(QColor(90, 150, 255, 160), 1))
        painter.drawLine(QPointF(float(fx), r.top()), QPointF(float(fx), r.bottom()))
        for c in self.curves:
            faint = QColor(c.colour)
            faint.setAlpha(60)
            self._line(painter, c.original, QPen(faint, 1.0))
            self._line(painter, c.key_curve, QPen(c.colour, 1.0, Qt.PenStyle.DashLine))
            self._line(painter, c.result, QPen(c.colour, 1.6 if c.editable else 1.0))
            self._keys(painter, c)
        painter.end()

    def _grid(self, painter: QPainter, r: QRectF) -> None:
        painter.setPen(QColor(150, 150, 150))
        (x0, x1), (y0, y1) = self.x_range, self.y_range
        for v in (y0, y1):
            _, py = self.to_px(0.0, v)
            painter.drawText(QPointF(2.0, float(py) + 4), f"{v:.3g}" if self.on_hair else f"{v:.0f}°")
        for f in (x0, x1):
            px, _ = self.to_px(f, 0.0)
            painter.drawText(QPointF(float(px) - 8, r.bottom() + 14), f"{f:.0f}")

    def _line(self, painter: QPainter, values: np.ndarray, pen: QPen) -> None:
        x0, x1 = self.x_range
        lo, hi = max(int(np.floor(x0)), 0), min(int(np.ceil(x1)) + 1, values.size)
        if hi - lo < 2:
            return
        step = max(1, (hi - lo) // max(int(self._plot().width()), 1))
        frames = np.arange(lo, hi, step)
        px, py = self.to_px(frames, values[frames])
        painter.setPen(pen)
        painter.setBrush(Qt.BrushStyle.NoBrush)
        painter.drawPolyline(polygon(px, py))

    def _keys(self, painter: QPainter, c: Curve) -> None:
        kx, ky = self.to_px(c.keys, c.values)
        if c.slope_in is not None and c.editable:
            painter.setPen(QPen(QColor(220, 220, 220, 160), 1))
            i = self.curves.index(c)
            for k in range(c.keys.size):
                a = QPointF(*self.handle_point(i, k, -1))
                b = QPointF(*self.handle_point(i, k, 1))
                painter.drawLine(a, b)
                for h in (a, b):
                    painter.drawEllipse(h, 2.5, 2.5)
        if c.editable:
            painter.setPen(QPen(QColor(20, 20, 20), 1))
            painter.setBrush(c.colour)
        else:  # hollow: a view, not dragged
            painter.setPen(QPen(c.colour, 1))
            painter.setBrush(Qt.BrushStyle.NoBrush)
        for x, y in zip(kx, ky, strict=True):
            painter.drawRect(QRectF(float(x) - 3.5, float(y) - 3.5, 7.0, 7.0))


class GraphEditorDock(QDockWidget):
    """The dock around :class:`GraphView` (View ▸ Graph editor)."""

    def __init__(self, window: StudioHost) -> None:
        super().__init__("Graph editor", window)
        self.setObjectName("GraphEditorDock")
        self.window = window
        capture: CaptureEditor = window.capture
        self.hair = HairChannels(window)
        self.view = GraphView(capture, self.hair)
        self.title = QLabel("")
        self.strand = QSpinBox()
        self.strand.setRange(0, 0)
        self.strand.setToolTip("The strand whose vertex is shown (a hair animation)")
        self.vertex = QSpinBox()
        self.vertex.setRange(-1, 0)
        self.vertex.setValue(-1)
        self.vertex.setSpecialValueText("tip")
        self.vertex.setToolTip("The vertex along the strand, from the root (0); tip: the last one")
        self.strand.valueChanged.connect(self._pick_vertex)
        self.vertex.valueChanged.connect(self._pick_vertex)
        # a long title gives way instead of widening the window past a laptop's screen
        self.title.setSizePolicy(QSizePolicy.Policy.Ignored, QSizePolicy.Policy.Preferred)
        top = QHBoxLayout()
        top.addWidget(self.title, 1)
        self.per_channel = QCheckBox("Per-channel keys")
        self.per_channel.setToolTip(
            "Each rotation channel keyed on its own at the timeline's price per key (seed 003: "
            "every degree of freedom its own curve and keys). Its keys drag like the pose keys, "
            "in value, time and handles, one channel at a time, over the pose keys' edits; a joint "
            "dragged in the viewport then keys each channel it turns on that channel's own keys"
        )
        self.per_channel.toggled.connect(self._set_per_channel)
        top.addWidget(self.per_channel)
        self.features = QCheckBox("Feature channels")
        self.features.setChecked(self.hair.features)
        self.features.setToolTip(
            "Also show the strand's feature channels at the sample as far along it as the vertex "
            "(lighter curves, hollow keys): the strand resampled along its length, relative to its "
            "root, the mean root removed, weighted toward the tip, which is what the key choice "
            "measures, with the key curve it fits through the keys (seed 000). Read-only: a "
            "resampled point slides between the vertices, so a value set there names no single "
            "pose; drag the vertex's x, y, z keys to edit"
        )
        self.features.toggled.connect(self._set_features)
        top.addWidget(self.features)
        self.pickers = [self.features, QLabel("Strand"), self.strand, QLabel("Vertex"), self.vertex]
        for widget in self.pickers:
            top.addWidget(widget)
        body = QWidget()
        layout = QVBoxLayout(body)
        layout.setContentsMargins(2, 2, 2, 2)
        layout.addLayout(top)
        layout.addWidget(self.view, 1)
        self.setWidget(body)
        self.setToolTip(
            "Drag a key up or down to move it in value, sideways to move it in time, or a handle "
            "end to turn it (the change spreads to the frames around it with the captured detail "
            "kept). Hollow keys are feature channels, shown, not edited. Wheel: zoom; middle-drag: "
            "pan; Ctrl+middle-drag: zoom each axis; Home: frame all"
        )
        window.addDockWidget(Qt.DockWidgetArea.BottomDockWidgetArea, self)
        self.hide()  # View ▸ Graph editor: the timeline keeps its first-start height
        model = window.animation
        for signal in (
            capture.changed,
            capture.selection_changed,
            model.keys_changed,
            model.animation_changed,
        ):
            signal.connect(self.refresh)
        model.frames_edited.connect(self.refresh)
        model.frame_changed.connect(lambda *_: self.view.update())
        self.refresh()

    def _set_per_channel(self, on: bool) -> None:
        self.view.per_channel = bool(on)
        self.window.capture.per_channel = bool(on)  # joint drags then key the channels too
        self.refresh()

    def _set_features(self, on: bool) -> None:
        self.hair.features = bool(on)
        self.refresh()

    def _pick_vertex(self, *_: object) -> None:
        self.hair.strand, self.hair.vertex = self.strand.value(), self.vertex.value()
        self.view.refresh()

    def refresh(self, *_: object) -> None:
        c = self.window.capture
        on_hair = self.view.on_hair
        for widget in self.pickers:
            widget.setVisible(on_hair)
        self.per_channel.setVisible(c.attached)
        if on_hair:
            topo = self.window.animation.animation.topology
            self.strand.setMaximum(topo.strand_count - 1)
            s = min(self.strand.value(), topo.strand_count - 1)
            self.vertex.setMaximum(int(topo.offsets[s + 1] - topo.offsets[s]) - 1)
            shown = ", its strand's features (read-only)" if self.hair.features else ""
            self.title.setText(f"strand vertex: x, y, z{shown}")
        else:
            each = ", each with its own keys" if self.view.per_channel else ""
            shown = c.attached and c.joint
            self.title.setText(f"{c.joint}: rotation channels (degrees){each}" if shown else "")
        self.view.refresh()
