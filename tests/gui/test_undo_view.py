"""The window's Edit ▸ Undo is a view of the document's one stack: Qt commands and document
commands land on the same stack, merge as Qt merges, and the signals follow every step."""

from __future__ import annotations

from PySide6.QtGui import QUndoCommand

from app.document.undo import Command, UndoStack
from app.ui.undo_view import UndoView


class _Set(Command):
    def __init__(self, box: list, value: int, text: str) -> None:
        self.box, self.value, self.text, self.old = box, value, text, None

    def do(self) -> None:
        self.old, self.box[0] = self.box[0], self.value

    def undo(self) -> None:
        self.box[0] = self.old


class _Drag(QUndoCommand):
    """Qt's way: redo on push, merge by id."""

    def __init__(self, box: list, value: int) -> None:
        super().__init__(f"Drag to {value}")
        self.box, self.before, self.after = box, box[0], value

    def id(self) -> int:
        return 7

    def mergeWith(self, other: QUndoCommand) -> bool:
        self.after = other.after
        self.setText(other.text())
        return True

    def redo(self) -> None:
        self.box[0] = self.after

    def undo(self) -> None:
        self.box[0] = self.before


def test_qt_and_document_commands_share_one_stack(qapp):
    stack, box = UndoStack(), [0]
    view = UndoView(stack)
    seen: list[tuple[str, object]] = []
    view.indexChanged.connect(lambda i: seen.append(("index", i)))
    view.cleanChanged.connect(lambda c: seen.append(("clean", c)))
    undo = view.createUndoAction(None, "&Undo")
    redo = view.createRedoAction(None, "&Redo")
    assert not undo.isEnabled() and undo.text() == "&Undo"

    view.push(_Drag(box, 1))
    view.push(_Drag(box, 2))  # the same drag: merged, as QUndoStack merges
    assert box == [2] and stack.count == 1 and view.undoText() == "Drag to 2"
    assert undo.text() == "&Undo Drag to 2" and undo.isEnabled()
    stack.push(_Set(box, 5, "Set 5"))  # a document command, pushed by the document itself
    assert view.count() == 2 and view.undoText() == "Set 5" and not view.isClean()
    assert ("index", 1) in seen and seen.count(("index", 1)) == 2  # the merged move was heard too
    assert ("clean", False) in seen

    undo.trigger()
    assert box == [2] and view.redoText() == "Set 5" and redo.text() == "&Redo Set 5"
    view.undo()
    assert box == [0] and view.isClean() and not view.canUndo()
    redo.trigger()
    assert box == [2] and isinstance(view.command(0), _Drag)
    view.setClean()
    view.resetClean()
    assert not view.isClean()
    view.clear()
    assert view.count() == 0 and view.isClean() and not redo.isEnabled()
