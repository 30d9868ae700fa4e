"""A character in the studio: opened from File ▸ Open (.vrm, .glb, .gltf), drawn skinned with its
hair chains as bones over it, animated by the anime dock's cycle and by its spring bones.

The state lives in :class:`app.document.character.CharacterDocument` (Qt-free, edits as undoable
commands); this controller only turns input into its commands and its state into pictures:

- the viewport draws the skinned meshes (``renderer.character``, GPU skinning) and, as the
  groom, the chains root → tip (so the ramp colours them as it colours strands);
- the timeline plays the motion shown (the applied cycle, the springs, or both on the same
  chains) as an animation of those chains, and each frame it shows poses the meshes;
- the anime dock's Apply makes the cycle the character's animation;
- :class:`app.ui.character_dock.CharacterDock` edits the chains, the springs and the view.
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING

import numpy as np
from PySide6.QtCore import QEvent, QObject, Qt
from PySide6.QtWidgets import QMenu

from app.document.character import CharacterDocument
from app.render.character_bones import chain_lines, pick_chain
from app.resources import path as resource
from app.ui.character_dock import CharacterDock
from app.ui.qt_utils import add_action
from hairtool.anime.settings import AnimeSettings
from hairtool.character.read import is_character_path, load_character
from hairtool.errors import HairtoolError
from hairtool.groom import Animation, Groom
from hairtool.keys import session as ks

if TYPE_CHECKING:
    from app.ui.host import StudioHost

SOURCE = "character"  # the animation model's source while a character's motion is on the timeline
OPEN_FILTER = "Characters (*.vrm *.glb *.gltf)"


class CharacterStudio(QObject):
    """Owned by the window (``window.character``); ``doc`` is None until a character is opened."""

    def __init__(self, window: StudioHost) -> None:
        super().__init__(window)
        self.window = window
        self.doc: CharacterDocument | None = None
        self.cycles = 2  # cycles of the applied cycle on the timeline (the anime dock's "cycles")
        self._shown: tuple | None = None  # what the timeline holds, to reload it only when that changes
        self.dock = CharacterDock(window)
        window.addDockWidget(Qt.DockWidgetArea.RightDockWidgetArea, self.dock)
        self.dock.hide()
        self.dock.chain_selected.connect(lambda c: self.doc is not None and self.doc.select(c))
        self.dock.chain_edited.connect(self._chain_edited)
        self.dock.view_chosen.connect(lambda v: self._edit(lambda d: d.set_view(v)))
        self.dock.source_chosen.connect(lambda s: self._edit(lambda d: d.set_springs(source=s)))
        self.dock.undo_requested.connect(lambda: self.doc is not None and self.doc.undo())
        self.dock.redo_requested.connect(lambda: self.doc is not None and self.doc.redo())
        window.animation.frame_changed.connect(self.show_frame)
        window.viewport.installEventFilter(self)  # a click on a chain's bones selects the chain
        window.scene.groom_loaded.connect(self._groom_loaded)

    # -- opening -------------------------------------------------------------------------------
    @staticmethod
    def handles(path: str | os.PathLike[str]) -> bool:
        return is_character_path(path)

    def open(self, path: str | os.PathLike[str]) -> bool:
        """Open a character: its chains as the groom, its meshes skinned, the dock shown."""
        try:
            doc = CharacterDocument(load_character(path))
        except HairtoolError as e:
            self.window.show_error("Cannot open character", str(e))
            return False
        self.doc, self._shown = doc, None
        doc.observe(self._changed)
        c = doc.character
        world = c.nodes.world()
        self.window.set_groom(Groom.from_strands(chain_lines(c, world)), path, None)
        self._with_renderer(lambda r: r.character.set_character(c))
        self.dock.set_document(doc)
        self.dock.show()
        self.dock.raise_()
        self._show_motion()
        self._sync_actions()
        return True

    def _groom_loaded(self) -> None:
        """Another groom replaced the character's chains (a sample, a groom file): forget it."""
        path = self.window.scene.path
        if self.doc is not None and (path is None or os.fspath(path) != os.fspath(self.doc.character.path)):
            self.close()

    def close(self) -> None:
        """Forget the character (another file was opened)."""
        if self.doc is None:
            return
        self.doc = None
        self._with_renderer(lambda r: r.character.set_character(None))
        self.dock.set_document(None)
        self.dock.hide()
        self._sync_actions()

    # -- edits ---------------------------------------------------------------------------------
    def _edit(self, change) -> bool:
        if self.doc is None:
            return False
        try:
            change(self.doc)
        except HairtoolError as e:
            self.window.show_error("Cannot change the character", str(e))
            return False
        return True

    def _chain_edited(self, chain: int, changes: dict, drag: object) -> None:
        self._edit(lambda d: d.set_chain(chain, drag, **changes))

    def apply(self, settings: AnimeSettings) -> bool:
        """The anime dock's Apply: its wave, timing and variation on the chains, made the
        character's animation (one undo step each for what changed)."""
        if self.doc is None:
            return False
        self.cycles = max(1, int(settings.cycles))

        def change(d: CharacterDocument) -> None:
            d.set_wave(
                **{
                    k: getattr(settings.wave, k)
                    for k in ("amplitude", "wavelength", "gravity", "profile", "period")
                }
            )
            d.set_timing(fps=settings.fps, hold=settings.hold)
            d.vary(settings.amplitude_spread, settings.phase_spread, settings.seed)
            d.apply()

        return self._edit(change)

    def chain_at(self, xy: tuple[float, float]) -> int | None:
        """The chain whose bones pass under the viewport's pixel ``xy`` on the frame shown."""
        if self.doc is None:
            return None
        vp = self.window.viewport
        world = self.doc.character.nodes.world(self._pose(self.window.animation.frame))
        return pick_chain(vp.camera, (vp.width(), vp.height()), chain_lines(self.doc.character, world), xy)

    def eventFilter(self, obj: QObject, event: QEvent) -> bool:
        """A plain left click on a chain's bones selects it (and goes no further); anywhere else
        the viewport gets the click as usual."""
        if (
            self.doc is None
            or event.type() != QEvent.Type.MouseButtonPress
            or event.button() != Qt.MouseButton.LeftButton
            or event.modifiers() != Qt.KeyboardModifier.NoModifier
        ):
            return False
        chain = self.chain_at((event.position().x(), event.position().y()))
        if chain is None:
            return False
        self.doc.select(chain)
        return True

    # -- state → pictures ------------------------------------------------------------------------
    def _changed(self) -> None:
        self.dock.refresh()
        self._show_motion()

    def motion(self) -> tuple[np.ndarray, list[np.ndarray]]:
        """``(F, J, 4)`` the rotations that pose the meshes on each timeline frame, and the
        chains' motions drawn (one, or the cycle's and the springs' for "both")."""
        d = self.doc
        view = d.state.view
        if view == "cycle":
            body = (
                d.cycle_frames(d.cycle().schedule.n_frames * self.cycles)
                if d.state.applied
                else d.animation()
            )
            return body, [body]
        springs = d.springs()
        if view == "springs":
            return springs, [springs]
        cycle = d.cycle_frames(len(springs))
        return cycle, [cycle, springs]

    def _pose(self, frame: int) -> np.ndarray:
        body, _ = self.motion()
        return body[int(np.clip(frame, 0, len(body) - 1))]

    def _show_motion(self) -> None:
        """The motion on the timeline as the chains' animation; the meshes posed on its frame."""
        d = self.doc
        if d is None:
            return
        _, drawn = self.motion()
        nodes = d.character.nodes  # (the chains' places on every frame: tens of chains, cheap)
        frames = [
            np.concatenate([np.concatenate(chain_lines(d.character, nodes.world(m[f]))) for m in drawn])
            for f in range(len(drawn[0]))
        ]
        counts = [len(ch.nodes) for _ in drawn for ch in d.character.chains]
        model = self.window.animation
        s = d.state
        shown = (s.applied, s.view, s.springs, s.cycle if s.view != "cycle" else None, self.cycles)
        if shown != self._shown:  # a motion to play (not a selection, not an unapplied edit)
            self._shown = shown
            frame = model.frame if model.animation is not None else 0
            if len(frames) > 1:
                anim = Animation(np.stack(frames), counts, fps=d.fps)
                stack = self.window.doc.stack
                clean = stack.is_clean
                model.load_animation(anim, SOURCE, settings=self._keys(len(frames)))
                # the motion is the character document's (its own undo, not in a project): no
                # step of the window's document, which holds nothing else while it is shown
                stack.clear()
                if clean:
                    stack.set_clean()
                model.set_frame(min(frame, len(frames) - 1))
            self.dock.show_measure(d.measure() if s.view != "cycle" else None, d.drawing_frames())
        self.show_frame(model.frame if model.animation is not None else 0)

    def _keys(self, count: int) -> ks.KeySettings | None:
        """The applied cycle's keys are its drawings (each frame where one starts, and the last
        frame): the timeline shows them as its keys. Other motions get the model's own solve."""
        d = self.doc
        if d.state.view != "cycle" or d.state.applied is None:
            return None
        n = d.cycle(d.state.applied).schedule.n_frames
        starts = d.drawing_frames()
        pins = sorted(
            {int(f) for c in range(count // n + 1) for f in starts + c * n if f < count} | {count - 1}
        )
        return ks.KeySettings(count=len(pins), pins=tuple(pins))

    def show_frame(self, frame: int) -> None:
        if self.doc is None:
            return
        world = self.doc.character.nodes.world(self._pose(frame))
        self._with_renderer(lambda r: r.character.pose(world))

    def _with_renderer(self, call) -> None:
        vp = self.window.viewport
        if vp.renderer is None:
            return
        vp.makeCurrent()
        try:
            call(vp.renderer)
        finally:
            vp.doneCurrent()
        vp.update()

    # -- menus -----------------------------------------------------------------------------------
    def build_menus(self, file, before, new_menu) -> None:
        """File ▸ New from sample ▸ Character, and File ▸ Export character ▸ … (before ``before``)."""
        new_menu.addSeparator()
        add_action(self, new_menu, "Character (hair bones)", lambda: self.open(resource("bunches.vrm")))
        menu = QMenu("Export c&haracter", file)
        file.insertMenu(before, menu)
        for text, which in (
            ("Cycle as glTF/VRM (STEP keys at the drawings)…", "cycle"),
            ("Springs as glTF/VRM (LINEAR keys)…", "springs"),
            ("Springs' optimal keys as glTF/VRM (CUBICSPLINE)…", "springs keys"),
            ("Cycle's chains as BVH…", "cycle bvh"),
            ("Springs' chains as BVH…", "springs bvh"),
        ):
            add_action(self, menu, text, lambda _=False, w=which: self.export_dialog(w))
        menu.setToolTipsVisible(True)
        self.export_menu = menu
        self._sync_actions()

    def _sync_actions(self) -> None:
        """The exports are greyed out, saying why, until a character is open; the anime dock's
        Apply says what it applies to."""
        sources = getattr(self.window, "sources", None)
        if sources is not None:
            button = sources.dock.apply_button
            button.setText("Apply to character" if self.doc is not None else "Apply to groom")
            button.setToolTip(
                "Make the cycle the character's animation, on its hair chains"
                if self.doc is not None
                else "Make the cycle animation of the groom (or of the selected strands)"
            )
        menu = getattr(self, "export_menu", None)
        if menu is None:
            return
        for action in menu.actions():
            action.setEnabled(self.doc is not None)
            action.setToolTip("" if self.doc is not None else "Open a character (.vrm, .glb, .gltf) first")

    # -- files out -------------------------------------------------------------------------------
    def export_dialog(self, which: str) -> bool:
        """File ▸ Export character ▸ …: the cycle or the springs as glTF/VRM, or the chains as BVH."""
        if self.doc is None:
            self.window.show_error("Cannot export", "open a character (.vrm, .glb, .gltf) first")
            return False
        bvh = which.endswith(" bvh")
        filters = "BVH (*.bvh)" if bvh else "glTF binary (*.glb);;VRM (*.vrm);;glTF (*.gltf)"
        path = self.window.ask_save_path(f"Export {which}", filters)
        if not path:
            return False
        return self.export(path, which)

    def export(self, path: str | os.PathLike[str], which: str) -> bool:
        """``which``: "cycle" (STEP keys at the drawings), "springs" (LINEAR on every frame),
        "springs keys" (their optimal keys, CUBICSPLINE with fitted tangents), or "cycle bvh" /
        "springs bvh" for the chains' BVH."""
        motion, _, form = which.partition(" ")
        try:
            if form == "bvh":
                self.doc.export_bvh(path, motion)
            elif form == "keys":
                self.doc.export(path, motion, key_frames=self.doc.spring_keys(), interp="hermite-fit")
            else:
                self.doc.export(path, motion)
        except HairtoolError as e:
            self.window.show_error("Cannot export", str(e))
            return False
        self.window.statusBar().showMessage(f"wrote {path}", 5000)
        return True
