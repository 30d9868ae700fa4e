"""The Select menu, the Selection toolbar and the tool dock's Selection group, with Blender's keys:
A select all, Alt+A none, Ctrl+I invert, B box select (the next left-drag draws the box and adds
what it holds; Ctrl+drag takes it away; Esc or a right-click cancels), H hide the selected,
Shift+H hide the unselected, Alt+H reveal, and the "Affect selection only" toggle the brushes
honour. Each step is one undo step; the selection brush is in the Brush menu (W)."""

from __future__ import annotations

from PySide6.QtCore import Qt
from PySide6.QtGui import QAction
from PySide6.QtWidgets import QGridLayout, QGroupBox, QLabel, QMenu, QToolBar, QToolButton, QVBoxLayout

from app.ui.engine_start import WAIT_MESSAGE
from app.ui.qt_utils import add_action
from hairtool.frozen.sample_schema import SELECTION
from hairtool.frozen.selection import SelectionSample

#: (op, menu text, key, tooltip) of each selection step, in the menu's order (None: a separator).
STEPS = (
    ("all", "Select &All", "A", "Select every shown strand"),
    ("none", "Select &None", "Alt+A", "Deselect every strand"),
    ("invert", "&Invert Selection", "Ctrl+I", "Select the shown strands not selected, and only them"),
    ("box", "&Box Select", "B", "Drag a box: the strands with a point inside it are selected (Ctrl+drag "
     "deselects them; with Front faces only, only the strands you can see, not those behind the head; "
     "Esc cancels)"),
    None,
    ("hide_selected", "&Hide Selected", "H", "Hide the selected strands: no brush touches them till "
     "revealed"),
    ("hide_unselected", "Hide &Unselected", "Shift+H", "Hide every strand not selected, to groom the "
     "selection on its own"),
    ("reveal", "&Reveal Hidden", "Alt+H", "Show the hidden strands again, selected"),
)  # fmt: skip
UNDO_TEXT = {
    "all": "Select all", "none": "Select none", "invert": "Invert selection", "box": "Box select",
    "hide_selected": "Hide selected", "hide_unselected": "Hide unselected", "reveal": "Reveal hidden",
}  # fmt: skip
ONLY_TIP = (
    "Brushes change only the selected strands (the Select brush, W, box select, B); hidden strands "
    "are never brushed"
)


class SelectionUI:
    """Builds the menu, toolbar and dock group of ``window`` and runs their steps."""

    def __init__(self, window) -> None:
        self.window = window
        self.scene = window.scene
        self.actions: dict[str, QAction] = {}
        bar = window.menuBar()
        groom = next(a for a in bar.actions() if a.text() == "&Groom")
        menu = QMenu("&Select", window)
        menu.setToolTipsVisible(True)
        bar.insertMenu(groom, menu)
        for step in STEPS:
            if step is None:
                menu.addSeparator()
                continue
            op, text, key, tip = step
            slot = self.arm_box if op == "box" else (lambda _=False, o=op: self.step(o))
            action = add_action(window, menu, text, slot, key)
            action.setToolTip(f"{tip} ({key})")
            self.actions[op] = action
        menu.addSeparator()
        toggle = self.scene.set_only_selected
        only = add_action(window, menu, "Affect Selection &Only", toggle, checkable=True)
        only.setToolTip(ONLY_TIP)
        self.actions["only"] = only
        self.toolbar = QToolBar("Selection", window)
        self.toolbar.setObjectName("SelectionToolBar")
        for op in ("box", "all", "invert", "hide_unselected", "reveal", "only"):
            self.toolbar.addAction(self.actions[op])
        window.addToolBar(Qt.ToolBarArea.TopToolBarArea, self.toolbar)
        view = next(a.menu() for a in bar.actions() if a.text() == "&View")
        view.addAction(self.toolbar.toggleViewAction())
        window.dock.add_group(self.group())
        self.scene.tool_changed.connect(self.refresh)
        self.scene.selection_changed.connect(lambda _hidden: self.refresh())
        self.scene.groom_loaded.connect(self.refresh)
        self.scene.drawn_changed.connect(self.refresh)
        window.viewport.box_finished.connect(self.box)
        self.refresh()

    def group(self) -> QGroupBox:
        """The tool dock's Selection group: the steps as buttons, the toggle and a count."""
        box = QGroupBox("Selection")
        layout = QVBoxLayout(box)
        grid = QGridLayout()
        ops = ("all", "none", "invert", "box", "hide_selected", "hide_unselected", "reveal")
        for i, op in enumerate(ops):
            button = QToolButton()
            button.setDefaultAction(self.actions[op])
            button.setToolButtonStyle(Qt.ToolButtonStyle.ToolButtonTextOnly)
            grid.addWidget(button, i // 2, i % 2)
        only = QToolButton()
        only.setDefaultAction(self.actions["only"])
        self.count = QLabel()
        self.count.setToolTip("the strands selected and hidden (the groom's; with render hair, the guides)")
        layout.addLayout(grid)
        layout.addWidget(only)
        layout.addWidget(self.count)
        return box

    def refresh(self) -> None:
        s = self.scene
        only = self.actions["only"]
        if only.isChecked() != s.tool.only_selected:
            only.setChecked(s.tool.only_selected)
        n = len(s.selected)
        chosen, hidden = int(s.selected.sum()), int(s.hidden.sum())
        text = f"all {n:,} strands selected" if chosen == n else f"{chosen:,} of {n:,} strands selected"
        self.count.setText(text + (f", {hidden:,} hidden" if hidden else ""))

    def _ready(self) -> bool:
        if not self.scene.engine_ready:
            self.window.statusBar().showMessage(WAIT_MESSAGE, 4000)
            return False
        return True

    def step(self, op: str) -> bool:
        """One selection step as an undo step (False: it changed nothing)."""
        return self.apply(SELECTION.make(op=op))

    def apply(self, sample: SelectionSample) -> bool:
        if not self._ready():
            return False
        return self.scene.selection_step(sample, UNDO_TEXT[sample.op])

    def arm_box(self) -> None:
        """B: the next left-drag in the viewport draws the box."""
        if self._ready():
            self.window.viewport.arm_box(True)
            self.window.statusBar().showMessage(
                "Box select: drag over the strands (Ctrl+drag deselects; Esc cancels)", 6000
            )

    def box(self, sample: SelectionSample) -> None:
        """The box the viewport drew: with Front faces only (a ``view``), judged by sight, as
        the brushes judge (the head hides what lies behind it; the root normal without one)."""
        self.apply(sample._replace(visible=sample.view is not None))
