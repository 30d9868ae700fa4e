"""Edit ▸ Undo and Redo, the title's "*" and autosave's count, as views of the document's one
undo stack (:class:`app.document.undo.UndoStack`).

The studio keeps no history of its own: :class:`UndoView` shows the document's stack with the
calls and signals a Qt widget expects of a ``QUndoStack`` (``indexChanged``, ``cleanChanged``,
actions whose text names the step), and every push lands on the document's stack. A
``QUndoCommand`` pushed here becomes one document step (:class:`QtStep`), merging as Qt merges
(the same ``id()``, ``mergeWith``), so every edit of the studio is on the one stack, in the order
made, and "changed" is that stack's clean state.
"""

from __future__ import annotations

from PySide6.QtCore import QObject, Signal
from PySide6.QtGui import QAction, QUndoCommand

from app.document.undo import Command, SaveMark, UndoStack


class QtStep(Command):
    """A ``QUndoCommand`` as one document step: ``do`` is its ``redo`` (the first one too, as
    ``QUndoStack.push`` calls it), ``undo`` its ``undo``."""

    def __init__(self, command: QUndoCommand) -> None:
        self.command = command

    @property
    def text(self) -> str:  # (read when shown: mergeWith may change it)
        return self.command.text()

    def do(self) -> None:
        self.command.redo()

    def undo(self) -> None:
        self.command.undo()

    def merge(self, other: Command) -> bool:
        if not isinstance(other, QtStep):
            return False
        mine, theirs = self.command.id(), other.command.id()
        return mine != -1 and mine == theirs and self.command.mergeWith(other.command)


class UndoView(QObject):
    """The document's undo stack as the window's widgets use it (see the module docstring)."""

    indexChanged = Signal(int)
    cleanChanged = Signal(bool)
    canUndoChanged = Signal(bool)
    canRedoChanged = Signal(bool)
    undoTextChanged = Signal(str)
    redoTextChanged = Signal(str)

    def __init__(self, stack: UndoStack, parent: QObject | None = None) -> None:
        super().__init__(parent)
        self._stack = stack
        self._seen = self._state()
        stack.observe(self._heard)

    @property
    def stack(self) -> UndoStack:
        return self._stack

    def _state(self) -> tuple:
        s = self._stack
        return (s.index, s.is_clean, s.can_undo, s.can_redo, s.undo_text, s.redo_text, s.edits)

    def _heard(self) -> None:
        """The stack changed: each signal whose value moved is emitted; ``indexChanged`` for every
        step moved, a drag's merged move too (as Qt's stack does: autosave counts them)."""
        old, new = self._seen, self._state()
        self._seen = new
        if new[0] != old[0] or new[6] != old[6]:
            self.indexChanged.emit(new[0])
        for i, signal in ((1, self.cleanChanged), (2, self.canUndoChanged), (3, self.canRedoChanged)):
            if new[i] != old[i]:
                signal.emit(new[i])
        if new[4] != old[4]:
            self.undoTextChanged.emit(new[4])
        if new[5] != old[5]:
            self.redoTextChanged.emit(new[5])

    # -- editing ------------------------------------------------------------------------------
    def push(self, command: Command | QUndoCommand) -> None:
        """Do ``command`` and make it the step Undo takes back (a Qt command as a :class:`QtStep`)."""
        self._stack.push(command if isinstance(command, Command) else QtStep(command))

    def undo(self) -> None:
        self._stack.undo()

    def redo(self) -> None:
        self._stack.redo()

    def clear(self) -> None:
        """No steps, and clean (as ``QUndoStack.clear``): the document just opened or made."""
        self._stack.clear()
        self._stack.set_clean()

    def setClean(self) -> None:
        self._stack.set_clean()

    def mark(self) -> SaveMark:
        """The state a save's snapshot holds (see :meth:`UndoStack.mark`)."""
        return self._stack.mark()

    def setCleanAt(self, mark: SaveMark) -> bool:
        """That snapshot was written: its state is the saved one; False when no longer held."""
        return self._stack.set_clean_at(mark)

    def resetClean(self) -> None:
        """Work no step holds: unsaved until the next save."""
        self._stack.mark_changed()

    # -- reading ------------------------------------------------------------------------------
    def count(self) -> int:
        return self._stack.count

    def index(self) -> int:
        return self._stack.index

    def command(self, i: int) -> object:
        """Step ``i`` (a Qt command as pushed)."""
        c = self._stack.command(i)
        return c.command if isinstance(c, QtStep) else c

    def isClean(self) -> bool:
        return self._stack.is_clean

    def canUndo(self) -> bool:
        return self._stack.can_undo

    def canRedo(self) -> bool:
        return self._stack.can_redo

    def undoText(self) -> str:
        return self._stack.undo_text

    def redoText(self) -> str:
        return self._stack.redo_text

    # -- the menu's actions ---------------------------------------------------------------------
    def createUndoAction(self, parent: QObject, prefix: str = "&Undo") -> QAction:
        return self._action(
            parent, prefix, self.undo, self.canUndo, self.undoText, self.undoTextChanged, self.canUndoChanged
        )

    def createRedoAction(self, parent: QObject, prefix: str = "&Redo") -> QAction:
        return self._action(
            parent, prefix, self.redo, self.canRedo, self.redoText, self.redoTextChanged, self.canRedoChanged
        )

    @staticmethod
    def _action(parent, prefix, run, enabled, text, text_changed, enabled_changed) -> QAction:
        """An action named after the step it takes back or does again, enabled while there is one."""
        action = QAction(parent)

        def show(*_: object) -> None:
            t = text()
            action.setText(f"{prefix} {t}" if t else prefix)
            action.setEnabled(enabled())

        action.triggered.connect(lambda: run())
        text_changed.connect(show)
        enabled_changed.connect(show)
        show()
        return action
