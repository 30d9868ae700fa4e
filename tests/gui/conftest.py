"""GUI fixtures: a 3.3 core GL surface before the QApplication exists, isolated settings, and a
window factory that closes what it made and fails a test that leaves a window open."""

from __future__ import annotations

import numpy as np
import pytest
from PySide6.QtCore import QEvent, QSettings
from PySide6.QtWidgets import QApplication

from app.surface import configure_gl
from app.ui.qt_utils import send_mouse

configure_gl()  # pytest-qt makes the QApplication later, on the first use of ``qapp``


@pytest.fixture(autouse=True)
def parallel_kernels_after():
    """A first start's window puts the process on the serial twins (hairtool.serial_twins)
    until its warm-up ends or it closes: the next test starts on the parallel kernels whatever
    this one left."""
    yield
    from hairtool import serial_twins

    if not serial_twins.parallel_in_use():
        serial_twins.use_parallel(True)


@pytest.fixture
def settings_path(tmp_path):
    return str(tmp_path / "studio.ini")


@pytest.fixture
def make_window(qapp, qtbot, settings_path):
    """``make_window(path=None, groom=None, size, engine_ready=True)`` → a shown MainWindow whose
    dialogs never block.

    Errors that would pop up a dialog are collected in ``window.errors`` instead. The settings
    (and the autosave recovery file beside them) live in the test's ``tmp_path``.
    """
    from app.ui.window import MainWindow

    made = []

    def make(path=None, *, groom=None, size=(900, 600), engine_ready=True):
        settings = QSettings(settings_path, QSettings.Format.IniFormat)
        window = MainWindow(None, settings=settings, groom=groom, engine_ready=engine_ready)
        window.errors = []
        window.show_error = lambda title, message: window.errors.append((title, message))
        # questions never block: close without saving, decline a recovery file (tests that
        # need other answers replace these again)
        window.ask_save_changes = lambda: "discard"
        window.ask_restore_recovery = lambda path: False
        window.resize(*size)
        window.show()
        qtbot.waitExposed(window)
        window.viewport.gl_ready()  # its GL window is painted a moment after the window
        if path is not None:
            window.open_path(path)
        window.viewport.frame_all()
        made.append(window)
        return window

    yield make
    for window in made:
        window.close()
        window.deleteLater()
    QApplication.processEvents()
    # deleted now, on this thread, not whenever a later test's event loop happens to run
    QApplication.sendPostedEvents(None, QEvent.Type.DeferredDelete)
    leaked = [w for w in QApplication.topLevelWidgets() if w.isVisible()]
    assert not leaked, f"windows left open: {leaked}"


def grab(viewport) -> np.ndarray:
    """The viewport's framebuffer as ``(H, W, 3)`` uint8 (paints first if anything changed)."""
    from PySide6.QtGui import QImage

    image = viewport.grabFramebuffer().convertToFormat(QImage.Format.Format_RGB888)
    w, h = image.width(), image.height()
    data = np.frombuffer(image.constBits(), dtype=np.uint8, count=image.bytesPerLine() * h)
    return data.reshape(h, image.bytesPerLine())[:, : w * 3].reshape(h, w, 3).copy()


def drag(widget, start, end, steps: int = 8, button=None, modifiers=None) -> None:
    """Press at ``start``, move in ``steps`` to ``end`` with the button held, release there."""
    from PySide6.QtCore import Qt

    button = Qt.MouseButton.LeftButton if button is None else button
    send_mouse(widget, "press", start, button, button, modifiers)
    for f in np.linspace(0.0, 1.0, steps + 1)[1:]:
        p = (1.0 - f) * np.asarray(start, float) + f * np.asarray(end, float)
        send_mouse(widget, "move", p, None, button, modifiers)
    send_mouse(widget, "release", end, button, None, modifiers)


def leave(widget) -> None:
    """The cursor leaves the viewport: the brush circle is hidden (for image comparisons)."""
    from PySide6.QtCore import QEvent

    QApplication.sendEvent(widget, QEvent(QEvent.Type.Leave))


def record(signal) -> list:
    """The argument tuples of every emission of ``signal`` from now on."""
    seen = []
    signal.connect(lambda *a: seen.append(a))
    return seen


def hair_mask(image: np.ndarray, background=(0.16, 0.17, 0.19)) -> np.ndarray:
    """Pixels that differ clearly from the background colour."""
    bg = np.round(np.asarray(background) * 255.0)
    return np.abs(image[..., :3].astype(np.float64) - bg).max(axis=-1) > 24


def curves_match(view, lib, joint: str) -> None:
    """The graph editor's curves of ``joint`` are the library editor ``lib``'s (a PoseEditor, or a
    ChannelEditor for per-channel keys): the edited capture, the key curve, the keys, their
    values and handles, channel by channel."""
    from hairtool.mocap import ik
    from hairtool.mocap.channel_edit import ChannelEditor

    m = lib.original
    j = m.joint_names.index(joint)
    cols, _ = ik.rotation_columns(m, j)
    result = lib.motion().values[:, cols]
    assert [c.name for c in view.curves] == [m.channels[j][c - int(m._starts[j])] for c in cols]
    per_channel = isinstance(lib, ChannelEditor)
    if not per_channel:
        curve, slopes = lib.key_curve(j, result), lib.key_slopes(j)
    for i, (drawn, c) in enumerate(zip(view.curves, cols, strict=True)):
        if per_channel:
            keys, key_curve, slope = lib.keys(c), lib.key_curve(c), lib.key_slopes(c)
        else:
            keys, key_curve = lib.keys, curve[:, i]
            slope = None if slopes is None else (slopes[0][:, i], slopes[1][:, i])
        np.testing.assert_array_equal(drawn.result, result[:, i])
        np.testing.assert_array_equal(drawn.key_curve, key_curve)
        np.testing.assert_array_equal(drawn.keys, keys)
        np.testing.assert_array_equal(drawn.values, key_curve[keys])
        if slope is None:
            assert drawn.slope_in is None and drawn.slope_out is None
        else:
            np.testing.assert_array_equal(drawn.slope_in, slope[0])
            np.testing.assert_array_equal(drawn.slope_out, slope[1])


@pytest.fixture
def ui():
    """The helpers above, for test modules (importlib import mode cannot import conftest)."""
    from types import SimpleNamespace

    return SimpleNamespace(
        grab=grab, drag=drag, leave=leave, send_mouse=send_mouse, hair_mask=hair_mask, record=record,
        curves_match=curves_match,
    )
