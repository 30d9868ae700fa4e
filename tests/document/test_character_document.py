"""The character side of the document: edits as undoable steps (a state machine of random edits,
undos and redos), the cycle the anime dock sets, the springs beside it, and the files out."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import settings
from hypothesis import strategies as st
from hypothesis.stateful import RuleBasedStateMachine, invariant, rule

from app.document.character import VIEWS, CharacterDocument
from hairtool.anime.wave import WaveParams
from hairtool.character import load_character
from hairtool.character.cycle import ChainWave, character_cycle
from hairtool.errors import ParameterError

VRM = Path(__file__).resolve().parents[1] / "data" / "characters" / "bunches.vrm"
CHARACTER = load_character(VRM)
CHAINS = len(CHARACTER.chains)


class CharacterEdits(RuleBasedStateMachine):
    """Random edits, drags, undos and redos: the document is always the state the model says,
    and the cycle it derives is the library's cycle of those settings."""

    def __init__(self) -> None:
        super().__init__()
        self.doc = CharacterDocument(CHARACTER)
        self.done = [self.doc.state]  # the state after each step, the first the opened one
        self.drags: list[object] = [None]  # the drag of each step (a redone step's merges too)
        self.undone: list = []

    def _pushed(self, drag: object = None) -> None:
        if drag is not None and drag == self.drags[-1] and len(self.done) > 1:
            self.done[-1] = self.doc.state
        else:
            self.done.append(self.doc.state)
            self.drags.append(drag)
        self.undone.clear()

    @rule(
        chain=st.integers(0, CHAINS - 1),
        phase=st.floats(-1, 1),
        scale=st.floats(0, 2),
        profile=st.none() | st.floats(0, 3),
        drag=st.none() | st.sampled_from(["a", "b"]),
    )
    def edit_chain(self, chain, phase, scale, profile, drag):
        self.doc.set_chain(chain, drag, phase=phase, amplitude_scale=scale, profile=profile)
        self._pushed(drag)

    @rule(amplitude=st.floats(-2, 2), drag=st.none() | st.just("a"))
    def edit_wave(self, amplitude, drag):
        self.doc.set_wave(drag, amplitude=amplitude)
        self._pushed(drag)

    @rule(hold=st.integers(1, 3))
    def timing(self, hold):
        self.doc.set_timing(hold=hold)
        self._pushed()

    @rule(view=st.sampled_from(VIEWS))
    def view(self, view):
        self.doc.set_view(view)
        self._pushed()

    @rule(chain=st.none() | st.integers(0, CHAINS - 1))
    def select(self, chain):
        pushes = chain != self.doc.state.selected  # selecting the selected chain is no step
        self.doc.select(chain)
        if pushes:
            self._pushed()

    @rule()
    def apply(self):
        self.doc.apply()
        self._pushed()

    @rule()
    def undo(self):
        if self.doc.undo():
            self.undone.append((self.done.pop(), self.drags.pop()))

    @rule()
    def redo(self):
        if self.doc.redo():
            state, drag = self.undone.pop()
            self.done.append(state)
            self.drags.append(drag)

    @invariant()
    def the_state_is_the_models(self):
        assert self.doc.state is self.done[-1]
        assert self.doc.stack.index == len(self.done) - 1

    @invariant()
    def the_cycle_is_the_librarys(self):
        c = self.doc.state.cycle
        want = character_cycle(CHARACTER, c.wave, fps=c.fps, hold=c.hold, waves=dict(enumerate(c.chains)))
        np.testing.assert_array_equal(self.doc.cycle().pictures, want.pictures)
        applied = self.doc.state.applied
        if applied is not None:
            assert len(self.doc.animation()) == self.doc.cycle(applied).schedule.n_frames
            assert self.doc.drawing_frames()[0] == 0


CharacterEdits.TestCase.settings = settings(max_examples=8, stateful_step_count=6, deadline=None)
test_character_edits = CharacterEdits.TestCase


@pytest.mark.parametrize(
    ("call", "kwargs"),
    [
        ("set_chain", {"chain": CHAINS, "phase": 0.1}),
        ("set_chain", {"chain": 0, "phase": float("nan")}),
        ("set_chain", {"chain": 0, "axis": (0.0, 0.0, 0.0)}),
        ("set_chain", {"chain": 0, "profile": -1.0}),
        ("set_chain", {"chain": 0, "bend": 1.0}),
        ("set_wave", {"period": -1.0}),
        ("set_timing", {"hold": 0}),
        ("set_timing", {"fps": float("inf")}),
        ("set_springs", {"source": "wind"}),
        ("set_springs", {"source": "animation"}),  # the bundled character has none
        ("set_view", {"view": "sideways"}),
        ("select", {"chain": -1}),
    ],
)
def test_a_refused_edit_changes_nothing(call, kwargs):
    doc = CharacterDocument(CHARACTER)
    before = doc.state
    with pytest.raises(ParameterError):
        getattr(doc, call)(**kwargs)
    assert doc.state is before and not doc.stack.can_undo


def test_a_drag_is_one_step_and_undo_brings_the_rest_back():
    doc = CharacterDocument(CHARACTER)
    rest = doc.state
    for phase in np.linspace(0.0, 0.5, 6):
        doc.set_chain(3, "drag", phase=float(phase))
    assert doc.stack.index == 1 and doc.state.cycle.chains[3].phase == 0.5
    assert doc.undo() and doc.state is rest


def test_the_cycle_drives_the_chains_and_the_springs_sit_beside_it(tmp_path):
    doc = CharacterDocument(CHARACTER)
    doc.set_wave(amplitude=0.6)
    doc.apply()
    assert doc.state.applied.wave == WaveParams(amplitude=0.6)
    sched = doc.cycle().schedule
    np.testing.assert_array_equal(doc.drawing_frames(), np.concatenate([[0], np.cumsum(sched.holds)[:-1]]))
    for f in range(sched.n_frames * 2):  # the cycle loops: frame f shows its drawing
        np.testing.assert_array_equal(doc.pose(f, "cycle"), doc.cycle().frames()[f % sched.n_frames])
    doc.set_wave(amplitude=0.8)  # the applied animation keeps the settings it was made with
    assert doc.state.applied.wave.amplitude == 0.6
    doc.set_view("both")
    assert len(doc.springs()) == 4 * sched.n_frames
    m = doc.measure()
    assert m["frames"] == 44 and m["angular_error_deg"] > 0 and m["position_error_pct"] > 0
    out = tmp_path / "cycle.vrm"
    written = doc.export(out, "cycle")
    assert written["interpolation"] == "STEP"
    clip = load_character(out).clips[-1]
    assert clip.frame_rate() == 24.0
    back = clip.frames(CHARACTER.nodes, 24.0)[: sched.n_frames]
    np.testing.assert_allclose(np.abs(np.sum(back * doc.cycle().frames(), axis=-1)), 1.0, atol=1e-6)
    assert doc.export(tmp_path / "springs.glb", "springs")["interpolation"] == "LINEAR"
    doc.export_bvh(tmp_path / "hair.bvh", "springs")
    assert (tmp_path / "hair.bvh").read_text().startswith("HIERARCHY")


def test_the_table_1_measure_is_the_command_lines():
    """Fig. 2 timing, a ±30° head shake at 1 Hz, 44 frames, the chains varied as ``hairtool anime``
    varies them: the numbers docs/cli/characters.md gives."""
    doc = CharacterDocument(CHARACTER)
    m = doc.measure()
    assert round(m["angular_error_deg"], 1) == 16.1 and round(m["position_error_pct"], 1) == 19.8
    doc.vary(0.0, 0.0)
    assert all(w == ChainWave() for w in doc.state.cycle.chains)
    with pytest.raises(ParameterError):
        doc.vary(2.0, 0.0)
