"""The tool dock's "Render hair" group: guides shown or hidden, and how many of the children
are drawn while a brush drags and once it is released (XGen's preview density, Houdini's
display percentage). Enabled while the groom has children (grown from the Groom menu)."""

from __future__ import annotations

from PySide6.QtWidgets import QCheckBox, QFormLayout, QGroupBox, QLabel, QWidget

from app.ui.qt_utils import signals_blocked
from app.ui.scene import Scene
from app.ui.widgets import SliderSpin


class RenderHairBox(QGroupBox):
    def __init__(self, scene: Scene, parent: QWidget | None = None) -> None:
        super().__init__("Render hair", parent)
        self.setObjectName("RenderHairBox")
        self.scene = scene
        form = QFormLayout(self)
        self.children_label = QLabel()
        self.show_guides = QCheckBox()
        self.show_guides.setToolTip("draw the guide curves (what the brushes move) over the render hair")
        self.show_guides.toggled.connect(scene.set_show_guides)
        self.clump_children = QCheckBox()
        self.clump_children.setToolTip(
            "ClumpWithGaps among the render strands (the paper's adhesion, at render density), "
            "with the engine's clump passes, gaps and Keep lengths; applied when the mouse is "
            "released and in saved files, not while a brush drags. On for grown children, off "
            "for authored hair (strands you picked guides among, render hair opened beside its "
            "guides), which stays as it was made"
        )
        self.clump_children.toggled.connect(scene.set_clump_children)
        self.drag_percent = SliderSpin(0.1, 100.0, decimals=1, log=True)
        self.drag_percent.setToolTip("share of the children drawn while a brush drags, in percent")
        self.drag_percent.edited.connect(lambda v, _d: scene.set_display_percent(drag=v))
        self.release_percent = SliderSpin(0.1, 100.0, decimals=1, log=True)
        self.release_percent.setToolTip("share of the children drawn when the mouse is released, in percent")
        self.release_percent.edited.connect(lambda v, _d: scene.set_display_percent(release=v))
        form.addRow("Children", self.children_label)
        form.addRow("Show guides", self.show_guides)
        form.addRow("Clump children", self.clump_children)
        form.addRow("While dragging %", self.drag_percent)
        form.addRow("On release %", self.release_percent)
        scene.drawn_changed.connect(self.refresh)
        scene.groom_loaded.connect(self.refresh)
        self.refresh()

    def refresh(self) -> None:
        s = self.scene
        b = s.children_binding()
        grown = None if b is None else f"{b.child_count:,} from {s.result.strand_count:,} guides"
        self.children_label.setText(grown or "none: Groom ▸ Grow render hair…")
        for w in (self.show_guides, self.clump_children, self.drag_percent, self.release_percent):
            w.setEnabled(b is not None)
        with signals_blocked(self.show_guides, self.clump_children, self.drag_percent, self.release_percent):
            self.show_guides.setChecked(s.show_guides)
            self.clump_children.setChecked(s.clump_children)
            self.drag_percent.set_value(s.drag_percent)
            self.release_percent.set_value(s.release_percent)
