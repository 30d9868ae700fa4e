"""Selection and hiding: the selection brush and box select pick the strands they say, brushes
with "only the selection" leave the unselected strands bit for bit, hidden strands are locked for
every brush, delete and add keep the selection with its strands, undo restores it, and a stroke
log (or a project) replays the selection to the same bytes."""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pytest

from hairtool import io, samples
from hairtool.cli import main
from hairtool.errors import FormatError, ParameterError
from hairtool.frozen.brushes import BrushSample, falloff_lut
from hairtool.frozen.pipeline import FrozenParams, FrozenPipeline
from hairtool.frozen.selection import SelectionSample, apply_selection, in_box
from hairtool.frozen.strokes import read_strokes, stroke_from_dict, strokes_from_log, write_strokes
from hairtool.groom import vertex_ids_of

PLAIN = FrozenParams(freeze=False, clump=False)
LUT = tuple(falloff_lut("smooth").tolist())


@pytest.fixture(scope="module")
def comb():
    return samples.comb(30, 10, spacing=0.2)  # 6 × 5 roots over x 0…1, z 0…0.8 (y = 0), 2 long down −y


def brush(name, cursor, radius, strength, direction=(0.0, 0.0, 0.0), only=False):
    c, d = tuple(map(float, cursor)), tuple(map(float, direction))
    return BrushSample(name, c, d, radius, strength, LUT, only_selected=only)


def ortho(lo=-2.0, hi=2.0) -> tuple[float, ...]:
    """A front (−z) orthographic world-to-clip matrix: x, y in [lo, hi] map to [−1, 1]."""
    s = 2.0 / (hi - lo)
    m = np.array([[s, 0, 0, -1 - s * lo], [0, s, 0, -1 - s * lo], [0, 0, -0.1, 0], [0, 0, 0, 1]], float)
    return tuple(m.ravel().tolist())


def box(x0, y0, x1, y1, mode="set", lo=-2.0, hi=2.0):
    """A box over world x0..x1, y0..y1 through :func:`ortho`."""
    s = 2.0 / (hi - lo)
    rect = tuple(float(-1 + s * (v - lo)) for v in (x0, y0, x1, y1))
    return SelectionSample("box", ortho(lo, hi), rect, mode)


def strand_moved(before, after):
    d = np.any(before.points != after.points, axis=1)
    return np.maximum.reduceat(d, before.offsets[:-1]).astype(bool)


def test_the_selection_brush_selects_and_deselects_what_it_touches(comb):
    pipe = FrozenPipeline(comb, PLAIN)
    assert pipe.selected.all() and not pipe.hidden.any()  # a new groom: everything selected
    near = np.hypot(comb.roots[:, 0] - 0.3, comb.roots[:, 2] - 0.3)  # from the brush to each strand
    pipe.brush(brush("select", (0.3, -0.25, 0.3), 0.25, -1.0))  # Ctrl: deselect
    np.testing.assert_array_equal(pipe.selected, near >= 0.25)
    assert 0 < (near < 0.25).sum() < comb.strand_count
    pipe.brush(brush("select", (0.4, -0.25, 0.4), 0.05, 1.0))
    again = np.hypot(comb.roots[:, 0] - 0.4, comb.roots[:, 2] - 0.4) < 0.05
    assert again.sum() == 1
    np.testing.assert_array_equal(pipe.selected, (near >= 0.25) | again)
    assert pipe.aligned is not None and np.array_equal(pipe.aligned.points, comb.points)  # moves nothing


def test_a_brush_with_only_the_selection_leaves_the_rest_bit_for_bit(comb):
    sweep = [brush("comb", (x, -0.4, 0.4), 1.0, 0.8, (0.0, 0.0, 0.2), only=True) for x in (0.3, 0.5, 0.7)]
    everything = FrozenPipeline(comb, PLAIN)
    everything.apply_samples(sweep)
    assert strand_moved(comb, everything.aligned).all()  # all selected: the flag changes nothing
    pipe = FrozenPipeline(comb, PLAIN)
    pipe.apply_samples([box(-0.1, -1.0, 0.45, 0.1)])  # the left half
    sel = pipe.selected
    assert 0 < sel.sum() < comb.strand_count
    pipe.apply_samples(sweep)
    moved = strand_moved(comb, pipe.aligned)
    np.testing.assert_array_equal(moved, sel)
    rest = vertex_ids_of(comb.topology, np.flatnonzero(~sel))
    np.testing.assert_array_equal(pipe.aligned.points[rest], comb.points[rest])
    free = FrozenPipeline(comb, PLAIN)  # the same selection, without the flag: everything moves
    free.apply_samples([box(-0.1, -1.0, 0.45, 0.1), *(replace(s, only_selected=False) for s in sweep)])
    assert strand_moved(comb, free.aligned).all()


def test_hidden_strands_are_locked_for_every_brush(comb):
    pipe = FrozenPipeline(comb, PLAIN)
    pipe.apply_samples([box(0.5, -1.0, 1.1, 0.1), SelectionSample("hide_unselected")])
    hidden = pipe.hidden
    assert hidden.any() and not hidden.all()
    before = pipe.aligned
    for name, strength in (("comb", 0.8), ("smooth", 0.5), ("length", 0.3), ("pinch", 0.5), ("mask", 1.0)):
        pipe.brush(brush(name, (0.5, -0.4, 0.0), 2.0, strength, (0.0, 0.0, 0.2)))
    pipe.align((0.5, -0.3, 0.3), 2.0, 0.9)
    ids = vertex_ids_of(comb.topology, np.flatnonzero(hidden))
    np.testing.assert_array_equal(pipe.aligned.points[ids], before.points[ids])
    assert not pipe.locked[hidden].any() and pipe.locked[~hidden].all()  # the mask skipped them too
    pipe.brush(brush("select", (0.5, -0.4, 0.0), 2.0, 1.0))  # hidden strands cannot be selected
    np.testing.assert_array_equal(pipe.selected, ~hidden)


def test_select_all_none_invert_hide_and_reveal():
    g = samples.comb(6, 4)
    sel, hid = np.array([1, 1, 0, 0, 1, 0], bool), np.zeros(6, bool)
    step = lambda op, s=sel, h=hid: apply_selection(g, SelectionSample(op), s, h)  # noqa: E731
    s, h = step("hide_selected")
    np.testing.assert_array_equal(h, sel)
    assert not s.any()  # Blender deselects what it hides
    np.testing.assert_array_equal(step("all", s, h)[0], ~sel)  # hidden strands stay unselected
    np.testing.assert_array_equal(step("invert", s, h)[0], ~sel)
    assert not step("none")[0].any()
    s2, h2 = step("hide_unselected")
    np.testing.assert_array_equal(h2, ~sel)
    np.testing.assert_array_equal(s2, sel)
    s3, h3 = step("reveal", s2, h2)
    assert s3.all() and not h3.any()  # revealed strands come back selected


def test_box_modes_and_the_box_test(comb):
    x = comb.roots[:, 0]
    np.testing.assert_array_equal(in_box(comb, ortho(), box(0.1, -1, 0.7, 0.1).rect), (x > 0.1) & (x < 0.7))
    none, hid = np.zeros(comb.strand_count, bool), np.zeros(comb.strand_count, bool)
    s, _ = apply_selection(comb, box(-0.1, -1, 0.3, 0.1, "add"), none, hid)
    s, _ = apply_selection(comb, box(0.7, -1, 1.1, 0.1, "add"), s, hid)
    np.testing.assert_array_equal(s, (x < 0.3) | (x > 0.7))
    s, _ = apply_selection(comb, box(0.9, -1, 1.1, 0.1, "subtract"), s, hid)
    np.testing.assert_array_equal(s, (x < 0.3) | ((x > 0.7) & (x < 0.9)))
    s, _ = apply_selection(comb, box(-0.1, -0.5, 1.1, -0.3, "set"), s, hid)  # a band across the strands
    assert s.all()
    behind = SelectionSample("box", ortho(), box(-0.1, -1, 1.1, 1).rect, "set", (0.0, 0.0, -1.0))
    away = np.arange(comb.strand_count) % 2 == 0  # (as the pipeline finds them from a view)
    s, _ = apply_selection(comb, behind, none, hid, away)
    np.testing.assert_array_equal(s, ~away)
    with pytest.raises(ParameterError, match="matrix"):
        apply_selection(comb, SelectionSample("box", (1.0,) * 3, (0, 0, 1, 1)), none, hid)
    with pytest.raises(ParameterError, match="selection"):
        apply_selection(comb, SelectionSample("lasso"), none, hid)


def test_delete_keeps_the_selection_with_its_strands_and_undo_restores_it(comb):
    pipe = FrozenPipeline(comb, PLAIN)
    pipe.apply_samples([box(0.0, -1, 0.5, 0.1)])
    before = pipe.snapshot()
    sel0 = pipe.selected
    pipe.brush(brush("delete", (0.25, 0.0, 0.0), 0.1, 1.0, only=True))  # roots within 0.1 of x = 0.25
    kept = pipe.origin
    assert len(kept) < comb.strand_count
    np.testing.assert_array_equal(pipe.selected, sel0[kept])
    pipe.brush(brush("delete", (0.75, 0.0, 0.0), 0.1, 1.0, only=True))  # unselected there: nothing goes
    assert len(pipe.origin) == len(kept)
    pipe.apply_samples([SelectionSample("hide_unselected")])
    after = pipe.snapshot()
    pipe.restore(before)
    np.testing.assert_array_equal(pipe.selected, sel0)
    assert not pipe.hidden.any() and pipe.result.strand_count == comb.strand_count
    pipe.restore(after)
    np.testing.assert_array_equal(pipe.hidden, ~sel0[kept])
    pipe.set_params(PLAIN.replace(seed=3))  # replayed on a new frozen groom: the same selection
    np.testing.assert_array_equal(pipe.hidden, ~sel0[kept])


def test_planted_strands_come_selected_and_shown():
    from hairtool.guides.planting import HeadSurface
    from hairtool.io.obj import Mesh

    n = 6  # a flat head: the plane y = 0 under the comb's roots
    t = np.linspace(-1.0, 1.5, n)
    x, z = np.meshgrid(t, t, indexing="ij")
    v = np.column_stack([x.ravel(), np.zeros(n * n), z.ravel()]).astype(np.float32)
    f = [(i * n + j, (i + 1) * n + j, (i + 1) * n + j + 1) for i in range(n - 1) for j in range(n - 1)]
    f += [(i * n + j, (i + 1) * n + j + 1, i * n + j + 1) for i in range(n - 1) for j in range(n - 1)]
    plane = Mesh(v, np.array(f, np.int32), np.tile([0.0, -1.0, 0.0], (n * n, 1)).astype(np.float32))
    g = samples.comb(36, 12)
    pipe = FrozenPipeline(g, PLAIN, HeadSurface(plane))
    pipe.apply_samples([SelectionSample("none")])
    add = BrushSample("add", (0.125, -0.2, 0.125), (0, 0, 0), 0.1, 1.0, LUT, count=4)
    out = pipe.brush(add)
    assert out.strand_count == 40
    np.testing.assert_array_equal(pipe.selected, np.arange(40) >= 36)
    assert not pipe.hidden.any()


def test_a_refused_sample_leaves_the_selection_as_it_was(comb):
    pipe = FrozenPipeline(comb, PLAIN)
    pipe.apply_samples([box(0.0, -1, 0.5, 0.1)])
    sel = pipe.selected
    with pytest.raises(ParameterError):
        pipe.apply_samples([SelectionSample("none"), brush("delete", (0.5, 0.0, 0.0), 5.0, 1.0)])
    np.testing.assert_array_equal(pipe.selected, sel)
    assert len(pipe.strokes) == 1


def session(groom):
    """Select by box and by brush, brush only the selection, hide the rest."""
    pipe = FrozenPipeline(groom, FrozenParams(seed=4))
    lo, hi = groom.bounds
    c = (lo.astype(np.float64) + hi) * 0.5
    r = 0.3 * float(np.ptp(groom.points, axis=0).max())
    left = SelectionSample("box", ortho(-3, 3), (-1.0, -1.0, 0.05, 1.0), "set", (0.0, 0.0, -1.0))
    pipe.apply_samples([left])
    pipe.brush(BrushSample("select", tuple(c), (0, 0, 0), 0.5 * r, -1.0, LUT))
    for k in range(3):
        at = tuple(c + k * 0.05)
        pipe.brush(BrushSample("comb", at, (0.05, 0.02, 0.0), r, 0.9, LUT, only_selected=True))
    pipe.apply_samples([SelectionSample("hide_unselected")])
    pipe.align(c + 0.1, r, 0.7)
    pipe.apply_samples([SelectionSample("invert"), SelectionSample("reveal")])
    pipe.brush(BrushSample("smooth", tuple(c), (0, 0, 0), r, 0.6, LUT, only_selected=True))
    return pipe


def test_a_selection_log_replays_to_the_same_bytes_through_the_cli(tmp_path):
    groom = samples.scalp(150, 12, seed=2)
    io.write(tmp_path / "groom.npz", groom)
    pipe = session(groom)
    plain = FrozenPipeline(groom, FrozenParams(seed=4))
    for s in pipe.strokes:  # the same strokes without any selection: another result
        plain.apply_samples([s] if not hasattr(s, "op") else [])
    assert not np.array_equal(plain.result.points, pipe.result.points)
    steps = strokes_from_log(pipe.strokes)
    write_strokes(tmp_path / "strokes.json", steps)
    raw = json.loads((tmp_path / "strokes.json").read_text())
    assert raw[0]["selection"] == "box" and len(raw[0]["matrix"]) == 16 and raw[0]["view"] == [0, 0, -1]
    assert raw[1]["brush"] == "select" and raw[2]["only_selected"] is True
    assert [r.get("selection") for r in raw[3:]] == ["hide_unselected", None, "invert", "reveal", None]
    back = read_strokes(tmp_path / "strokes.json")
    assert back == steps
    out = tmp_path / "replayed.npz"
    argv = ["freeze", str(tmp_path / "groom.npz"), str(out), "--seed", "4"]
    assert main([*argv, "--strokes", str(tmp_path / "strokes.json")]) == 0
    # (the stroke released: a brush-local move's clumping settles into the full run's)
    assert io.read(out).points.tobytes() == pipe.settle().points.tobytes()


def test_an_older_log_reads_with_nothing_left_out():
    comb_stroke = {"brush": "comb", "samples": [{"cursor": [0, 0, 0], "radius": 1.0, "strength": 0.4}]}
    (sample,) = stroke_from_dict(comb_stroke).pipeline_samples(0.0)
    assert sample.only_selected is False


@pytest.mark.parametrize(
    "entry,words",
    [
        ({"selection": "lasso"}, "strokes[0].selection"),
        ({"selection": "box", "matrix": [1, 2], "rect": [0, 0, 1, 1]}, "strokes[0].matrix"),
        ({"selection": "box", "matrix": [0] * 16, "rect": [0, 0, 1, 1], "mode": "xor"}, "strokes[0].mode"),
        ({"brush": "comb", "only_selected": 1, "samples": []}, "strokes[0].only_selected"),
    ],
)
def test_bad_selection_steps_are_one_clear_error(tmp_path, entry, words):
    (tmp_path / "bad.json").write_text(json.dumps([entry]))
    with pytest.raises(FormatError, match=words.replace("[", r"\[").replace("]", r"\]")):
        read_strokes(tmp_path / "bad.json")


def test_the_selection_survives_a_project_round_trip(tmp_path):
    from hairtool import project as pf

    groom = samples.scalp(60, 10, seed=1)
    pipe = session(groom)
    pipe.apply_samples([SelectionSample("hide_selected")])
    assert pipe.hidden.any() and not pipe.hidden.all()
    pf.save(tmp_path / "p.hairproj", pf.Project.from_pipeline(pipe))
    back = pf.load(tmp_path / "p.hairproj")
    assert back.strokes == pipe.strokes
    again = back.pipeline()
    np.testing.assert_array_equal(again.selected, pipe.selected)
    np.testing.assert_array_equal(again.hidden, pipe.hidden)
    assert again.result.points.tobytes() == pipe.result.points.tobytes()
    import zipfile

    with zipfile.ZipFile(tmp_path / "p.hairproj") as z:
        assert json.loads(z.read("manifest.json"))["version"] == 3
    older = FrozenPipeline(groom)  # brush strokes without a selection: still version 2
    older.brush(BrushSample("comb", (0.0, 0.0, 0.0), (0.1, 0, 0), 1.0, 0.5, LUT))
    pf.save(tmp_path / "o.hairproj", pf.Project.from_pipeline(older))
    with zipfile.ZipFile(tmp_path / "o.hairproj") as z:
        assert json.loads(z.read("manifest.json"))["version"] == 2


def test_a_new_selection_keeps_only_what_its_stroke_touches(comb):
    """Blender's Selection Paint: a plain stroke's first sample (``new_selection``) deselects
    every shown strand, then selects what it touches; its later samples, its mirrored first
    sample and a stroke without the flag (Shift, every older log) add; hidden strands stay."""
    pipe = FrozenPipeline(comb, PLAIN)
    pipe.apply_samples([box(0.9, -1.0, 1.1, 0.1), SelectionSample("hide_selected"), SelectionSample("all")])
    hidden = pipe.hidden
    assert hidden.sum() == 5 and (pipe.selected == ~hidden).all()
    first = replace(brush("select", (0.4, -0.25, 0.4), 0.05, 1.0), new_selection=True)
    pipe.brush(first)
    one = np.hypot(comb.roots[:, 0] - 0.4, comb.roots[:, 2] - 0.4) < 0.05
    np.testing.assert_array_equal(pipe.selected, one)
    mirror = first.mirrored(0.5)  # (0.6, 0.4): the same move's second sample adds
    assert not mirror.new_selection
    pipe.brush(mirror)
    np.testing.assert_array_equal(
        pipe.selected, one | (np.hypot(comb.roots[:, 0] - 0.6, comb.roots[:, 2] - 0.4) < 0.05)
    )
    pipe.brush(brush("select", (0.5, -0.25, 0.4), 2.0, 1.0))  # over everything: the shown only
    np.testing.assert_array_equal(pipe.selected, ~hidden)
    pipe.brush(replace(brush("select", (1.0, -0.25, 0.4), 0.05, 1.0), new_selection=True))  # on hidden ones
    assert not pipe.selected.any() and (pipe.hidden == hidden).all()


def test_a_new_selection_is_written_on_its_first_sample_only_and_older_logs_add(tmp_path):
    from hairtool import project as pf

    groom = samples.scalp(40, 6, seed=3)
    c = tuple(float(x) for x in groom.tips[7])
    first = BrushSample("select", c, (0.0, 0.0, 0.0), 0.3, 1.0, LUT, new_selection=True)
    pipe = FrozenPipeline(groom, PLAIN)
    log = [first, first.mirrored(0.0), replace(first, cursor=(c[0] + 0.1, c[1], c[2]), new_selection=False)]
    again = replace(first, cursor=(c[0], c[1] + 0.1, c[2]))  # a second plain stroke right after
    pipe.apply_samples([*log, again])
    steps = strokes_from_log(pipe.strokes)
    assert [len(s.samples) for s in steps] == [3, 1]  # each new selection begins a stroke
    write_strokes(tmp_path / "s.json", steps)
    raw = json.loads((tmp_path / "s.json").read_text())
    assert [[x.get("new_selection") for x in r["samples"]] for r in raw] == [[True, None, None], [True]]
    replayed = [s for st in read_strokes(tmp_path / "s.json") for s in st.pipeline_samples(0.0)]
    assert tuple(replayed) == pipe.strokes
    del raw[0]["samples"][0]["new_selection"]  # as a log written before the choice: it adds
    older = stroke_from_dict(raw[0]).pipeline_samples(0.0)
    assert not any(s.new_selection for s in older)
    pf.save(tmp_path / "p.hairproj", pf.Project.from_pipeline(pipe))
    back = pf.load(tmp_path / "p.hairproj")
    assert back.strokes == pipe.strokes
    np.testing.assert_array_equal(back.pipeline().selected, pipe.selected)


def test_a_new_selection_that_is_not_true_or_false_is_refused_naming_it(tmp_path):
    sample = {"cursor": [0, 0, 0], "radius": 1.0, "strength": 1.0, "new_selection": "yes"}
    (tmp_path / "bad.json").write_text(json.dumps([{"brush": "select", "samples": [sample]}]))
    with pytest.raises(FormatError, match=r"strokes\[0\]\.samples\[0\]\.new_selection"):
        read_strokes(tmp_path / "bad.json")
