"""The contract every registered brush keeps, checked for each brush the registry finds (a new
brush with no tests of its own is checked too), on hypothesis-drawn samples over a small comb
under a flat head: its kernel equals its numpy twin byte for byte with 1 and 2 numba threads;
locked, hidden and (with "selection only") unselected strands come out untouched; its samples
survive the JSON stroke log and the project file; a mirrored sample on the mirrored groom gives
the mirrored result; undo brings back the bytes; a replay gives the bytes the strokes gave;
and the studio has a label, a key and a tip for it."""

from __future__ import annotations

import contextlib
from dataclasses import replace

import numba
import numpy as np
import pytest
from hypothesis import HealthCheck, Phase, given, settings
from hypothesis import strategies as st

from hairtool import project, samples
from hairtool.frozen.align import MODES
from hairtool.frozen.brushes import (
    BrushSample,
    facing_away,
    falloff_lut,
    mirrored_view,
    registry,
    root_normals,
    scalp_centre,
)
from hairtool.frozen.brushes.align import AlignSample
from hairtool.frozen.brushes.spec import Brush, StrokeContext, StrokeMemory
from hairtool.frozen.pipeline import FrozenParams, FrozenPipeline, FrozenSnapshot
from hairtool.frozen.strand_state import StrandState
from hairtool.frozen.strokes import read_strokes, strokes_from_log, write_strokes
from hairtool.groom import Groom
from hairtool.guides.planting import HeadSurface

from .conftest import plane_mesh

NAMES = registry.names()
TWINNED = tuple(n for n in NAMES if type(registry.brush_of(n)).reference is not Brush.reference)
GROOM = samples.comb(strands=25, vertices=8, spacing=0.1)
SURFACE = HeadSurface(plane_mesh(-1.5, 1.5, 7))  # symmetric about x = 0, as the mirror test needs
LUTS = (tuple(falloff_lut("smooth").tolist()), tuple(falloff_lut("constant").tolist()))
VIEWS = (None, (0.0, 1.0, 0.0), (0.0, -1.0, 0.0), (0.3, 0.5, 0.8))
PARAMS = FrozenParams(freeze=False, clump_iterations=1, clump_step=1e-3)
# Derandomized: the examples are the same every run, so CI is not a lottery over the kernels'
# last bits (a drawn comb sample once found a difference there: pinned below).
SETTINGS = settings(
    max_examples=6,
    derandomize=True,
    deadline=None,
    suppress_health_check=list(HealthCheck),
    phases=(Phase.explicit, Phase.generate),
)  # (no shrinking: on a busy 2-core machine it ran for minutes; the printed seed reproduces)


@st.composite
def brush_samples(
    draw, name: str, groom: Groom = GROOM, only_selected: bool | None = None, start: bool = True
):
    """One sample of the brush ``name`` over ``groom``: a cursor near it, a radius up to most of
    its size, a strength in the spec's range, and each of the spec's own fields in its range."""
    spec = registry.spec_of(name)
    lo, hi = (b.astype(np.float64) for b in groom.bounds)
    extent = float(np.max(hi - lo))
    cursor = tuple(draw(st.floats(float(lo[i]) - 0.05, float(hi[i]) + 0.05)) for i in range(3))
    radius = draw(st.floats(0.1 * extent, 0.7 * extent))
    strength = draw(st.floats(-1.0 if spec.signed else 0.0, 1.0))
    view = draw(st.sampled_from(VIEWS))
    collide = draw(st.booleans())
    only = draw(st.booleans()) if only_selected is None else only_selected
    pressure = draw(st.sampled_from((1.0, 0.5)))
    if name == "align":
        return AlignSample(
            cursor, radius, abs(strength), draw(st.sampled_from(MODES)), view, collide, only, pressure
        )
    direction = tuple(draw(st.floats(-0.3, 0.3)) for _ in range(3))
    fields = {}
    for p in spec.params:
        if p.kind is bool:  # (a rule: both ways)
            fields[p.field] = draw(st.booleans())
        elif p.kind is int:
            fields[p.field] = draw(st.integers(int(p.low), int(min(p.high, p.low + 4))))
        else:
            low = max(p.low, 0.05 * radius)
            fields[p.field] = draw(st.floats(low, max(low, min(p.high, 0.5 * radius))))
    return BrushSample(
        name, cursor, direction, radius, strength, draw(st.sampled_from(LUTS)), view,
        start and spec.keeps_stroke, collide,
        only_selected=only, pressure=pressure, **fields,
    )  # fmt: skip


@st.composite
def strand_states(draw, n: int = GROOM.strand_count):
    """Some strands masked, some hidden, some not selected (at least one of each kind free)."""
    flags = st.lists(st.booleans(), min_size=n, max_size=n).map(lambda v: np.array(v, bool))
    locked, hidden, unselected = draw(flags), draw(flags), draw(flags)
    free = draw(st.integers(0, n - 1))
    locked[free] = hidden[free] = unselected[free] = False
    strength = np.array(draw(st.lists(st.floats(0.0, 1.0), min_size=n, max_size=n)))
    return StrandState(locked, strength, np.arange(n, dtype=np.int64), ~unselected, hidden)


def context(state: StrandState, sample, groom: Groom = GROOM) -> StrokeContext:
    away = None if sample.view is None else facing_away(root_normals(groom), sample.view)
    centre = scalp_centre(groom)
    return StrokeContext(state, away, SURFACE, lambda: centre, StrokeMemory(), None)


@contextlib.contextmanager
def numba_threads(n: int):
    was = numba.get_num_threads()
    numba.set_num_threads(min(n, numba.config.NUMBA_NUM_THREADS))
    try:
        yield
    finally:
        numba.set_num_threads(was)


def same_state(a: StrandState, b: StrandState) -> bool:
    return all(
        x.tobytes() == y.tobytes() and x.dtype == y.dtype for x, y in zip(a.arrays(), b.arrays(), strict=True)
    )


def state_of(pipe: FrozenPipeline) -> StrandState:
    return StrandState(pipe.locked, pipe.clump_strength, pipe.origin, pipe.selected, pipe.hidden)


@pytest.mark.parametrize("name", TWINNED)
@SETTINGS
@given(data=st.data())
def test_a_brush_kernel_equals_its_numpy_twin_with_one_and_two_threads(name, data):
    brush = registry.brush_of(name)
    sample, state = data.draw(brush_samples(name)), data.draw(strand_states())
    twin_ctx = context(state, sample)
    twin = brush.reference(twin_ctx, GROOM, sample)
    for threads in (1, 2):
        ctx = context(state, sample)
        with numba_threads(threads):
            out = brush.apply(ctx, GROOM, sample)
        assert out.counts.tobytes() == twin.counts.tobytes()
        assert out.points.tobytes() == twin.points.tobytes()
        assert same_state(ctx.state, twin_ctx.state)


def protected(name: str, state: StrandState, away: np.ndarray | None) -> np.ndarray:
    """The strands a sample with "selection only" must leave as they are: hidden and facing
    away for every brush, masked for all but the two that paint flags (mask paints the mask,
    select selects masked strands too), unselected for all but select (it paints the selection)."""
    keep = state.hidden.copy()
    if away is not None:
        keep |= away
    if name not in ("mask", "select"):
        keep |= state.locked
    if name != "select":
        keep |= ~state.selected
    return keep


@pytest.mark.parametrize("name", NAMES)
@SETTINGS
@given(data=st.data())
def test_locked_hidden_and_unselected_strands_come_out_untouched(name, data):
    sample, state = data.draw(brush_samples(name, only_selected=True)), data.draw(strand_states())
    ctx = context(state, sample)
    out = registry.brush_of(name).apply(ctx, GROOM, sample)
    origin = ctx.state.origin
    for s in np.flatnonzero(protected(name, state, ctx.away)):
        rows = np.flatnonzero(origin == s)
        assert rows.size == 1, f"strand {s} was removed"
        r = int(rows[0])
        was = GROOM.points[GROOM.offsets[s] : GROOM.offsets[s + 1]]
        now = out.points[out.offsets[r] : out.offsets[r + 1]]
        assert now.tobytes() == was.tobytes()
        for before, after in zip(state.arrays(), ctx.state.arrays(), strict=True):
            assert after[r] == before[s]


def mirror(groom: Groom) -> Groom:
    pts = groom.points.copy()
    pts[:, 0] = -pts[:, 0]
    return groom.with_points(pts)


def mirrored(sample, plane_x: float = 0.0):
    if isinstance(sample, AlignSample):
        c = sample.cursor
        return sample._replace(cursor=(2.0 * plane_x - c[0], c[1], c[2]), view=mirrored_view(sample.view))
    return sample.mirrored(plane_x)


SYMMETRIC = tuple(n for n in NAMES if not any(p.field == "seed" for p in registry.spec_of(n).params))


@pytest.mark.parametrize("name", SYMMETRIC)
@SETTINGS
@given(data=st.data())
def test_a_mirrored_sample_on_the_mirrored_groom_gives_the_mirrored_result(name, data):
    """(Brushes that plant from a seed draw their roots at random: not mirror images.)"""
    brush = registry.brush_of(name)
    sample, state = data.draw(brush_samples(name)), data.draw(strand_states())
    there = GROOM.with_points(GROOM.points + np.float32([0.05, 0.0, 0.0]))  # not symmetric itself
    a_ctx, b_ctx = context(state, sample, there), context(state, mirrored(sample), mirror(there))
    a = brush.apply(a_ctx, there, sample)
    b = brush.apply(b_ctx, mirror(there), mirrored(sample))
    assert a.counts.tobytes() == b.counts.tobytes()
    np.testing.assert_allclose(mirror(b).points, a.points, atol=1e-5)
    assert same_state(a_ctx.state, b_ctx.state)


def stroke(name: str, data) -> list:
    """A stroke of three samples (the first starts it), each mirrored across x = 0."""
    first = data.draw(brush_samples(name, start=True))
    cursors = data.draw(st.lists(st.tuples(*[st.floats(-0.1, 0.5)] * 3), min_size=2, max_size=2))
    if isinstance(first, BrushSample):
        rest = [replace(first, cursor=c, start=False) for c in cursors]
    else:
        rest = [first._replace(cursor=c) for c in cursors]
    return [x for s in (first, *rest) for x in (s, mirrored(s))]


def refused_or(pipe: FrozenPipeline, samples_: list):
    """The samples applied, or None where the pipeline refuses them (a stroke that would remove
    every strand: refused with a ParameterError, the log unchanged)."""
    from hairtool.errors import ParameterError

    try:
        return pipe.apply_samples(samples_)
    except ParameterError:
        assert pipe.strokes == ()
        return None


@pytest.mark.parametrize("name", NAMES)
@SETTINGS
@given(data=st.data())
def test_undo_brings_back_the_bytes_and_a_replay_gives_the_same_bytes(name, data):
    pipe = FrozenPipeline(GROOM, PARAMS, SURFACE)
    start, snap = pipe.result, pipe.snapshot()
    if refused_or(pipe, stroke(name, data)) is None:
        return
    settled = pipe.settle()
    stroked = pipe.snapshot()
    assert same_state(stroked.state, state_of(pipe)) and stroked.log == pipe.strokes
    replay = FrozenPipeline(GROOM, PARAMS, SURFACE)
    replay.apply_samples(pipe.strokes, local=False)
    assert replay.aligned.points.tobytes() == pipe.aligned.points.tobytes()
    assert replay.result.points.tobytes() == settled.points.tobytes()
    assert same_state(state_of(replay), state_of(pipe))
    logged = FrozenPipeline(GROOM, PARAMS, SURFACE)  # the log alone (a project's strokes)
    logged.restore(FrozenSnapshot.replaying(pipe.strokes, GROOM))
    assert logged.result.points.tobytes() == settled.points.tobytes()
    assert same_state(state_of(logged), state_of(pipe))
    pipe.restore(snap)
    assert pipe.result.points.tobytes() == start.points.tobytes()
    assert pipe.strokes == ()
    assert same_state(state_of(pipe), StrandState.fresh(GROOM.strand_count))
    pipe.restore(stroked)  # redo: the snapshot's state, untouched by the undo
    assert pipe.result.points.tobytes() == settled.points.tobytes()
    assert same_state(state_of(pipe), stroked.state) and pipe.strokes == stroked.log


@pytest.mark.parametrize("name", NAMES)
@settings(SETTINGS, max_examples=3)
@given(data=st.data())
def test_a_brush_stroke_survives_the_json_stroke_log_and_the_project_file(name, data, tmp_path_factory):
    pipe = FrozenPipeline(GROOM, PARAMS, SURFACE)
    if refused_or(pipe, stroke(name, data)) is None:
        return
    where = tmp_path_factory.mktemp(name)
    write_strokes(where / "log.json", strokes_from_log(pipe.strokes))
    back = [x for s in read_strokes(where / "log.json") for x in s.pipeline_samples(0.0)]
    assert tuple(back) == pipe.strokes
    project.save(where / "p.hairproj", project.Project.from_pipeline(pipe))
    assert project.load(where / "p.hairproj").strokes == pipe.strokes


@pytest.mark.parametrize("name", NAMES)
def test_the_studio_has_a_label_a_key_and_a_tip_for_every_brush(name):
    from app.ui.brush_tool import DEFAULT_STRENGTH, LABELS, SHORTCUTS, TIPS, brushes

    assert name in brushes()
    assert LABELS[name] and TIPS[name] and SHORTCUTS[name]
    assert list(SHORTCUTS.values()).count(SHORTCUTS[name]) == 1
    assert 0.0 < DEFAULT_STRENGTH[name] <= 1.0


@pytest.mark.parametrize("name", NAMES)
def test_a_brushs_own_flags_are_read_from_a_log_that_leaves_them_out_as_their_defaults(name):
    """A stroke log written before a flag was added (no such param) replays as it did: the
    flag at its default, and the log written again without it (the pinned logs stay bytes)."""
    flags = [p for p in registry.spec_of(name).params if p.kind is bool]
    if not flags or name == "align":
        return
    sample = BrushSample(name, (0.0, 0.1, 0.0), (0.0, 0.0, 0.0), 0.2, 0.5 * (name != "add") + 0.5, LUTS[0])
    (written,) = strokes_from_log([sample])
    assert all(p.log_name not in written.params for p in flags)
    (back,) = written.pipeline_samples(0.0)
    assert all(getattr(back, p.field) == p.default for p in flags)
    for p in flags:
        (other,) = strokes_from_log([replace(sample, **{p.field: not p.default})])
        assert other.params[p.log_name] is (not p.default)


def test_delete_by_any_segment_takes_strands_whose_roots_are_elsewhere():
    """Blender's rule removes the strands with a segment under the brush; the root rule only
    those whose root is: a brush over the tips alone removes strands by the first, none by the
    second."""
    tips = GROOM.points[GROOM.topology.tip_indices].astype(np.float64)
    cursor = tuple(float(x) for x in tips[len(tips) // 2])
    brush = registry.brush_of("delete")
    by_root = BrushSample("delete", cursor, (0.0, 0.0, 0.0), 0.05, 1.0, LUTS[0], any_segment=False)
    by_segment = replace(by_root, any_segment=True)
    free = StrandState.fresh(GROOM.strand_count)
    kept_root = brush.apply(StrokeContext(free, centre_of=lambda: scalp_centre(GROOM)), GROOM, by_root)
    kept_any = brush.apply(StrokeContext(free, centre_of=lambda: scalp_centre(GROOM)), GROOM, by_segment)
    assert kept_root.strand_count == GROOM.strand_count
    assert kept_any.strand_count < GROOM.strand_count


@pytest.mark.parametrize("any_segment", (True, False))
def test_delete_by_either_rule_equals_its_twin_over_every_tip_and_middle(any_segment):
    """(The drawn samples above rarely sit where the two rules differ: here every cursor does.)"""
    from hairtool.frozen.brushes.delete import strands_to_delete, strands_to_delete_reference

    locked = np.arange(GROOM.strand_count) % 7 == 3
    middle = GROOM.topology.offsets[:-1] + 3
    for at in np.concatenate([GROOM.topology.tip_indices, middle]):
        cursor = tuple(float(x) for x in GROOM.points[at] + np.float32([0.01, 0.0, 0.0]))
        for radius in (0.02, 0.11, 0.4):
            sample = BrushSample("delete", cursor, (0.0,) * 3, radius, 1.0, LUTS[0], any_segment=any_segment)
            got = strands_to_delete(GROOM, sample, locked)
            assert got.tobytes() == strands_to_delete_reference(GROOM, sample, locked).tobytes()


@pytest.mark.parametrize("value", ("yes", 1, None, [True]))
def test_a_log_whose_delete_rule_is_not_true_or_false_is_refused_naming_it(value):
    from hairtool.errors import ParameterError
    from hairtool.frozen.strokes import stroke_from_dict

    raw = {"brush": "delete", "params": {"any_segment": value},
           "samples": [{"cursor": [0, 0, 0], "radius": 0.1, "strength": 1.0}]}  # fmt: skip
    with pytest.raises(ParameterError, match=r"params\.any_segment"):
        stroke_from_dict(raw).pipeline_samples(0.0)
