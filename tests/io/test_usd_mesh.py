"""The head a USD groom sits on: Mesh prims beside the curves read as one triangle mesh (world
space, polygons fanned, area-weighted normals), written back as one prim; bad meshes refused."""

from __future__ import annotations

import numpy as np
import pytest

from hairtool import io, samples
from hairtool.errors import FormatError
from hairtool.io.usd_mesh import add_mesh, read_mesh, vertex_normals

QUAD_HEAD = """#usda 1.0
(
    upAxis = "Z"
)
def Xform "Groom" {
    def BasisCurves "Strands" {
        uniform token type = "linear"
        int[] curveVertexCounts = [2]
        point3f[] points = [(0, 0, 1), (0, 0, 2)]
    }
    def Xform "Head" {
        double3 xformOp:translate = (10, 0, 0)
        uniform token[] xformOpOrder = ["xformOp:translate"]
        def Mesh "Scalp" {
            int[] faceVertexCounts = [4, 3]
            int[] faceVertexIndices = [0, 1, 2, 3, 0, 2, 4]
            point3f[] points = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0.5, 0.5, 1)]
        }
    }
}
"""


def test_mesh_prims_beside_the_curves_are_the_grooms_head(tmp_path):
    path = tmp_path / "head.usda"
    path.write_text(QUAD_HEAD)
    assert io.read_groom(path).strand_count == 1
    mesh = read_mesh(path)
    assert mesh.faces.tolist() == [[0, 1, 2], [0, 2, 3], [0, 2, 4]]  # the quad fanned into two
    np.testing.assert_allclose(mesh.vertices[:, 0], [10, 11, 11, 10, 10.5])  # in world space
    np.testing.assert_allclose(np.linalg.norm(mesh.normals, axis=1), 1.0, atol=1e-6)
    np.testing.assert_allclose(mesh.normals[1], [0, 0, 1], atol=1e-6)  # only the flat quad touches it
    assert mesh.groups["Scalp"].tolist() == [0, 1, 2]


def test_a_groom_without_meshes_has_none_and_a_written_head_reads_back(tmp_path):
    path = tmp_path / "g.usdc"
    io.write(path, samples.scalp(6, 4, seed=1))
    assert read_mesh(path) is None
    src = tmp_path / "head.usda"
    src.write_text(QUAD_HEAD)
    head = read_mesh(src)
    add_mesh(path, head)
    back = read_mesh(path)
    assert back.vertices.tobytes() == head.vertices.tobytes() and back.faces.tolist() == head.faces.tolist()
    assert io.read_groom(path).strand_count == 6  # the curves stay as they were


def test_normals_match_a_loop_over_triangles():
    rng = np.random.default_rng(3)
    v = rng.normal(size=(7, 3))
    f = np.array([[0, 1, 2], [2, 3, 4], [0, 4, 5], [1, 2, 4]])
    want = np.zeros((7, 3))
    for a, b, c in f:
        n = np.cross(v[b] - v[a], v[c] - v[a])
        for k in (a, b, c):
            want[k] += n
    norm = np.linalg.norm(want, axis=1, keepdims=True)
    want = np.divide(want, norm, out=np.zeros_like(want), where=norm > 0)
    np.testing.assert_allclose(vertex_normals(v, f), want, atol=1e-12)


@pytest.mark.parametrize(
    "counts, indices, message",
    [
        ("[4, 3]", "[0, 1, 2, 3, 0, 2, 9]", "out of range"),
        ("[2]", "[0, 1]", "3 corners"),
        ("[4]", "[0, 1]", "add up"),
    ],
)
def test_a_bad_mesh_is_one_error_naming_the_file(tmp_path, counts, indices, message):
    path = tmp_path / "bad.usda"
    text = QUAD_HEAD.replace("[4, 3]", counts).replace("[0, 1, 2, 3, 0, 2, 4]", indices)
    path.write_text(text)
    with pytest.raises(FormatError, match=message) as e:
        read_mesh(path)
    assert "bad.usda" in str(e.value)
