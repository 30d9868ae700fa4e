"""Whether a stroke log collides with the head is read on from where the last look stopped, so a
move's cost does not grow with the session's log; a log replaced (an undo, a reset) is read anew."""

from __future__ import annotations

import hypothesis.strategies as st
from hypothesis import given, settings

from hairtool import samples
from hairtool.frozen import head_collision
from hairtool.frozen.brushes import BrushSample, falloff_lut
from hairtool.frozen.head_collision import HeadCollision

LUT = tuple(falloff_lut("smooth").tolist())


def comb(collide: bool) -> BrushSample:
    return BrushSample("comb", (0.0, 0.0, 1.0), (0.1, 0.0, 0.0), 0.5, 0.8, LUT, collide=collide)


# a step: ("add", the collide flags of a move's samples), ("other", those of another log: a
# redo, an opened file), ("undo", samples kept), ("reset", 0)
steps = st.lists(
    st.one_of(
        st.tuples(st.sampled_from(["add", "other"]), st.lists(st.booleans(), min_size=1, max_size=4)),
        st.tuples(st.just("undo"), st.integers(0, 12)),
        st.tuples(st.just("reset"), st.just(0)),
    ),
    max_size=12,
)


@settings(max_examples=150, deadline=None)
@given(steps=steps, collide_weight=st.integers(0, 3))
def test_the_answer_is_a_fresh_scans_and_a_move_reads_only_its_own_samples(steps, collide_weight):
    collision = HeadCollision(samples.scalp(4, 3, seed=1))
    read = []
    real = head_collision._collides
    head_collision._collides = lambda s: read.append(s) or real(s)
    try:
        log: list = []
        for op, arg in steps:
            new = []
            if op == "add":
                new = [comb(flag and collide_weight > 0) for flag in arg]
                log.extend(new)  # a move: the same list, grown
            elif op == "other":
                log = [comb(flag and collide_weight > 0) for flag in arg] * 3
            elif op == "undo":
                log = list(log[:arg])  # a snapshot's log: another list
            else:
                log = []
            read.clear()
            fresh = any(s.collide for s in log)
            assert collision.strokes_collide(log) == fresh
            if op == "add":
                assert len(read) <= len(new)  # never the samples before the move
    finally:
        head_collision._collides = real
