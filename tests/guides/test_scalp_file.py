"""``--scalp`` from USD (its stage's up axis and unit) or OBJ (``--scalp-up-axis``), brought into
the groom's frame; a scalp far from the guide roots is refused with both boxes."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from hairtool import io
from hairtool.cli import main
from hairtool.errors import FormatError, ParameterError
from hairtool.guides.files import split_guides
from hairtool.guides.scalp_file import FAR_SHARE, check_fit, load_scalp, read_scalp
from hairtool.io.obj import Mesh
from hairtool.io.usd_mesh import read_mesh as read_usd_mesh
from hairtool.metadata import Metadata

BLENDER = Path(__file__).resolve().parents[1] / "data" / "interop" / "b.usda"  # Z-up metres, a head
Y_TO_Z = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])  # Y-up (x, y, z) is Z-up (x, -z, y)


def write_obj(path: Path, vertices: np.ndarray, faces: np.ndarray) -> None:
    lines = [f"v {x:.9g} {y:.9g} {z:.9g}" for x, y, z in np.asarray(vertices, np.float64)]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in faces]
    path.write_text("\n".join(lines) + "\n")


def write_usd_mesh(path: Path, vertices, faces, up: str, mpu: float, offset=(0.0, 0.0, 0.0)) -> None:
    """A stage with one Mesh under a translated parent (points given in the stage's own axes and unit)."""
    from pxr import Gf, Usd, UsdGeom, Vt

    stage = Usd.Stage.CreateNew(str(path))
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.z if up == "Z" else UsdGeom.Tokens.y)
    UsdGeom.SetStageMetersPerUnit(stage, mpu)
    parent = UsdGeom.Xform.Define(stage, "/Head")
    parent.AddTranslateOp().Set(Gf.Vec3d(*map(float, offset)))
    mesh = UsdGeom.Mesh.Define(stage, "/Head/Scalp")
    mesh.CreatePointsAttr(Vt.Vec3fArray.FromNumpy(np.asarray(vertices, np.float32) - np.float32(offset)))
    mesh.CreateFaceVertexCountsAttr(Vt.IntArray.FromNumpy(np.full(len(faces), 3, np.int32)))
    mesh.CreateFaceVertexIndicesAttr(Vt.IntArray.FromNumpy(np.asarray(faces, np.int32).reshape(-1)))
    stage.GetRootLayer().Save()


def octahedron(centre, radius) -> tuple[np.ndarray, np.ndarray]:
    v = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], np.float64)
    f = np.array(
        [[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]], np.int64
    )
    return np.asarray(centre) + radius * v, f


def to_axes(points: np.ndarray, up: str) -> np.ndarray:
    """Points given Y-up (hairtool's reference axes) in a scene of up axis ``up``."""
    return points if up == "Y" else points @ Y_TO_Z.T


@st.composite
def scalp_cases(draw):
    """A head (octahedron) in the reference axes, in metres; the groom's frame; the USD stage's."""
    coord = st.floats(-2.0, 2.0, allow_nan=False)
    centre = np.array([draw(coord), draw(coord), draw(coord)])
    radius = draw(st.floats(0.05, 0.5))
    groom = (draw(st.sampled_from("YZ")), draw(st.sampled_from([0.01, 1.0])))
    stage = (draw(st.sampled_from("YZ")), draw(st.sampled_from([0.01, 1.0])))
    obj_up = draw(st.sampled_from("YZ"))
    return centre, radius, groom, stage, obj_up


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(scalp_cases())
def test_generated_usd_scalps_land_where_their_obj_twins_do(tmp_path, case):
    centre, radius, (g_up, g_mpu), (s_up, s_mpu), obj_up = case
    v, f = octahedron(centre, radius)
    usd_path, obj_path = tmp_path / "head.usda", tmp_path / "head.obj"
    usd_path.unlink(missing_ok=True)
    write_usd_mesh(usd_path, to_axes(v, s_up) / s_mpu, f, s_up, s_mpu, offset=to_axes(centre, s_up) / s_mpu)
    write_obj(obj_path, to_axes(v, obj_up) / g_mpu, f)  # an OBJ is in the groom's unit
    frame = Metadata(up_axis=g_up, meters_per_unit=g_mpu)
    from_usd = read_scalp(usd_path, frame)
    from_obj = read_scalp(obj_path, frame, obj_up.lower())
    want = to_axes(v, g_up) / g_mpu
    scale = max(1.0, float(np.abs(want).max()))
    np.testing.assert_allclose(from_usd.vertices, want, atol=2e-6 * scale)
    np.testing.assert_allclose(from_obj.vertices, want, atol=2e-6 * scale)
    np.testing.assert_allclose(from_usd.normals, from_obj.normals, atol=1e-6)
    np.testing.assert_array_equal(from_usd.faces, from_obj.faces)
    # the normals point out of the head in the groom's axes: the turn is a rotation, not a mirror
    out = (from_usd.vertices - want.mean(axis=0)) * from_usd.normals
    assert np.all(out.sum(axis=1) > 0)


def test_a_scalp_in_the_grooms_frame_is_the_mesh_itself(tmp_path):
    v, f = octahedron((0.0, 1.0, 0.0), 10.0)
    write_obj(tmp_path / "h.obj", v, f)
    frame = Metadata()
    assert read_scalp(tmp_path / "h.obj", frame) is not None
    from hairtool.io.obj import read_mesh

    plain, read = read_mesh(tmp_path / "h.obj"), read_scalp(tmp_path / "h.obj", frame, "y")
    assert plain.vertices.tobytes() == read.vertices.tobytes()
    assert plain.normals.tobytes() == read.normals.tobytes()


def test_the_blender_head_read_from_usd_and_from_its_y_up_obj_are_the_same(tmp_path):
    groom = io.read(BLENDER)
    assert groom.metadata.up_axis == "Z" and groom.metadata.meters_per_unit == 1.0
    head = read_usd_mesh(BLENDER)
    # Blender's OBJ export of the head: Y-up, (x, y, z) -> (x, z, -y)
    write_obj(tmp_path / "head.obj", head.vertices.astype(np.float64) @ Y_TO_Z, head.faces)
    from_usd = load_scalp(BLENDER, groom)
    from_obj = load_scalp(tmp_path / "head.obj", groom, "y")
    assert from_usd.vertices.tobytes() == head.vertices.tobytes()
    np.testing.assert_array_equal(from_obj.vertices, from_usd.vertices)
    np.testing.assert_allclose(from_obj.normals, from_usd.normals, atol=1e-6)
    with pytest.raises(ParameterError, match="scalp-up-axis"):
        read_scalp(BLENDER, groom.metadata, "y")
    with pytest.raises(FormatError, match="no Mesh prim"):
        io.write(tmp_path / "bare.usda", groom)
        read_scalp(tmp_path / "bare.usda", groom.metadata)


def test_a_far_scalp_is_refused_with_both_boxes():
    groom = io.read(BLENDER)
    head = read_usd_mesh(BLENDER)
    check_fit(BLENDER, head, groom.points, groom.roots)  # Blender's own head: the roots are on it
    size = float(np.linalg.norm(groom.points.max(axis=0) - groom.points.min(axis=0)))
    near = Mesh(head.vertices + np.float32([0.0, 0.0, 0.5 * FAR_SHARE * size]), head.faces, head.normals)
    check_fit(BLENDER, near, groom.points, groom.roots)
    far = Mesh(head.vertices + np.float32([0.0, 0.0, 2.0 * FAR_SHARE * size]), head.faces, head.normals)
    with pytest.raises(FormatError) as e:
        check_fit("far.obj", far, groom.points, groom.roots)
    line = str(e.value)
    assert "\n" not in line and line.startswith("far.obj: ")
    assert "scalp box [" in line and "groom box [" in line and "--scalp-up-axis" in line


def test_the_cli_takes_a_usd_scalp_and_refuses_a_y_up_head_on_a_z_up_groom(tmp_path, capsys):
    groom = io.read(BLENDER)
    lift = np.float32([0.0, 0.0, 1.7])  # a head at a person's height, as in a scene
    io.write(tmp_path / "hair.usda", groom.with_points(groom.points + lift))
    head = read_usd_mesh(BLENDER)
    write_obj(tmp_path / "head.obj", (head.vertices.astype(np.float64) + lift) @ Y_TO_Z, head.faces)
    out = tmp_path / "kids.usda"
    argv = ["interpolate", str(tmp_path / "hair.usda"), str(out), "--count", "200", "--scalp"]
    assert main([*argv, str(tmp_path / "head.obj")]) == 2  # read as Z-up: 2.4 m from the roots
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "head.obj" in err and "scalp box [" in err and "groom box [" in err
    assert not out.exists()
    assert main([*argv, str(tmp_path / "head.obj"), "--scalp-up-axis", "y"]) == 0
    kids, _ = split_guides(io.read_groom(out))
    centre = np.float32([0.0, 0.0, 1.7])
    radius = np.linalg.norm(kids.roots - centre, axis=1)
    assert kids.strand_count == 200 and np.all((radius > 0.09) & (radius < 0.1001))
    usd_out = tmp_path / "kids_usd.usda"
    lifted = tmp_path / "head.usda"
    write_usd_mesh(lifted, head.vertices.astype(np.float64) + lift, head.faces, "Z", 1.0, offset=lift)
    argv = ["interpolate", str(tmp_path / "hair.usda"), str(usd_out), "--count", "200", "--scalp"]
    assert main([*argv, str(lifted)]) == 0
    np.testing.assert_allclose(split_guides(io.read_groom(usd_out))[0].roots, kids.roots, atol=1e-6)
    assert main([*argv, str(lifted), "--scalp-up-axis", "z"]) == 2
    assert "scalp-up-axis" in capsys.readouterr().err
