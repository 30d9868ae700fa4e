"""Reading characters: VRM 1.0, VRM 0.x, plain glTF/GLB, and broken or hostile files."""

from __future__ import annotations

import base64
import json
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from hairtool.character import bundled, load_character
from hairtool.character.glb import pack, unpack
from hairtool.errors import FormatError

DATA = Path(__file__).resolve().parents[1] / "data" / "characters"


def test_vrm1_springs_settings_and_colliders():
    c = load_character(DATA / "bunches.vrm")
    ch = c.chains[0]
    assert ch.settings[0].stiffness == bundled.SPRING["stiffness"]
    assert ch.settings[0].gravity_dir == (0.0, -1.0, 0.0)
    assert ch.colliders == (0, 1) and not ch.virtual_tail
    assert c.meshes[0].base_color == bundled.SKIN


def test_vrm0_bone_groups_become_chains_with_a_virtual_tail(tmp_path):
    path = tmp_path / "zero.vrm"
    doc, binary = bundled.build_vrm0()
    sphere = doc["extensions"]["VRM"]["secondaryAnimation"]["colliderGroups"][0]["colliders"][0]
    sphere["offset"]["z"] = -0.02
    path.write_bytes(pack(doc, binary))
    c = load_character(path)
    one = load_character(DATA / "bunches.vrm")
    assert c.vrm_version == "0.x"
    assert [ch.nodes for ch in c.chains] == [ch.nodes for ch in one.chains]
    assert all(ch.virtual_tail for ch in c.chains)
    assert c.chains[0].settings[0].stiffness == bundled.SPRING["stiffness"]  # read from "stiffiness"
    assert c.colliders[0].offset[2] == pytest.approx(0.02)  # Unity's z turned into glTF's


def test_gltf_text_with_a_data_uri_reads_as_the_glb(tmp_path):
    doc, binary = bundled.build(vrm=True)
    doc["buffers"] = [
        {
            "byteLength": len(binary),
            "uri": "data:application/octet-stream;base64," + base64.b64encode(binary).decode(),
        }
    ]
    path = tmp_path / "c.gltf"
    path.write_text(json.dumps(doc))
    a, b = load_character(path), load_character(DATA / "bunches.vrm")
    assert np.array_equal(a.meshes[1].positions, b.meshes[1].positions)
    assert [ch.nodes for ch in a.chains] == [ch.nodes for ch in b.chains]


def test_a_name_pattern_picks_chains():
    c = load_character(DATA / "bunches.vrm", pattern=r"Hair\d_0[12]$")
    assert [len(ch.nodes) for ch in c.chains] == [5, 5]
    assert all(j.stiffness == 1.0 for ch in c.chains for j in ch.settings)


def test_a_buffer_outside_the_folder_is_refused(tmp_path):
    doc, _binary = bundled.build(vrm=False)
    doc["buffers"] = [{"byteLength": 4, "uri": "../../etc/passwd"}]
    path = tmp_path / "c.gltf"
    path.write_text(json.dumps(doc))
    with pytest.raises(FormatError, match=r"c\.gltf: buffer 0"):
        load_character(path)


ORIGINAL = (DATA / "bunches.vrm").read_bytes()


def _check(tmp_path, data: bytes) -> None:
    path = tmp_path / "x.vrm"
    path.write_bytes(data)
    try:
        load_character(path)
    except FormatError as e:
        assert str(e).startswith(str(path)) and "\n" not in str(e)


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(cut=st.integers(0, len(ORIGINAL) - 1))
def test_a_truncated_file_is_one_line_naming_it(tmp_path, cut):
    with pytest.raises(FormatError):
        path = tmp_path / "x.vrm"
        path.write_bytes(ORIGINAL[:cut])
        load_character(path)


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(
    flips=st.lists(st.tuples(st.integers(0, len(ORIGINAL) - 1), st.integers(1, 255)), min_size=1, max_size=8)
)
def test_corrupt_bytes_read_or_fail_with_one_line(tmp_path, flips):
    data = bytearray(ORIGINAL)
    for at, x in flips:
        data[at] ^= x
    _check(tmp_path, bytes(data))


_JUNK = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(-3, 10**12),
    st.floats(allow_nan=True),
    st.text(max_size=4),
    st.lists(st.integers(-2, 200), max_size=4),
    st.dictionaries(st.text(max_size=3), st.integers(), max_size=2),
)


def _paths(obj, prefix=()):
    if isinstance(obj, dict):
        for k, v in obj.items():
            yield (*prefix, k)
            yield from _paths(v, (*prefix, k))
    elif isinstance(obj, list):
        for i, v in enumerate(obj[:3]):
            yield (*prefix, i)
            yield from _paths(v, (*prefix, i))


DOC, BINARY = unpack("bunches.vrm", ORIGINAL)
PATHS = sorted(set(_paths(DOC)), key=repr)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(edits=st.lists(st.tuples(st.sampled_from(PATHS), _JUNK), min_size=1, max_size=3))
def test_hostile_json_values_read_or_fail_with_one_line(tmp_path, edits):
    doc = json.loads(json.dumps(DOC))
    for where, value in edits:
        node = doc
        try:
            for k in where[:-1]:
                node = node[k]
            node[where[-1]] = value
        except (KeyError, IndexError, TypeError):
            continue
    try:
        data = pack(doc, BINARY)
    except ValueError:  # json cannot write NaN keys etc.; nothing to read
        return
    _check(tmp_path, data)
