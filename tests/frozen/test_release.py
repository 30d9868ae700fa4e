"""The release of a stroke: brush-local moves already leave the bytes a full run gives, so
``settle`` clumps nothing again (a full run cost the bear 150 ms for the same bytes). Checked on
generated strokes of every brush that runs locally (mirrored pairs too), with and without kept
lengths, under each gap rule, on a scalp and on a comb that strokes keep out of a head: the
released result is byte for byte a full run's on the same state and a replay's of the log, the
release runs no clumping, and the next stroke goes on locally from it."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, Phase, given, settings
from hypothesis import strategies as st

from hairtool import samples
from hairtool.frozen import pipeline as pipeline_module
from hairtool.frozen.brushes import BrushSample, falloff_lut, registry
from hairtool.frozen.brushes.align import AlignSample
from hairtool.frozen.pipeline import FrozenParams, FrozenPipeline
from hairtool.guides.planting import HeadSurface

from .conftest import plane_mesh

SCALP = samples.scalp(300, 8, seed=6)
COMB = samples.comb(strands=400, vertices=8, spacing=0.05)
HEAD = HeadSurface(plane_mesh())  # the comb hangs under it; strokes with ``collide`` keep out
LUT = tuple(falloff_lut("smooth").tolist())
# brushes that run locally and change the clump's input (mask and select change neither)
MOVING = tuple(n for n in registry.names() if registry.spec_of(n).local and n not in ("mask", "select"))
SETTINGS = settings(
    max_examples=8,
    derandomize=True,
    deadline=None,
    suppress_health_check=list(HealthCheck),
    phases=(Phase.explicit, Phase.generate),
)


@st.composite
def strokes(draw, groom) -> list[list[list]]:
    """Two strokes of two to four mouse moves each, near one tip per stroke: each move one
    sample (with its mirror about x = 0 where drawn) of a brush that moves or paints."""
    lo, hi = (b.astype(np.float64) for b in groom.bounds)
    extent = float(np.max(hi - lo))
    tips = groom.tips.astype(np.float64)
    out = []
    for _ in range(2):
        name = draw(st.sampled_from(MOVING))
        spec = registry.spec_of(name)
        tip = tips[draw(st.integers(0, groom.strand_count - 1))]
        radius = draw(st.floats(0.04, 0.12)) * extent
        sign = draw(st.sampled_from((-1.0, 1.0))) if spec.signed else 1.0
        strength = sign * draw(st.floats(0.3, 1.0))
        mirror, collide = draw(st.booleans()), draw(st.booleans())
        moves = []
        for k in range(draw(st.integers(2, 4))):
            c = tuple(map(float, tip + 0.02 * k * extent * np.array([1.0, 0.5, 0.0])))
            if name == "align":
                s = AlignSample(c, radius, abs(strength), "paper", None, collide)
                twin = s._replace(cursor=(-c[0], c[1], c[2]))
            else:
                d = (0.02 * extent, 0.01 * extent, 0.0)
                s = BrushSample(name, c, d, radius, strength, LUT, collide=collide, start=k == 0)
                twin = s.mirrored(0.0)
            moves.append([s, twin] if mirror else [s])
        out.append(moves)
    return out


@pytest.fixture
def clumps(monkeypatch):
    """The calls of the whole groom's ClumpWithGaps, counted."""
    calls = []
    run = pipeline_module.clump_points

    def counted(*args, **kwargs):
        calls.append(1)
        return run(*args, **kwargs)

    monkeypatch.setattr(pipeline_module, "clump_points", counted)
    return calls


@pytest.mark.parametrize("on_head", [False, True])
def test_a_release_gives_a_full_runs_bytes_without_clumping_again(on_head, clumps):
    groom, head = (COMB, HEAD) if on_head else (SCALP, None)
    released_local = []  # per stroke: whether it had brush-local moves to release

    @SETTINGS
    @given(data=st.data(), keep_lengths=st.booleans(), gap_mode=st.sampled_from(("printed", "text", "off")))
    def strokes_released(data, keep_lengths, gap_mode):
        params = FrozenParams(seed=3, keep_lengths=keep_lengths, gap_mode=gap_mode)
        pipe = FrozenPipeline(groom, params, head)
        for stroke in data.draw(strokes(groom)):
            for batch in stroke:
                pipe.apply_samples(batch)
            was = pipe.unsettled
            before = len(clumps)
            released = pipe.settle().points.copy()
            assert len(clumps) == before  # the release clumps nothing
            assert not pipe.unsettled
            released_local.append(was)
            if was:  # a full run on the same stroked state: the same bytes
                assert released.tobytes() == pipe.update().points.tobytes()
                assert len(clumps) == before + 1
        replay = FrozenPipeline(groom, params, head)
        replay.apply_samples(pipe.strokes, local=False)
        assert replay.aligned.points.tobytes() == pipe.aligned.points.tobytes()
        assert replay.result.points.tobytes() == pipe.result.points.tobytes()

    strokes_released()
    assert sum(released_local) >= 4  # (most strokes ran locally: what the release trusts)


def test_the_next_stroke_goes_on_locally_from_a_release(clumps):
    """Two comb strokes, released between them without a full run: the second is local from its
    first move, and the two together are a replay's bytes."""
    groom = SCALP
    pipe = FrozenPipeline(groom, FrozenParams(seed=3, keep_lengths=True))
    lo, hi = (b.astype(np.float64) for b in groom.bounds)
    extent = float(np.max(hi - lo))
    start = len(clumps)
    for tip in (groom.tips[10], groom.tips[200]):
        for k in range(3):
            c = tuple(map(float, tip + 0.02 * k * extent))
            pipe.apply_samples([BrushSample("comb", c, (0.02 * extent, 0.0, 0.0), 0.08 * extent, 0.8, LUT)])
            assert pipe.changed is not None and pipe.clump_redone < 0.5
        pipe.settle()
    assert len(clumps) == start  # neither the moves nor the releases clumped the whole groom
    replay = FrozenPipeline(groom, FrozenParams(seed=3, keep_lengths=True))
    replay.apply_samples(pipe.strokes, local=False)
    assert replay.result.points.tobytes() == pipe.result.points.tobytes()
