"""The anime wave preview dock (Furukawa & Nakata 2018): eq. (1) drawn for every picture of a
cycle, the exposure sheet as a strip, and the parameters with live update.

API (the window wires it; the dock itself never touches the scene or the animation model):

- ``settings() -> AnimeSettings`` / ``set_settings(s)``: the values shown (set_settings emits
  nothing, so a model can push values in without an echo).
- ``settings_changed(AnimeSettings)``: every user edit, also when the combination is invalid
  (then ``schedule`` is None and ``error_text()`` says why, in the dock, not in a dialog).
- ``apply_requested(AnimeSettings)``: "Apply to groom" was pressed (only enabled when valid).
- ``set_current_frame(frame | None)``: highlight a shot frame in the strip (the timeline's).
- ``schedule``, ``curves``: what is drawn, for tests and for the window.

:func:`hairtool.anime.settings.cycle_for_groom` builds the cycle animation the window loads into
the timeline.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray
from PySide6.QtCore import QPointF, QRectF, QSize, Qt, Signal
from PySide6.QtGui import QColor, QPainter, QPen
from PySide6.QtWidgets import (
    QDockWidget,
    QDoubleSpinBox,
    QFormLayout,
    QFrame,
    QGroupBox,
    QLabel,
    QPushButton,
    QScrollArea,
    QSizePolicy,
    QSpinBox,
    QVBoxLayout,
    QWidget,
)

from app.ui.qt_utils import signals_blocked
from app.ui.timeline_plots import polygon
from app.ui.widgets import SliderSpin
from hairtool.anime.schedule import Schedule
from hairtool.anime.settings import AnimeSettings, wave_curves
from hairtool.anime.wave import WaveParams
from hairtool.errors import HairtoolError

SOURCE = "anime cycle"  # the ``source`` the window gives the animation model


def picture_colour(i: int, n: int) -> QColor:
    """Picture i of n: hues around the wheel, the first picture red, as on the strip."""
    return QColor.fromHsvF((i / max(n, 1)) * 0.85, 0.65, 0.95)


class WavePlot(QWidget):
    """f(x, t_i) for every picture: root at the left, tip at the right, y up."""

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.curves: list[NDArray] = []  # (n, 2) x, y per picture, in wave units
        self.setMinimumHeight(140)
        self.setSizePolicy(QSizePolicy.Policy.Expanding, QSizePolicy.Policy.Expanding)

    def sizeHint(self) -> QSize:
        return QSize(300, 180)

    def set_curves(self, x: NDArray | None, y: NDArray | None) -> None:
        self.curves = [] if x is None else [np.column_stack([x, row]) for row in y]
        self.update()

    def paintEvent(self, event) -> None:
        p = QPainter(self)
        p.setRenderHint(QPainter.RenderHint.Antialiasing)
        p.fillRect(self.rect(), QColor(40, 42, 48))
        if not self.curves:
            return
        pts = np.concatenate(self.curves)
        lo, hi = float(min(pts[:, 1].min(), 0.0)), float(max(pts[:, 1].max(), 0.0))
        pad = 0.08 * max(hi - lo, 1e-6)
        lo, hi = lo - pad, hi + pad
        m = 10.0
        w, h = max(self.width() - 2 * m, 1.0), max(self.height() - 2 * m, 1.0)

        def to_px(x: float, y: float) -> QPointF:
            return QPointF(m + w * x / np.pi, m + h * (hi - y) / (hi - lo))

        p.setPen(QPen(QColor(90, 92, 100), 1, Qt.PenStyle.DashLine))
        p.drawLine(to_px(0.0, 0.0), to_px(np.pi, 0.0))  # the rest chain
        p.setBrush(QColor(220, 220, 220))
        p.drawEllipse(to_px(0.0, 0.0), 3.5, 3.5)  # the root
        n = len(self.curves)
        for i, c in enumerate(self.curves):
            xy = np.asarray(c, dtype=np.float64).reshape(-1, 2)
            p.setPen(QPen(picture_colour(i, n), 2.0))
            p.setBrush(Qt.BrushStyle.NoBrush)
            xs, ys = m + w * xy[:, 0] / np.pi, m + h * (hi - xy[:, 1]) / (hi - lo)
            p.drawPolyline(polygon(xs, ys))  # one call: QPainterPath.lineTo leaks in PySide6 6.12


class ExposureStrip(QWidget):
    """One cell per frame of the shot, coloured and numbered by the picture it exposes."""

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.exposure: NDArray | None = None
        self.n_pictures = 0
        self.cycle_frames = 0
        self.current: int | None = None
        self.setMinimumHeight(30)
        self.setSizePolicy(QSizePolicy.Policy.Expanding, QSizePolicy.Policy.Fixed)

    def sizeHint(self) -> QSize:
        return QSize(300, 34)

    def set_exposure(self, exposure: NDArray | None, n_pictures: int, cycle_frames: int) -> None:
        self.exposure, self.n_pictures, self.cycle_frames = exposure, n_pictures, cycle_frames
        self.update()

    def set_current(self, frame: int | None) -> None:
        if frame != self.current:
            self.current = frame
            self.update()

    def cell_rect(self, frame: int) -> QRectF:
        n = 0 if self.exposure is None else len(self.exposure)
        cw = self.width() / max(n, 1)
        return QRectF(frame * cw, 0.0, cw, float(self.height()))

    def paintEvent(self, event) -> None:
        p = QPainter(self)
        p.fillRect(self.rect(), QColor(40, 42, 48))
        if self.exposure is None:
            return
        n = len(self.exposure)
        show_numbers = self.width() / max(n, 1) >= 12
        for f, pic in enumerate(self.exposure.tolist()):
            r = self.cell_rect(f).adjusted(0.5, 3, -0.5, -3)
            colour = picture_colour(pic, self.n_pictures)
            if f > 0 and self.exposure[f - 1] == pic:
                colour = colour.darker(135)  # a held frame: same drawing, shown again
            p.fillRect(r, colour)
            if show_numbers:
                p.setPen(QColor(20, 20, 20))
                p.drawText(r, Qt.AlignmentFlag.AlignCenter, str(pic + 1))
            if self.cycle_frames and f % self.cycle_frames == 0 and f:
                p.setPen(QPen(QColor(250, 250, 250), 2))
                p.drawLine(r.topLeft(), r.bottomLeft())
        if self.current is not None and 0 <= self.current < n:
            p.setPen(QPen(QColor(255, 255, 255), 2))
            p.setBrush(Qt.BrushStyle.NoBrush)
            p.drawRect(self.cell_rect(self.current).adjusted(1, 1, -1, -1))


class AnimeDock(QDockWidget):
    """See the module docstring for the signal/method API."""

    settings_changed = Signal(object)  # AnimeSettings
    apply_requested = Signal(object)  # AnimeSettings

    def __init__(self, parent: QWidget | None = None, settings: AnimeSettings | None = None) -> None:
        super().__init__("Anime wave", parent)
        self.setObjectName("AnimeDock")
        self.schedule: Schedule | None = None
        self._error = ""
        body = QWidget()
        layout = QVBoxLayout(body)
        self.plot = WavePlot()
        self.strip = ExposureStrip()
        self.info = QLabel()
        self.info.setWordWrap(True)
        self.error_label = QLabel()
        self.error_label.setWordWrap(True)
        self.error_label.setStyleSheet("color: #e06c6c")
        layout.addWidget(self.plot, 3)
        layout.addWidget(self.strip)
        layout.addWidget(self.info)
        layout.addWidget(self.error_label)
        layout.addWidget(self._wave_box())
        layout.addWidget(self._timing_box())
        self.apply_button = QPushButton("Apply to groom")
        self.apply_button.setToolTip("Make the cycle animation of the groom (or of the selected strands)")
        self.apply_button.clicked.connect(lambda: self.apply_requested.emit(self.settings()))
        layout.addWidget(self.apply_button)
        layout.addStretch(1)
        scroll = QScrollArea()  # a short screen scrolls the controls instead of growing the window
        scroll.setWidgetResizable(True)
        scroll.setFrameShape(QFrame.Shape.NoFrame)
        scroll.setWidget(body)
        self.setWidget(scroll)
        self.set_settings(settings or AnimeSettings())

    # -- widgets ---------------------------------------------------------------------------
    def _wave_box(self) -> QGroupBox:
        box = QGroupBox("Swing")
        box.setToolTip("the wave f(x, t) of Furukawa & Nakata, eq. (1), drawn for every picture above")
        form = QFormLayout(box)
        self.a = SliderSpin(-3.0, 3.0, 3)
        self.k = SliderSpin(0.05, 10.0, 3, log=True)
        self.s = SliderSpin(0.1, 10.0, 3, log=True)
        self.p = SliderSpin(0.0, 4.0, 3)
        self.period = SliderSpin(0.02, 5.0, 3, log=True)
        rows = (
            (self.a, "Swing size", "a, eq. (1): how far the hair line swings (negative flips it)"),
            (self.k, "Wave length", "k, eq. (1): spatial period; smaller puts more ripples on a bunch"),
            (self.s, "Weight", "s, eq. (1): gravity on the hair: sag a/s², swing a/s"),
            (self.p, "Whip toward the tip", "p, eq. (1): swing growth root to tip; 0 even, 2 whips"),
            (self.period, "Cycle length (s)", "T, eq. (1): seconds per cycle"),
        )
        for widget, label, tip in rows:
            widget.setToolTip(tip)
            widget.edited.connect(self._edited)
            form.addRow(label, widget)
        return box

    def _timing_box(self) -> QGroupBox:
        box = QGroupBox("Timing and variation")
        form = QFormLayout(box)
        self.fps = QDoubleSpinBox()
        self.fps.setRange(1.0, 240.0)
        self.fps.setDecimals(3)
        self.fps.setSuffix(" fps")
        self.hold = QSpinBox()
        self.hold.setRange(1, 12)
        self.hold.setToolTip("frames each picture is held: 2 = on twos, 3 = on threes")
        self.cycles = QSpinBox()
        self.cycles.setRange(1, 1000)
        self.amp_spread = QDoubleSpinBox()
        self.amp_spread.setRange(0.0, 1.0)
        self.amp_spread.setSingleStep(0.05)
        self.phase_spread = QDoubleSpinBox()
        self.phase_spread.setRange(0.0, 1.0)
        self.phase_spread.setSingleStep(0.05)
        self.phase_spread.setToolTip("bunch phase offsets in [0, spread) cycles; 0: lock step")
        self.seed = QSpinBox()
        self.seed.setRange(0, 2**31 - 1)
        for w in (self.fps, self.amp_spread, self.phase_spread):
            w.setKeyboardTracking(False)
            w.valueChanged.connect(self._edited)
        for w in (self.hold, self.cycles, self.seed):
            w.setKeyboardTracking(False)
            w.valueChanged.connect(self._edited)
        form.addRow("Frame rate", self.fps)
        form.addRow("Hold (frames)", self.hold)
        form.addRow("Cycles", self.cycles)
        form.addRow("Amplitude spread", self.amp_spread)
        form.addRow("Phase spread", self.phase_spread)
        form.addRow("Seed", self.seed)
        return box

    def _inputs(self) -> tuple[QWidget, ...]:
        return (self.fps, self.hold, self.cycles, self.amp_spread, self.phase_spread, self.seed)

    # -- API -------------------------------------------------------------------------------
    def settings(self) -> AnimeSettings:
        """The values shown; a wave the eq. (1) checks refuse raises ParameterError."""
        w = WaveParams(
            amplitude=self.a.value(),
            wavelength=self.k.value(),
            gravity=self.s.value(),
            profile=self.p.value(),
            period=self.period.value(),
        )
        return AnimeSettings(
            wave=w,
            fps=self.fps.value(),
            hold=self.hold.value(),
            cycles=self.cycles.value(),
            amplitude_spread=self.amp_spread.value(),
            phase_spread=self.phase_spread.value(),
            seed=self.seed.value(),
        )

    def set_settings(self, s: AnimeSettings) -> None:
        """Show ``s`` without emitting ``settings_changed``."""
        for widget, value in (
            (self.a, s.wave.amplitude),
            (self.k, s.wave.wavelength),
            (self.s, s.wave.gravity),
            (self.p, s.wave.profile),
            (self.period, s.wave.period),
        ):
            widget.set_value(value)
        with signals_blocked(*self._inputs()):
            self.fps.setValue(s.fps)
            self.hold.setValue(s.hold)
            self.cycles.setValue(s.cycles)
            self.amp_spread.setValue(s.amplitude_spread)
            self.phase_spread.setValue(s.phase_spread)
            self.seed.setValue(s.seed)
        self._refresh()

    def error_text(self) -> str:
        """Why the current combination cannot make a cycle ("" when it can)."""
        return self._error

    @property
    def curves(self) -> list[NDArray]:
        return self.plot.curves

    def set_current_frame(self, frame: int | None) -> None:
        self.strip.set_current(frame)

    # -- live update -----------------------------------------------------------------------
    def _edited(self, *_: object) -> None:
        self._refresh()
        try:
            s = self.settings()
        except HairtoolError:
            return
        self.settings_changed.emit(s)

    def _refresh(self) -> None:
        try:
            s = self.settings()
            sched, x, y = wave_curves(s)
        except HairtoolError as e:
            self.schedule, self._error = None, str(e)
            self.plot.set_curves(None, None)
            self.strip.set_exposure(None, 0, 0)
            self.info.setText("")
        else:
            self.schedule, self._error = sched, ""
            self.plot.set_curves(x, y)
            shot = sched.shot_exposure(sched.n_frames * s.cycles)
            self.strip.set_exposure(shot, sched.n_pictures, sched.n_frames)
            holds = ",".join(map(str, sched.holds.tolist()))
            self.info.setText(
                f"{sched.n_frames} frames/cycle ({sched.cycle_seconds:.3f} s) · "
                f"{sched.n_pictures} pictures · Δt {sched.dt:.4g} s · K {sched.k} · holds {holds}"
            )
        self.error_label.setText(self._error)
        self.error_label.setVisible(bool(self._error))
        self.apply_button.setEnabled(not self._error)
