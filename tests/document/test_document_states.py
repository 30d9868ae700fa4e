"""Random sequences of the studio's actions on the Qt-free document (issue 43 point 4).

Rules are the artist's actions. On the groom (a few dozen strands on a tiny head): strokes of
every registered brush with random radius, strength, falloff, direction, symmetry, pen pressure
and its toggles, front faces only, an orthographic or a perspective camera (whose eye the
samples record), "affect selection only" and Ctrl or Shift held (a select
stroke: deselect, or add instead of a new selection); selection steps (all, none,
invert, box, hide and reveal); the up axis; the head mesh taken off and put back; render hair
grown and removed; engine parameters; the camera; opening another groom. On the animation side:
open a capture (or another one), apply an anime cycle, simulate, close the animation (each
answering the Save / Discard / Cancel question at random), key count, budget, price per key and
interpolation switches, pins and exclusions, IK poses and graph-editor key edits (value, handle,
move in time; drags of several moves). And undo, redo, save and reload. After every step: save →
load gives an equal document (every array's bytes: the file's, and the strokes' state replayed
from it; the archive made and read in memory by the file's own code, real files written and read
by the save-and-reload rule and the Save answers), undo back to the start gives the start (and
redo comes back), the keys record and the BVH read back and carry the edits, and every edit
applies or has its line.

CI runs ``DOCUMENT_EXAMPLES`` sequences (default 200) of at least 30 steps from a seed that
changes per run and is printed; ``DOCUMENT_SEED`` replays one. Longer runs:
``DOCUMENT_EXAMPLES=2000 DOCUMENT_STEPS=60 pytest -n 0 -s tests/document/test_document_states.py``.
"""

from __future__ import annotations

import json
import os
import random
import tempfile
from functools import cache
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, Phase, seed, settings
from hypothesis import strategies as st
from hypothesis.stateful import (
    RuleBasedStateMachine,
    initialize,
    invariant,
    precondition,
    rule,
    run_state_machine_as_test,
)

from app.document import project_io
from app.document.animation import AnimationState, Document
from app.document.groom import GroomState
from app.ui.brush_tool import FALLOFF_LABELS, BrushTool
from hairtool import project as pf
from hairtool import samples
from hairtool.anime.settings import AnimeSettings, cycle_for_groom
from hairtool.errors import HairtoolError, ParameterError
from hairtool.frozen.brushes import registry
from hairtool.frozen.selection import BOX_MODES, SelectionSample
from hairtool.guides.binding import bind_scalp
from hairtool.io.obj import Mesh
from hairtool.keys import session as ks
from hairtool.keys.edit import retime_key
from hairtool.keys.export import read_keys_json, record_keys
from hairtool.keys.session import key_edit_block
from hairtool.mocap import ik
from hairtool.mocap.bvh import read_bvh
from hairtool.mocap.pose_edit import ChannelEdit, PoseEdit, RetimeEdit, TangentEdit
from hairtool.simulate.options import SimulateOptions, run_simulation

MOTION = Path(__file__).resolve().parents[1] / "data" / "motion"
FRAMES = 20  # each capture is cut to this many frames: a step stays a few milliseconds
START = ks.KeySettings(samples=4)  # 4 samples per bone keep every solve cheap


@cache
def capture(which: int):
    m = read_bvh(MOTION / "mocapbank_walk.bvh")
    return m.with_values(m.values[which * FRAMES : (which + 1) * FRAMES])


@cache
def groom(which: int = 0):
    """Two tiny grooms on the sample head: a few dozen strands of a few vertices."""
    return samples.scalp(strands=(24, 16)[which], vertices=(5, 4)[which], seed=which)


@cache
def head(rings: int = 5, segments: int = 8) -> Mesh:
    """A low sphere inside the sample head (its vertices on it, so its faces under the roots)."""
    theta = np.linspace(0.0, np.pi, rings + 1)[1:-1]
    phi = np.linspace(0.0, 2.0 * np.pi, segments, endpoint=False)
    ring = np.stack([np.sin(theta)[:, None] * np.cos(phi), np.cos(theta)[:, None] + 0 * phi,
                     np.sin(theta)[:, None] * np.sin(phi)], axis=-1).reshape(-1, 3)  # fmt: skip
    v = np.concatenate([[[0.0, 1.0, 0.0]], ring, [[0.0, -1.0, 0.0]]]) * samples.HEAD_RADIUS
    last, f = len(v) - 1, []
    for j in range(segments):
        k = (j + 1) % segments
        f += [(0, 1 + k, 1 + j), (last, 1 + (rings - 2) * segments + j, 1 + (rings - 2) * segments + k)]
        for i in range(rings - 2):
            a, b = 1 + i * segments, 1 + (i + 1) * segments
            f += [(a + j, a + k, b + k), (a + j, b + k, b + j)]
    n = v / np.linalg.norm(v, axis=1, keepdims=True)
    return Mesh(v.astype(np.float32), np.array(f, np.int32), n.astype(np.float32))


def hair(which: int = 0) -> GroomState:
    return GroomState(groom(which), mesh=head(), source=f"tiny{which}.tfx")


@cache
def children(which: int, count: int):
    """Render hair of ``count`` children on the head, the groom's strands their guides."""
    return bind_scalp(groom(which), head(), count, seed=count)


@cache
def cycle(seed_: int, cycles: int, which: int = 0):
    return cycle_for_groom(groom(which), AnimeSettings(cycles=cycles, seed=seed_), None)


@cache
def simulation(frames: int, which: int = 0):
    opts = SimulateOptions(frames=frames, substeps=1)
    return run_simulation(groom(which), opts, lambda *a: None, lambda: False)


def snapshot_arrays(s: GroomState) -> tuple:
    """The groom side as bytes: groom, its metadata, parameters, head, view, and the strokes'
    log, stroked points and per-strand state (mask, clump strength, origin, selection, hidden)."""
    st_ = s.strokes
    strokes = ()
    if st_ is not None:
        k = st_.state
        per_strand = (k.locked, k.clump_strength, k.origin, k.selected, k.hidden)
        strokes = (repr(st_.log), st_.aligned.points.tobytes(), st_.aligned.counts.tobytes(),
                   *(None if a is None else a.tobytes() for a in per_strand))  # fmt: skip
    mesh = None if s.mesh is None else (s.mesh.vertices.tobytes(), s.mesh.faces.tobytes())
    return (s.rest.points.tobytes(), s.rest.counts.tobytes(), repr(s.rest.metadata), s.params,
            mesh, s.source, s.children is None, s.clump_children, strokes)  # fmt: skip


def same_groom(a: GroomState, b: GroomState) -> bool:
    return a is b or snapshot_arrays(a) == snapshot_arrays(b)


def same_state(a: AnimationState, b: AnimationState) -> bool:
    """Equal documents: every array's bytes, the settings and the edits."""

    def anim(x, y):
        if x is None or y is None:
            return x is y
        return (
            x.frames.tobytes() == y.frames.tobytes()
            and x.frames.dtype == y.frames.dtype
            and x.counts.tobytes() == y.counts.tobytes()
            and x.fps == y.fps
        )

    def motion(x, y):
        if x is None or y is None:
            return x is y
        return x.values.tobytes() == y.values.tobytes() and x.joint_names == y.joint_names

    return (
        anim(a.animation, b.animation)
        and a.source == b.source
        and motion(a.capture, b.capture)
        and a.settings == b.settings
        and a.edits == b.edits
        and a.channel_edits == b.channel_edits
        and a.held_keys == b.held_keys
    )


def rotated(v: np.ndarray, turn: np.ndarray) -> np.ndarray:
    """``v`` turned about the axis ``turn`` by its length in radians (Rodrigues)."""
    angle = float(np.linalg.norm(turn))
    if angle == 0.0:
        return v
    k = turn / angle
    return v * np.cos(angle) + np.cross(k, v) * np.sin(angle) + k * (k @ v) * (1.0 - np.cos(angle))


def written_out(doc: Document) -> tuple[dict, dict]:
    """The project as the file holds it: its manifest (less the time of saving) and arrays."""
    manifest, arrays = pf.manifest_and_arrays(project_io.to_project(doc))
    manifest.pop("saved")
    return manifest, arrays


answers = st.sampled_from(["discard", "cancel", "save"])


class DocumentMachine(RuleBasedStateMachine):
    def __init__(self) -> None:
        super().__init__()
        self.dir = Path(tempfile.mkdtemp(prefix="document-"))
        self.doc = Document(hair(0), AnimationState(settings=START))
        self.start, self.start_hair = self.doc.state, self.doc.hair.state
        self._listen()
        self.drag = 0
        self.saved_checked: dict[tuple, tuple] = {}  # (states, view) checked → the states
        self.exports_checked = None

    @property
    def which(self) -> int:
        """The groom open (its cycles, simulations and render hair are its own)."""
        return 0 if self.doc.groom.strand_count == groom(0).strand_count else 1

    def _listen(self) -> None:
        """What a widget observing the document last heard (it must hear every change)."""
        self.heard = (self.doc.state, self.doc.hair.state)

        def hear() -> None:
            self.heard = (self.doc.state, self.doc.hair.state)

        self.doc.observe(hear)
        self.doc.hair.observe(hear)

    def teardown(self) -> None:
        for p in self.dir.iterdir():
            p.unlink()
        self.dir.rmdir()

    @initialize(answer=answers)
    def open_a_capture_first(self, answer: str) -> None:
        """Most sequences pose a capture: the start is the empty document, one step before."""
        self.open_capture(0, answer)

    # -- what refuses must leave everything as it was ----------------------------------------
    def _try(self, action, refusals=ParameterError) -> None:
        before, hair, index = self.doc.state, self.doc.hair.state, self.doc.stack.index
        try:
            action()
        except refusals:
            assert self.doc.state is before and self.doc.stack.index == index
            assert same_groom(self.doc.hair.state, hair)

    def _confirm(self, answer: str):
        def ask() -> bool:
            if answer == "save":
                project_io.save(self.doc, self.dir / "asked.hairproj")
            return answer != "cancel"

        return ask

    def _replace(self, answer: str, **what) -> None:
        before, dirty = self.doc.state, self.doc.changed
        done = self.doc.replace_animation(confirm=self._confirm(answer), **what)
        if dirty and before.animation is not None and answer == "cancel":
            assert not done and self.doc.state is before
        else:
            assert done and self.doc.changed and not self.doc.state.edits

    # -- the groom ----------------------------------------------------------------------------
    @rule(
        data=st.data(),
        brush=st.sampled_from(registry.names()),
        moves=st.integers(1, 3),
        radius=st.floats(0.1, 1.2),
        strength=st.floats(0.05, 1.0),
        falloff=st.sampled_from(list(FALLOFF_LABELS)),
        symmetry=st.booleans(),
        pressures=st.lists(st.floats(0.0, 1.0), min_size=3, max_size=3),
        pressure_radius=st.booleans(),
        pressure_strength=st.booleans(),
        invert=st.booleans(),
        add=st.booleans(),
        front_only=st.booleans(),
        only_selected=st.booleans(),
        perspective=st.booleans(),
    )
    def stroke(self, data, brush, moves, radius, strength, falloff, symmetry, pressures,
               pressure_radius, pressure_strength, invert, add, front_only,
               only_selected, perspective) -> None:  # fmt: skip
        """One stroke of a brush: its moves as the studio samples them (BrushTool), one step
        (``add``: Shift held, so a select stroke adds instead of starting a new selection;
        ``perspective``: the camera's eye 4 units back along the view, which the samples record,
        else an orthographic camera's none)."""
        tool = BrushTool(brush=brush, falloff=falloff, symmetry=symmetry, front_only=front_only,
                         only_selected=only_selected, add_count=data.draw(st.integers(1, 3)))  # fmt: skip
        tool.reset_radius(radius)
        tool.strength[brush] = strength
        tool.pressure_radius[brush], tool.pressure_strength[brush] = pressure_radius, pressure_strength
        tool.align_mode = data.draw(st.sampled_from(["paper", "preserve-length"]))
        tool.delete_any_segment = data.draw(st.booleans())
        # density's spacing: a few candidates per move (a tiny groom stays tiny)
        tool.spacing = radius * data.draw(st.floats(0.3, 0.8))
        side = self.doc.hair
        pts = side.pipeline.aligned.points
        at = pts[data.draw(st.integers(0, len(pts) - 1))].astype(np.float64)
        view = data.draw(st.sampled_from([None, (0.0, 0.0, -1.0), (0.0, -1.0, 0.0)]))
        eye = None
        if perspective:  # from the front (no view: front faces only off) or from above
            eye = (0.0, 4.0, 0.0) if view == (0.0, -1.0, 0.0) else (0.0, 0.5, 4.0)
        self.drag += 1
        before, index = side.state, self.doc.stack.index
        for k in range(moves):
            step = np.array(data.draw(st.tuples(*[st.floats(-0.3, 0.3)] * 3)))
            moves_made = tool.samples(at, step, view, 0.0, invert, k == 0, pressures[k], add, eye)
            at = at + step
            if not moves_made:
                continue
            try:
                side.stroke(moves_made, stroke=self.drag, text=f"{brush} stroke")
            except HairtoolError:  # refused (no head, no strand left …): nothing of it happened
                assert side.state is before or k > 0
                assert self.doc.stack.index == index or k > 0
        side.end_stroke()
        top = self.doc.stack.top
        assert top is None or self.doc.stack.index <= index + 1  # a stroke is one step

    @rule(
        op=st.sampled_from(["all", "none", "invert", "box", "hide_selected", "hide_unselected", "reveal"]),
        rect=st.tuples(*[st.floats(-1.0, 1.0)] * 4),
        mode=st.sampled_from(BOX_MODES),
        view=st.sampled_from([None, (0.0, 0.0, -1.0)]),
        visible=st.booleans(),
        perspective=st.booleans(),
        to_eye=st.booleans(),
    )
    def select(self, op, rect, mode, view, visible, perspective, to_eye) -> None:
        """A selection step: the box seen through a front camera (orthographic, or with
        ``perspective`` from an eye at z = 4; the head in it), front faces only by sight
        (``visible``, the studio's; ``to_eye``: rays to the eye, the studio's in 3-D) or by root
        normal (older files)."""
        x0, x1 = sorted(rect[::2])
        y0, y1 = sorted(rect[1::2])
        sample = SelectionSample(op)
        if op == "box":
            matrix = (0.4, 0, 0, 0, 0, 0.4, 0, -0.2, 0, 0, -0.1, 0, 0, 0, 0, 1)
            if perspective:  # focal 1.5, near 0.1, far 100, the eye at (0, 0.5, 4) looking down -z
                a, b = -100.1 / 99.9, -20.0 / 99.9
                matrix = (1.5, 0, 0, 0, 0, 1.5, 0, -0.75, 0, 0, a, b - 4 * a, 0, 0, -1, 4)
            m = tuple(float(v) for v in matrix)
            sample = SelectionSample(op, m, (x0, y0, x1, y1), mode, view, visible, to_eye)
        self._try(lambda: self.doc.hair.select(sample))

    @rule(axis=st.sampled_from(["Y", "Z"]))
    def up_axis(self, axis: str) -> None:
        self.doc.hair.set_up_axis(axis)
        assert self.doc.groom.metadata.up_axis == axis

    # (a fourth of the time: a project with render hair binds it again on every load)
    @precondition(lambda self: self.doc.stack.index % 4 == 1)
    @rule(count=st.sampled_from([0, 4]), clump=st.sampled_from([None, True, False]))
    def render_hair(self, count: int, clump: bool | None) -> None:
        """Render hair grown on the head from the groom's strands (0: removed), its children
        clumped or not (None: the binding's default); then Clump children switched."""
        self.doc.hair.set_children(children(self.which, count) if count else None, clump=clump)
        assert (self.doc.hair.state.children is None) == (count == 0)
        if clump is not None:
            assert self.doc.hair.state.clump_children == clump
            self.doc.hair.set_clump_children(not clump)
            assert self.doc.hair.state.clump_children != clump

    @rule(yaw=st.floats(-180.0, 180.0), ortho=st.booleans())
    def view(self, yaw: float, ortho: bool) -> None:
        """The camera turned: kept and saved, but neither a step nor a change."""
        changed, index = self.doc.changed, self.doc.stack.index
        self.doc.hair.set_view(camera={"yaw": yaw}, ortho=ortho)
        assert self.doc.changed == changed and self.doc.stack.index == index

    @rule(on=st.booleans())
    def head_mesh(self, on: bool) -> None:
        """The head taken off (refused while strokes need it) or put back."""
        side, asked = self.doc.hair, head() if on else None
        before = side.state.mesh
        taken = []
        self._try(lambda: taken.append(side.set_mesh(asked)), HairtoolError)
        assert side.state.mesh is (asked if taken else before)  # refused: the old head stays
        assert (side.pipeline.surface is None) == (side.state.mesh is None)  # the engine's head is it

    @rule(stiffness=st.sampled_from([4.0, 7.0]), keep=st.booleans(), clump=st.booleans())
    def engine_parameters(self, stiffness: float, keep: bool, clump: bool) -> None:
        p = self.doc.hair.state.params.replace(bend_stiffness=stiffness, keep_lengths=keep, clump=clump)
        self._try(lambda: self.doc.hair.set_params(p), HairtoolError)

    @rule(which=st.integers(0, 1), answer=answers)
    def open_groom(self, which: int, answer: str) -> None:
        dirty, before = self.doc.changed, self.doc.hair.state
        done = self.doc.open_groom(hair(which), confirm=self._confirm(answer))
        if dirty and answer == "cancel":
            assert not done and self.doc.hair.state is before
        else:
            assert done and self.doc.groom is groom(which)

    # -- animations -------------------------------------------------------------------------
    @rule(which=st.integers(0, 1), answer=answers)
    def open_capture(self, which: int, answer: str) -> None:
        self._replace(answer, animation=None, source=f"walk{which}.bvh", capture=capture(which))

    @rule(seed_=st.integers(0, 3), cycles=st.integers(1, 2), answer=answers)
    def apply_cycle(self, seed_: int, cycles: int, answer: str) -> None:
        self._replace(answer, animation=cycle(seed_, cycles, self.which), source="anime cycle")

    @rule(frames=st.integers(3, 6), answer=answers)
    def simulate(self, frames: int, answer: str) -> None:
        self._replace(answer, animation=simulation(frames, self.which), source="simulation")

    @precondition(lambda self: self.doc.state.animation is not None)
    @rule(answer=answers)
    def close_animation(self, answer: str) -> None:
        self._replace(answer, animation=None)

    # -- keys ---------------------------------------------------------------------------------
    @rule(count=st.integers(0, 12))
    def key_count(self, count: int) -> None:
        self._try(lambda: self.doc.set_settings("Key count", mode="count", count=count))

    @rule(scale=st.floats(0.01, 2.0))
    def budget(self, scale: float) -> None:
        k = self.doc.keys
        if k is None:
            return
        self._try(lambda: self.doc.set_settings("Error budget", mode="budget", budget=scale))

    @rule(tau=st.sampled_from([0.001, 0.01, 0.1]))
    def price_per_key(self, tau: float) -> None:
        self._try(lambda: self.doc.set_settings("Price per key", mode="tau", tau=tau))

    @rule(interp=st.sampled_from(["linear", "hermite"]))
    def interpolation(self, interp: str) -> None:
        self._try(lambda: self.doc.set_settings("Interpolation", interp=interp))

    @precondition(lambda self: self.doc.state.animation is not None)
    @rule(data=st.data(), kind=st.sampled_from(["pin", "unpin", "exclude", "include"]))
    def steer(self, data, kind: str) -> None:
        s, n = self.doc.state.settings, self.doc.state.animation.n_frames
        f = data.draw(st.integers(0, n - 1))
        pins, excl = set(s.pins), set(s.excludes)
        {"pin": pins.add, "unpin": pins.discard, "exclude": excl.add, "include": excl.discard}[kind](f)
        if kind == "pin":
            excl.discard(f)
        if kind == "exclude":
            pins.discard(f)
        try:
            self._try(lambda: self.doc.steer(sorted(pins), sorted(excl), kind))
        except HairtoolError:  # an end excluded: refused by the constraints
            pass

    # -- key edits of the capture ------------------------------------------------------------
    def _key(self, data) -> int | None:
        keys = self.doc.keys
        if self.doc.state.capture is None or keys is None:
            return None
        return int(data.draw(st.sampled_from(keys.tolist())))

    def _edit(self, edit, drag=None) -> None:
        try:
            self.doc.edit(edit, drag=drag)
        except ParameterError:
            pass  # an edit the solver refuses changes nothing (checked by the invariants)

    @precondition(lambda self: self.doc.state.capture is not None)
    @rule(data=st.data(), moves=st.integers(1, 3), chain=st.integers(1, 3))
    def ik(self, data, moves: int, chain: int) -> None:
        f = self._key(data)
        if f is None:
            return
        m = self.doc.keyed().motion
        deep = np.flatnonzero(m.depths() >= 2)
        j = int(data.draw(st.sampled_from(deep.tolist())))
        self.drag += 1
        at = m.joint_positions()[f]
        p, q = at[j], at[m.parents[j]]
        for _ in range(moves):  # one drag: its moves merge into one undo step
            # the joint turned about its parent: a target in reach, so the solve converges in
            # a few steps (one out of reach walks its 300 before it stops)
            turn = np.array(data.draw(st.tuples(*[st.floats(-0.3, 0.3)] * 3)))
            target = tuple(float(v) for v in q + rotated(p - q, turn))
            self._edit(PoseEdit(f, m.joint_names[j], target, chain), drag=self.drag)

    @precondition(lambda self: self.doc.state.capture is not None)
    @rule(data=st.data(), kind=st.sampled_from(["value", "slope", "move"]))
    def graph(self, data, kind: str) -> None:
        f = self._key(data)
        if f is None:
            return
        m = self.doc.state.capture
        j = int(data.draw(st.integers(1, m.n_joints - 1)))
        rot = [c for c in m.channels[j] if c.endswith("rotation")]
        if kind == "move":
            self._edit(RetimeEdit(f, f + data.draw(st.sampled_from([-2, -1, 1, 2]))))
        elif rot:
            c = data.draw(st.sampled_from(rot))
            v = data.draw(st.floats(-90, 90))
            name = m.joint_names[j]
            edit = ChannelEdit(f, name, c, v) if kind == "value" else TangentEdit(f, name, c, v / 10)
            self._edit(edit)

    @precondition(lambda self: self.doc.state.capture is not None)
    @rule(data=st.data(), kind=st.sampled_from(["value", "slope"]))
    def channel_edit(self, data, kind: str) -> None:
        """A per-channel key edit (the graph editor with per-channel keys): the document keeps
        it; the studio's layer applies it."""
        m = self.doc.state.capture
        j = int(data.draw(st.integers(1, m.n_joints - 1)))
        rot = [c for c in m.channels[j] if c.endswith("rotation")]
        if not rot:
            return
        f, c, v = (
            data.draw(st.integers(0, m.n_frames - 1)),
            data.draw(st.sampled_from(rot)),
            data.draw(st.floats(-90, 90)),
        )
        edit = (
            ChannelEdit(f, m.joint_names[j], c, v)
            if kind == "value"
            else TangentEdit(f, m.joint_names[j], c, v / 10)
        )
        self.doc.edit_channels([edit], f"Channel {kind}")

    # -- key edits of a hair animation -------------------------------------------------------
    @precondition(lambda self: self.doc.state.animation is not None and self.doc.state.capture is None)
    @rule(data=st.data(), move=st.booleans(), lift=st.floats(-0.02, 0.02))
    def hair_key_edit(self, data, move: bool, lift: float) -> None:
        """A hair animation's key pose dragged (its frames between the neighbouring keys follow)
        or a key moved in time: the edited frames, the keys held."""
        keys, anim = self.doc.keys, self.doc.state.animation
        if keys is None or keys.size < 3:
            return
        key = int(keys[data.draw(st.integers(1, keys.size - 2))])
        interp = self.doc.state.settings.interp
        if move:
            to = key + data.draw(st.sampled_from([-1, 1]))
            try:
                start, block, held = retime_key(anim.frames, keys, interp, key, to)
            except ParameterError:
                return  # next to its neighbour: the graph editor stops it there
        else:
            pose = np.array(anim.frames[key])
            tips = anim.topology.tip_indices
            pose[tips] += np.float32(lift)
            start, block = key_edit_block(anim.frames, keys, interp, key, pose)
            held = keys
        frames = np.array(anim.frames)
        frames[start : start + len(block)] = block
        self.doc.edit_frames(anim.with_frames(frames), held.tolist(), f"Edit key {key}")

    # -- history and files -------------------------------------------------------------------
    @rule()
    def undo(self) -> None:
        self.doc.undo()

    @rule()
    def redo(self) -> None:
        self.doc.redo()

    @rule()
    def save_and_reload(self) -> None:
        path = self.dir / "saved.hairproj"
        project_io.save(self.doc, path)
        assert not self.doc.changed
        self.doc = project_io.load(path)
        # a reopened document starts here, with nothing to undo
        self.start, self.start_hair = self.doc.state, self.doc.hair.state
        self._listen()

    # -- after every step -----------------------------------------------------------------------
    def _checked_key(self) -> tuple:
        return id(self.doc.state), id(self.doc.hair.state), repr(dict(self.doc.hair.view))

    @invariant()
    def saves_and_loads_the_same(self) -> None:
        """The project file's bytes, made and read in memory by the file's own code (the rule
        ``save_and_reload`` and a Save answer write real files), once per state and view: an
        undo, a redo or a refused step back in a state checked before is checked already."""
        if self._checked_key() in self.saved_checked:
            return
        copy = Document(self.doc.hair.state, self.doc.state)
        copy.hair.view = self.doc.hair.view
        data = pf.to_bytes(project_io.to_project(copy))
        back = project_io.from_project(pf.from_bytes(data, "check.hairproj"), "check.hairproj")
        # (saving settles the strokes: the key is taken after; the states are held, so no id
        # of a checked state is reused by a new one)
        self.saved_checked[self._checked_key()] = (self.doc.state, self.doc.hair.state)
        assert same_state(back.state, self.doc.state)
        assert same_groom(back.hair.state, self.doc.hair.state)
        assert dict(back.hair.view) == dict(self.doc.hair.view)
        written, again = (written_out(d) for d in (self.doc, back))
        assert written[0] == again[0] and written[1].keys() == again[1].keys()
        for name, a in written[1].items():
            assert a.dtype == again[1][name].dtype and a.tobytes() == again[1][name].tobytes(), name

    @invariant()
    def the_views_heard_every_change(self) -> None:
        assert self.heard[0] is self.doc.state and self.heard[1] is self.doc.hair.state

    @invariant()
    def undo_to_the_start_gives_the_start(self) -> None:
        """Every Undo lands where Redo climbing back passes (a step that undoes only part of
        itself shows there, even where an earlier step's undo would hide it at the start)."""
        n = self.doc.stack.index
        down = [(self.doc.state, self.doc.hair.state)]
        while self.doc.undo():
            down.append((self.doc.state, self.doc.hair.state))
        assert same_state(self.doc.state, self.start)
        assert same_groom(self.doc.hair.state, self.start_hair)
        for k in range(n):
            assert self.doc.redo()
            state, hair = down[n - 1 - k]
            if state is not self.doc.state:
                assert same_state(self.doc.state, state)
            assert same_groom(self.doc.hair.state, hair)

    @invariant()
    def exports_read_back_with_the_edits(self) -> None:
        if self.doc.state is self.exports_checked:
            return
        self.exports_checked = self.doc.state
        k = self.doc.keyed()
        if k.keys is not None:
            path = self.dir / "keys.json"
            project_io.export_keys(self.doc, path)
            record = read_keys_json(path)
            assert record_keys(record).tolist() == k.keys.tolist()
            assert json.loads(path.read_text())["params"]["count"] == k.keys.size
        if k.motion is not None:
            path = self.dir / "edited.bvh"
            project_io.export_bvh(self.doc, path)
            back = read_bvh(path).values
            np.testing.assert_allclose(back, k.motion.values, atol=1e-4)
            self._last_pose_in_file(read_bvh(path))
        assert len(self.doc.notes()) == k.applied.count(False)

    def _last_pose_in_file(self, back) -> None:
        """An IK pose just made is in the exported file: its joint is no farther from the target
        at its key than before the pose (the solve only takes steps that bring it nearer)."""
        top, state = self.doc.stack.top, self.doc.state
        if top is None or getattr(top, "after", None) is not state or not state.edits:
            return
        edit = state.edits[-1]
        if top.before.edits != state.edits[:-1] or not isinstance(edit, PoseEdit):
            return
        if not self.doc.keyed().applied[-1]:
            return
        j = back.joint_names.index(edit.joint)
        target = np.array(edit.target)
        after = back.joint_positions()[edit.frame, j]
        before = self.doc.keyed(top.before).motion.joint_positions()[edit.frame, j]
        slack = 1e-4 * ik.figure_height(back)
        assert np.linalg.norm(after - target) <= np.linalg.norm(before - target) + slack


@pytest.mark.slow(seconds=90)  # 200 sequences of 30 steps: about 18 s for 40 here
def test_random_sequences_of_actions_keep_the_document_whole(monkeypatch):
    import numba

    # thousands of tiny solves: one thread each (no pool wake-ups), and files that need not
    # reach the disk (the atomic writers fsync; durability is not what this test checks)
    threads = numba.get_num_threads()
    numba.set_num_threads(1)
    monkeypatch.setattr(os, "fsync", lambda fd: None)
    try:
        _run()
    finally:
        numba.set_num_threads(threads)


def _run() -> None:
    chosen = int(os.environ.get("DOCUMENT_SEED", random.randrange(2**32)))
    print(f"document state machine: DOCUMENT_SEED={chosen}")
    examples = int(os.environ.get("DOCUMENT_EXAMPLES", 200))
    steps = int(os.environ.get("DOCUMENT_STEPS", 30))
    run_state_machine_as_test(
        seed(chosen)(DocumentMachine),
        settings=settings(
            max_examples=examples,
            stateful_step_count=steps,
            deadline=None,
            database=None,
            phases=tuple(Phase) if os.environ.get("DOCUMENT_SHRINK", "1") == "1" else [Phase.generate],
            suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much],
        ),
        _min_steps=steps,
    )
