"""Undo steps: one per brush stroke (or replayed stroke log) or selection step, one per (merged)
parameter edit, one per render hair grown or removed, one per head mesh loaded or removed, one
per up axis set."""

from __future__ import annotations

from PySide6.QtGui import QUndoCommand

from app.ui.scene import Scene
from hairtool.frozen.pipeline import FrozenParams
from hairtool.guides.binding import ChildBinding
from hairtool.io.obj import Mesh

_PARAM_ID_BASE = 1000
_PARAM_IDS: dict[str, int] = {}


class StrokeCommand(QUndoCommand):
    """A whole left-drag, already applied while dragging: pushing it does not apply it again."""

    def __init__(self, scene: Scene, before: object, after: object, brush: str | None = "Align") -> None:
        super().__init__(f"{brush or 'Brush'} stroke")
        self._scene = scene
        self._before = before
        self._after = after
        self._applied = True

    def redo(self) -> None:
        if self._applied:  # the first redo() comes from QUndoStack.push: the drag already did it
            self._applied = False
            return
        self._scene.restore(self._after)

    def undo(self) -> None:
        self._scene.restore(self._before)


class SelectionCommand(StrokeCommand):
    """A selection step (select all, box select, hide, reveal …), already applied."""

    def __init__(self, scene: Scene, before: object, after: object, text: str) -> None:
        super().__init__(scene, before, after)
        self.setText(text)


class ParamCommand(QUndoCommand):
    """A change of one engine parameter; slider drags on the same field merge into one step."""

    def __init__(
        self, scene: Scene, name: str, before: FrozenParams, after: FrozenParams, drag: int | None = None
    ) -> None:
        """``drag``: an id shared by the edits of one slider drag (None: never merge)."""
        super().__init__(f"Change {name.replace('_', ' ')}")
        self._scene = scene
        self.name = name
        self.drag = drag
        self._before = before
        self._after = after

    def id(self) -> int:
        return _PARAM_IDS.setdefault(self.name, _PARAM_ID_BASE + len(_PARAM_IDS))

    def mergeWith(self, other: QUndoCommand) -> bool:
        if not isinstance(other, ParamCommand) or other.name != self.name:
            return False
        if self.drag is None or other.drag != self.drag:
            return False
        self._after = other._after
        return True

    def redo(self) -> None:
        self._scene.set_params(self._after)

    def undo(self) -> None:
        self._scene.set_params(self._before)


class RenderHairCommand(QUndoCommand):
    """Render hair grown on, or taken off, the groom's strands (which stay as they are)."""

    def __init__(
        self, scene: Scene, before: ChildBinding | None, after: ChildBinding | None, text: str
    ) -> None:
        super().__init__(text)
        self._scene = scene
        self._before = before
        self._after = after
        self._clump_before = scene.clump_children  # Clump children as the artist left it …
        self._clump_after: bool | None = None  # … and, once undone, as it was after (None: the default)

    def redo(self) -> None:
        self._scene.set_binding(self._after, clump=self._clump_after)

    def undo(self) -> None:
        self._clump_after = self._scene.clump_children
        self._scene.set_binding(self._before, clump=self._clump_before)


class MeshCommand(QUndoCommand):
    """The groom's head mesh loaded, replaced or removed (the strands stay as they are)."""

    def __init__(self, scene: Scene, before: Mesh | None, after: Mesh | None, text: str) -> None:
        super().__init__(text)
        self._scene, self._before, self._after = scene, before, after

    def redo(self) -> None:
        self._scene.set_mesh(self._after)

    def undo(self) -> None:
        self._scene.set_mesh(self._before)


class UpAxisCommand(QUndoCommand):
    """The groom's up axis set (View > Up axis): the points stay, the view and engines turn."""

    def __init__(self, scene: Scene, before: str, after: str) -> None:
        super().__init__(f"Up axis {after}")
        self._scene, self._before, self._after = scene, before, after

    def redo(self) -> None:
        self._scene.set_up_axis(self._after)

    def undo(self) -> None:
        self._scene.set_up_axis(self._before)
