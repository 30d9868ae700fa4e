"""The window's status line: one message at a time, drawn in its own label, never over its
neighbours.

Qt's own status bar paints a temporary message as text across the bar, over whatever widgets
sit there, so a long message ran under the engine's progress and the counts. Here a message is
the text of one elided label (the whole text in its tooltip) with its own place in the layout;
read-outs and progress bars are widgets beside it. Two kinds of text share that label:

- a *message* (``showMessage(text, timeout_ms)``, as with ``QStatusBar``): the latest thing
  that happened, gone after its timeout;
- a *note* (``set_note(key, text)``): a state that holds until it is over ("her render hair
  follows once the engine is ready"); shown whenever no message is.

:meth:`StatusLine.clear_document` drops both when another document opens, so nothing said about
the last groom stays on screen.
"""

from __future__ import annotations

from PySide6.QtCore import QSize, Qt, QTimer
from PySide6.QtGui import QResizeEvent
from PySide6.QtWidgets import QLabel, QSizePolicy, QStatusBar, QWidget


class ElidedLabel(QLabel):
    """A one-line label that shortens its text with "…" to the width it is given (the whole
    text in its tooltip), so the layout can always fit it beside its neighbours."""

    def __init__(self, text: str = "", parent: QWidget | None = None, min_width: int = 40) -> None:
        super().__init__(parent)
        self._full = ""
        self.detail = ""  # the tooltip while the whole text shows (a shortened text shows itself)
        self._min_width = int(min_width)
        self.setSizePolicy(QSizePolicy.Policy.Preferred, QSizePolicy.Policy.Preferred)
        self.setText(text)

    def setText(self, text: str) -> None:
        self._full = str(text)
        self.updateGeometry()
        self._elide()

    def text(self) -> str:
        """The whole text (what is shown may be shortened)."""
        return self._full

    def shown_text(self) -> str:
        return super().text()

    def sizeHint(self) -> QSize:
        return QSize(self.fontMetrics().horizontalAdvance(self._full) + 8, super().sizeHint().height())

    def minimumSizeHint(self) -> QSize:
        return QSize(min(self._min_width, self.sizeHint().width()), super().minimumSizeHint().height())

    def resizeEvent(self, event: QResizeEvent) -> None:
        super().resizeEvent(event)
        self._elide()

    def _elide(self) -> None:
        width = max(self.width() - 4, 0)
        shown = self.fontMetrics().elidedText(self._full, Qt.TextElideMode.ElideRight, width)
        super().setText(shown)
        self.setToolTip(self._full if shown != self._full else self.detail)


class StatusLine(QStatusBar):
    """See the module docstring; ``message_label`` is the one place messages are drawn."""

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("StatusLine")
        self.message_label = ElidedLabel(min_width=80)
        self.message_label.setObjectName("StatusMessage")
        self.addWidget(self.message_label, 1)
        self._message = ""
        self._notes: dict[str, str] = {}
        self._timer = QTimer(self)
        self._timer.setSingleShot(True)
        self._timer.timeout.connect(self.clearMessage)

    # QStatusBar's API, so every caller of ``statusBar().showMessage`` lands here
    def showMessage(self, text: str, timeout: int = 0) -> None:
        self._message = str(text)
        if timeout > 0:
            self._timer.start(int(timeout))
        else:
            self._timer.stop()
        self._show()

    def clearMessage(self) -> None:
        self._message = ""
        self._timer.stop()
        self._show()

    def currentMessage(self) -> str:
        """What the line says now: the message, else the newest note."""
        if self._message:
            return self._message
        return next(reversed(self._notes.values()), "")

    def set_note(self, key: str, text: str | None) -> None:
        """A state that holds until it is over (None or "" ends it)."""
        self._notes.pop(key, None)
        if text:
            self._notes[key] = str(text)
        self._show()

    def clear_document(self) -> None:
        """Another document opened: nothing said about the last one stays."""
        self._message = ""
        self._timer.stop()
        self._notes.clear()
        self._show()

    def _show(self) -> None:
        text = self.currentMessage()
        if text != self.message_label.text():
            self.message_label.setText(text)
            self.messageChanged.emit(text)
