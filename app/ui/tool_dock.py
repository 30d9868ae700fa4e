"""The tool dock: the brush (size, strength, falloff curve, symmetry, front faces only), every
frozen-hair engine parameter, and the display settings.

Widgets write to the scene through the window (engine parameters become undo steps) and are
refreshed from the scene's signals with their own signals blocked, so nothing echoes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from PySide6.QtCore import Qt, Signal
from PySide6.QtWidgets import (
    QCheckBox,
    QComboBox,
    QDockWidget,
    QDoubleSpinBox,
    QFormLayout,
    QGroupBox,
    QHBoxLayout,
    QPushButton,
    QSpinBox,
    QToolButton,
    QVBoxLayout,
    QWidget,
)

from app.render.ramps import RAMPS
from app.ui.brush_tool import (
    FALLOFF_LABELS,
    LABELS,
    SHORTCUTS,
    SIGN_LABELS,
    SIGNED,
    STRENGTHLESS,
    TIPS,
    brushes,
)
from app.ui.falloff_editor import FalloffEditor
from app.ui.qt_utils import signals_blocked
from app.ui.render_hair_box import RenderHairBox
from app.ui.scene import ALIGN_MODES, COLOUR_MODES, Scene
from app.ui.widgets import SliderSpin, scrolling
from hairtool.frozen.brushes import MOVE_NONE, registry
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
    choices: tuple[tuple[str, str], ...] = ()  # (value, label)
    tip: str = ""
    relative: bool = False  # lo and hi are fractions of the groom's extent (distances)


#: How ClumpWithGaps keeps gaps, in the artist's words (the paper's eqs. 17–19 in the tooltip).
GAP_MODES = (("printed", "Sharp edges (as printed)"), ("text", "Soft edges (as described)"), ("off", "Off"))
ENGINE_PARAMS: tuple[ParamSpec, ...] = (
    ParamSpec("freeze", "Stylised noise", "bool", tip="FreezeDeform, eqs. 2–7: random stretch, bend"),
    ParamSpec(
        "stretch_stiffness", "Stiffness (stretch)", "float", 1.0, 100.0, log=True,
        tip="k_s, eq. 3: each segment's length varies by up to ±1/k_s; higher keeps lengths closer",
    ),
    ParamSpec(
        "bend_stiffness", "Stiffness (bend)", "float", 0.1, 100.0, log=True,
        tip="k_b, eq. 4: bend angle θ = θ_max / k_b · ξ; higher bends less",
    ),
    ParamSpec(
        "max_bend_angle", "Max bend angle (°)", "angle", 0.0, 180.0,
        tip="θ_max, eq. 4: the largest bend of one segment (degrees here, radians inside)",
    ),
    ParamSpec(
        "strand_variation", "Stiffness variation", "float", 0.0, 4.0,
        tip="each strand's stiffnesses k_s, k_b multiplied by 2^(±spread): some strands wilder than others",
    ),
    ParamSpec(
        "seed", "Random seed", "int", 0, 2**31 - 1,
        tip="the noise η, ξ, ζ is hashed from (seed, strand, vertex): the same seed, the same look",
    ),
    ParamSpec(
        "redraw_noise", "New noise every update", "bool",
        tip="draw η, ξ afresh at every update (flickers while dragging, as in the paper)",
    ),
    ParamSpec("clump", "Clumps", "bool", tip="ClumpWithGaps, eqs. 14–19: strands pulled into clumps"),
    ParamSpec(
        "clump_radius", "Clump size", "optional", 1e-3, 0.5, log=True, relative=True,
        tip="h, eq. 14: how far apart strands may be and still clump together (groom units)",
    ),
    ParamSpec(
        "clump_iterations", "Clump passes", "int", 0, 100,
        tip="k, eq. 16: how many times strands are pulled toward their clump",
    ),
    ParamSpec(
        "clump_step", "Clump strength", "optional", 1e-4, 0.5, log=True, relative=True,
        tip="Δt²/m, eq. 16: how far each pass pulls a strand toward its clump (groom units)",
    ),
    ParamSpec(
        "gap_mode", "Keep gaps between clumps", "choice", choices=GAP_MODES,
        tip="eqs. 17–19, δ = clamp((r1 − r0)/h, 0, 1): λ = (1 − δ)ζ + δ as printed (sharp edges), "
        "λ = (1 − δ)ζ with |r1 − r0| as the text says (soft edges), or no gaps",
    ),
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
        self._layout = layout
        self.setWidget(scrolling(body))
        scene.params_changed.connect(lambda _p: self.refresh_params())
        scene.tool_changed.connect(self.refresh_brush)
        scene.display_changed.connect(self.refresh_display)
        scene.groom_loaded.connect(self.refresh)
        self.refresh()

    # -- building --------------------------------------------------------------------------
    def _brush_box(self) -> QGroupBox:
        box = QGroupBox("Brush")
        form = self._brush_form = QFormLayout(box)
        self.brush = QComboBox()
        for name in brushes():
            self.brush.addItem(f"{LABELS.get(name, name)}  ({SHORTCUTS.get(name, '')})", name)
            self.brush.setItemData(self.brush.count() - 1, TIPS.get(name, ""), Qt.ItemDataRole.ToolTipRole)
        self.brush.currentIndexChanged.connect(lambda i: self.scene.set_brush(self.brush.itemData(i)))
        self.radius = SliderSpin(0.001, 10.0, decimals=4, log=True)
        self.radius.edited.connect(lambda v, _d: self.scene.set_radius(v))
        self.radius.setToolTip("strands within this distance of the cursor are brushed ([ / ], Ctrl+wheel); "
                               "r, eqs. 8–9 for align")  # fmt: skip
        self.intensity = SliderSpin(0.0, 1.0, decimals=2)
        self.intensity.edited.connect(lambda v, _d: self.scene.set_intensity(v))
        self.mode = QComboBox()
        for mode, label in zip(ALIGN_MODES, ("Follow the cursor", "Keep strand lengths"), strict=True):
            self.mode.addItem(label, mode)
        self.mode.setToolTip(
            "Follow the cursor: UserAlign as printed (eq. 13), strands may stretch; "
            "Keep strand lengths: the same turn with every segment's length kept"
        )
        self.mode.currentIndexChanged.connect(lambda i: self.scene.set_align_mode(self.mode.itemData(i)))
        self.sign = QComboBox()
        self.sign.addItems(["", ""])
        self.sign.setToolTip("Ctrl while dragging does the other (as in Blender)")
        self.sign.currentIndexChanged.connect(lambda i: self.scene.set_subtract(self.scene.brush, i == 1))
        self.falloff = QComboBox()
        for key, label in FALLOFF_LABELS.items():
            self.falloff.addItem(label, key)
        self.falloff.addItem("Custom curve", None)
        self.falloff.setToolTip("how the strength fades from the brush's centre to its rim")
        self.falloff.currentIndexChanged.connect(self._on_falloff_preset)
        self.curve = FalloffEditor()
        self.curve.curve_edited.connect(self.scene.set_falloff)
        self.symmetry = QCheckBox("X mirror")
        self.symmetry.setToolTip("every stroke is mirrored across the plane x = … (Shift+X)")
        self.symmetry.toggled.connect(self.scene.set_symmetry)
        self.mirror_x = QDoubleSpinBox()
        self.mirror_x.setDecimals(4)
        self.mirror_x.setKeyboardTracking(False)
        self.mirror_x.setToolTip(
            "x of the mirror plane (default: through the centre of the sphere fitted to the roots)"
        )
        self.mirror_x.valueChanged.connect(lambda v: self.scene.set_mirror_x(float(v)))
        self.mirror_centre = QPushButton("Centre")
        self.mirror_centre.setToolTip("the mirror plane back through the head's centre")
        self.mirror_centre.clicked.connect(lambda: self.scene.set_mirror_x(None))
        mirror_row = QWidget()
        row = QHBoxLayout(mirror_row)
        row.setContentsMargins(0, 0, 0, 0)
        row.addWidget(self.symmetry)
        row.addWidget(self.mirror_x, 1)
        row.addWidget(self.mirror_centre)
        self.front_only = QCheckBox("Front faces only")
        self.front_only.setToolTip(
            "brush only the strands whose roots face the camera (the hair behind the head is left alone)"
        )
        self.front_only.toggled.connect(self.scene.set_front_only)
        self.collide = QCheckBox("Keep out of the head")
        self.collide.setToolTip(
            "with a head mesh loaded, no point of a brushed strand ends inside the head (pushed out "
            "along the surface normal, lengths kept); each brush has its own"
        )
        self.collide.toggled.connect(self.scene.set_collide)
        self.add_count = QSpinBox()
        self.add_count.setRange(1, 1000)
        self.add_count.setToolTip("how many strands the add brush plants at each mouse move")
        self.add_count.valueChanged.connect(self.scene.set_add_count)
        self.delete_rule = QComboBox()
        self.delete_rule.addItem("Any part under the brush", True)
        self.delete_rule.addItem("Root under the brush", False)
        self.delete_rule.setToolTip(
            "which strands delete removes: every strand with any segment under the brush "
            "(as Blender), or only those whose root is"
        )
        self.delete_rule.currentIndexChanged.connect(
            lambda i: self.scene.set_delete_any_segment(bool(self.delete_rule.itemData(i)))
        )
        self.spacing = QDoubleSpinBox()
        self.spacing.setDecimals(4)
        self.spacing.setKeyboardTracking(False)
        self.spacing.setToolTip(
            "the density brush leaves roots this far apart (groom units): no two closer, "
            "no gap wider than twice it"
        )
        self.spacing.valueChanged.connect(lambda x: self.scene.set_spacing(float(x)))
        self.pressure_radius = self._pressure_button(
            "radius", "a pen's pressure scales the brush size (a light touch: a smaller brush; "
            "each brush its own; a mouse always presses fully)",
        )  # fmt: skip
        self.pressure_strength = self._pressure_button(
            "strength", "a pen's pressure scales the strength (a light touch: a gentler brush; "
            "each brush its own; a mouse always presses fully)",
        )  # fmt: skip
        self.radius_row = self._with_button(self.radius, self.pressure_radius)
        self.intensity_row = self._with_button(self.intensity, self.pressure_strength)
        form.addRow("Brush", self.brush)
        form.addRow("Brush size", self.radius_row)
        form.addRow("Strength", self.intensity_row)
        form.addRow("Mode", self.mode)
        form.addRow("Direction", self.sign)
        form.addRow("Strands per move", self.add_count)
        form.addRow("Spacing", self.spacing)
        form.addRow("Removes", self.delete_rule)
        form.addRow("Falloff", self.falloff)
        form.addRow(self.curve)
        form.addRow("Symmetry", mirror_row)
        form.addRow(self.front_only)
        form.addRow(self.collide)
        return box

    def _pressure_button(self, what: str, tip: str) -> QToolButton:
        """A toggle beside a slider, as Blender's pressure buttons: the pen scales ``what``."""
        button = QToolButton()
        button.setText("Pen")
        button.setCheckable(True)
        button.setToolTip(tip)
        button.setObjectName(f"pressure_{what}")
        button.toggled.connect(lambda on: self.scene.set_pressure(what, on))
        return button

    @staticmethod
    def _with_button(slider: QWidget, button: QWidget) -> QWidget:
        row = QWidget()
        layout = QHBoxLayout(row)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.addWidget(slider, 1)
        layout.addWidget(button)
        return row

    def add_group(self, box: QWidget) -> None:
        """Another group (the Selection's, :mod:`app.ui.selection_ui`) after the Brush group."""
        self._layout.insertWidget(1, box)

    def _on_falloff_preset(self, i: int) -> None:
        key = self.falloff.itemData(i)
        self.scene.set_falloff(key if key is not None else self.curve.points())

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
            for value, label in spec.choices:
                w.addItem(label, value)
            w.currentIndexChanged.connect(lambda i: self.param_edited.emit(name, w.itemData(i), None))
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
        tool = s.tool
        lo, hi = s.rest.bounds
        extent = max(float((hi - lo).max()), 1e-3)
        widgets = (self.brush, self.radius, self.intensity, self.mode, self.sign, self.falloff, self.curve)
        more = (
            self.symmetry, self.mirror_x, self.front_only, self.collide, self.add_count, self.spacing,
            self.delete_rule,
        )  # fmt: skip
        pens = (self.pressure_radius, self.pressure_strength)
        with signals_blocked(*widgets, *more, *pens):
            self.brush.setCurrentIndex(self.brush.findData(s.brush))
            self.radius.set_range(extent * 1e-3, extent * 2.0)
            self.radius.set_value(s.radius)
            self.intensity.set_value(s.intensity)
            self.intensity.setToolTip(
                "x, eq. 13: how far the strands turn toward the drag (0 none, 1 fully)"
                if s.brush == "align"
                else "how strongly each mouse move acts at the brush's centre (0 none, 1 fully)"
            )
            self.mode.setCurrentIndex(self.mode.findData(s.align_mode))
            labels = SIGNED.get(s.brush)
            if labels is not None:
                for i, label in enumerate(labels):
                    self.sign.setItemText(i, label)
                self.sign.setCurrentIndex(1 if tool.subtract[s.brush] else 0)
                self._brush_form.labelForField(self.sign).setText(SIGN_LABELS[s.brush])
            self._brush_form.setRowVisible(self.mode, s.brush == "align")
            spec = registry.spec_of(s.brush)
            fields = {p.field for p in spec.params}
            on_or_off = spec.signed and not spec.takes_strength  # the sign says it all
            self._brush_form.setRowVisible(self.intensity_row, not on_or_off)
            self.pressure_radius.setChecked(tool.pressure_radius.get(s.brush, False))
            self.pressure_strength.setChecked(tool.pressure_strength.get(s.brush, False))
            self.pressure_strength.setVisible(s.brush not in STRENGTHLESS)
            self._brush_form.setRowVisible(self.sign, labels is not None)
            custom = not isinstance(tool.falloff, str)
            preset = self.falloff.count() - 1 if custom else self.falloff.findData(tool.falloff)
            self.falloff.setCurrentIndex(preset)
            self.curve.set_falloff(tool.falloff)
            for w in (self.falloff, self.curve):  # align weighs by the paper's own rule
                w.setEnabled(s.brush != "align")
            self.symmetry.setChecked(tool.symmetry)
            self.mirror_x.setRange(float(lo[0]) - extent, float(hi[0]) + extent)
            self.mirror_x.setSingleStep(extent / 100.0)
            self.mirror_x.setValue(s.mirror_plane_x())
            self.front_only.setChecked(tool.front_only)
            self.collide.setChecked(tool.collide.get(s.brush, True))
            self._brush_form.setRowVisible(self.collide, s.brush not in MOVE_NONE)
            self.add_count.setValue(tool.add_count)
            self._brush_form.setRowVisible(self.add_count, "count" in fields)
            self.spacing.setRange(extent * 1e-4, extent)
            self.spacing.setSingleStep(extent / 200.0)
            self.spacing.setValue(tool.spacing)
            self._brush_form.setRowVisible(self.spacing, "spacing" in fields)
            self.delete_rule.setCurrentIndex(self.delete_rule.findData(tool.delete_any_segment))
            self._brush_form.setRowVisible(self.delete_rule, "any_segment" in fields)

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
                    w.setCurrentIndex(w.findData(str(value)))
                elif spec.kind == "optional":
                    with signals_blocked(w.auto, w.value):
                        if spec.relative:
                            w.value.set_range(spec.lo * extent, spec.hi * extent)
                        w.auto.setChecked(value is None)
                        w.value.setEnabled(value is not None)
                        if value is not None:
                            w.value.set_value(float(value))
                        elif self.scene.pipeline is not None:  # "Auto": the engine's value
                            w.value.set_value(float(getattr(self.scene.pipeline, spec.name)))

    def refresh_display(self) -> None:
        s = self.scene
        with signals_blocked(self.colour_mode, self.ramp, self.line_width):
            self.colour_mode.setCurrentIndex(self.colour_mode.findData(s.colour_mode))
            self.ramp.setCurrentText(s.ramp)
            self.line_width.set_value(s.line_width)
