import numpy as np
import pytest

from hairtool import Animation, Groom, GroomError
from hairtool.resample import resample, resample_points
from hairtool.samples import SAMPLES, comb, portrait, sample, scalp


def two_strands() -> Groom:
    return Groom.from_strands([[[0, 0, 0], [1, 0, 0], [1, 2, 0]], [[5, 5, 5], [5, 5, 8]]])


def test_layout_and_accessors():
    g = two_strands()
    assert g.strand_count == 2 and g.vertex_count == 5
    assert g.points.dtype == np.float32 and g.points.shape == (5, 3)
    np.testing.assert_array_equal(g.offsets, [0, 3, 5])
    np.testing.assert_array_equal(g.roots, [[0, 0, 0], [5, 5, 5]])
    np.testing.assert_array_equal(g.tips, [[1, 2, 0], [5, 5, 8]])
    np.testing.assert_array_equal(g.topology.strand_index, [0, 0, 0, 1, 1])
    np.testing.assert_allclose(g.vertex_param, [0, 0.5, 1, 0, 1])
    np.testing.assert_array_equal(g.segment_vectors, [[1, 0, 0], [0, 2, 0], [0, 0, 3]])
    np.testing.assert_allclose(g.segment_lengths, [1, 2, 3])
    np.testing.assert_allclose(g.arc_length, [0, 1, 3, 0, 3])
    np.testing.assert_allclose(g.arc_param, [0, 1 / 3, 1, 0, 1])
    np.testing.assert_allclose(g.strand_lengths, [3, 3])
    lo, hi = g.bounds
    np.testing.assert_array_equal(lo, [0, 0, 0])
    np.testing.assert_array_equal(hi, [5, 5, 8])
    np.testing.assert_array_equal(g.strand(1), [[5, 5, 5], [5, 5, 8]])
    assert not g.is_planar


def test_points_are_immutable_and_copied():
    src = np.zeros((4, 3), dtype=np.float32)
    g = Groom(src, [2, 2])
    src[0, 0] = 9
    assert g.points[0, 0] == 0
    with pytest.raises(ValueError):
        g.points[0, 0] = 1


def test_with_points_shares_topology_and_attributes():
    g = Groom(np.zeros((4, 3)), [2, 2], thickness=[1, 2, 3, 4])
    h = g.with_points(np.ones((4, 3)))
    assert h.topology is g.topology
    np.testing.assert_array_equal(h.thickness, [1, 2, 3, 4])


def test_moved_rows_adopt_the_array_and_check_only_those_rows():
    g = Groom(np.random.default_rng(0).normal(size=(12, 3)), [4, 8], thickness=np.linspace(1, 2, 12))
    p = g.points.copy()
    p[[5, 6]] += 1.0
    moved, plain = g.with_moved_rows(p, [5, 6]), g.with_points(p)
    assert moved.points is p and not p.flags.writeable  # handed over, read-only
    assert set(vars(moved)) == set(vars(plain))  # every field the constructor sets (and no cache)
    for name in ("topology", "metadata", "thickness", "transparency", "colors"):
        assert getattr(moved, name) is getattr(g, name)
    assert moved.points.tobytes() == plain.points.tobytes()
    bad = g.points.copy()
    bad[7, 1] = np.nan
    with pytest.raises(GroomError, match="vertex 7"):
        g.with_moved_rows(bad, [6, 7])
    view = np.zeros((24, 3), np.float32)[::2]  # not its own memory: copied as with_points does
    assert g.with_moved_rows(view, []).points is not view
    assert g.with_moved_rows(p.astype(np.float64), [5]).points.dtype == np.float32


def test_attributes_name_the_constructor_keywords():
    g = Groom(np.zeros((4, 3)), [2, 2], thickness=[1, 2, 3, 4])
    assert list(g.attributes) == ["thickness", "transparency", "colors"]
    assert g.attributes["thickness"] is g.thickness and g.attributes["colors"] is None
    a = Animation(np.zeros((2, 4, 3)), g.topology, **g.attributes)
    assert a.attributes["thickness"] is not None and a.frame(1).attributes["thickness"] is not None
    np.testing.assert_array_equal(Groom(g.points, g.topology, **g.attributes).thickness, g.thickness)


def test_subset_keeps_order_and_attributes():
    g = Groom(np.arange(15).reshape(5, 3), [3, 2], colors=np.eye(5, 3))
    s = g.subset([1, 0])
    np.testing.assert_array_equal(s.counts, [2, 3])
    np.testing.assert_array_equal(s.points[:2], g.points[3:5])
    np.testing.assert_array_equal(s.colors[:2], g.colors[3:5])


@pytest.mark.parametrize(
    "points, counts, message",
    [
        (np.zeros((3, 3)), [1, 2], "at least 2"),
        (np.zeros((3, 3)), [2, 2], "add up to 4"),
        (np.array([[0, 0, 0], [np.nan, 0, 0]]), [2], "non-finite"),
        (np.zeros((2, 2)), [2], "shape"),
        (np.zeros((0, 3)), [], "at least one strand"),
    ],
)
def test_validation(points, counts, message):
    with pytest.raises(GroomError, match=message):
        Groom(points, counts)


def test_planar_groom_is_just_z_zero():
    g = Groom.from_strands([[[0, 0], [1, 1]], [[2, 0], [2, 3], [2, 4]]])
    assert g.is_planar
    assert g.points.shape == (5, 3)


def test_animation_views_and_validation():
    g = two_strands()
    frames = np.stack([g.points, g.points + 1, g.points + 2])
    a = Animation(frames, g.counts, fps=30)
    assert a.n_frames == 3 and a.fps == 30 and a.duration == pytest.approx(2 / 30)
    np.testing.assert_array_equal(a.frame(1).points, g.points + 1)
    np.testing.assert_array_equal(a.frame(-1).points, g.points + 2)
    assert a.frame(2).topology is a.topology
    with pytest.raises(GroomError, match="non-finite"):
        bad = frames.copy()
        bad[2, 1, 0] = np.inf
        Animation(bad, g.counts)
    with pytest.raises(GroomError, match="vertices"):
        Animation(frames[:, :4], g.counts)
    with pytest.raises(GroomError, match="frame rate"):
        Animation(frames, g.counts, fps=0)
    with pytest.raises(GroomError, match="different strand topology"):
        Animation.from_grooms([g, Groom(np.zeros((5, 3)), [2, 3])])


def test_resample_by_arc_length():
    g = Groom.from_strands([[[0, 0, 0], [1, 0, 0], [1, 3, 0]], [[0, 0, 0], [0, 0, 0]]])
    p = resample_points(g, 5)
    np.testing.assert_allclose(p[0], [[0, 0, 0], [1, 0, 0], [1, 1, 0], [1, 2, 0], [1, 3, 0]], atol=1e-12)
    np.testing.assert_allclose(p[1], 0.0)  # a zero-length strand collapses to its root
    r = resample(g, 5)
    assert r.vertex_count == 10


def test_resample_keeps_roots_tips_and_spacing():
    g = scalp(strands=50, vertices=17, seed=3)
    p = resample_points(g, 9)
    np.testing.assert_allclose(p[:, 0], g.roots, atol=1e-6)
    np.testing.assert_allclose(p[:, -1], g.tips, atol=1e-5)
    seg = np.linalg.norm(np.diff(p, axis=1), axis=2)
    # chords of an evenly split arc: never longer than the arc step
    assert np.all(seg <= g.strand_lengths[:, None] / 8 + 1e-5)


@pytest.mark.parametrize("kind", sorted(SAMPLES))
def test_samples_are_seeded_and_sized(kind):
    a = sample(kind, strands=30, vertices=12, seed=1)
    b = sample(kind, strands=30, vertices=12, seed=1)
    assert a.strand_count == 30 and a.vertex_count == 360
    np.testing.assert_array_equal(a.points, b.points)
    if kind != "comb":
        c = sample(kind, strands=30, vertices=12, seed=2)
        assert not np.array_equal(a.points, c.points)


def test_portrait_is_2d_and_hangs_outside_the_head():
    g = portrait(strands=80, vertices=20)
    assert g.is_planar
    assert np.all(np.linalg.norm(g.points[:, :2], axis=1) >= 1.0 - 1e-6)
    assert np.all(g.tips[:, 1] < g.roots[:, 1])  # gravity pulls every strand down


def test_scalp_roots_on_hemisphere():
    g = scalp(strands=200, vertices=10)
    np.testing.assert_allclose(np.linalg.norm(g.roots, axis=1), 1.0, atol=1e-6)
    assert np.all(g.roots[:, 1] > 0)
    assert not g.is_planar


def test_comb_grid_is_straight():
    g = comb(strands=16, vertices=5, spacing=0.1)
    d = g.segment_vectors
    np.testing.assert_allclose(d[:, [0, 2]], 0)
    assert np.all(d[:, 1] < 0)


def test_counts_whose_int64_sum_wraps_around_are_refused():
    """Counts of 2^62 add up, modulo 2^64, to the 10 points given: refused before they are summed."""
    counts = np.array([2**62, 2**62, 2**62, 2**62, 10], dtype=np.int64)
    assert counts.sum() == 10
    with pytest.raises(GroomError, match="strand 0 has 4611686018427387904 vertices"):
        Groom(np.zeros((10, 3)), counts)
    with pytest.raises(GroomError, match="vertices"):
        Groom(np.zeros((10, 3)), np.array([2**64 - 1, 11], dtype=np.uint64))
    with pytest.raises(GroomError, match="whole numbers"):
        Groom(np.zeros((10, 3)), np.array([10**30, 10], dtype=object))


def test_float64_beyond_float32_is_cast_then_checked():
    p = np.zeros((5, 3))
    p[3, 1] = 1e39  # finite as float64, inf as float32
    with pytest.raises(GroomError, match="vertex 3"):
        Groom(p, [2, 3])
    with pytest.raises(GroomError, match="frame 1"):
        Animation(np.stack([np.zeros((5, 3)), p]), [2, 3])
    with pytest.raises(GroomError, match="thickness"):
        Groom(np.zeros((5, 3)), [2, 3], thickness=[1, 1, 1e39, 1, 1])
    assert Groom(np.full((5, 3), 3.4e38), [2, 3]).points.max() == np.float32(3.4e38)
