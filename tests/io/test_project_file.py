"""Project files: exact round trip, atomic saves, one FormatError naming the file for bad input."""

from __future__ import annotations

import json
import zipfile

import numpy as np
import pytest

from hairtool import project, samples
from hairtool.anime.wave import cycle_animation
from hairtool.errors import FormatError
from hairtool.frozen.pipeline import FrozenParams, FrozenPipeline


@pytest.fixture(scope="module")
def edited():
    """A small edited groom: array strand variation, three strokes, and an anime cycle."""
    rest = samples.scalp(30, 8, seed=2)
    params = FrozenParams(seed=5, strand_variation=np.linspace(0.5, 1.5, 30), clump_iterations=2)
    pipe = FrozenPipeline(rest, params)
    for i, mode in enumerate(("paper", "preserve-length", "paper")):
        pipe.align(rest.points[40 * i].astype(np.float64) + 0.1, 0.6, 0.7, mode)
    anim = cycle_animation(pipe.result, fps=24, cycles=1)
    proj = project.Project.from_pipeline(
        pipe,
        animation=anim,
        animation_source="anime",
        brush={"radius": 0.6, "intensity": 0.7, "align_mode": "paper"},
        display={"colour_mode": "strand", "ramp": "root-tip", "line_width": 3.0},
        key_settings={"keys": 5, "interp": "hermite"},
        settings={"anime": {"period": 0.45}},
        groom_source="scalp.npz",
    )
    return pipe, proj


def test_round_trip_restores_the_same_scene(tmp_path, edited):
    pipe, proj = edited
    path = tmp_path / "a.hairproj"
    project.save(path, proj)
    back = project.load(path)
    assert back.rest.points.tobytes() == proj.rest.points.tobytes()
    assert np.array_equal(back.rest.counts, proj.rest.counts)
    assert back.params == proj.params
    assert back.strokes == pipe.strokes
    assert back.pipeline().result.points.tobytes() == pipe.result.points.tobytes()
    assert back.animation.frames.tobytes() == proj.animation.frames.tobytes()
    assert back.animation.fps == 24.0 and back.animation_source == "anime"
    for name in ("brush", "display", "key_settings", "settings", "groom_source"):
        assert getattr(back, name) == getattr(proj, name)


def test_the_archive_in_memory_is_the_files_and_reads_as_the_file(tmp_path, edited, monkeypatch):
    """to_bytes is save's bytes and from_bytes is load's project (the state-machine test checks
    its steps in memory); a refusal names the place given."""
    monkeypatch.setattr(project.time, "localtime", lambda *a: (2026, 1, 2, 3, 4, 5, 0, 2, 0))
    monkeypatch.setattr(project.time, "strftime", lambda *a: "2026-01-02T03:04:05+0000")
    _, proj = edited
    path = tmp_path / "a.hairproj"
    for compress in (False, True):
        project.save(path, proj, compress=compress)
        assert project.to_bytes(proj, compress=compress) == path.read_bytes()
    written = project.manifest_and_arrays(project.load(path))
    again = project.manifest_and_arrays(project.from_bytes(path.read_bytes(), "kept"))
    assert written[0] == again[0] and written[1].keys() == again[1].keys()
    for name, a in written[1].items():
        assert a.dtype == again[1][name].dtype and a.tobytes() == again[1][name].tobytes(), name
    for data in (b"", path.read_bytes()[:-9]):
        with pytest.raises(FormatError) as e:
            project.from_bytes(data, "a recovery")
        assert e.value.path == "a recovery"


def test_replaying_the_log_gives_the_same_result_as_the_saved_snapshot(tmp_path, edited):
    pipe, proj = edited
    bare = project.Project(rest=proj.rest, params=proj.params, strokes=proj.strokes)
    project.save(tmp_path / "b.hairproj", bare, compress=True)
    back = project.load(tmp_path / "b.hairproj")
    assert back.aligned is None and back.animation is None
    assert back.pipeline().result.points.tobytes() == pipe.result.points.tobytes()


def test_attributes_and_an_unedited_groom_survive(tmp_path, groom, animation):
    """The io suite's awkward groom (tiny, huge, −0 coordinates, every attribute) stays exact."""
    g, anim = groom, animation
    proj = project.Project(rest=g, animation=anim, animation_source="file.usda")
    project.save(tmp_path / "c.hairproj", proj)
    back = project.load(tmp_path / "c.hairproj")
    for name in ("points", "thickness", "transparency", "colors"):
        assert getattr(back.rest, name).tobytes() == getattr(g, name).tobytes()
    assert back.animation.colors.tobytes() == anim.colors.tobytes() and back.animation.fps == anim.fps
    assert back.strokes == () and back.params == FrozenParams()


def test_interrupted_save_leaves_the_previous_project(tmp_path, edited, monkeypatch):
    _pipe, proj = edited
    path = tmp_path / "d.hairproj"
    project.save(path, proj)
    before = path.read_bytes()
    calls = []
    real = np.lib.format.write_array

    def failing(*args, **kwargs):
        calls.append(1)
        if len(calls) == 3:
            raise KeyboardInterrupt  # the worst case: not even an Exception
        return real(*args, **kwargs)

    monkeypatch.setattr(np.lib.format, "write_array", failing)
    with pytest.raises(KeyboardInterrupt):
        project.save(path, project.Project(rest=samples.comb(4, 3)))
    assert path.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["d.hairproj"]  # no temporary file left


def _rewrite(src, dst, manifest_edit=None, drop=(), add=None):
    with zipfile.ZipFile(src) as zin, zipfile.ZipFile(dst, "w") as zout:
        for info in zin.infolist():
            data = zin.read(info)
            if info.filename in drop:
                continue
            if info.filename == project.MANIFEST and manifest_edit is not None:
                m = json.loads(data)
                manifest_edit(m)
                data = json.dumps(m).encode()
            zout.writestr(info.filename, data)
        for name, data in (add or {}).items():
            zout.writestr(name, data)


def _set(path, value):
    def edit(m):
        node = m
        for k in path[:-1]:
            node = node[k]
        node[path[-1]] = value

    return edit


@pytest.mark.parametrize(
    "kind,needle",
    [
        (dict(manifest_edit=_set(["version"], 4)), "version 4; this hairtool reads versions 1, 2 and 3"),
        (dict(manifest_edit=_set(["format"], "x")), "not a hairtool project"),
        (dict(drop=(project.MANIFEST,)), "no manifest"),
        (dict(drop=("groom/points.npy",)), "missing member 'groom/points.npy'"),
        (dict(add={"evil.npy": b"x"}), "unexpected member"),
        (dict(manifest_edit=_set(["params", "bogus"], 1)), "unknown engine parameter"),
        (dict(manifest_edit=_set(["params", "seed"], -3)), "engine parameters"),
        (dict(manifest_edit=_set(["animation", "fps"], 0)), "fps"),
        (dict(manifest_edit=_set(["strokes", "count"], 9)), "strokes"),
        (dict(manifest_edit=_set(["display"], [1])), "display"),
    ],
)
def test_bad_members_name_the_file(tmp_path, edited, kind, needle):
    src, dst = tmp_path / "good.hairproj", tmp_path / "bad.hairproj"
    project.save(src, edited[1])
    _rewrite(src, dst, **kind)
    with pytest.raises(FormatError, match=needle) as e:
        project.load(dst)
    assert str(dst) in str(e.value)


def test_non_finite_points_and_foreign_files(tmp_path):
    g = samples.comb(3, 4)
    src = tmp_path / "g.hairproj"
    project.save(src, project.Project(rest=g))
    with zipfile.ZipFile(src) as z:
        members = {i.filename: z.read(i) for i in z.infolist()}
    raw = bytearray(members["groom/points.npy"])
    raw[-4:] = np.array([np.nan], "<f4").tobytes()
    members["groom/points.npy"] = bytes(raw)
    with zipfile.ZipFile(tmp_path / "nan.hairproj", "w") as z:
        for name, data in members.items():
            z.writestr(name, data)
    with pytest.raises(FormatError, match="non-finite"):
        project.load(tmp_path / "nan.hairproj")
    for name, data in (("empty.hairproj", b""), ("text.hairproj", b"hello"), ("npz.hairproj", None)):
        p = tmp_path / name
        if data is None:
            np.savez(p, X=np.zeros(3))
        else:
            p.write_bytes(data)
        with pytest.raises(FormatError) as e:
            project.load(p)
        assert name in str(e.value)
    with pytest.raises(FormatError, match="no such file"):
        project.load(tmp_path / "missing.hairproj")


def test_truncated_and_flipped_files_are_format_errors(tmp_path, edited):
    """Every truncation point tried and seeded byte flips: a valid project or one FormatError."""
    src = tmp_path / "fuzz.hairproj"
    project.save(src, edited[1], compress=True)
    data = src.read_bytes()
    bad = tmp_path / "broken.hairproj"
    rng = np.random.default_rng(0)
    cuts = sorted(set(rng.integers(1, len(data), 40).tolist()) | {1, 22, len(data) - 1})
    for cut in cuts:
        bad.write_bytes(data[:cut])
        with pytest.raises(FormatError) as e:
            project.load(bad)
        assert "broken.hairproj" in str(e.value)
    loaded = 0
    for _ in range(60):
        flipped = bytearray(data)
        for i in rng.integers(0, len(data), 3):
            flipped[i] ^= 1 << int(rng.integers(0, 8))
        bad.write_bytes(bytes(flipped))
        try:
            project.load(bad)
            loaded += 1  # a flip in a field nobody reads (a timestamp) is harmless
        except FormatError as e:
            assert "broken.hairproj" in str(e)
    assert loaded < 30


# -- issue 17's hostile classes ------------------------------------------------------------------
@pytest.mark.parametrize("member", ["groom/points.npy", "groom/thickness.npy", "animation/frames.npy"])
def test_float64_beyond_float32_is_refused_after_the_cast(tmp_path, member):
    from .hostile import write_project_beyond_float32

    p = write_project_beyond_float32(tmp_path / "big.hairproj", member)
    with pytest.raises(FormatError, match="beyond float32") as e:
        project.load(p)
    assert e.value.path == str(p)


def test_counts_whose_sum_wraps_around_are_refused(tmp_path):
    from .hostile import write_project_wrapping_counts

    p = write_project_wrapping_counts(tmp_path / "wrap.hairproj")
    with pytest.raises(FormatError, match="strand 0 claims 4611686018427387904 points"):
        project.load(p)


def test_corrupt_npy_header_in_a_member_is_a_format_error(tmp_path):
    """Found by fuzzing: a header with an unbalanced bracket let tokenize.TokenError escape."""
    from hairtool.groom import Groom

    p = tmp_path / "bad.hairproj"
    project.save(p, project.Project(rest=Groom(np.zeros((4, 3)), [2, 2])))
    header = b"{'descr': '<f4', 'fortran_order': False, 'shape': (4, \x0f}"
    member = b"\x93NUMPY\x01\x00" + len(header).to_bytes(2, "little") + header + bytes(48)
    with zipfile.ZipFile(p) as zf:
        members = {i.filename: zf.read(i) for i in zf.infolist()}
    members["groom/points.npy"] = member
    with zipfile.ZipFile(p, "w") as zf:
        for name, data in members.items():
            zf.writestr(name, data)
    with pytest.raises(FormatError, match=r"'groom/points\.npy' has a corrupt \.npy header"):
        project.load(p)


def test_the_head_mesh_and_the_up_axis_are_part_of_the_project(tmp_path):
    from hairtool.io.obj import Mesh

    rest = samples.scalp(8, 4, seed=1)
    rest = rest.with_metadata(rest.metadata.with_(up_axis="Z", meters_per_unit=1.0))
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], np.float32)
    f = np.array([[0, 1, 2], [0, 2, 3]], np.int32)
    mesh = Mesh(v, f, np.tile(np.float32([0, 0, 1]), (4, 1)), {"scalp": np.array([1])})
    path = tmp_path / "head.hairproj"
    project.save(path, project.Project(rest=rest, mesh=mesh))
    back = project.load(path)
    assert back.rest.metadata.up_axis == "Z" and back.rest.metadata.meters_per_unit == 1.0
    assert back.mesh.vertices.tobytes() == v.tobytes() and back.mesh.faces.tolist() == f.tolist()
    assert back.mesh.groups["scalp"].tolist() == [1]
    assert project.load(_saved(tmp_path, project.Project(rest=samples.comb()))).mesh is None

    bad = Mesh(v, np.array([[0, 1, 9]], np.int32), v, {})
    project.save(path, project.Project(rest=rest, mesh=bad))
    with pytest.raises(FormatError, match=r"head\.hairproj.*outside"):
        project.load(path)


def _saved(tmp_path, proj) -> object:
    path = tmp_path / "plain.hairproj"
    project.save(path, proj)
    return path
