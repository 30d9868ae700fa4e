"""The viewport's GL surface: a native GL window shown through a window container.

Why not a ``QOpenGLWidget``: with one in it, Qt composes the whole top-level window through GL
on every update of any widget (the widgets' backing store uploaded and drawn with the GL
widget's texture); under a software GL (Mesa's llvmpipe) that is 40-70 ms for a status label
alone, more than a scrubbed frame's whole budget. A native GL window beside the widgets is
drawn and swapped on its own, and the widgets flush as a plain raster image.

The surface takes no input: it is transparent to the mouse and the pen and never takes the
keyboard focus, so every event reaches the widget that holds it (the viewport) exactly as a
widget's own events do: its cursor, its focus, the window's shortcuts and event filters. Input a
platform gives the surface anyway (one that cannot make a child window transparent to input) is
passed on to that widget.
"""

from __future__ import annotations

from typing import Protocol

from PySide6.QtCore import QCoreApplication, QEvent, QPoint, Qt
from PySide6.QtGui import QImage, QPainter
from PySide6.QtOpenGL import QOpenGLWindow
from PySide6.QtWidgets import QVBoxLayout, QWidget


class Painter(Protocol):
    """What the surface calls, with its GL context current."""

    def initializeGL(self) -> None: ...

    def resizeGL(self, w: int, h: int) -> None: ...

    def paintGL(self) -> None: ...


_T = QEvent.Type
INPUT = frozenset(
    (_T.MouseButtonPress, _T.MouseButtonRelease, _T.MouseButtonDblClick, _T.MouseMove, _T.Wheel,
     _T.TabletPress, _T.TabletMove, _T.TabletRelease, _T.KeyPress, _T.KeyRelease, _T.Enter, _T.Leave)
)  # fmt: skip


class GLSurface(QOpenGLWindow):
    """Calls ``painter``'s GL methods; Qt keeps the image in a framebuffer object of the
    window's size (``defaultFramebufferObject``) and copies it to the window when painted."""

    def __init__(self, painter: Painter) -> None:
        super().__init__(QOpenGLWindow.UpdateBehavior.PartialUpdateBlit)
        self._painter = painter
        self.setFlags(
            self.flags() | Qt.WindowType.WindowTransparentForInput | Qt.WindowType.WindowDoesNotAcceptFocus
        )

    def event(self, event: QEvent) -> bool:
        if event.type() in INPUT and isinstance(self._painter, QWidget):
            if event.type() == QEvent.Type.MouseButtonPress:
                self._painter.setFocus(Qt.FocusReason.MouseFocusReason)
            QCoreApplication.sendEvent(self._painter, event)
            return True
        return super().event(event)

    def initializeGL(self) -> None:
        self._painter.initializeGL()

    def resizeGL(self, w: int, h: int) -> None:
        self._painter.resizeGL(w, h)

    def paintGL(self) -> None:
        self._painter.paintGL()


def hold_surface(widget: QWidget, surface: GLSurface) -> QWidget:
    """Show ``surface`` over all of ``widget`` (a window container in a margin-less layout);
    returns the container."""
    container = QWidget.createWindowContainer(surface, widget)
    container.setFocusPolicy(Qt.FocusPolicy.NoFocus)
    container.setAttribute(Qt.WidgetAttribute.WA_TransparentForMouseEvents)
    layout = QVBoxLayout(widget)
    layout.setContentsMargins(0, 0, 0, 0)
    layout.addWidget(container)
    return container


def grab_with_view(window: QWidget, view: QWidget) -> QImage:
    """``window`` as it looks, as an image: its widgets (``QWidget.grab``, which sees no native
    GL window) with ``view``'s own image (its ``grabFramebuffer()``) painted in its place."""
    image = window.grab().toImage()
    drawn = view.grabFramebuffer()
    if not drawn.isNull():
        drawn.setDevicePixelRatio(view.devicePixelRatioF())
        painter = QPainter(image)
        painter.drawImage(view.mapTo(window, QPoint(0, 0)), drawn)
        painter.end()
    return image
