"""Random sequences of an artist's groom actions in the real window prove that the studio runs on
the document (issue 43 point 3): strokes dragged with the mouse, selection steps, slider drags of
the engine's parameters, the up axis, the head mesh, render hair and Clump children, Edit ▸ Undo
and Redo, Save and reopen.

After every step: what the window shows is what the document's state gives when made afresh
(every array's bytes: strands, mask, clump strengths, selection, hidden), the title's "*" is the
stack's clean state and Edit ▸ Undo names its step. Undo back to the start gives the start, and
a save reopens as shown. The Qt-free document has its own machine
(``tests/document/test_document_states.py``); this one covers the window's way to it.

CI runs ``STUDIO_DOCUMENT_EXAMPLES`` sequences (default 4) of ``STUDIO_DOCUMENT_STEPS`` (12).
"""

from __future__ import annotations

import os
from functools import cache

import numpy as np
import pytest
from hypothesis import HealthCheck, Phase, settings
from hypothesis import strategies as st
from hypothesis.stateful import (
    RuleBasedStateMachine,
    initialize,
    invariant,
    precondition,
    rule,
    run_state_machine_as_test,
)
from PySide6.QtCore import Qt

from app.document.groom import GroomSide
from app.document.undo import UndoStack
from app.ui.brush_tool import brushes
from hairtool import samples
from hairtool.errors import ParameterError
from hairtool.guides.binding import bind_scalp
from hairtool.io.obj import read_mesh

pytestmark = pytest.mark.gui

OPS = ["all", "none", "invert", "hide_selected", "hide_unselected", "reveal"]


@cache
def _head(path):
    return read_mesh(path)


def _bytes(scene_or_pipeline) -> tuple:
    p = scene_or_pipeline
    return tuple(
        np.ascontiguousarray(a).tobytes() for a in (p.locked, p.clump_strength, p.selected, p.hidden)
    )


def _machine(make_window, ui, grooms_dir, tmp_path):
    head_path = grooms_dir / "sintel_head.obj"

    class StudioOnTheDocument(RuleBasedStateMachine):
        @initialize()
        def open_window(self) -> None:
            self.w = make_window(groom=samples.scalp(strands=30, vertices=6, seed=3))
            self.w.scene.set_radius(0.6)
            self.start = self.w.doc.hair.state
            self.saves = self.drags = 0

        # -- the artist's actions ----------------------------------------------------------
        @rule(
            brush=st.sampled_from(
                ["align", "comb", "length", "mask", "clump", "smooth", "puff", "cut", "select"]
            ),
            strand=st.integers(0, 29),
            offset=st.tuples(st.floats(-40, 40), st.floats(-40, 40)),
            held=st.sampled_from([None, "shift", "ctrl"]),
        )
        def stroke(self, brush, strand, offset, held) -> None:
            """A left-drag in the viewport from a strand's tip (the engine thread runs it); a
            select drag with Shift (add) or Ctrl (deselect) held, or neither (a new selection)."""
            assert brush in brushes()
            w = self.w
            w.scene.set_brush(brush)
            start = w.viewport.project(
                w.scene.result.tips[strand % w.scene.result.strand_count : 1 + strand]
            )[0]
            index = w.undo_stack.count()
            mods = {"shift": Qt.KeyboardModifier.ShiftModifier, "ctrl": Qt.KeyboardModifier.ControlModifier}
            modifiers = mods.get(held) if brush == "select" else None
            ui.drag(w.viewport, start, start + np.array(offset), steps=3, modifiers=modifiers)
            assert w.undo_stack.count() <= index + 1  # one stroke, one step at most

        @rule(op=st.sampled_from(OPS))
        def select(self, op) -> None:
            self.w.selection.step(op)

        @rule(values=st.lists(st.floats(2.0, 20.0), min_size=1, max_size=3), drag=st.integers(0, 3))
        def stiffness_slider(self, values, drag) -> None:
            """A slider dragged through a few values: one step."""
            index = self.w.undo_stack.count()
            self.drags += 1
            for v in values:
                self.w.dock.param_edited.emit("bend_stiffness", v, (self.drags, drag))
            assert self.w.undo_stack.count() <= index + 1

        @rule(axis=st.sampled_from(["Y", "Z"]))
        def up_axis(self, axis) -> None:
            self.w.up_axis_actions[axis].trigger()
            assert self.w.scene.up_axis == axis

        @rule(on=st.booleans())
        def head_mesh(self, on) -> None:
            if on:
                self.w.scene.set_mesh(_head(head_path), "Load head mesh")
            else:
                self.w.remove_mesh()

        @rule(on=st.booleans(), clump=st.booleans())
        def render_hair(self, on, clump) -> None:
            s = self.w.scene
            if on and s.mesh is not None and s.result.topology == s.rest.topology:
                try:  # (the head is Sintel's: an up-axis switch can leave no scalp near the roots,
                    # which the studio refuses with a line and this rule skips)
                    binding = bind_scalp(s.rest, s.mesh, 40, seed=1)
                except ParameterError:
                    return
                s.set_binding(binding, clump=clump, text="Grow render hair")
            else:
                self.w.remove_render_hair()

        @precondition(lambda self: self.w.scene.binding is not None)
        @rule()
        def toggle_clump_children(self) -> None:
            s = self.w.scene
            s.set_clump_children(not s.clump_children)

        @rule(n=st.integers(1, 3))
        def undo(self, n) -> None:
            for _ in range(n):
                self.w.undo_action.trigger()

        @rule(n=st.integers(1, 2))
        def redo(self, n) -> None:
            for _ in range(n):
                self.w.redo_action.trigger()

        @rule()
        def save_and_reopen(self) -> None:
            """File ▸ Save to a project, opened in another window: what this one shows."""
            self.saves += 1
            path = tmp_path / f"p{self.saves}.hairproj"
            assert self.w.project.save_to(path), self.w.errors
            assert self.w.undo_stack.isClean() and "*" not in self.w.windowTitle()
            other = make_window()
            assert other.project.open_project(path), other.errors
            a, b = self.w.scene, other.scene
            assert a.result.points.tobytes() == b.result.points.tobytes()
            assert _bytes(a) == _bytes(b) and a.up_axis == b.up_axis and a.params == b.params
            assert (a.binding is None) == (b.binding is None) and a.clump_children == b.clump_children
            other.close()

        # -- what holds after every step --------------------------------------------------------
        @invariant()
        def the_window_shows_the_document(self) -> None:
            w = self.w
            state = w.doc.hair.state
            fresh = GroomSide(UndoStack(), state).pipeline  # the state made afresh
            s = w.scene
            assert s.result.points.tobytes() == fresh.result.points.tobytes()
            assert _bytes(s) == _bytes(fresh)
            assert s.mesh is state.mesh and s.binding is state.children and s.params == state.params
            assert ("*" in w.windowTitle()) != w.undo_stack.isClean()
            assert w.undo_action.text().replace("&", "").strip() == f"Undo {w.undo_stack.undoText()}".strip()

        def teardown(self) -> None:
            """Undo to the start gives the start; Redo back to where the sequence ended gives its
            last state back (steps it ended by undoing stay undone: redoing them changes it)."""
            if not hasattr(self, "w"):
                return
            w, stack = self.w, self.w.doc.stack
            last, at = w.scene.result.points.tobytes(), stack.index
            while stack.can_undo:
                w.undo_action.trigger()
            assert w.doc.hair.state is self.start
            assert (
                w.scene.result.points.tobytes() == GroomSide(UndoStack(), self.start).result.points.tobytes()
            )
            while stack.index < at:
                w.redo_action.trigger()
            assert w.scene.result.points.tobytes() == last
            w.close()

    return StudioOnTheDocument


def test_random_groom_actions_in_the_window_stay_on_the_document(make_window, ui, grooms_dir, tmp_path):
    examples = int(os.environ.get("STUDIO_DOCUMENT_EXAMPLES", 4))
    steps = int(os.environ.get("STUDIO_DOCUMENT_STEPS", 12))
    run_state_machine_as_test(
        _machine(make_window, ui, grooms_dir, tmp_path),
        settings=settings(
            max_examples=examples,
            stateful_step_count=steps,
            deadline=None,
            derandomize=True,
            phases=[Phase.generate],
            suppress_health_check=list(HealthCheck),
        ),
    )
