"""The document's undo stack against a list model: random pushes, merges, undos, redos, saves
and clears, and saves written later than their snapshot was taken (a snapshot marked, a write
ending after more edits); the value, the clean state and the menu's words agree with the model
after each."""

from __future__ import annotations

from hypothesis import settings
from hypothesis import strategies as st
from hypothesis.stateful import RuleBasedStateMachine, invariant, rule

from app.document.undo import Command, UndoStack


class Add(Command):
    """Adds ``n`` to a one-item list; moves of the same ``drag`` merge into one step."""

    def __init__(self, box: list[int], n: int, drag: int | None) -> None:
        self.box, self.n, self.drag, self.text = box, n, drag, f"add {n}"

    def do(self) -> None:
        self.box[0] += self.n

    def undo(self) -> None:
        self.box[0] -= self.n

    def merge(self, other: Command) -> bool:
        if self.drag is None or not isinstance(other, Add) or other.drag != self.drag:
            return False
        self.n += other.n
        return True


class StackMachine(RuleBasedStateMachine):
    def __init__(self) -> None:
        super().__init__()
        self.box = [0]
        self.stack = UndoStack()
        self.heard = 0
        self.stack.observe(self._heard)
        # the model: values after each step (index 0: the start), the index, the saved value
        self.values, self.index = [0], 0
        self.saved: int | None = 0  # the index saved at (None: unreachable)
        self.drags: list[int | None] = [None]
        self.ids: list[int | None] = [None]  # which step holds each state (None: the start)
        self.made = 0
        self.kept: set[int] = set()  # the steps snapshots were taken at: no merges into them
        self.generation = 0
        self.marks: list[tuple] = []  # (the stack's mark, index, step id, generation, value)

    def _heard(self) -> None:
        self.heard += 1

    @rule(n=st.integers(-5, 5), drag=st.sampled_from([None, 1, 2]))
    def push(self, n: int, drag: int | None) -> None:
        heard = self.heard
        self.stack.push(Add(self.box, n, drag))
        if self.saved is not None and self.saved > self.index:
            self.saved = None
        merged = drag is not None and self.index > 0 and self.drags[self.index] == drag
        merged = merged and self.index != self.saved and self.ids[self.index] not in self.kept
        del self.values[self.index + 1 :], self.drags[self.index + 1 :], self.ids[self.index + 1 :]
        if merged:
            self.values[self.index] += n
        else:
            self.values.append(self.values[self.index] + n)
            self.drags.append(drag)
            self.made += 1
            self.ids.append(self.made)
            self.index += 1
        assert self.heard == heard + 1

    @rule()
    def undo(self) -> None:
        assert self.stack.undo() == (self.index > 0)
        self.index = max(self.index - 1, 0)

    @rule()
    def redo(self) -> None:
        can = self.index < len(self.values) - 1
        assert self.stack.redo() == can
        self.index += can

    @rule()
    def save(self) -> None:
        self.stack.set_clean()
        self.saved = self.index

    @rule()
    def clear(self) -> None:
        clean = self.saved == self.index
        self.stack.clear()
        self.values, self.drags, self.ids, self.index = [self.box[0]], [None], [None], 0
        self.saved = 0 if clean else None
        self.kept, self.generation = set(), self.generation + 1

    @rule()
    def changed_outside_the_steps(self) -> None:
        self.stack.mark_changed()
        self.saved, self.generation = None, self.generation + 1

    @rule()
    def snapshot(self) -> None:
        """A save takes its snapshot; its write ends later (:meth:`written`)."""
        mark = self.stack.mark()
        self.kept.add(self.ids[self.index])
        self.marks.append((mark, self.index, self.ids[self.index], self.generation, self.box[0]))

    @rule(which=st.integers(0, 3))
    def written(self, which: int) -> None:
        """A snapshot's write ended: its state is the saved one while the stack still holds it."""
        if not self.marks:
            return
        mark, index, step, generation, value = self.marks.pop(which % len(self.marks))
        holds = generation == self.generation and index < len(self.ids) and self.ids[index] == step
        assert self.stack.set_clean_at(mark) == holds
        if holds:
            assert self.values[index] == value  # the state saved is the snapshot's, not a later one
            self.saved = index

    @invariant()
    def agrees(self) -> None:
        assert self.box[0] == self.values[self.index]
        assert self.stack.index == self.index
        assert self.stack.is_clean == (self.saved == self.index)
        assert self.stack.can_undo == (self.index > 0)
        assert self.stack.can_redo == (self.index < len(self.values) - 1)


TestUndoStack = StackMachine.TestCase
TestUndoStack.settings = settings(max_examples=100, stateful_step_count=40, deadline=None)


def test_a_save_undone_and_replaced_never_reads_clean_again():
    box, stack = [0], UndoStack()
    for n in (1, 2, 3):
        stack.push(Add(box, n, None))
    stack.set_clean()
    stack.undo()
    stack.undo()
    stack.push(Add(box, 5, None))
    stack.push(Add(box, 7, None))  # the same depth as the save, other work
    assert stack.index == 3 and not stack.is_clean and box == [13]


def test_a_write_ending_after_edits_marks_the_snapshot_saved_not_the_edits():
    box, stack = [0], UndoStack()
    stack.push(Add(box, 1, 7))
    mark = stack.mark()  # a save's snapshot: box == [1]
    stack.push(Add(box, 2, 7))  # the same drag goes on: a step of its own, not merged into the snapshot's
    assert stack.count == 2
    assert stack.set_clean_at(mark) and not stack.is_clean
    stack.undo()
    assert stack.is_clean and box == [1]


def test_a_snapshot_undone_past_and_replaced_is_not_saved_when_its_write_ends():
    box, stack = [0], UndoStack()
    stack.push(Add(box, 1, None))
    stack.push(Add(box, 2, None))
    mark = stack.mark()  # box == [3]
    stack.undo()
    stack.push(Add(box, 5, None))  # the same depth, other work: box == [6]
    assert not stack.set_clean_at(mark) and not stack.is_clean
    cleared = stack.mark()
    stack.clear()  # another document
    assert not stack.set_clean_at(cleared)
