"""Wavefront OBJ: polylines round-trip bit-exact; meshes triangulate with sensible normals."""

from __future__ import annotations

import numpy as np
import pytest

from hairtool.errors import FormatError
from hairtool.io import read, write
from hairtool.io.obj import Mesh, read_mesh


def test_polyline_round_trip_is_bit_exact(tmp_path, groom):
    p = tmp_path / "g.obj"
    write(p, groom)
    back = read(p)
    np.testing.assert_array_equal(back.counts, groom.counts)
    assert back.points.tobytes() == groom.points.tobytes()
    lines = p.read_text().splitlines()
    assert sum(ln.startswith("l ") for ln in lines) == groom.strand_count
    assert sum(ln.startswith("v ") for ln in lines) == groom.vertex_count
    assert lines[-1].split()[-1] == str(groom.vertex_count)  # 1-based indices


def test_reads_relative_and_slashed_indices_and_shared_vertices(tmp_path):
    p = tmp_path / "l.obj"
    p.write_text(
        "# comment\no hair\nv 0 0 0\nv 0 1 0 1.0\nv 0 2 0\nvt 0 0\nl 1/1 2/1 3/1\nl -1 -2\nv 5 5 5\nl 4 1\n"
    )
    g = read(p)
    np.testing.assert_array_equal(g.counts, [3, 2, 2])
    np.testing.assert_array_equal(g.points[3:5], [[0, 2, 0], [0, 1, 0]])
    np.testing.assert_array_equal(g.points[5:], [[5, 5, 5], [0, 0, 0]])


@pytest.mark.parametrize(
    ("text", "reason"),
    [
        ("", "empty"),
        ("   \n\n", "empty"),
        ("v 0 0 0\nv 1 1 1\nf 1 2 1\n", "no polylines"),
        ("v 0 0 0\nv 1 1 1\nl 1\n", "at least 2"),
        ("v 0 0 0\nv 1 1 1\nl 1 3\n", "out of range"),
        ("v 0 0 0\nv 1 1 1\nl 0 1\n", "index 0"),
        ("v 0 0 0\nv 1 1 1\nl -3 1\n", "out of range"),
        ("v 0 0 0\nv 1 1 1\nl 1 two\n", "not a whole number"),
        ("v 0 0 0\nv 1 1 1\nl 1 99999999999999999999999\n", "not a whole number"),
        ("v 0 0 0\nv 1 nan 1\nl 1 2\n", "non-finite"),
        ("v 0 0 0\nv 1 1e999 1\nl 1 2\n", "non-finite"),
        ("v 0 0 0\nv 1 x 1\nl 1 2\n", "not a number"),
        ("v 0 0\nv 1 1 1\nl 1 2\n", "needs x y z"),
    ],
)
def test_bad_polyline_files_raise_format_error(tmp_path, text, reason):
    p = tmp_path / "bad.obj"
    p.write_text(text)
    with pytest.raises(FormatError, match=reason):
        read(p)


def test_sintel_head_loads_as_a_mesh(grooms_dir):
    m = read_mesh(grooms_dir / "sintel_head.obj")
    assert isinstance(m, Mesh)
    assert m.vertices.shape == (3046, 3) and m.vertices.dtype == np.float32
    assert m.faces.shape == (5952, 3) and m.faces.dtype == np.int32
    assert m.normals.shape == (3046, 3) and m.normals.dtype == np.float32
    assert m.faces.min() == 0 and m.faces.max() == 3045
    np.testing.assert_allclose(np.linalg.norm(m.normals, axis=1), 1.0, atol=1e-5)


def test_sintel_head_file_normals_agree_with_computed_ones(grooms_dir, tmp_path):
    src = grooms_dir / "sintel_head.obj"
    with_vn = read_mesh(src)
    stripped = tmp_path / "head.obj"
    kept = []
    for line in src.read_text().splitlines():
        if line.startswith("vn "):
            continue
        if line.startswith("f "):
            line = "f " + " ".join(c.split("/")[0] for c in line.split()[1:])
        kept.append(line)
    stripped.write_text("\n".join(kept))
    computed = read_mesh(stripped)
    np.testing.assert_array_equal(computed.faces, with_vn.faces)
    agree = np.einsum("ij,ij->i", computed.normals, with_vn.normals)
    assert np.median(agree) > 0.95  # same orientation; smooth-shaded file normals vs area-weighted


def test_quads_fan_triangulate_and_normals_are_area_weighted(tmp_path):
    p = tmp_path / "quad.obj"
    # A unit quad in z = 0 (normal +z) sharing vertex 1 with a large triangle in x = 0 (normal +x).
    p.write_text("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 -10\nv 0 10 0\nf 1 2 3 4\nf 1 5 6\n")
    m = read_mesh(p)
    np.testing.assert_array_equal(m.faces, [[0, 1, 2], [0, 2, 3], [0, 4, 5]])
    np.testing.assert_allclose(m.normals[2], [0, 0, 1], atol=1e-6)
    n0 = m.normals[0]
    assert n0[0] > 0.99  # the 50-unit² triangle outweighs the 1-unit² quad
    np.testing.assert_allclose(np.linalg.norm(m.normals, axis=1), 1.0, atol=1e-6)


@pytest.mark.parametrize(
    ("text", "reason"),
    [
        ("v 0 0 0\nv 1 0 0\n", "no faces"),
        ("v 0 0 0\nv 1 0 0\nf 1 2\n", "at least 3 corners"),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n", "out of range"),
        ("", "empty"),
    ],
)
def test_bad_meshes_raise_format_error(tmp_path, text, reason):
    p = tmp_path / "bad.obj"
    p.write_text(text)
    with pytest.raises(FormatError, match=reason):
        read_mesh(p)


def test_missing_mesh_file(tmp_path):
    with pytest.raises(FormatError, match="no such file"):
        read_mesh(tmp_path / "absent.obj")
