"""Custom-painted timeline widgets: the scrubbable ruler with both key rows and the per-frame
curves, and the small error-versus-key-count plot. They read the :class:`AnimationModel` and
write only the frame (scrubbing) or the key count (clicking the plot) back to it."""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
from PySide6.QtCore import QEvent, QPointF, QRect, QRectF, QSize, Qt
from PySide6.QtGui import (
    QColor,
    QFont,
    QHelpEvent,
    QKeyEvent,
    QMouseEvent,
    QPainter,
    QPainterPath,
    QPaintEvent,
    QPen,
    QPixmap,
    QPolygonF,
    QResizeEvent,
    QWheelEvent,
)
from PySide6.QtWidgets import QApplication, QSizePolicy, QToolTip, QWidget

from app.ui import view_range
from app.ui.animation_model import AnimationModel
from hairtool.keys.dp import keys_cost, uniform_keys

BACKGROUND = QColor(38, 40, 44)
GRID = QColor(70, 73, 80)
TEXT = QColor(200, 200, 205)
DP_COLOUR = QColor(255, 140, 26)  # DP keys and their reconstruction's curves: orange
UNIFORM_COLOUR = QColor(74, 163, 223)  # uniform keys and theirs: blue
PIN_COLOUR = QColor(245, 245, 245)  # the ring round a pinned key
EXCLUDE_COLOUR = QColor(230, 80, 80)  # the cross on a frame that must not be a key
SPEED_COLOUR = QColor(150, 150, 150, 90)
PLAYHEAD = QColor(235, 64, 64)

LEFT, RIGHT = 56, 12  # px margins; frames map linearly onto the width between them
RULER_H, ROW_H = 22, 16
ZOOM_STEP = 1.25  # one wheel notch with Ctrl: the frames shown shrink or grow by this factor
MIN_SPAN = 8  # frames: the deepest zoom

#: What the dope sheet's marks mean (the dock's legend and the view's tooltip say the same).
KEY_LEGEND = (
    "◆ DP key: click pins it, drag moves it · ○ pinned: always a key · "
    "✕ never a key: a key was moved away from it (or Delete excluded it; Insert or undo frees it) · "
    "□ uniform keys of the same count · Ctrl+wheel zoom, middle-drag pan, Home all frames"
)


def polygon(xs: np.ndarray, ys: np.ndarray) -> QPolygonF:
    """Points ``(xs[i], ys[i])`` as a QPolygonF for one drawPolyline (the graph editor's curves
    too). Not a QPainterPath.lineTo per point: in PySide6 6.12 each lineTo call takes a
    reference from Python 3.11's None (50,000 calls end the process with none_dealloc), and it
    is one Python call per frame either way."""
    return QPolygonF(list(map(QPointF, np.asarray(xs, float).tolist(), np.asarray(ys, float).tolist())))


def _nice_step(span: float, pixels: float, min_px: float = 50.0) -> int:
    """A 1/2/5×10^k frame step whose labels are at least ``min_px`` apart."""
    if span <= 0 or pixels <= 0:
        return 1
    raw = span * min_px / pixels
    base = 10 ** math.floor(math.log10(max(raw, 1.0)))
    for m in (1, 2, 5, 10):
        if m * base >= raw:
            return int(m * base)
    return int(10 * base)


class TimelineView(QWidget):
    """Ruler, DP and uniform key rows, and the error and speed curves over frames.

    A left press or drag anywhere sets the frame (the viewport follows at once). The DP row is a
    dope sheet when a ``steer`` callback is given: a click on a key pins or unpins it (the mouse
    may wander less than Qt's start-drag distance: at a thousand frames a pixel is more than a
    frame), dragging a key moves it (the new frame pinned, the old one excluded, drawn as a
    cross, so the solve cannot put the key straight back; the other keys re-solve at once),
    Delete excludes the current frame and Insert pins it. Ctrl+wheel zooms about the cursor, a
    middle drag (or the wheel, zoomed in) pans, Home shows every frame again. Everything but the
    playhead is drawn once into a pixmap and reused until the keys, curves, view or size change,
    so a frame change repaints in well under a millisecond.
    """

    def __init__(
        self,
        model: AnimationModel,
        parent: QWidget | None = None,
        steer: Callable[..., bool] | None = None,
    ) -> None:
        super().__init__(parent)
        self.model = model
        self.steer = steer
        self._grab: int | None = None  # the DP key pressed on, while the button is down
        self._press_x = 0.0
        self._dragging = False  # the grabbed key moved past the start-drag distance
        self._view: tuple[float, float] | None = None  # first and last frame shown (None: all)
        self._pan: tuple[float, tuple[float, float]] | None = None  # middle drag: start x, view
        self.setMinimumHeight(150)
        self.setSizePolicy(QSizePolicy.Policy.Expanding, QSizePolicy.Policy.Expanding)
        self.setMouseTracking(False)
        self.setFocusPolicy(Qt.FocusPolicy.ClickFocus)
        self.setObjectName("TimelineView")
        self._cache: QPixmap | None = None
        for signal in (
            model.animation_changed,
            model.keys_changed,
            model.analysis_changed,
            model.frames_edited,
            model.busy_changed,
            model.settings_changed,
        ):
            signal.connect(self.invalidate)
        model.animation_changed.connect(self.show_all)
        model.frame_changed.connect(self._follow_frame)
        self.setToolTip(KEY_LEGEND)

    def invalidate(self, *_: object) -> None:
        self._cache = None
        self.update()

    def resizeEvent(self, event: QResizeEvent) -> None:
        self._cache = None
        super().resizeEvent(event)

    def sizeHint(self) -> QSize:
        return QSize(700, 190)

    # -- the frames shown: zoom and pan ---------------------------------------------------------
    @property
    def view_range(self) -> tuple[float, float]:
        """The first and last frame across the width (every frame unless zoomed in)."""
        return self._view if self._view is not None else (0.0, float(max(self.model.n_frames - 1, 1)))

    @property
    def zoomed(self) -> bool:
        return self._view is not None

    def set_view(self, first: float, last: float) -> None:
        """Show frames ``first .. last`` (kept inside the animation, at least :data:`MIN_SPAN`)."""
        view = view_range.fit((first, last), 0.0, float(max(self.model.n_frames - 1, 1)), MIN_SPAN)
        if view != self._view:
            self._view = view
            self.invalidate()

    def show_all(self) -> None:
        self.set_view(0.0, float(max(self.model.n_frames - 1, 1)))

    def zoom(self, factor: float, about_x: float) -> None:
        """Zoom by ``factor`` (> 1: fewer frames across) keeping the frame under ``about_x`` put."""
        self.set_view(*view_range.zoom(self.view_range, factor, self._x_to_f(about_x)))

    def pan(self, frames: float) -> None:
        self.set_view(*view_range.pan(self.view_range, frames))

    def _follow_frame(self, frame: int) -> None:
        """Zoomed in, a frame outside the view (playback, the arrows) brings the view with it."""
        v0, v1 = self.view_range
        margin = 0.1 * (v1 - v0)  # the frame lands a tenth of the view inside the edge it crossed
        if self.zoomed and frame < v0:
            self.pan(frame - margin - v0)
        elif self.zoomed and frame > v1:
            self.pan(frame + margin - v1)
        self.update()

    # -- geometry (tests use these to find pixels) --------------------------------------------
    def _axis(self) -> view_range.Axis:
        return view_range.Axis(self.view_range, LEFT, max(self.width() - LEFT - RIGHT, 1))

    def _frames_per_px(self) -> float:
        return self._axis().per_px

    def frame_to_x(self, frame: float) -> float:
        return float(self._axis().to_px(float(frame)))

    def _x_to_f(self, x: float) -> float:
        return self._axis().from_px(x)

    def x_to_frame(self, x: float) -> int:
        return round(self._x_to_f(x))

    def visible_frames(self) -> range:
        v0, v1 = self.view_range
        return range(max(math.floor(v0), 0), min(math.ceil(v1), self.model.n_frames - 1) + 1)

    def row_rect(self, row: str) -> QRect:
        """ "ruler", "dp", "uniform" or "curves": the band each is drawn in."""
        top = {"ruler": 0, "dp": RULER_H, "uniform": RULER_H + ROW_H, "curves": RULER_H + 2 * ROW_H}[row]
        height = {"ruler": RULER_H, "dp": ROW_H, "uniform": ROW_H}.get(row, self.height() - top)
        return QRect(0, top, self.width(), height)

    @property
    def drawn_keys(self) -> dict[str, list[int]]:
        """The frames each key row shows (what the last paint drew)."""
        m = self.model
        return {
            "dp": [] if m.dp_keys is None else m.dp_keys.tolist(),
            "uniform": [] if m.uniform_keys is None else m.uniform_keys.tolist(),
        }

    def key_at(self, pos: QPointF) -> int | None:
        """The DP key drawn under ``pos`` (within its diamond's reach), or None."""
        m = self.model
        if m.dp_keys is None or not self.row_rect("dp").contains(pos.toPoint()):
            return None
        xs = np.array([self.frame_to_x(k) for k in m.dp_keys])
        i = int(np.argmin(np.abs(xs - pos.x())))
        return int(m.dp_keys[i]) if abs(xs[i] - pos.x()) <= max(self._half(), 4.0) else None

    # -- input ----------------------------------------------------------------------------------
    def mousePressEvent(self, event: QMouseEvent) -> None:
        if event.button() == Qt.MouseButton.MiddleButton:
            self._pan = (event.position().x(), self.view_range)
            event.accept()
        elif event.button() == Qt.MouseButton.LeftButton:
            self.model.set_scrubbing(True)  # (first: a pause stays live while the frame is dragged)
            self.model.pause()
            self._grab = self.key_at(event.position()) if self.steer is not None else None
            self._press_x, self._dragging = event.position().x(), False
            frame = self._grab if self._grab is not None else self.x_to_frame(event.position().x())
            self.model.set_frame(frame)
            event.accept()

    def mouseMoveEvent(self, event: QMouseEvent) -> None:
        x = event.position().x()
        if self._pan is not None and event.buttons() & Qt.MouseButton.MiddleButton:
            start, view = self._pan
            self.set_view(*view_range.pan(view, -(x - start) * self._frames_per_px()))
            event.accept()
        elif event.buttons() & Qt.MouseButton.LeftButton:
            if self._grab is not None and not self._dragging:
                if abs(x - self._press_x) < QApplication.startDragDistance():
                    return  # a click wobbles: the key stays where it is
                self._dragging = True
            self.model.set_frame(min(max(self.x_to_frame(x), 0), self.model.last_frame))
            event.accept()

    def mouseReleaseEvent(self, event: QMouseEvent) -> None:
        if event.button() == Qt.MouseButton.MiddleButton:
            self._pan = None
            return
        grabbed, self._grab = self._grab, None
        if event.button() == Qt.MouseButton.LeftButton:
            self.model.set_scrubbing(False)
        if event.button() != Qt.MouseButton.LeftButton or grabbed is None or self.steer is None:
            return
        target = min(max(self.x_to_frame(event.position().x()), 0), self.model.last_frame)
        if not self._dragging:  # a click: pin or unpin
            if grabbed in self.model.settings.pins:
                self.steer(f"Unpin key {grabbed}", unpin=grabbed)
            else:
                self.steer(f"Pin key {grabbed}", pin=grabbed)
        elif target != grabbed:
            self.steer(f"Move key {grabbed} to {target}", move=(grabbed, target))
        else:
            self.model.set_frame(grabbed)  # dragged back where it was: nothing changes
        event.accept()

    def wheelEvent(self, event: QWheelEvent) -> None:
        notches = event.angleDelta().y() / 120.0
        if not notches or self.model.n_frames < 2:
            event.ignore()
        elif event.modifiers() & Qt.KeyboardModifier.ControlModifier:
            self.zoom(ZOOM_STEP**notches, event.position().x())
            event.accept()
        elif self.zoomed:  # zoomed in, the plain wheel walks along the frames
            v0, v1 = self.view_range
            self.pan(-notches * (v1 - v0) * 0.1)
            event.accept()
        else:
            event.ignore()

    def event(self, event: QEvent) -> bool:
        if event.type() == QEvent.Type.ShortcutOverride and self._home_frames_all(event):
            event.accept()  # Home here shows every frame, not the first frame's shortcut
            return True
        if event.type() == QEvent.Type.ToolTip and isinstance(event, QHelpEvent):
            QToolTip.showText(event.globalPos(), self.tooltip_at(QPointF(event.pos())), self)
            return True
        return super().event(event)

    def _home_frames_all(self, event: QEvent) -> bool:
        return (
            isinstance(event, QKeyEvent)
            and event.key() == Qt.Key.Key_Home
            and event.modifiers() == Qt.KeyboardModifier.NoModifier
            and self.zoomed
        )

    def tooltip_at(self, pos: QPointF) -> str:
        """What the mark under ``pos`` means (a key, a pin, an excluded frame), else the legend."""
        m = self.model
        if m.n_frames >= 2 and self.row_rect("dp").contains(pos.toPoint()):
            frame = min(max(self.x_to_frame(pos.x()), 0), m.last_frame)
            at = self._x_to_f(pos.x())
            near = max(max(self._half(), 4.0) * self._frames_per_px(), 0.5)
            excluded = sorted((abs(f - at), f) for f in m.settings.excludes if abs(f - at) <= near)
            key = self.key_at(pos)
            if excluded and (key is None or excluded[0][0] < abs(key - at)):
                key = None  # the cross is nearer than the key beside it
            excluded = [f for _, f in excluded]
            if key is not None and key in m.settings.pins:
                return f"Key {key}, pinned: a key whatever the solve. Click unpins it, drag moves it."
            if key is not None:
                return f"Key {key}, chosen by the solve. Click pins it, drag moves it."
            if excluded:
                return (
                    f"Frame {excluded[0]} is never a key: a key was moved away from it (or Delete "
                    "excluded it), so the solve cannot put it back there. Insert at that frame, or "
                    "undo, frees it again."
                )
            return f"Frame {frame}. {KEY_LEGEND}"
        return KEY_LEGEND

    def keyPressEvent(self, event) -> None:
        if self._home_frames_all(event):
            self.show_all()
            event.accept()
            return
        frame = self.model.frame
        if self.steer is not None and self.model.n_frames >= 2:
            if event.key() in (Qt.Key.Key_Delete, Qt.Key.Key_Backspace):
                self.steer(f"Exclude frame {frame}", exclude=frame)
                event.accept()
                return
            if event.key() == Qt.Key.Key_Insert:
                self.steer(f"Pin frame {frame}", pin=frame)
                event.accept()
                return
        super().keyPressEvent(event)

    # -- painting -------------------------------------------------------------------------------
    def paintEvent(self, event: QPaintEvent) -> None:
        if self._cache is None or self._cache.size() != self.size() * self.devicePixelRatioF():
            self._cache = self._render_static()
        p = QPainter(self)
        p.drawPixmap(0, 0, self._cache)
        if self.model.n_frames:
            p.setRenderHint(QPainter.RenderHint.Antialiasing, True)
            x = self.frame_to_x(self.model.frame)
            p.setPen(QPen(PLAYHEAD, 1.5))
            p.drawLine(QPointF(x, 0), QPointF(x, self.height()))
        p.end()

    def _render_static(self) -> QPixmap:
        """Ruler, key rows and curves (all but the playhead) at the widget's size."""
        dpr = self.devicePixelRatioF()
        pixmap = QPixmap(self.size() * dpr)
        pixmap.setDevicePixelRatio(dpr)
        pixmap.fill(BACKGROUND)
        p = QPainter(pixmap)
        m = self.model
        if m.n_frames == 0:
            p.setPen(TEXT)
            p.drawText(self.rect(), Qt.AlignmentFlag.AlignCenter, "No animation: open one, or record a drag")
        else:
            p.setRenderHint(QPainter.RenderHint.Antialiasing, True)
            self._paint_row_label(p, "dp", "DP")
            self._paint_row_label(p, "uniform", "uniform")
            p.setClipRect(QRectF(LEFT - 8, 0, self.width() - LEFT - RIGHT + 16, self.height()))
            self._paint_ruler(p)
            self._paint_keys(p, "dp", m.dp_keys, DP_COLOUR, filled=True)
            self._paint_constraints(p)
            self._paint_keys(p, "uniform", m.uniform_keys, UNIFORM_COLOUR, filled=False)
            self._paint_curves(p)
        p.end()
        return pixmap

    def _paint_ruler(self, p: QPainter) -> None:
        r = self.row_rect("ruler")
        v0, v1 = self.view_range
        span = self.width() - LEFT - RIGHT
        step = _nice_step(v1 - v0, span)
        small = span / max(v1 - v0, 1) >= 5
        font = QFont(p.font())
        font.setPointSizeF(7.5)
        p.setFont(font)
        for f in self.visible_frames():
            x = self.frame_to_x(f)
            if f % step == 0:
                p.setPen(TEXT)
                p.drawLine(QPointF(x, r.bottom() - 8), QPointF(x, r.bottom()))
                p.drawText(QRectF(x - 30, r.top(), 60, 12), Qt.AlignmentFlag.AlignCenter, str(f))
            elif small:
                p.setPen(GRID)
                p.drawLine(QPointF(x, r.bottom() - 4), QPointF(x, r.bottom()))
        p.setPen(GRID)
        p.drawLine(LEFT, r.bottom(), self.width() - RIGHT, r.bottom())

    def _half(self) -> float:
        """Half the size of a key's mark at the current zoom."""
        v0, v1 = self.view_range
        return min(5.0, max(2.5, (self.width() - LEFT - RIGHT) / max(v1 - v0 + 1, 1) / 2.2))

    def _paint_constraints(self, p: QPainter) -> None:
        """Pinned keys get a ring round their diamond; excluded frames a cross on the DP row."""
        s, r = self.model.settings, self.row_rect("dp")
        cy, half = r.center().y() + 0.5, self._half()
        p.setBrush(Qt.BrushStyle.NoBrush)
        p.setPen(QPen(PIN_COLOUR, 1.5))
        for f in s.pins:
            p.drawEllipse(QPointF(self.frame_to_x(f), cy), half + 2.5, half + 2.5)
        p.setPen(QPen(EXCLUDE_COLOUR, 1.5))
        d = half * 0.8
        for f in s.excludes:
            x = self.frame_to_x(f)
            p.drawLine(QPointF(x - d, cy - d), QPointF(x + d, cy + d))
            p.drawLine(QPointF(x - d, cy + d), QPointF(x + d, cy - d))

    def _paint_row_label(self, p: QPainter, row: str, text: str) -> None:
        r = self.row_rect(row)
        p.setPen(TEXT)
        p.drawText(QRect(2, r.top(), LEFT - 6, r.height()), Qt.AlignmentFlag.AlignVCenter, text)

    def _paint_keys(self, p: QPainter, row: str, keys, colour: QColor, filled: bool) -> None:
        r = self.row_rect(row)
        if keys is None:
            return
        cy = r.center().y() + 0.5
        half = self._half()
        if filled:  # diamonds, solid
            p.setPen(Qt.PenStyle.NoPen)
            p.setBrush(colour)
            for k in keys:
                x = self.frame_to_x(k)
                p.drawPolygon(
                    QPolygonF(
                        [
                            QPointF(x, cy - half),
                            QPointF(x + half, cy),
                            QPointF(x, cy + half),
                            QPointF(x - half, cy),
                        ]
                    )
                )
        else:  # squares, outlined
            p.setPen(QPen(colour, 1.6))
            p.setBrush(Qt.BrushStyle.NoBrush)
            for k in keys:
                x = self.frame_to_x(k)
                p.drawRect(QRectF(x - half + 0.8, cy - half + 0.8, 2 * half - 1.6, 2 * half - 1.6))
        p.setBrush(Qt.BrushStyle.NoBrush)

    def _curve_points(self, values: np.ndarray, top: float, height: float, scale: float) -> QPolygonF:
        """The visible frames of a per-frame curve as one polygon (drawn by drawPolyline, not a
        lineTo per frame)."""
        frames = np.asarray(self.visible_frames(), dtype=np.int64)
        xs = self._axis().to_px(frames.astype(np.float64))
        ys = top + height - height * np.asarray(values, dtype=np.float64)[frames] / scale
        return polygon(xs, ys)

    def _paint_curves(self, p: QPainter) -> None:
        m, r = self.model, self.row_rect("curves")
        top, height = r.top() + 14.0, max(r.height() - 20.0, 10.0)
        p.setPen(GRID)
        p.drawLine(LEFT, int(top + height), self.width() - RIGHT, int(top + height))
        a = m.analysis
        if a is None:
            p.setPen(TEXT)
            text = "measuring errors…" if m.busy else ""
            p.drawText(QRect(LEFT, r.top(), 300, 14), Qt.AlignmentFlag.AlignLeft, text)
            return
        if a.speed is not None and a.speed.max() > 0:
            area = self._curve_points(a.speed, top, height, float(a.speed.max()))
            frames = self.visible_frames()
            area.append(QPointF(self.frame_to_x(frames[-1]), top + height))
            area.append(QPointF(self.frame_to_x(frames[0]), top + height))
            path = QPainterPath()
            path.addPolygon(area)
            path.closeSubpath()
            p.fillPath(path, SPEED_COLOUR)
        scale = max(
            float(max(a.dp.tip.max(), a.dp.mean.max(), a.uniform.tip.max(), a.uniform.mean.max())), 1e-12
        )
        for err, colour in ((a.uniform, UNIFORM_COLOUR), (a.dp, DP_COLOUR)):
            p.setPen(QPen(colour, 1.6))
            p.drawPolyline(self._curve_points(err.mean, top, height, scale))
            p.setPen(QPen(colour, 1.2, Qt.PenStyle.DashLine))
            p.drawPolyline(self._curve_points(err.tip, top, height, scale))
        p.setPen(TEXT)
        legend = (
            f"distance on the vertices (max {scale:.3g}): — mean  - - tip   DP {a.dp.mean.mean():.3g}  "
            f"uniform {a.uniform.mean.mean():.3g} (mean)   ▒ speed"
        )
        p.drawText(QRect(LEFT, r.top(), self.width() - LEFT - RIGHT, 14), Qt.AlignmentFlag.AlignLeft, legend)


class KeyCountPlot(QWidget):
    """Optimal error against key count (log scale), with uniform keys' error dashed and the
    current count marked, so the artist can see the knee; a click picks that count."""

    def __init__(self, model: AnimationModel, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.model = model
        self.setObjectName("KeyCountPlot")
        self.setMinimumSize(180, 110)
        self._uniform: np.ndarray | None = None
        model.curve_changed.connect(self._on_curve)
        model.keys_changed.connect(self.update)
        model.animation_changed.connect(self._on_curve)

    def sizeHint(self) -> QSize:
        return QSize(240, 130)

    def _on_curve(self) -> None:
        """Uniform keys' cost from the same table for every count (each O(K): cheap)."""
        s = self.model.key_solve
        self._uniform = None
        if s is not None:
            n = s.n_frames
            self._uniform = np.array(
                [keys_cost(s.table, uniform_keys(n, int(k)), s.objective) for k in s.curve[:, 0]]
            )
        self.update()

    def _plot_rect(self) -> QRectF:
        return QRectF(44, 8, max(self.width() - 52, 10), max(self.height() - 26, 10))

    def _scale(self):
        s = self.model.key_solve
        curve = s.curve
        values = np.concatenate([curve[:, 1], self._uniform if self._uniform is not None else []])
        positive = values[values > 0]
        lo = float(positive.min()) if positive.size else 1e-12
        hi = float(values.max()) if values.size else 1.0
        lo = min(lo, hi * 0.999) if hi > 0 else 1e-12
        return curve, math.log10(lo), math.log10(max(hi, lo * 10))

    def count_at(self, x: float) -> int:
        s = self.model.key_solve
        r = self._plot_rect()
        f = (x - r.left()) / r.width()
        least, most = s.key_range  # the pins need a few keys at least
        return int(min(max(round(2 + f * (s.kmax - 2)), least), most))

    def _point(self, k: float, v: float, lo: float, hi: float) -> QPointF:
        r, kmax = self._plot_rect(), self.model.key_solve.kmax
        x = r.left() + r.width() * (k - 2) / max(kmax - 2, 1)
        y = r.bottom() - r.height() * (math.log10(max(v, 10**lo)) - lo) / (hi - lo)
        return QPointF(x, y)

    def current_point(self) -> tuple[int, float] | None:
        """The marked point: the current key count and its optimal error on the curve (the
        curve starts at the fewest keys the pins allow, not always at 2)."""
        s, keys = self.model.key_solve, self.model.dp_keys
        if s is None or keys is None:
            return None
        curve = s.curve
        row = np.flatnonzero(curve[:, 0] == keys.size)
        return (int(keys.size), float(curve[row[0], 1])) if row.size else None

    def mousePressEvent(self, event: QMouseEvent) -> None:
        if event.button() == Qt.MouseButton.LeftButton and self.model.key_solve is not None:
            self.model.set_key_count(self.count_at(event.position().x()))

    def mouseMoveEvent(self, event: QMouseEvent) -> None:
        if event.buttons() & Qt.MouseButton.LeftButton and self.model.key_solve is not None:
            self.model.set_key_count(self.count_at(event.position().x()))

    def paintEvent(self, event: QPaintEvent) -> None:
        p = QPainter(self)
        p.fillRect(self.rect(), BACKGROUND)
        s = self.model.key_solve
        font = QFont(p.font())
        font.setPointSizeF(7.5)
        p.setFont(font)
        p.setPen(TEXT)
        if s is None or s.kmax < 3:
            p.drawText(self.rect(), Qt.AlignmentFlag.AlignCenter, "error vs key count")
            p.end()
            return
        p.setRenderHint(QPainter.RenderHint.Antialiasing, True)
        curve, lo, hi = self._scale()
        r = self._plot_rect()
        p.setPen(GRID)
        p.drawRect(r)
        p.setPen(TEXT)
        p.drawText(QRectF(0, r.top() - 4, 42, 12), Qt.AlignmentFlag.AlignRight, f"{10**hi:.2g}")
        p.drawText(QRectF(0, r.bottom() - 8, 42, 12), Qt.AlignmentFlag.AlignRight, f"{10**lo:.2g}")
        p.drawText(QRectF(r.left(), r.bottom() + 2, 40, 12), Qt.AlignmentFlag.AlignLeft, "2")
        p.drawText(QRectF(r.right() - 40, r.bottom() + 2, 40, 12), Qt.AlignmentFlag.AlignRight, str(s.kmax))
        p.drawText(
            QRectF(r.left(), r.bottom() + 2, r.width(), 12), Qt.AlignmentFlag.AlignCenter, "keys (log error)"
        )
        if self._uniform is not None:
            p.setPen(QPen(UNIFORM_COLOUR, 1.2, Qt.PenStyle.DashLine))
            points = zip(curve[:, 0], self._uniform, strict=True)
            p.drawPolyline(QPolygonF([self._point(k, v, lo, hi) for k, v in points]))
        p.setPen(QPen(DP_COLOUR, 1.6))
        p.drawPolyline(QPolygonF([self._point(k, v, lo, hi) for k, v in curve]))
        keys = self.model.dp_keys
        current = self.current_point()
        if current is not None:
            pt = self._point(current[0], current[1], lo, hi)
            p.setPen(QPen(PLAYHEAD, 1.0))
            p.drawLine(QPointF(pt.x(), r.top()), QPointF(pt.x(), r.bottom()))
            p.setBrush(PLAYHEAD)
            p.drawEllipse(pt, 3.0, 3.0)
            p.drawText(QRectF(pt.x() + 4, r.top(), 60, 12), Qt.AlignmentFlag.AlignLeft, f"K={keys.size}")
        p.end()
