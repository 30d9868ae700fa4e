"""The timeline dock: transport buttons, the scrubbable ruler with the DP and uniform key rows
and the error/speed curves, the key controls and the error-versus-key-count plot.

Widgets write to the :class:`AnimationModel` and are refreshed from its signals with their own
signals blocked, so nothing echoes. The transport buttons show the window's actions (Space,
arrows, Home/End), so a button and its shortcut are one thing.
"""

from __future__ import annotations

from collections.abc import Callable

from PySide6.QtCore import Qt
from PySide6.QtGui import QAction
from PySide6.QtWidgets import (
    QComboBox,
    QDockWidget,
    QDoubleSpinBox,
    QFormLayout,
    QHBoxLayout,
    QLabel,
    QMainWindow,
    QSlider,
    QSpinBox,
    QSplitter,
    QToolButton,
    QVBoxLayout,
    QWidget,
)

from app.ui.animation_model import VIEW_MODES, AnimationModel
from app.ui.qt_utils import signals_blocked
from app.ui.timeline_plots import KEY_LEGEND, KeyCountPlot, TimelineView
from app.ui.widgets import SliderSpin, scrolling
from hairtool.errors import HairtoolError
from hairtool.keys.session import KEY_MODES

#: The key modes as the timeline names them.
MODE_LABELS = {"count": "Key count", "tau": "Price per key (tau)", "budget": "Error budget"}
TAU_RANGE = (1e-5, 1.0)  # a key's price as a share of the two-key error

UNFOLDED_HEIGHT = 300  # px the timeline takes when an animation opens (the artist may drag it)
FOLDED_MARGIN = 6  # px beside the transport bar when folded

TRANSPORT = (
    "first",
    "previous_key",
    "step_back",
    "play",
    "step_forward",
    "next_key",
    "last",
    "loop",
    "record",
)


SUMMARY_TIP = (
    "Solved key error: what the keys minimise, E = Σ e_ij over the key segments (the worst "
    "frame: max e_ij), with e_ij = Σ_f ‖x_f − x̂_f‖² over the frames f between keys i and j, in "
    "seed 000's feature space (M points per strand by arc length, mean root removed, relative to "
    "each root, weighted root to tip; plus λ times the curvature term). Pins and moves can only "
    "raise it. Mean and tip distance: |p − p̂| on the original vertices (tips alone), averaged "
    "over vertices and frames, in scene units. The solve does not minimise them, so steering a "
    "key may lower them while E rises."
)


class KeyControls(QWidget):
    """Mode (count / tau / budget), the key-count slider, tau, budget, objective, interpolation,
    feature settings and the view mode."""

    def __init__(
        self, model: AnimationModel, report: Callable[[str, str], None], parent: QWidget | None = None
    ) -> None:
        super().__init__(parent)
        self.model = model
        self.report = report
        form = QFormLayout(self)
        form.setContentsMargins(4, 2, 4, 2)
        form.setVerticalSpacing(2)
        self.mode = QComboBox()
        for key in KEY_MODES:
            self.mode.addItem(MODE_LABELS[key], key)
        self.count_slider = QSlider(Qt.Orientation.Horizontal)
        self.count_slider.setObjectName("KeyCountSlider")
        self.count_spin = QSpinBox()
        row = QHBoxLayout()
        row.addWidget(self.count_slider, 3)
        row.addWidget(self.count_spin, 1)
        self.tau = SliderSpin(TAU_RANGE[0], TAU_RANGE[1], decimals=6, log=True)
        self.budget = SliderSpin(1e-6, 1e3, decimals=6, log=True)
        self.objective = QComboBox()
        self.objective.addItem("Total error", "total")
        self.objective.addItem("Worst frame", "worst")
        self.interp = QComboBox()
        self.interp.addItem("Linear", "linear")
        self.interp.addItem("Hermite (tangents from the data)", "hermite")
        self.interp.addItem("Hermite (fitted handles)", "hermite-fit")
        self.interp.setToolTip(
            "how the frames between keys are rebuilt: straight lines (seed 000), cubic Hermite with "
            "tangents from the neighbouring frames (seed 003), or cubic Hermite with each segment's "
            "handles fitted by least squares, as a DCC's free Bezier handles"
        )
        self.samples = QSpinBox()
        self.samples.setRange(0, 256)
        self.samples.setSpecialValueText("vertices")
        self.samples.setToolTip("points per strand by arc length (seed 000, step 1); 0 keeps the vertices")
        self.tip_weight = QDoubleSpinBox()
        self.tip_weight.setRange(0.1, 20.0)
        self.tip_weight.setSingleStep(0.25)
        self.tip_weight.setToolTip("root-to-tip weight at the tip (1 at the root): tip motion counts more")
        self.curvature = QDoubleSpinBox()
        self.curvature.setDecimals(4)
        self.curvature.setRange(0.0, 1000.0)
        self.curvature.setStepType(QDoubleSpinBox.StepType.AdaptiveDecimalStepType)
        self.curvature.setToolTip(
            "weight λ of the curvature term (seed 000): short, sharp deformations cost more to skip"
        )
        self.view = QComboBox()
        self.view.setObjectName("ViewMode")
        for key, label in VIEW_MODES.items():
            self.view.addItem(label, key)
        for w in (self.samples, self.tip_weight, self.curvature, self.count_spin):
            w.setKeyboardTracking(False)
        form.addRow("Keys by", self.mode)
        form.addRow("Key count", row)
        self.tau.setToolTip(
            "price of one more key, as a share of the error of keying only the first and last frame: "
            "a key stays when it saves at least that much (seed 003's tau, scaled by the two-key error)"
        )
        form.addRow("Price per key", self.tau)
        form.addRow("Error budget", self.budget)
        form.addRow("Objective", self.objective)
        form.addRow("Interpolation", self.interp)
        form.addRow("Samples / strand", self.samples)
        form.addRow("Tip weight", self.tip_weight)
        form.addRow("Curvature weight", self.curvature)
        form.addRow("View", self.view)
        self.summary = QLabel()
        self.summary.setObjectName("KeySummary")
        self.summary.setWordWrap(True)
        self.summary.setToolTip(SUMMARY_TIP)
        form.addRow(self.summary)

        self.mode.activated.connect(lambda _i: self._set_mode(self.mode.currentData()))
        self._count_drags = 0  # one undo step per drag of the key-count slider
        self.count_slider.sliderPressed.connect(self._count_drag)
        self.count_slider.valueChanged.connect(
            lambda v: self._set("Key count", self._count_dragged(), mode="count", count=int(v))
        )
        self.count_spin.valueChanged.connect(lambda v: self._set("Key count", mode="count", count=int(v)))
        self.tau.edited.connect(lambda v, d: self._set("Price per key", d, mode="tau", tau=float(v)))
        self.budget.edited.connect(lambda v, d: self._set("Error budget", d, mode="budget", budget=float(v)))
        self.objective.activated.connect(
            lambda _i: self._set("Objective", objective=self.objective.currentData())
        )
        self.interp.activated.connect(lambda _i: self._set("Interpolation", interp=self.interp.currentData()))
        self.samples.valueChanged.connect(lambda v: self._set("Samples per strand", samples=int(v)))
        self.tip_weight.valueChanged.connect(lambda v: self._set("Tip weight", tip_weight=float(v)))
        self.curvature.valueChanged.connect(lambda v: self._set("Curvature", curvature=float(v)))
        self.view.activated.connect(lambda _i: self._set_view(self.view.currentData()))
        for signal in (
            model.settings_changed,
            model.keys_changed,
            model.curve_changed,
            model.animation_changed,
        ):
            signal.connect(self.refresh)
        model.view_mode_changed.connect(self.refresh)
        model.analysis_changed.connect(self._refresh_summary)
        model.busy_changed.connect(self._refresh_summary)
        self.refresh()

    def _count_drag(self) -> None:
        self._count_drags += 1

    def _count_dragged(self) -> object:
        """The drag the key-count slider's move belongs to (None: a click or a key press)."""
        return ("key count", id(self), self._count_drags) if self.count_slider.isSliderDown() else None

    def _set(self, text: str = "", drag: object = None, **changes: object) -> None:
        """One step of the document (the moves of one slider drag merge into one)."""
        try:
            self.model.set_settings(text, drag, **changes)
        except HairtoolError as e:
            self.report("Invalid key setting", str(e))
            self.refresh()

    def _set_mode(self, mode: str) -> None:
        """Switching to the error budget starts from the current keys' error, so the keys stay."""
        solved = self.model.key_errors()
        if mode == "budget" and self.model.settings.mode != "budget" and solved is not None:
            self._set("Key mode", mode="budget", budget=solved[0])
        else:
            self._set("Key mode", mode=mode)

    def budget_shown(self) -> float:
        """The budget field: the budget itself in budget mode; otherwise the current keys' solved
        error (in the units of the current interpolation's table), which is the budget that
        keeps them, so the field never shows a figure of another table or a clamped default."""
        s, solved = self.model.settings, self.model.key_errors()
        return s.budget if s.mode == "budget" or solved is None else solved[0]

    def _set_view(self, mode: str) -> None:
        self.model.set_view_mode(mode)

    def refresh(self, *_: object) -> None:
        m, s = self.model, self.model.settings
        widgets = (
            self.mode, self.count_slider, self.count_spin, self.tau, self.tau.slider, self.tau.spin,
            self.budget, self.budget.slider, self.budget.spin, self.objective, self.interp,
            self.samples, self.tip_weight, self.curvature, self.view,
        )  # fmt: skip
        with signals_blocked(*widgets):
            self.mode.setCurrentIndex(self.mode.findData(s.mode))
            least, top = m.key_solve.key_range if m.key_solve is not None else (2, max(m.max_keys, 2))
            count = m.dp_keys.size if m.dp_keys is not None else max(s.count, 2)
            for w in (self.count_slider, self.count_spin):
                w.setRange(least, top)
                w.setValue(min(max(count, least), top))
            if m.key_solve is not None:  # the budget's range follows the error scale; tau is relative
                curve = m.key_solve.curve[:, 1]
                positive = curve[curve > 0]
                lo = max(float(positive.min()) * 0.1, 1e-9) if positive.size else 1e-6
                hi = max(float(curve.max()) * 2.0, lo * 10.0)
                shown = self.budget_shown()  # within the range: never clamped to another value
                self.budget.set_range(min(lo, shown) if shown > 0 else lo, max(hi, shown))
            self.tau.set_value(s.tau)
            self.budget.set_value(self.budget_shown())
            self.objective.setCurrentIndex(self.objective.findData(s.objective))
            self.interp.setCurrentIndex(self.interp.findData(s.interp))
            self.samples.setValue(s.samples)
            self.tip_weight.setValue(s.tip_weight)
            self.curvature.setValue(s.curvature)
            self.view.setCurrentIndex(self.view.findData(m.view_mode))
        enabled = m.n_frames >= 2
        for w in widgets:
            w.setEnabled(enabled)
        self.view.setEnabled(m.n_frames >= 1)
        self._refresh_summary()

    def _refresh_summary(self, *_: object) -> None:
        m = self.model
        if m.n_frames < 2:
            self.summary.setText("")
            return
        if m.dp_keys is None:
            self.summary.setText("solving keys…" if m.busy else "no keys")
            return
        text = f"{m.dp_keys.size} keys of {m.n_frames} frames"
        solved = m.key_errors()
        if solved is not None:
            worst = "worst-frame " if m.key_solve.objective == "worst" else ""
            text += f" · solved {worst}key error {solved[0]:.4g} (uniform keys {solved[1]:.4g})"
        a = m.analysis
        if a is not None:
            text += (
                f" · mean distance DP {a.dp.mean.mean():.4g} / uniform {a.uniform.mean.mean():.4g}"
                f" · tip DP {a.dp.tip.mean():.4g} / uniform {a.uniform.tip.mean():.4g}"
            )
        if m.settings.constraints:
            text += " · the uniform keys ignore the pins and exclusions"
        if m.solve_stale:
            text += " · edited since the solve"
        if m.busy:
            text += " · working…"
        self.summary.setText(text)


class TimelineDock(QDockWidget):
    """Bottom dock: transport row, the timeline view, key controls and the key-count plot."""

    def __init__(
        self,
        model: AnimationModel,
        actions: dict[str, QAction],
        report: Callable[[str, str], None],
        parent: QWidget | None = None,
        steer: Callable[..., bool] | None = None,
    ) -> None:
        """``steer(text, **edit)``: one undoable dope-sheet edit (the animation controller's)."""
        super().__init__("Timeline", parent)
        self.setObjectName("TimelineDock")
        self.model = model
        body = QWidget()
        outer = QVBoxLayout(body)
        outer.setContentsMargins(2, 2, 2, 2)
        outer.setSpacing(2)

        transport = QHBoxLayout()
        self.buttons: dict[str, QToolButton] = {}
        for name in TRANSPORT:
            if name in actions:
                b = QToolButton()
                b.setDefaultAction(actions[name])
                b.setObjectName(f"Transport_{name}")
                self.buttons[name] = b
                transport.addWidget(b)
        self.frame_spin = QSpinBox()
        self.frame_spin.setPrefix("frame ")
        self.frame_spin.setKeyboardTracking(False)
        self.fps_spin = QDoubleSpinBox()
        self.fps_spin.setRange(0.1, 1000.0)
        self.fps_spin.setDecimals(2)
        self.fps_spin.setSuffix(" fps")
        self.fps_spin.setKeyboardTracking(False)
        self.info = QLabel()
        transport.addSpacing(8)
        transport.addWidget(self.frame_spin)
        transport.addWidget(self.fps_spin)
        transport.addWidget(self.info, 1)
        outer.addLayout(transport)

        split = QSplitter(Qt.Orientation.Horizontal)
        self.view = TimelineView(model, steer=steer)
        self.legend = QLabel(KEY_LEGEND)  # what the dope sheet's marks mean, the red cross too
        self.legend.setObjectName("KeyLegend")
        self.legend.setWordWrap(True)
        self.legend.setStyleSheet("color: #9aa0a8; font-size: 8pt")
        sheet = QWidget()
        sheet_layout = QVBoxLayout(sheet)
        sheet_layout.setContentsMargins(0, 0, 0, 0)
        sheet_layout.setSpacing(1)
        sheet_layout.addWidget(self.view, 1)
        sheet_layout.addWidget(self.legend)
        side = QWidget()
        side_layout = QVBoxLayout(side)
        side_layout.setContentsMargins(0, 0, 0, 0)
        self.controls = KeyControls(model, report)
        self.plot = KeyCountPlot(model)
        side_layout.addWidget(self.controls)
        side_layout.addWidget(self.plot, 1)
        split.addWidget(sheet)
        split.addWidget(scrolling(side))  # a short screen scrolls the key controls
        split.setChildrenCollapsible(False)
        self.split = split
        split.setStretchFactor(0, 3)
        split.setStretchFactor(1, 1)
        outer.addWidget(split, 1)
        self.setWidget(body)

        self.frame_spin.valueChanged.connect(model.set_frame)
        self.fps_spin.valueChanged.connect(self._set_fps)
        self._report = report
        for signal in (model.animation_changed, model.frame_changed, model.fps_changed):
            signal.connect(self.refresh)
        self.refresh()

    def _set_fps(self, fps: float) -> None:
        try:
            self.model.set_fps(fps)
        except HairtoolError as e:
            self._report("Invalid frame rate", str(e))
            self.refresh()

    def refresh(self, *_: object) -> None:
        m = self.model
        with signals_blocked(self.frame_spin, self.fps_spin):
            self.frame_spin.setRange(0, m.last_frame)
            self.frame_spin.setValue(m.frame)
            self.fps_spin.setValue(m.fps)
        self.frame_spin.setEnabled(m.n_frames > 0)
        if m.n_frames:
            self.info.setText(f"/ {m.last_frame} · {m.frame / m.fps:.2f} s · {m.source}")
        else:
            self.info.setText("no animation: open one, Apply to groom (Anime wave) or Animation → Simulate…")
        self.set_folded(m.n_frames == 0)

    @property
    def folded(self) -> bool:
        """True while only the transport bar shows (no animation to draw a timeline for)."""
        return self.split.isHidden()

    def set_folded(self, folded: bool) -> None:
        """Fold the dock to its transport bar, or unfold it to the timeline and key controls,
        handing the height to or taking it from the viewport."""
        if folded == self.folded:
            return
        self.split.setHidden(folded)
        self.fit_height()

    def fit_height(self) -> None:
        """Give the docked timeline the height its state wants: the transport bar when folded,
        :data:`UNFOLDED_HEIGHT` otherwise (the window calls this after restoring a layout)."""
        window = self.parentWidget()
        if not isinstance(window, QMainWindow) or self.isFloating() or not self.isVisible():
            return
        vertical = (Qt.DockWidgetArea.TopDockWidgetArea, Qt.DockWidgetArea.BottomDockWidgetArea)
        if window.dockWidgetArea(self) not in vertical:
            return
        minimum = self.widget().minimumSizeHint().height()
        height = minimum + FOLDED_MARGIN if self.folded else max(UNFOLDED_HEIGHT, minimum)
        window.resizeDocks([self], [height], Qt.Orientation.Vertical)
