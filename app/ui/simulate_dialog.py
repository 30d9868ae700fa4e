"""The Simulate… dialog: the parameters of :func:`hairtool.simulate.dynamics.simulate` (head motion, wind
and gusts, timing, forces, head sphere) and the job that runs it.

API: ``SimulateDialog(parent, options)``; ``options() -> SimulateOptions`` (ParameterError for a
bad motion or vector) and ``set_options``. :func:`run_simulation` is the job body for
``window.jobs.run``: it reports progress per frame and stops as soon as the job is cancelled.
"""

from __future__ import annotations

from PySide6.QtWidgets import (
    QCheckBox,
    QDialog,
    QDialogButtonBox,
    QDoubleSpinBox,
    QFormLayout,
    QGroupBox,
    QHBoxLayout,
    QLabel,
    QLineEdit,
    QPushButton,
    QSpinBox,
    QVBoxLayout,
    QWidget,
)

from hairtool.errors import ParameterError
from hairtool.groom import Groom
from hairtool.simulate.head_motion import MOTIONS, parse_motion
from hairtool.simulate.options import SimulateOptions

SOURCE = "simulation"


def _spin(
    lo: float, hi: float, decimals: int = 3, step: float | None = None, suffix: str = ""
) -> QDoubleSpinBox:
    box = QDoubleSpinBox()
    box.setRange(lo, hi)
    box.setDecimals(decimals)
    if step is not None:
        box.setSingleStep(step)
    box.setSuffix(suffix)
    return box


def _int_spin(lo: int, hi: int) -> QSpinBox:
    box = QSpinBox()
    box.setRange(lo, hi)
    return box


class _Vector(QWidget):
    """Three spin boxes x, y, z."""

    def __init__(self, lo: float, hi: float) -> None:
        super().__init__()
        layout = QHBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        self.boxes = [_spin(lo, hi, 3, 1.0) for _ in range(3)]
        for b in self.boxes:
            layout.addWidget(b)

    def value(self) -> tuple[float, float, float]:
        return tuple(b.value() for b in self.boxes)  # type: ignore[return-value]

    def set_value(self, v) -> None:
        for b, c in zip(self.boxes, v, strict=True):
            b.setValue(float(c))


class SimulateDialog(QDialog):
    """Modal form; the window asks for options through ``ask_simulate_options`` (tests stub it)."""

    def __init__(
        self,
        parent: QWidget | None = None,
        options: SimulateOptions | None = None,
        groom: Groom | None = None,
    ) -> None:
        super().__init__(parent)
        self.groom = groom  # for "Fit to groom"
        self.setWindowTitle("Simulate hair dynamics")
        layout = QVBoxLayout(self)

        motion = QGroupBox("Head motion and timing")
        form = QFormLayout(motion)
        self.motion = QLineEdit()
        self.motion.setToolTip(f"comma-separated, played in equal slots: {', '.join(MOTIONS)}")
        self.frames = _int_spin(2, 100_000)
        self.fps = _spin(1.0, 1000.0, 3, suffix=" fps")
        self.substeps = _int_spin(1, 1000)
        self.duration = QLabel()
        form.addRow("Motion", self.motion)
        form.addRow("Frames", self.frames)
        form.addRow("Frame rate", self.fps)
        form.addRow("Duration", self.duration)
        form.addRow("Substeps / frame", self.substeps)

        forces = QGroupBox("Forces")
        f = QFormLayout(forces)
        self.gravity = _spin(-1e4, 1e4, 2, 1.0, " m/s²")
        self.damping = _spin(0.0, 1e4, 3, 0.5, " /s")
        self.stiffness = _spin(0.0, 1.0, 3, 0.01)
        self.stiffness.setToolTip("pull toward the styled shape per frame (0: none, 1: rigid)")
        self.wind = _Vector(-1e5, 1e5)
        self.wind.setToolTip("constant wind acceleration x, y, z in units/s² (0, 0, 0: none)")
        self.gusts = _int_spin(0, 10_000)
        self.gust_strength = _spin(0.0, 1e6, 1, 50.0, " units/s²")
        self.gust_duration = _spin(0.001, 1e3, 3, 0.05, " s")
        self.seed = _int_spin(0, 2**31 - 1)
        f.addRow("Gravity", self.gravity)
        f.addRow("Damping", self.damping)
        f.addRow("Stiffness", self.stiffness)
        f.addRow("Wind x, y, z", self.wind)
        f.addRow("Gusts", self.gusts)
        f.addRow("Gust strength", self.gust_strength)
        f.addRow("Gust duration", self.gust_duration)
        f.addRow("Seed", self.seed)

        head = QGroupBox("Head sphere")
        h = QFormLayout(head)
        self.collide = QCheckBox("Keep strands outside the head")
        self.head_center = _Vector(-1e4, 1e4)
        self.head_radius = _spin(0.0, 1e4, 3, 0.1)
        self.fit_button = QPushButton("Fit to groom")
        self.fit_button.setToolTip(
            "Fit the sphere to the groom's roots and scale wind and gusts with the head size"
        )
        self.fit_button.setEnabled(groom is not None)
        self.fit_button.clicked.connect(self.fit_to_groom)
        h.addRow(self.collide)
        h.addRow("Centre", self.head_center)
        h.addRow("Radius", self.head_radius)
        h.addRow(self.fit_button)

        for box in (motion, forces, head):
            layout.addWidget(box)
        self.error_label = QLabel()
        self.error_label.setStyleSheet("color: #e06c6c")
        self.error_label.setWordWrap(True)
        layout.addWidget(self.error_label)
        buttons = QDialogButtonBox(
            QDialogButtonBox.StandardButton.Ok | QDialogButtonBox.StandardButton.Cancel
        )
        buttons.button(QDialogButtonBox.StandardButton.Ok).setText("Simulate")
        buttons.accepted.connect(self._accept)
        buttons.rejected.connect(self.reject)
        layout.addWidget(buttons)
        self.frames.valueChanged.connect(self._update_duration)
        self.fps.valueChanged.connect(self._update_duration)
        self.set_options(options or SimulateOptions())

    def _update_duration(self, *_: object) -> None:
        self.duration.setText(f"{(self.frames.value() - 1) / self.fps.value():.3f} s")

    def options(self) -> SimulateOptions:
        """The values shown; ParameterError names a bad motion."""
        motion = ",".join(parse_motion(self.motion.text()))
        return SimulateOptions(
            motion=motion,
            frames=self.frames.value(),
            fps=self.fps.value(),
            substeps=self.substeps.value(),
            gravity=self.gravity.value(),
            damping=self.damping.value(),
            stiffness=self.stiffness.value(),
            wind=self.wind.value(),
            gusts=self.gusts.value(),
            gust_strength=self.gust_strength.value(),
            gust_duration=self.gust_duration.value(),
            seed=self.seed.value(),
            collide=self.collide.isChecked(),
            head_center=self.head_center.value(),
            head_radius=self.head_radius.value(),
        )

    def set_options(self, o: SimulateOptions) -> None:
        self.motion.setText(o.motion)
        self.frames.setValue(o.frames)
        self.fps.setValue(o.fps)
        self.substeps.setValue(o.substeps)
        self.gravity.setValue(o.gravity)
        self.damping.setValue(o.damping)
        self.stiffness.setValue(o.stiffness)
        self.wind.set_value(o.wind)
        self.gusts.setValue(o.gusts)
        self.gust_strength.setValue(o.gust_strength)
        self.gust_duration.setValue(o.gust_duration)
        self.seed.setValue(o.seed)
        self.collide.setChecked(o.collide)
        self.head_center.set_value(o.head_center)
        self.head_radius.setValue(o.head_radius)
        self._update_duration()

    def fit_to_groom(self) -> None:
        if self.groom is None:
            return
        try:
            self.set_options(self.options().fitted_to(self.groom))
        except ParameterError as e:
            self.error_label.setText(str(e))

    def _accept(self) -> None:
        try:
            self.options()
        except ParameterError as e:
            self.error_label.setText(str(e))  # stay open: the user fixes the field
            return
        self.accept()


def ask_simulate_options(
    parent: QWidget, options: SimulateOptions, groom: Groom | None = None
) -> SimulateOptions | None:
    """Modal: the chosen options, or None when the user cancels."""
    dialog = SimulateDialog(parent, options, groom)
    if dialog.exec() != QDialog.DialogCode.Accepted:
        return None
    return dialog.options()
