"""The tool dock: the align brush, every frozen-hair engine parameter, and the display settings.

Widgets write to the scene through the window (engine parameters become undo steps) and are
refreshed from the scene's signals with their own signals blocked, so nothing echoes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from PySide6.QtCore import Signal
from PySide6.QtWidgets import (
    QCheckBox,
    QComboBox,
    QDockWidget,
    QFormLayout,
    QGroupBox,
    QHBoxLayout,
    QSpinBox,
    QVBoxLayout,
    QWidget,
)

from app.render.ramps import RAMPS
from app.ui.qt_utils import signals_blocked
from app.ui.render_hair_box import RenderHairBox
from app.ui.scene import ALIGN_MODES, COLOUR_MODES, Scene
from app.ui.widgets import SliderSpin
from hairtool.frozen.pipeline import FrozenParams


@dataclass(frozen=True)
class ParamSpec:
    """How one FrozenParams field is edited: kind "float" | "angle" | "int" | "bool" | "choice"."""

    name: str
    label: str
    kind: str
    lo: float = 0.0
    hi: float = 1.0
    log: bool = False
    choices: tuple[str, ...] = ()
    tip: str = ""
    relative: bool = False  # lo and hi are fractions of the groom's extent (distances)


GAP_MODES = ("printed", "text", "off")
ENGINE_PARAMS: tuple[ParamSpec, ...] = (
    ParamSpec("freeze", "Freeze", "bool", tip="run FreezeDeform (stretch and bend noise)"),
    ParamSpec("stretch_stiffness", "Stretch k_s", "float", 1.0, 100.0, log=True, tip="eq. 3: ±1/k_s length"),
    ParamSpec("bend_stiffness", "Bend k_b", "float", 0.1, 100.0, log=True, tip="eq. 4: θ = θ_max/k_b·ξ"),
    ParamSpec("max_bend_angle", "θ_max (°)", "angle", 0.0, 180.0, tip="eq. 4; degrees here, radians inside"),
    ParamSpec(
        "strand_variation", "Strand variation", "float", 0.0, 4.0, tip="stiffness ×2^(±spread) per strand"
    ),
    ParamSpec("seed", "Seed", "int", 0, 2**31 - 1, tip="η, ξ, ζ are hashed from (seed, strand, vertex)"),
    ParamSpec(
        "redraw_noise", "Redraw noise", "bool", tip="new η, ξ every update (flickers, as in the paper)"
    ),
    ParamSpec("clump", "Clump", "bool", tip="run ClumpWithGaps"),
    ParamSpec("clump_radius", "Clump radius h", "optional", 1e-3, 0.5, log=True, relative=True, tip="eq. 14"),
    ParamSpec("clump_iterations", "Iterations k", "int", 0, 100, tip="eq. 16"),
    ParamSpec("clump_step", "Step Δt²/m", "optional", 1e-4, 0.5, log=True, relative=True, tip="eq. 16"),
    ParamSpec("gap_mode", "Gaps", "choice", choices=GAP_MODES, tip="eqs. 17–19: printed formula, text, off"),
    ParamSpec(
        "keep_lengths",
        "Keep lengths",
        "bool",
        tip="after clumping, every segment back to its length (ClumpWithGaps as printed stretches them)",
    ),
)


class ToolDock(QDockWidget):
    """Emits ``param_edited(name, value, drag)``; brush and display edits go to the scene directly."""

    param_edited = Signal(str, object, object)

    def __init__(self, scene: Scene, parent: QWidget | None = None) -> None:
        super().__init__("Tools", parent)
        self.setObjectName("ToolDock")
        self.scene = scene
        body = QWidget()
        layout = QVBoxLayout(body)
        layout.addWidget(self._brush_box())
        layout.addWidget(self._engine_box())
        layout.addWidget(self._display_box())
        layout.addWidget(RenderHairBox(scene))
        layout.addStretch(1)
        self.setWidget(body)
        scene.params_changed.connect(lambda _p: self.refresh_params())
        scene.tool_changed.connect(self.refresh_brush)
        scene.display_changed.connect(self.refresh_display)
        scene.groom_loaded.connect(self.refresh)
        self.refresh()

    # -- building --------------------------------------------------------------------------
    def _brush_box(self) -> QGroupBox:
        box = QGroupBox("Align brush")
        form = QFormLayout(box)
        self.radius = SliderSpin(0.001, 10.0, decimals=4, log=True)
        self.radius.edited.connect(lambda v, _d: self.scene.set_radius(v))
        self.intensity = SliderSpin(0.0, 1.0, decimals=2)
        self.intensity.edited.connect(lambda v, _d: self.scene.set_intensity(v))
        self.mode = QComboBox()
        for mode, label in zip(ALIGN_MODES, ("Paper (eq. 13)", "Length-preserving"), strict=True):
            self.mode.addItem(label, mode)
        self.mode.currentIndexChanged.connect(lambda i: self.scene.set_align_mode(self.mode.itemData(i)))
        form.addRow("Radius r", self.radius)
        form.addRow("Intensity x", self.intensity)
        form.addRow("Mode", self.mode)
        return box

    def _engine_box(self) -> QGroupBox:
        box = QGroupBox("Frozen hair")
        form = QFormLayout(box)
        self.params: dict[str, QWidget] = {}
        for spec in ENGINE_PARAMS:
            widget = self._param_widget(spec)
            widget.setToolTip(spec.tip)
            self.params[spec.name] = widget
            form.addRow(spec.label, widget)
        return box

    def _param_widget(self, spec: ParamSpec) -> QWidget:
        name = spec.name
        if spec.kind in ("float", "angle"):
            w = SliderSpin(spec.lo, spec.hi, decimals=3 if spec.kind == "float" else 1, log=spec.log)
            if spec.kind == "angle":
                w.edited.connect(lambda v, d: self.param_edited.emit(name, math.radians(v), d))
            else:
                w.edited.connect(lambda v, d: self.param_edited.emit(name, v, d))
            return w
        if spec.kind == "int":
            w = QSpinBox()
            w.setRange(int(spec.lo), int(spec.hi))
            w.setKeyboardTracking(False)
            w.valueChanged.connect(lambda v: self.param_edited.emit(name, int(v), None))
            return w
        if spec.kind == "bool":
            w = QCheckBox()
            w.toggled.connect(lambda v: self.param_edited.emit(name, bool(v), None))
            return w
        if spec.kind == "choice":
            w = QComboBox()
            w.addItems(list(spec.choices))
            w.currentTextChanged.connect(lambda v: self.param_edited.emit(name, v, None))
            return w
        if spec.kind == "optional":  # a value or None ("Auto")
            w = QWidget()
            row = QHBoxLayout(w)
            row.setContentsMargins(0, 0, 0, 0)
            w.auto = QCheckBox("Auto")
            w.value = SliderSpin(spec.lo, spec.hi, decimals=4, log=spec.log)
            row.addWidget(w.auto)
            row.addWidget(w.value, 1)

            def emit(_=None, drag=None) -> None:
                w.value.setEnabled(not w.auto.isChecked())
                self.param_edited.emit(name, None if w.auto.isChecked() else w.value.value(), drag)

            w.auto.toggled.connect(lambda _v: emit())
            w.value.edited.connect(lambda _v, d: emit(drag=d))
            return w
        raise ValueError(f"unknown parameter kind {spec.kind!r}")

    def _display_box(self) -> QGroupBox:
        box = QGroupBox("Display")
        form = QFormLayout(box)
        self.colour_mode = QComboBox()
        for key, label in COLOUR_MODES.items():
            self.colour_mode.addItem(label, key)
        self.colour_mode.currentIndexChanged.connect(
            lambda i: self.scene.set_colour_mode(self.colour_mode.itemData(i))
        )
        self.ramp = QComboBox()
        self.ramp.addItems(list(RAMPS))
        self.ramp.currentTextChanged.connect(self.scene.set_ramp)
        self.line_width = SliderSpin(0.5, 10.0, decimals=1)
        self.line_width.edited.connect(lambda v, _d: self.scene.set_line_width(v))
        form.addRow("Colour by", self.colour_mode)
        form.addRow("Ramp", self.ramp)
        form.addRow("Line width", self.line_width)
        return box

    # -- scene → widgets ------------------------------------------------------------------------
    def refresh(self) -> None:
        self.refresh_brush()
        self.refresh_params()
        self.refresh_display()

    def refresh_brush(self) -> None:
        s = self.scene
        lo, hi = s.rest.bounds
        extent = max(float((hi - lo).max()), 1e-3)
        with signals_blocked(self.radius, self.intensity, self.mode):
            self.radius.set_range(extent * 1e-3, extent * 2.0)
            self.radius.set_value(s.radius)
            self.intensity.set_value(s.intensity)
            self.mode.setCurrentIndex(self.mode.findData(s.align_mode))

    def refresh_params(self) -> None:
        p: FrozenParams = self.scene.params
        lo, hi = self.scene.rest.bounds
        extent = max(float((hi - lo).max()), 1e-6)
        for spec in ENGINE_PARAMS:
            w = self.params[spec.name]
            value = getattr(p, spec.name)
            with signals_blocked(w):
                if spec.kind == "float" and np.ndim(value) != 0:  # per-strand array set from code
                    w.setEnabled(False)
                elif spec.kind == "float":
                    w.setEnabled(True)
                    if spec.relative:
                        w.set_range(spec.lo * extent, spec.hi * extent)
                    w.set_value(float(value))
                elif spec.kind == "angle":
                    w.set_value(math.degrees(float(value)))
                elif spec.kind == "int":
                    w.setValue(int(value))
                elif spec.kind == "bool":
                    w.setChecked(bool(value))
                elif spec.kind == "choice":
                    w.setCurrentText(str(value))
                elif spec.kind == "optional":
                    with signals_blocked(w.auto, w.value):
                        if spec.relative:
                            w.value.set_range(spec.lo * extent, spec.hi * extent)
                        w.auto.setChecked(value is None)
                        w.value.setEnabled(value is not None)
                        if value is not None:
                            w.value.set_value(float(value))
                        else:  # "Auto": show the value the engine uses (unticking starts there)
                            w.value.set_value(float(getattr(self.scene.pipeline, spec.name)))

    def refresh_display(self) -> None:
        s = self.scene
        with signals_blocked(self.colour_mode, self.ramp, self.line_width):
            self.colour_mode.setCurrentIndex(self.colour_mode.findData(s.colour_mode))
            self.ramp.setCurrentText(s.ramp)
            self.line_width.set_value(s.line_width)
