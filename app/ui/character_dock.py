"""The Character dock: the hair chains (a list; a click on their bones in the view picks too), the
selected chain's own swing, what drives the spring bones, what the view shows, and the paper's
Table-1 measure between the cycle and the springs.

It only shows a :class:`~app.document.character.CharacterDocument` and emits what the artist
asked for; :class:`app.ui.character_studio.CharacterStudio` turns that into the document's
commands.
"""

from __future__ import annotations

from PySide6.QtCore import Signal
from PySide6.QtWidgets import (
    QComboBox,
    QDockWidget,
    QDoubleSpinBox,
    QFormLayout,
    QHBoxLayout,
    QLabel,
    QListWidget,
    QPushButton,
    QVBoxLayout,
    QWidget,
)

from app.document.character import SOURCES, VIEWS, CharacterDocument
from app.ui.qt_utils import signals_blocked
from app.ui.widgets import SliderSpin

VIEW_WORDS = {"cycle": "Anime cycle", "springs": "Spring bones", "both": "Both on the same chains"}
AXES = (
    ("its own axis", None),
    ("X (left-right)", (1.0, 0.0, 0.0)),
    ("Y (up)", (0.0, 1.0, 0.0)),
    ("Z (front-back)", (0.0, 0.0, 1.0)),
)
SOURCE_WORDS = {"shake": "Head shake", "turn": "Head turn", "animation": "The character's animation"}


class CharacterDock(QDockWidget):
    """See the module docstring; :meth:`set_document` and :meth:`refresh` show, signals ask."""

    chain_selected = Signal(object)  # chain index or None
    chain_edited = Signal(int, dict, object)  # chain, {setting: value}, drag id
    view_chosen = Signal(str)
    source_chosen = Signal(str)
    undo_requested = Signal()
    redo_requested = Signal()

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__("Character", parent)
        self.setObjectName("character_dock")
        self.doc: CharacterDocument | None = None
        body = QWidget()
        layout = QVBoxLayout(body)
        self.chains = QListWidget()
        self.chains.setToolTip("The hair chains (VRM spring bones); click one here or its bones in the view")
        self.chains.currentRowChanged.connect(lambda row: self.chain_selected.emit(row if row >= 0 else None))
        layout.addWidget(self.chains)
        form = QFormLayout()
        self.phase = SliderSpin(0.0, 1.0)
        self.phase.setToolTip("When this chain swings, in cycles after the others (the paper's phase)")
        self.amplitude = SliderSpin(0.0, 2.0)
        self.amplitude.setToolTip("How far this chain swings, times the wave's amplitude a")
        self.profile = QDoubleSpinBox()
        self.profile.setRange(-0.01, 4.0)
        self.profile.setSingleStep(0.1)
        self.profile.setSpecialValueText("as the wave")
        self.profile.setToolTip(
            "How the swing grows root to tip on this chain (p); 'as the wave' uses the dock's p"
        )
        self.phase.edited.connect(lambda v, drag: self._edited({"phase": v}, drag))
        self.amplitude.edited.connect(lambda v, drag: self._edited({"amplitude_scale": v}, drag))
        self.profile.valueChanged.connect(lambda v: self._edited({"profile": None if v < 0 else v}, None))
        self.axis = QComboBox()
        for words, axis in AXES:
            self.axis.addItem(words, axis)
        self.axis.setToolTip(
            "The line this chain bends about: its own (across the chain, level), or a world axis"
        )
        self.axis.activated.connect(lambda i: self._edited({"axis": self.axis.itemData(i)}, None))
        form.addRow("Bends about", self.axis)
        form.addRow("Phase", self.phase)
        form.addRow("Swing", self.amplitude)
        form.addRow("Root to tip", self.profile)
        self.view = QComboBox()
        for v in VIEWS:
            self.view.addItem(VIEW_WORDS[v], v)
        self.view.setToolTip("Show the anime cycle, the spring bones, or both on the same chains")
        self.view.activated.connect(lambda i: self.view_chosen.emit(self.view.itemData(i)))
        self.source = QComboBox()
        for s in SOURCES:
            self.source.addItem(SOURCE_WORDS[s], s)
        self.source.setToolTip("What moves the head the spring bones follow")
        self.source.activated.connect(lambda i: self.source_chosen.emit(self.source.itemData(i)))
        form.addRow("Show", self.view)
        form.addRow("Springs follow", self.source)
        layout.addLayout(form)
        self.measure = QLabel()
        self.measure.setWordWrap(True)
        self.measure.setToolTip(
            "The paper's Table 1 between the cycle and the springs: mean angular error of the bones "
            "and node displacement in % of chain length (a measure, not a verdict)"
        )
        layout.addWidget(self.measure)
        buttons = QHBoxLayout()
        undo, redo = QPushButton("Undo"), QPushButton("Redo")
        undo.clicked.connect(self.undo_requested.emit)
        redo.clicked.connect(self.redo_requested.emit)
        buttons.addWidget(undo)
        buttons.addWidget(redo)
        self.undo_button, self.redo_button = undo, redo
        layout.addLayout(buttons)
        layout.addStretch(1)
        self.setWidget(body)

    def set_document(self, doc: CharacterDocument | None) -> None:
        self.doc = doc
        with signals_blocked(self.chains):
            self.chains.clear()
            if doc is not None:
                self.chains.addItems([chain.name for chain in doc.character.chains])
        self.refresh()

    def refresh(self) -> None:
        """Show the document's state (emits nothing)."""
        doc = self.doc
        self.setEnabled(doc is not None)
        if doc is None:
            return
        s = doc.state
        with signals_blocked(self.chains, self.profile, self.view, self.source, self.axis):
            self.chains.setCurrentRow(-1 if s.selected is None else s.selected)
            self.view.setCurrentIndex(VIEWS.index(s.view))
            self.source.setCurrentIndex(SOURCES.index(s.springs.source))
            chosen = s.selected is not None
            for w in (self.phase, self.amplitude, self.profile, self.axis):
                w.setEnabled(chosen)
            if chosen:
                wave = s.cycle.chains[s.selected]
                self.phase.set_value(wave.phase)
                self.amplitude.set_value(wave.amplitude_scale)
                self.profile.setValue(-0.01 if wave.profile is None else wave.profile)
                known = [axis for _, axis in AXES]
                self.axis.setCurrentIndex(known.index(wave.axis) if wave.axis in known else 0)
        self.undo_button.setEnabled(doc.stack.can_undo)
        self.redo_button.setEnabled(doc.stack.can_redo)

    def show_measure(self, measure: dict | None, drawings) -> None:
        words = (
            f"Drawings on frames {', '.join(str(int(f)) for f in drawings)}"
            if len(drawings)
            else "No cycle applied"
        )
        if measure is not None:
            words += (
                f"\nCycle against springs over {measure['frames']} frames: "
                f"{measure['angular_error_deg']:.1f}° mean angular error, "
                f"{measure['position_error_pct']:.1f} % node displacement"
            )
        self.measure.setText(words)

    def _edited(self, changes: dict, drag: object) -> None:
        if self.doc is not None and self.doc.state.selected is not None:
            self.chain_edited.emit(self.doc.state.selected, changes, drag)
