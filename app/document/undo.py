"""One undo stack for every edit of the document.

A :class:`Command` does, undoes, and may absorb the next command of the same drag
(:meth:`Command.merge`), so a drag is one step however many moves it made. "Changed" is the
stack's clean state: the index saved last, or none when work no step holds was added (an
animation made here, a step undone past the save and replaced).
"""

from __future__ import annotations

import weakref
from collections.abc import Callable
from dataclasses import dataclass


class Command:
    """One edit: ``do`` applies it, ``undo`` takes it back exactly. ``text`` is the menu's words."""

    text = ""

    def do(self) -> None:
        raise TypeError(f"{type(self).__name__} does not say what it does")

    def undo(self) -> None:
        raise TypeError(f"{type(self).__name__} does not say how it is undone")

    def merge(self, other: Command) -> bool:
        """Absorb ``other`` (already done) into this step; True when it did (a drag's next move)."""
        return False


@dataclass(frozen=True, eq=False)
class SaveMark:
    """Where the stack stood when a save took its snapshot (:meth:`UndoStack.mark`): the save
    that finishes later makes that state, not the one reached meanwhile, the clean one."""

    index: int
    top: Command | None
    generation: int


class UndoStack:
    """Commands done (undoable) and undone (redoable); callbacks hear every change."""

    def __init__(self) -> None:
        self._done: list[Command] = []
        self._undone: list[Command] = []
        self._clean: int | None = 0
        self._kept: weakref.WeakSet[Command] = weakref.WeakSet()  # saves' snapshots: no merges
        self._generation = 0  # moves on when the document's states no step holds change
        self._listeners: list[Callable[[], None]] = []
        self.edits = 0  # counts pushes (merged ones too), undos, redos and clears: the steps moved

    def observe(self, callback: Callable[[], None]) -> None:
        self._listeners.append(callback)

    def _tell(self) -> None:
        for callback in list(self._listeners):
            callback()

    # -- editing ------------------------------------------------------------------------------
    def push(self, command: Command) -> None:
        """Do ``command`` and make it the step Undo takes back (merged into the last step when
        that one absorbs it, unless the last step is the saved state)."""
        command.do()
        if self._undone:
            if self._clean is not None and self._clean > len(self._done):
                self._clean = None  # the saved state was a step undone: it cannot come back
            self._undone.clear()
        top = self._done[-1] if self._done else None
        kept = len(self._done) == self._clean or top in self._kept
        if top is None or kept or not top.merge(command):
            self._done.append(command)
        self.edits += 1
        self._tell()

    def undo(self) -> bool:
        if not self._done:
            return False
        command = self._done.pop()
        command.undo()
        self._undone.append(command)
        self.edits += 1
        self._tell()
        return True

    def redo(self) -> bool:
        if not self._undone:
            return False
        command = self._undone.pop()
        command.do()
        self._done.append(command)
        self.edits += 1
        self._tell()
        return True

    def clear(self) -> None:
        """No steps (a new document); clean if it was."""
        clean = self.is_clean
        self._done.clear()
        self._undone.clear()
        self._clean = 0 if clean else None
        self._kept.clear()
        self._generation += 1
        self.edits += 1
        self._tell()

    # -- state ----------------------------------------------------------------------------------
    @property
    def index(self) -> int:
        """Steps done (the position Undo takes back from)."""
        return len(self._done)

    @property
    def count(self) -> int:
        """Steps held, done and undone."""
        return len(self._done) + len(self._undone)

    def command(self, i: int) -> Command:
        """Step ``i`` in the order done (0: the oldest; from :attr:`index` on, the undone ones)."""
        if not 0 <= i < self.count:
            raise IndexError(f"no step {i}: the stack holds {self.count}")
        return (
            self._done[i]
            if i < len(self._done)
            else self._undone[len(self._undone) - 1 - (i - len(self._done))]
        )

    @property
    def top(self) -> Command | None:
        """The step Undo takes back (None: none)."""
        return self._done[-1] if self._done else None

    @property
    def can_undo(self) -> bool:
        return bool(self._done)

    @property
    def can_redo(self) -> bool:
        return bool(self._undone)

    @property
    def undo_text(self) -> str:
        return self._done[-1].text if self._done else ""

    @property
    def redo_text(self) -> str:
        return self._undone[-1].text if self._undone else ""

    @property
    def is_clean(self) -> bool:
        return self._clean == len(self._done)

    def set_clean(self) -> None:
        """The document was saved here."""
        self._clean = len(self._done)
        self._tell()

    def mark_changed(self) -> None:
        """Work no step holds was added: unsaved until the next save."""
        self._clean = None
        self._generation += 1
        self._tell()

    def mark(self) -> SaveMark:
        """The state a save's snapshot holds; the step there takes no later merge, so the state
        at that index stays the snapshot's while the write runs."""
        if self.top is not None:
            self._kept.add(self.top)
        return SaveMark(len(self._done), self.top, self._generation)

    def holds(self, mark: SaveMark) -> bool:
        """Whether ``mark``'s state is still a state of this stack: not cleared or replaced since
        (a step undone past it and another pushed), no work outside the steps added."""
        if mark.generation != self._generation or mark.index > self.count:
            return False
        return mark.index == 0 or self.command(mark.index - 1) is mark.top

    def set_clean_at(self, mark: SaveMark) -> bool:
        """A save of ``mark``'s snapshot was written: that state is the saved one (edits made
        since stay unsaved). False, and nothing changes, when the stack no longer holds it."""
        if not self.holds(mark):
            return False
        self._clean = mark.index
        self._tell()
        return True
