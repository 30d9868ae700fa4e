"""The document's undo stack against a list model: random pushes, merges, undos, redos, saves
and clears; the value, the clean state and the menu's words agree with the model after each."""

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

    def _heard(self) -> None:
        self.heard += 1

    @rule(n=st.integers(-5, 5), drag=st.sampled_from([None, 1, 2]))
    def push(self, n: int, drag: int | None) -> None:
        heard = self.heard
        self.stack.push(Add(self.box, n, drag))
        if self.saved is not None and self.saved > self.index:
            self.saved = None
        merged = drag is not None and self.index > 0 and self.drags[self.index] == drag
        merged = merged and self.saved != self.index
        del self.values[self.index + 1 :], self.drags[self.index + 1 :]
        if merged:
            self.values[self.index] += n
        else:
            self.values.append(self.values[self.index] + n)
            self.drags.append(drag)
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
        self.values, self.drags, self.index = [self.box[0]], [None], 0
        self.saved = 0 if clean else None

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
