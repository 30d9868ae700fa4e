"""At 1366×768 with an animation on the timeline and the graph editor open, the window stays on
the screen: opening the editor does not grow it, and every dock's minimum fits beside the view."""

from __future__ import annotations

import pytest
from PySide6.QtWidgets import QApplication

from hairtool import samples

from .test_studio_layout import LAPTOP, TITLE_BAR, sway

pytestmark = pytest.mark.gui


def test_the_graph_editor_opens_inside_a_laptop_screen(make_window):
    w = make_window(groom=samples.comb(strands=12, vertices=8), size=LAPTOP)
    w.resize(LAPTOP[0], LAPTOP[1] - TITLE_BAR)
    w.animation.load_animation(sway(w.scene.result), "sway")
    QApplication.processEvents()
    w.graph_editor.toggleViewAction().trigger()
    QApplication.processEvents()
    assert w.graph_editor.isVisible()
    hint = w.minimumSizeHint()
    assert hint.width() <= LAPTOP[0] and hint.height() <= LAPTOP[1] - TITLE_BAR, hint
    assert w.width() <= LAPTOP[0] and w.height() <= LAPTOP[1] - TITLE_BAR, w.size()
    assert w.viewport.height() >= 150 and w.viewport.width() >= 400, w.viewport.size()
    assert w.timeline.height() < 0.5 * w.height()  # the timeline no longer takes half the height
