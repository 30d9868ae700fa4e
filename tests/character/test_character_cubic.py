"""CUBICSPLINE keys: the character's bones play back, through our reader and sampler, the keys
module's Hermite curve at every frame, on any key set and either kind of tangent."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from hairtool.character import load_character
from hairtool.character.accessors import buffers, read
from hairtool.character.export import animated_nodes, hermite_keys, key_times, write_animated
from hairtool.character.read import _gltf, load_document
from hairtool.character.springs import head_shake, simulate
from hairtool.cli import main
from hairtool.errors import ParameterError
from hairtool.keys.reconstruct import interpolate_keys
from hairtool.mocap import quaternion as quat

VRM = Path(__file__).resolve().parents[1] / "data" / "characters" / "bunches.vrm"
CHARACTER = load_character(VRM)
FRAMES = 20
SPRINGS = simulate(CHARACTER, head_shake(CHARACTER, FRAMES, 24.0, turn_deg=35.0, period=0.6), 24.0)
# float32 values and tangents: the curves part by a few 1e-8 rad; 1e-6 leaves room and no more
TOLERANCE = 1e-6


def _angles(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Rotation angles (radians) between two arrays of unit quaternions, either sign."""
    chord = np.minimum(np.linalg.norm(a - b, axis=-1), np.linalg.norm(a + b, axis=-1))
    return 4 * np.arcsin(np.minimum(chord / 2, 1.0))


key_sets = st.sets(st.integers(1, FRAMES - 2), max_size=8).map(
    lambda s: np.array([0, *sorted(s), FRAMES - 1])
)


@settings(max_examples=20, deadline=None)
@given(
    keys=key_sets,
    interp=st.sampled_from(["hermite-fit", "hermite"]),
    fps=st.sampled_from([24.0, 30.0, 24000 / 1001]),
    suffix=st.sampled_from([".glb", ".vrm", ".gltf"]),
)
def test_cubic_keys_play_back_the_keys_modules_hermite_curve(tmp_path_factory, keys, interp, fps, suffix):
    out = tmp_path_factory.mktemp("cubic") / f"keys{suffix}"
    report = write_animated(
        VRM, out, SPRINGS, CHARACTER.nodes.rotation, fps, name="k", step=False, key_frames=keys, interp=interp
    )
    assert report["interpolation"] == "CUBICSPLINE" and report["keys"] == keys.size
    back = load_character(out)
    played = back.clips[-1].frames(back.nodes, fps)
    assert played.shape == SPRINGS.shape
    nodes = animated_nodes(SPRINGS, CHARACTER.nodes.rotation)
    curve = quat.normalize(interpolate_keys(hermite_keys(SPRINGS[:, nodes], keys, interp)))
    assert _angles(played[:, nodes], curve).max() < TOLERANCE
    assert _angles(played[keys][:, nodes], SPRINGS[keys][:, nodes]).max() < TOLERANCE  # exact at the keys
    still = np.setdiff1d(np.arange(CHARACTER.nodes.count), nodes)
    assert np.array_equal(
        played[:, still], np.broadcast_to(back.nodes.rotation[still], played[:, still].shape)
    )


def test_each_key_holds_in_tangent_value_out_tangent_per_second(tmp_path):
    """The layout glTF asks for: 3 rows per key, the tangents scaled by the float32 key interval."""
    keys = np.array([0, 4, 11, FRAMES - 1])
    out = tmp_path / "keys.glb"
    write_animated(
        VRM,
        out,
        SPRINGS,
        CHARACTER.nodes.rotation,
        24.0,
        name="k",
        step=False,
        key_frames=keys,
        interp="hermite-fit",
    )
    doc, binary = load_document(out)
    gltf = _gltf(str(out), doc)
    data = buffers(str(out), gltf, binary)
    sampler = doc["animations"][-1]["samplers"][0]
    node = doc["animations"][-1]["channels"][0]["target"]["node"]
    assert sampler["interpolation"] == "CUBICSPLINE"
    times = read(str(out), gltf, data, sampler["input"], "times")
    assert np.array_equal(times, key_times(keys, 24.0))
    rows = np.roll(read(str(out), gltf, data, sampler["output"], "rows").reshape(-1, 3, 4), 1, axis=2)
    nodes = animated_nodes(SPRINGS, CHARACTER.nodes.rotation)
    kp = hermite_keys(SPRINGS[:, nodes], keys, "hermite-fit")
    k = nodes.index(node)
    span = np.diff(times.astype(np.float64))
    assert np.allclose(rows[:, 1], kp.poses[:, k], atol=1e-7)
    assert np.allclose(rows[:-1, 2] * span[:, None], kp.tangents[:-1, k] * np.diff(keys)[:, None], atol=1e-6)
    assert np.allclose(rows[1:, 0] * span[:, None], kp.tangents_in[1:, k] * np.diff(keys)[:, None], atol=1e-6)


def test_cubic_keys_need_optimal_keys_through_both_ends(tmp_path):
    rest = CHARACTER.nodes.rotation
    for kwargs in (
        {"step": True},
        {"step": False},
        {"step": False, "key_frames": np.array([0, 5, FRAMES - 1]), "loop_frames": FRAMES},
    ):
        with pytest.raises(ParameterError, match="interp"):
            write_animated(
                VRM, tmp_path / "a.glb", SPRINGS, rest, 24.0, name="k", interp="hermite-fit", **kwargs
            )
    with pytest.raises(ParameterError, match="keys"):
        write_animated(
            VRM,
            tmp_path / "a.glb",
            SPRINGS,
            rest,
            24.0,
            name="k",
            step=False,
            key_frames=np.array([2, 9]),
            interp="hermite-fit",
        )
    assert not (tmp_path / "a.glb").exists()


def test_hairtool_keys_writes_cubic_keys_of_a_character(tmp_path, capsys):
    """``hairtool keys CHARACTER --interp hermite-fit --export OUT.glb``: CUBICSPLINE on the keys it found."""
    src = tmp_path / "springs.glb"
    write_animated(VRM, src, SPRINGS, CHARACTER.nodes.rotation, 24.0, name="springs", step=False)
    out = tmp_path / "keys.glb"
    assert (
        main(["keys", str(src), "--keys", "5", "--interp", "hermite-fit", "--export", str(out), "--json"])
        == 0
    )
    result = json.loads(capsys.readouterr().out)
    assert result["written"]["interpolation"] == "CUBICSPLINE"
    keys = np.array(result["keys"])
    back = load_character(out)
    assert all(np.allclose(t, key_times(keys, 24.0)) for t, _ in back.clips[-1].rotations.values())
    assert set(back.clips[-1].cubic) == set(back.clips[-1].rotations)


def test_a_cubic_sampler_without_three_rows_per_key_is_one_line_naming_the_file(tmp_path, capsys):
    from hairtool.character.glb import pack

    out = tmp_path / "keys.glb"
    keys = np.array([0, 6, FRAMES - 1])
    write_animated(
        VRM,
        out,
        SPRINGS,
        CHARACTER.nodes.rotation,
        24.0,
        name="k",
        step=False,
        key_frames=keys,
        interp="hermite",
    )
    doc, binary = load_document(out)
    doc["accessors"][doc["animations"][-1]["samplers"][0]["output"]]["count"] = 2 * keys.size
    bad = tmp_path / "bad.glb"
    bad.write_bytes(pack(doc, binary))
    assert main(["keys", str(bad), "--keys", "2"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "bad.glb" in err[0] and "in-tangent, value and out-tangent" in err[0], err
