"""Posing a motion capture at its keys (seed 003 §5) in the studio.

A BVH opened in the studio is drawn as a skeleton of bones (:mod:`app.ui.animation_io`); this
module keeps the capture itself beside it. At a key frame its joints are handles
(:mod:`app.ui.joint_handles`): dragging one moves that joint to the cursor by inverse
kinematics on the chain above it (the tool dock's chain length, or Alt-drag for the whole limb
up to the root's child), solved live through :class:`hairtool.mocap.pose_edit.PoseEditor`
while the frames around the key follow as faint ghosts. With per-channel keys on (the graph
editor's box ticked, or per-channel key edits made) the drag poses the top layer, the one shown:
the IK keys each channel it turns on that channel's own keys (a ``channel_edits`` pose, which
``hairtool keys --edit`` replays the same way), so the joint lands on the cursor there too. A
finished drag is one undo step; the
timeline's skeleton is the edited capture (the key curves plus the captured residuals), so the
key errors and the viewport follow. File ▸ Export Animation writes it as BVH, and a project
keeps the capture and its list of edits (the ``hairtool keys --edit`` EDITS.json dicts, plus the
graph editor's key and handle edits) and applies them again on open.

The capture and its edits are the document's (``window.doc.state``: ``capture``, ``edits``,
``channel_edits``); a finished drag is :meth:`app.document.animation.Document.edit` (or
``edit_channels``), and this editor follows the document: its PoseEditor and layer are rebuilt
from the document's edits after every change, an undo and a redo alike.
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING

import numpy as np
from PySide6.QtCore import QObject, QPointF, Qt, Signal
from PySide6.QtWidgets import QFormLayout, QGroupBox, QLabel, QScrollArea, QSpinBox

from app.document.capture import skeleton_animation
from app.document.project_io import animation_settings
from hairtool.errors import HairtoolError
from hairtool.keys.channels import per_channel_keys
from hairtool.mocap import ik
from hairtool.mocap.bvh import Motion, write_bvh
from hairtool.mocap.channel_edit import ChannelEditor, ChannelRetimeEdit, channel_features
from hairtool.mocap.pose_edit import Edit, PoseEdit, PoseEditor, RetimeEdit

if TYPE_CHECKING:
    from app.ui.host import StudioHost

PICK_PX = 12.0  # a press this near a handle (widget pixels) takes that joint
GHOSTS = 6  # neighbouring frames drawn faintly while a key pose is dragged
NOT_A_KEY = "Capture poses are edited at a key frame: jump to one with ↑ / ↓"
NO_HANDLE = "Drag a joint's handle (the dots) to pose the capture; Alt-drag moves the whole limb"


class JointDrag:
    """The viewport's drag target on a capture: picks a joint handle in screen space (so Alt can
    mean "whole limb" there rather than orbit) and solves the IK on every move."""

    def __init__(self, capture: CaptureEditor) -> None:
        self.c = capture
        self.edit: PoseEdit | None = None
        self.last_target: np.ndarray | None = None
        self._start: tuple[int, int, np.ndarray, np.ndarray] | None = None  # frame, joint, p0, cursor0

    # The press / drag / end protocol (viewport): screen positions, modifiers.
    def press(self, pos: QPointF, modifiers: Qt.KeyboardModifier) -> bool:
        c = self.c
        if not c.attached or c.editor is None or not c.at_key():
            return False  # off a key no handle is drawn: the press is the viewport's
        j = c.handle_at(pos)
        if j is None:
            return False
        c.select(c.original.joint_names[j])
        m = c.model
        m.pause()
        alt = bool(modifiers & Qt.KeyboardModifier.AltModifier)
        depth = int(c.original.depths()[j])
        chain = max(depth - 1, 1) if alt else min(c.chain, depth)
        if c.layered:  # the chain's channels keyed on their own before the first solve
            c.column_keys(c.chain_columns(j, chain))
        p0 = c.pose_positions()[j]
        self._start = (m.frame, j, p0, c.window.viewport.cursor_on_plane(pos, p0))
        self._chain = chain
        self.edit = None
        return True

    def drag(self, pos: QPointF) -> None:
        if self._start is None:
            return
        frame, j, p0, cursor0 = self._start
        target = p0 + (self.c.window.viewport.cursor_on_plane(pos, p0) - cursor0)
        self.last_target = target
        self.edit = PoseEdit(
            frame, self.c.original.joint_names[j], tuple(float(v) for v in target), self._chain
        )
        self.c.preview(self.edit)

    def end(self) -> None:
        start, edit = self._start, self.edit
        self._start = self.edit = None
        if start is None:
            return
        self.c.preview(None)
        if edit is not None:
            self.c.commit_pose(edit, f"Pose {edit.joint} at key {edit.frame}")

    # The older protocol (a 3-D cursor): on a capture the old position drag is replaced.
    def begin(self, cursor: np.ndarray) -> bool:
        self.c.window.statusBar().showMessage(NO_HANDLE if self.c.at_key() else NOT_A_KEY, 4000)
        return False

    def move(self, cursor: np.ndarray) -> None:
        return None


class CaptureEditor(QObject):
    """Owned by the window (``window.capture``); see the module docstring."""

    changed = Signal()  # the edited capture changed (an edit, an undo, new keys)
    selection_changed = Signal(str)  # the selected joint's name ("" for none)
    preview_changed = Signal()

    def __init__(self, window: StudioHost) -> None:
        super().__init__(window)
        self.window, self.model = window, window.animation
        self.doc = self.model.doc
        self.editor: PoseEditor | None = None
        self.applied: list[bool] = []
        self.chain = 2
        self.joint = ""  # the selected joint
        self.ghosts: list[np.ndarray] = []  # (P, 3) joint positions of neighbouring frames in a drag
        self._preview: tuple[int, np.ndarray] | None = None  # frame, (J, 3) joints being dragged
        self.drag = JointDrag(self)
        self._syncing = False  # the timeline's keys are being set to the edited ones
        self.per_channel = False  # the graph editor's "Per-channel keys" box
        self.channel_applied: list[bool] = []
        self._column_keys: dict = {}
        self._layer: ChannelEditor | None = None
        self._seen = self.doc.state
        self.model.animation_changed.connect(self._on_animation_changed)
        self.model.keys_changed.connect(self._on_keys_changed)
        self.doc.observe(self._on_doc)
        self.box = self._tool_box()
        from app.ui.joint_handles import JointHandles

        self.handles = JointHandles(self, window.viewport)

    # -- state (the document's) ---------------------------------------------------------------
    @property
    def original(self) -> Motion | None:
        """The capture as captured."""
        return self.doc.state.capture

    @property
    def source(self) -> str:
        return self.doc.state.source

    @property
    def edits(self) -> list[Edit]:
        """IK poses and graph-editor key edits, in the order made."""
        return list(self.doc.state.edits)

    @property
    def channel_edits(self) -> list:
        """Per-channel key edits (and IK poses on them), over the pose edits."""
        return list(self.doc.state.channel_edits)

    @property
    def attached(self) -> bool:
        return self.original is not None and self.model.animation is not None

    @property
    def layered(self) -> bool:
        """Joint drags pose the per-channel layer: its box is ticked, or it holds edits (the
        layer is what is shown, so a pose below it would not land on the cursor)."""
        return self.per_channel or bool(self.channel_edits)

    def at_key(self) -> bool:
        return self.editor is not None and bool(np.any(self.editor.keys == self.model.frame))

    def _on_animation_changed(self) -> None:
        """Another animation: a capture's is posed here, anything else is not."""
        self.editor, self.applied, self.joint = None, [], ""
        self.channel_applied, self._column_keys, self._layer = [], {}, None
        self._preview, self.ghosts = None, []
        if self.attached:
            self.window.viewport.brush_target = self.drag
            self._rebuild()
        self._sync_box()
        self.selection_changed.emit("")
        self.changed.emit()

    def _on_doc(self) -> None:
        """The document's edits changed (an edit, its undo or redo): shown again."""
        old, new = self._seen, self.doc.state
        self._seen = new
        if new.take != old.take or new.capture is None:
            return  # another animation: :meth:`_on_animation_changed`
        if new.edits != old.edits or new.channel_edits != old.channel_edits:
            self._layer = None
            self._rebuild()

    def _on_keys_changed(self) -> None:
        if self.attached and not self._syncing:
            self._rebuild()

    def _sync_keys(self) -> None:
        """The timeline's keys become the edited ones (a key moved in time, or moved back)."""
        if self.editor is not None:
            self._syncing = True
            try:
                self.model.set_edited_keys(self.editor.keys)
            finally:
                self._syncing = False

    def _rebuild(self, show: bool = True) -> None:
        """A PoseEditor on the solved keys (whose frames include every edit's, pinned by the
        document), with every edit that applies (an edit at a frame the dope sheet excludes, or a
        key moved in time past its neighbours, waits, and the status bar says so)."""
        m = self.model
        keys = m.solved_keys if m.solved_keys is not None else m.dp_keys
        if keys is None:
            self.editor = None
            return
        interp = m.dp_poses.interp if m.dp_poses is not None else m.settings.interp
        self.editor = PoseEditor(self.original, keys, interp)
        self._layer = None
        self.applied = [self._try(e) for e in self.doc.state.edits]
        self._sync_keys()
        waiting = self.applied.count(False)
        if waiting:
            self.window.statusBar().showMessage(
                f"{waiting} pose edit(s) are at frames that are not keys now (excluded in the dope "
                "sheet): they come back with those keys",
                8000,
            )
        if show:
            self._show()
        self.changed.emit()

    def _apply(self, edit: Edit | list[Edit]) -> None:
        self.editor.apply_all(edit if isinstance(edit, list) else [edit])

    def _try(self, edit: Edit) -> bool:
        """Apply one edit where it still applies (its frame a key, a move between neighbours)."""
        if self.editor is None or not np.any(self.editor.keys == edit.frame):
            return False
        try:
            self._apply(edit)
        except HairtoolError:
            return False
        return True

    def motion(self) -> Motion:
        """The edited capture at every frame (the capture itself before any edit or keys): the
        pose-key edits, then the per-channel key edits on top."""
        if self.editor is None:
            return self.original
        if self.channel_edits:
            return self.channel_layer().motion()
        return self.editor.motion()

    # -- per-channel keys (seed 003: each channel its own keys) --------------------------------
    def column_keys(self, cols: list[int]) -> list[np.ndarray]:
        """Each column's own keys, solved on the capture as captured at the timeline's price per
        key (relative), angles unwrapped; cached per column until the price or interpolation
        changes."""
        interp = self.editor.interp if self.editor is not None else self.model.settings.interp
        what = (id(self.original), self.model.settings.tau, interp)
        if self._column_keys.get("what") != what:
            self._column_keys = {"what": what}
            self._layer = None
        missing = [c for c in cols if c not in self._column_keys]
        if missing:
            x = channel_features(self.original)[:, missing]
            found = per_channel_keys(x, self.model.settings.tau, interp=interp, relative=True).keys
            self._column_keys.update(zip(missing, found, strict=True))
            self._layer = None  # those columns had two keys there
        return [self._column_keys[c] for c in cols]

    def channel_layer(self) -> ChannelEditor | None:
        """The per-channel key edits over the pose-edited capture (a ChannelEditor on it, its
        edits applied where they still apply); None before keys."""
        if self.editor is None:
            return None
        cols = sorted({c for e in self.channel_edits for c in self._columns(e)})
        solved = dict(zip(cols, self.column_keys(cols), strict=True))
        if self._layer is None:
            m = self.original
            two = np.array([0, m.n_frames - 1], dtype=np.int64)
            keys = [solved.get(c, self._column_keys.get(c, two)) for c in range(m.n_channels)]
            layer = ChannelEditor(self.editor.motion(), keys, self.editor.interp, pose_keys=self.editor.keys)
            self.channel_applied = []
            for e in self.channel_edits:
                try:
                    layer.apply_all([e])
                    self.channel_applied.append(True)
                except HairtoolError:
                    self.channel_applied.append(False)
            self._layer = layer
        return self._layer

    def _columns(self, edit: object) -> list[int]:
        """The capture's columns an edit of the layer keys: one channel's, or for an IK pose the
        rotation channels of the joints its chain turns."""
        m = self.original
        j = m.joint_names.index(edit.joint)
        if isinstance(edit, PoseEdit):
            return self.chain_columns(j, edit.chain)
        return [int(m._starts[j]) + m.channels[j].index(edit.channel)]

    def chain_columns(self, joint: int, chain: int) -> list[int]:
        """The rotation columns of the ``chain`` joints above ``joint`` (what its IK may turn)."""
        m = self.original
        return [c for a in ik.ancestors(m, joint, chain) for c in ik.rotation_columns(m, a)[0]]

    def commit_channel(self, edits: list, text: str) -> bool:
        """One undo step for a per-channel key dragged (refused with a message when it cannot be)."""
        self.column_keys(sorted({c for e in edits for c in self._columns(e)}))
        self._layer = None
        layer = self.channel_layer()
        if layer is None:
            return False
        done = 0
        try:
            for e in edits:
                layer.apply_all([e])
                done += 1
        except HairtoolError as e:
            title = "Cannot pose the capture" if isinstance(edits[-1], PoseEdit) else "Cannot move the key"
            self.window.show_error(title, str(e))
            return False
        finally:
            last = layer.reports[-1] if done else None
            for _ in range(done):
                layer.undo()
        self.doc.edit_channels(list(edits), text)
        if isinstance(edits[-1], PoseEdit):
            self._say_reach(edits[-1], last, " on its channels' own keys")
        return True

    def preview_channel(self, edits: list | None) -> Motion | None:
        """Show per-channel key edits at the dragged key's frame (None: stop); the edited capture
        is returned."""
        m = self.model
        layer = self.channel_layer()
        if not edits or layer is None:
            m.set_preview(m.frame, None)
            return None
        layer.apply_all(edits)
        try:
            out = layer.motion()
        finally:
            for _ in edits:
                layer.undo()
        last = edits[-1]
        key = last.to if isinstance(last, ChannelRetimeEdit) else last.frame
        sub = out.with_values(out.values[key : key + 1])
        m.set_preview(key, skeleton_animation(sub).frames[0])
        return out

    def _show(self) -> None:
        """The timeline's skeleton becomes the edited capture (only the frames that changed)."""
        anim = self.model.animation
        frames = skeleton_animation(self.motion()).frames
        rows = np.flatnonzero(np.any(frames != anim.frames, axis=(1, 2)))
        if rows.size:
            lo, hi = int(rows[0]), int(rows[-1])
            self.model.replace_frames(lo, frames[lo : hi + 1])

    # -- editing -----------------------------------------------------------------------------
    def commit(self, edit: Edit | list[Edit], text: str) -> bool:
        """One undo step for ``edit`` (or a list of edits; refused with a message when one
        cannot be solved)."""
        if self.editor is None:
            return False
        edits = edit if isinstance(edit, list) else [edit]
        done = 0
        try:  # solved once here so the undo step's redo cannot fail; undone exactly
            for one in edits:
                self._apply(one)
                done += 1
        except HairtoolError as e:
            self.window.show_error("Cannot pose the capture", str(e))
            return False
        finally:
            last = self.editor.reports[-1] if done and self.editor.reports else None
            for _ in range(done):
                self.editor.undo()
        try:
            self.doc.edit(list(edits), text)
        except HairtoolError as e:
            self.window.show_error("Cannot pose the capture", str(e))
            return False
        edit = edits[-1]
        if isinstance(edit, PoseEdit):
            self._say_reach(edit, last)
        return True

    def commit_pose(self, edit: PoseEdit, text: str) -> bool:
        """One undo step for a joint drag, on the layer shown (:attr:`layered`)."""
        if self.layered:
            return self.commit_channel([edit], text)
        return self.commit(edit, text)

    def _say_reach(self, edit: PoseEdit, r, where: str = "") -> None:
        """The tool dock's line on how near the dragged joint got to the cursor."""
        if r is None:
            return
        reach = "reached" if r.miss_share <= r.tolerance_share else "out of reach; nearest pose"
        self.report.setText(f"{edit.joint}: {reach}{where} ({r.miss_share:.1e} of the figure's height)")

    def select(self, joint: str) -> None:
        if joint != self.joint:
            self.joint = joint
            self.selection_changed.emit(joint)
            self.handles.update()

    # -- the live drag -----------------------------------------------------------------------
    def preview(self, edit: Edit | list[Edit] | None) -> None:
        """Show ``edit`` (or edits) solved at its key, with the frames around it as ghosts
        (None: stop)."""
        m = self.model
        if edit is None or self.editor is None:
            self._preview, self.ghosts = None, []
            m.set_preview(m.frame, None)
            self.preview_changed.emit()
            self.handles.update()
            return
        edits = edit if isinstance(edit, list) else [edit]
        layer = self.channel_layer() if self.layered and isinstance(edits[-1], PoseEdit) else None
        editor = self.editor if layer is None else layer
        editor.apply_all(edits)
        try:
            out = editor.motion()
            key = edits[-1].to if isinstance(edits[-1], RetimeEdit) else edits[-1].frame
            if layer is None:
                first, last = self.editor.span(key)
            else:  # the frames the channels it keyed changed
                first, last = layer.reports[-1].first, layer.reports[-1].last
        finally:
            for _ in edits:
                editor.undo()
        inner = np.setdiff1d(np.arange(first, last + 1), [key])
        if inner.size:
            inner = inner[
                np.unique(np.linspace(0, inner.size - 1, min(GHOSTS, inner.size)).round().astype(int))
            ]
        frames = np.r_[key, inner].astype(np.int64)
        sub = out.with_values(out.values[frames])
        joints = sub.joint_positions(end_sites=True)
        self._preview = (key, joints[0])
        self.ghosts = list(joints[1:])
        m.set_preview(key, skeleton_animation(sub).frames[0])
        self.preview_changed.emit()
        self.handles.update()

    def pose_positions(self) -> np.ndarray:
        """``(J + E, 3)`` joint and End Site positions drawn now (a drag's preview, else the frame)."""
        if self._preview is not None and self._preview[0] == self.model.frame:
            return self._preview[1]
        m = self.motion()
        f = self.model.frame
        return m.with_values(m.values[f : f + 1]).joint_positions(end_sites=True)[0]

    def handle_at(self, pos: QPointF) -> int | None:
        """The joint whose handle is under ``pos`` (widget pixels), or None; the root is no handle
        (it has no parents to turn)."""
        m = self.original
        p = self.pose_positions()[: m.n_joints]
        xy = self.window.viewport.project(p)
        d = np.hypot(xy[:, 0] - pos.x(), xy[:, 1] - pos.y())
        d[m.depths() == 0] = np.inf
        j = int(np.argmin(d))
        return j if d[j] <= PICK_PX else None

    # -- files -------------------------------------------------------------------------------
    def export_bvh(self, path: str | os.PathLike[str]) -> bool:
        """The edited capture at every frame as BVH (the capture's skeleton, channels, frame time)."""
        try:
            if not self.attached:
                raise HairtoolError("BVH is written for a motion capture: open a .bvh first")
            write_bvh(path, self.motion())
        except HairtoolError as e:
            self.window.show_error("Cannot export animation", str(e))
            return False
        left = self.applied.count(False) + self.channel_applied.count(False)
        without = f", without {left} edit(s) at frames that are no longer keys" if left else ""
        self.window.statusBar().showMessage(f"exported {path}{without}", 8000 if left else 5000)
        return True

    def to_settings(self) -> dict | None:
        """What a project keeps: the capture (BVH text), where it came from and its edits (the
        document's, as :mod:`app.document.project_io` writes them), and the tool's chain."""
        if not self.attached:
            return None
        return animation_settings(self.doc.state)["capture"] | {"chain": self.chain}

    def apply_settings(self, saved: object) -> None:
        """A project's tool setting (the chain length); its capture and edits came with the
        document."""
        if isinstance(saved, dict) and isinstance(saved.get("chain"), int):
            self.set_chain(saved["chain"])

    # -- the tool dock's box -----------------------------------------------------------------
    def _tool_box(self) -> QGroupBox:
        box = QGroupBox("Capture pose")
        form = QFormLayout(box)
        self.chain_spin = QSpinBox()
        self.chain_spin.setRange(1, 16)
        self.chain_spin.setValue(self.chain)
        self.chain_spin.setToolTip(
            "How many joints above the dragged one turn: 2 is the upper and lower limb, solved "
            "exactly (two-bone IK); longer chains by damped least squares. Alt-drag turns the "
            "whole limb up to the root's child"
        )
        self.chain_spin.valueChanged.connect(self.set_chain)
        form.addRow("Chain length", self.chain_spin)
        self.report = QLabel("")
        self.report.setWordWrap(True)
        form.addRow(self.report)
        dock = self.window.dock.widget()
        body = dock.widget() if isinstance(dock, QScrollArea) else dock
        layout = body.layout()
        layout.insertWidget(max(layout.count() - 1, 0), box)
        box.setVisible(False)
        return box

    def set_chain(self, n: int) -> None:
        self.chain = int(n)
        if self.chain_spin.value() != self.chain:
            self.chain_spin.setValue(self.chain)

    def _sync_box(self) -> None:
        self.box.setVisible(self.attached)
        self.report.setText("")
