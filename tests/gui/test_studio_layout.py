"""The window on a 1366×768 laptop screen: it fits, every dock's controls can be scrolled to, the
timeline folds without an animation, the layout resets; legends, framing and the missed-brush
message."""

from __future__ import annotations

import numpy as np
import pytest
from PySide6.QtCore import Qt
from PySide6.QtWidgets import (
    QAbstractButton,
    QAbstractSlider,
    QAbstractSpinBox,
    QApplication,
    QComboBox,
    QDockWidget,
    QScrollArea,
    QWidget,
)

from hairtool import samples
from hairtool.groom import Animation

pytestmark = pytest.mark.gui

LAPTOP = (1366, 768)
TITLE_BAR = 32  # px a window manager's title bar may take from the screen's height


def controls(dock: QDockWidget) -> list:
    kinds = (QAbstractButton, QAbstractSlider, QAbstractSpinBox, QComboBox)
    return [c for c in dock.widget().findChildren(QWidget) if isinstance(c, kinds)]


def scroll_to(control) -> bool:
    """Scroll ``control``'s enclosing scroll areas to it; True when part of it is then on screen."""
    parent = control.parentWidget()
    while parent is not None:
        if isinstance(parent, QScrollArea):
            parent.ensureWidgetVisible(control)
        parent = parent.parentWidget()
    QApplication.processEvents()
    return not control.visibleRegion().isEmpty()


def sway(groom, frames: int = 24, travel: float = 0.0) -> Animation:
    """The groom swaying sideways, carried ``travel`` (× its size) along x over the shot."""
    lo, hi = groom.bounds
    size = float(np.max(hi - lo))
    t = np.linspace(0.0, 1.0, frames)[:, None, None]
    height = (groom.points[:, 1] - lo[1])[None, :, None] / max(float(hi[1] - lo[1]), 1e-9)
    wave = np.zeros((frames, 1, 3), np.float32)
    wave[..., 0] = 1.0
    moved = groom.points[None] + 0.1 * size * np.sin(6.0 * t) * height * wave
    moved = moved + travel * size * t * wave
    return Animation(moved.astype(np.float32), groom.topology, 24.0)


def test_first_start_fits_the_screen_and_every_control_can_be_reached(make_window):
    from app.ui.window import fitting_size

    screen = QApplication.primaryScreen().availableGeometry().size()
    assert fitting_size(screen)[0] <= screen.width() and fitting_size(screen)[1] <= screen.height()
    w = make_window(size=LAPTOP)
    w.resize(LAPTOP[0], LAPTOP[1] - TITLE_BAR)
    QApplication.processEvents()
    hint = w.minimumSizeHint()
    assert hint.width() <= LAPTOP[0] and hint.height() <= LAPTOP[1] - TITLE_BAR, hint
    assert w.size().height() <= LAPTOP[1] - TITLE_BAR  # the layout did not force the window taller
    assert w.statusBar().isVisible() and w.statusBar().geometry().bottom() < w.height()
    assert w.timeline.folded and w.timeline.height() < 90  # no animation: the transport bar only
    docks = [w.dock, w.sources.dock, w.timeline]
    for dock in docks:
        dock.raise_()  # the tool and anime docks share a tabbed place
        QApplication.processEvents()
        found = controls(dock)
        assert found, dock.objectName()
        for control in found:
            if control.isHidden() or not control.isVisibleTo(dock):
                continue  # e.g. the folded timeline's key controls
            assert scroll_to(control), f"{dock.objectName()}: {type(control).__name__} {control.toolTip()!r}"
    assert scroll_to(w.sources.dock.apply_button)  # the anime dock's button, once below the fold


def test_the_timeline_unfolds_for_an_animation_and_folds_again(make_window):
    w = make_window(groom=samples.comb(strands=12, vertices=8), size=LAPTOP)
    folded = w.timeline.height()
    w.animation.load_animation(sway(w.scene.result), "sway")
    QApplication.processEvents()
    assert not w.timeline.folded and w.timeline.height() >= 200 > folded
    assert w.minimumSizeHint().height() <= LAPTOP[1] - TITLE_BAR
    for control in controls(w.timeline):  # the key controls scroll on a short screen
        if control.isVisibleTo(w.timeline):
            assert scroll_to(control), control.objectName()
    w.animation.clear()
    QApplication.processEvents()
    assert w.timeline.folded and w.timeline.height() == pytest.approx(folded, abs=4)


def test_docks_float_and_move_and_reset_layout_puts_them_back(make_window):
    w = make_window(size=LAPTOP)
    area = w.dockWidgetArea(w.timeline)
    w.dock.setFloating(True)
    w.addDockWidget(Qt.DockWidgetArea.TopDockWidgetArea, w.timeline)
    w.sources.dock.hide()
    assert w.dock.isFloating() and w.dockWidgetArea(w.timeline) == Qt.DockWidgetArea.TopDockWidgetArea
    menus = [m.menu() for m in w.menuBar().actions() if m.menu()]
    action = next(a for m in menus for a in m.actions() if a.text() == "&Reset layout")
    action.trigger()
    QApplication.processEvents()
    assert not w.dock.isFloating() and w.dock.isVisible()
    assert w.dockWidgetArea(w.timeline) == area
    assert w.tabifiedDockWidgets(w.dock) == [w.sources.dock]


def test_displacement_legend_in_a_length_an_artist_reads_and_unmoved_strands_stay_visible(ui, make_window):
    w = make_window(groom=samples.scalp(strands=80, vertices=8))
    ui.leave(w.viewport)
    plain = ui.hair_mask(ui.grab(w.viewport)).sum()
    assert not w.legend.isVisible()
    w.scene.set_colour_mode("displacement")
    assert w.legend.isVisible()
    text = w.legend.text()
    assert text.startswith("Moved 0") and text.endswith(" cm"), text
    unmoved = ui.hair_mask(ui.grab(w.viewport)).sum()
    assert unmoved > 0.8 * plain  # nothing has moved: still drawn, in the ramp's grey
    w.scene.set_colour_mode("root-to-tip")
    assert not w.legend.isVisible()


def test_key_error_legend_and_ghost_show_both(ui, make_window):
    w = make_window(groom=samples.comb(strands=12, vertices=8), size=(1000, 700))
    m = w.animation
    m.load_animation(sway(w.scene.result, 40), "sway")
    m.set_key_count(3)
    m.set_view_mode("error")
    QApplication.processEvents()
    assert w.legend.isVisible() and w.legend.text().startswith("Key error 0")
    mm = m.error_scale * w.scene.rest.metadata.meters_per_unit * 1e3  # a small error reads in mm
    assert mm < 10 and f"{mm:.3g} mm" in w.legend.text()
    m.set_view_mode("ghost")
    assert not w.legend.isVisible()
    frame = int(np.argmax(m.analysis.dp.max))  # the frame the keys rebuild worst
    m.set_frame(frame)
    ui.leave(w.viewport)
    image = ui.grab(w.viewport).astype(int)
    cyan = (image[..., 2] > 180) & (image[..., 1] > 160) & (image[..., 0] < 120)
    hair = ui.hair_mask(image) & ~cyan
    assert cyan.sum() > 20 and hair.sum() > 20  # the reconstruction and the original, both


def test_an_animation_opens_framed_on_the_groom_not_its_whole_motion(make_window):
    w = make_window(groom=samples.scalp(strands=60, vertices=8), size=(900, 600))
    w.animation.load_animation(sway(w.scene.result, 24, travel=6.0), "walk")
    QApplication.processEvents()
    v = w.viewport
    px = v.project(w.animation.animation.frames[0])
    span = px.max(axis=0) - px.min(axis=0)
    # framed on the whole motion (seven groom widths) it would fill about a tenth of the view
    assert max(span[0] / v.width(), span[1] / v.height()) > 0.3, span


def test_a_brush_drag_that_misses_every_strand_says_so(ui, make_window):
    from app.ui.window import MISSED_STRANDS

    w = make_window(groom=samples.scalp(strands=60, vertices=8))
    v = w.viewport
    w.scene.set_radius(w.scene.radius * 0.05)
    corner = (8.0, 8.0)
    ui.drag(v, corner, (20.0, 14.0))
    assert w.statusBar().currentMessage() == MISSED_STRANDS
    w.statusBar().clearMessage()
    w.scene.set_radius(w.scene.radius * 20.0)
    centre = v.project(w.scene.centre[None])[0]
    ui.drag(v, centre, centre + np.array([60.0, 20.0]))
    assert w.statusBar().currentMessage() != MISSED_STRANDS
