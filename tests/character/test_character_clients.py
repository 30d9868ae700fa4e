"""What the programs users open our files with make of them: the Khronos glTF validator, and
three.js with @pixiv/three-vrm, run with Node on the files hairtool writes.

The npm packages are pinned and installed by this test into ``.npm-clients/`` (ignored by git);
without Node and npm, or without the registry on a first run, the test is skipped.
"""

from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from hairtool.character import load_character
from hairtool.character.cycle import character_cycle
from hairtool.character.export import write_animated
from hairtool.character.springs import head_shake, simulate

ROOT = Path(__file__).resolve().parents[2]
CLIENTS = ROOT / ".npm-clients"
SCRIPTS = Path(__file__).resolve().parent / "clients"
PACKAGES = ["gltf-validator@2.0.0-dev.3.10", "three@0.170.0", "@pixiv/three-vrm@3.3.3"]
VRM = ROOT / "tests" / "data" / "characters" / "bunches.vrm"


@pytest.fixture(scope="module")
def node() -> Path:
    if shutil.which("node") is None or shutil.which("npm") is None:
        pytest.skip("Node and npm are not installed")
    stamp = CLIENTS / "installed.txt"
    if not stamp.is_file() or stamp.read_text() != " ".join(PACKAGES):
        CLIENTS.mkdir(exist_ok=True)
        (CLIENTS / "package.json").write_text('{"private": true}\n')
        r = subprocess.run(
            ["npm", "install", "--no-audit", "--no-fund", "--prefix", str(CLIENTS), *PACKAGES],
            capture_output=True,
            text=True,
            timeout=300,
            check=False,
        )
        if r.returncode != 0:
            pytest.skip(f"npm could not install {PACKAGES}: {r.stderr.strip().splitlines()[-1:]}")
        stamp.write_text(" ".join(PACKAGES))
    for script in SCRIPTS.glob("*.mjs"):  # beside node_modules, where Node resolves the imports
        shutil.copy(script, CLIENTS / script.name)
    return CLIENTS


def _run(node: Path, *args: str) -> str:
    r = subprocess.run(["node", *args], cwd=node, capture_output=True, text=True, timeout=120, check=False)
    assert r.returncode == 0, r.stderr[-2000:]
    return r.stdout


def _three_rotations(node: Path, path: Path, fps: float, frames: int, *mode: str) -> list[dict]:
    return json.loads(_run(node, "sample_three.mjs", str(path), str(fps), str(frames), *mode))


def _angles(character, rows: list[dict], ours: np.ndarray) -> np.ndarray:
    """Rotation angles (radians) between three.js's local rotations and ours, every node, every frame."""
    out = []
    for f, row in enumerate(rows):
        for name, xyzw in row.items():
            q = np.roll(np.asarray(xyzw, dtype=np.float64), 1)
            r = ours[f, character.nodes.names.index(name)]
            chord = min(
                np.linalg.norm(q - r), np.linalg.norm(q + r)
            )  # well conditioned near 0, unlike arccos
            out.append(4 * np.arcsin(min(chord / 2, 1.0)))
    return np.array(out)


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    c = load_character(VRM)
    folder = tmp_path_factory.mktemp("clients")
    cyc = character_cycle(c)
    cycle = cyc.frames(2 * cyc.schedule.n_frames)
    write_animated(
        VRM, folder / "cycle.vrm", cycle, c.nodes.rotation, 24.0, name="cycle", step=True, loop_frames=22
    )
    springs = simulate(c, head_shake(c, 24, 24.0), 24.0)
    write_animated(VRM, folder / "springs.glb", springs, c.nodes.rotation, 24.0, name="springs", step=False)
    return c, folder, cycle, springs


@pytest.fixture(scope="module")
def cubic(written):
    """Optimal keys of the spring motion as CUBICSPLINE (hermite-fit tangents), shared and per chain,
    and the rotations our reader plays back from each at every frame."""
    from hairtool.character.chain_keys import node_keys
    from hairtool.character.export import animated_nodes

    c, folder, _, springs = written
    keys = np.array([0, 3, 7, 12, 18, 23])
    per_chain = [np.array([0, 2 + c_ % 9, 14, 23]) for c_ in range(len(c.chains))]
    each = node_keys(c, animated_nodes(springs, c.nodes.rotation), per_chain)
    out = []
    for name, key_frames in (("keys.glb", keys), ("chains.vrm", each)):
        path = folder / name
        write_animated(
            VRM,
            path,
            springs,
            c.nodes.rotation,
            24.0,
            name="keys",
            step=False,
            key_frames=key_frames,
            interp="hermite-fit",
        )
        back = load_character(path)
        out.append((path, back.clips[-1].frames(back.nodes, 24.0)))
    return out


def test_the_validator_reports_no_errors(node, written, cubic):
    _, folder, _, _ = written
    files = [
        VRM,
        VRM.with_suffix(".glb"),
        folder / "cycle.vrm",
        folder / "springs.glb",
        *(p for p, _ in cubic),
    ]
    for line in _run(node, "validate.mjs", *map(str, files)).splitlines():
        report = json.loads(line)
        assert report["errors"] == 0 and report["warnings"] == 0, report


def test_three_js_plays_the_same_rotations_on_every_frame(node, written):
    c, folder, cycle, springs = written
    for name, ours in (("cycle.vrm", cycle), ("springs.glb", springs)):
        rows = _three_rotations(node, folder / name, 24.0, len(ours), "clip")
        assert rows and len(rows[0]) >= 14 * 4  # every chain joint (and the shaken head)
        assert _angles(c, rows, ours).max() < 1e-4, name  # float32 keys


def test_three_js_plays_cubic_spline_keys_as_our_reader_does(node, written, cubic):
    """three.js's cubic-spline quaternion interpolant (normalised after) against our sampler."""
    c = written[0]
    for path, ours in cubic:
        rows = _three_rotations(node, path, 24.0, len(ours), "clip")
        assert rows and len(rows[0]) >= 14 * 4
        assert _angles(c, rows, ours).max() < 1e-6, path.name  # float32 keys and tangents: a few 1e-8 rad


def test_three_vrm_swings_the_springs_as_we_do(node):
    """three-vrm measures each bone's length to its child as the child was before the step moved
    the bone; with that reproduced (``stale_lengths``) the two agree to float rounding. Our default,
    the specification's rigid bones, differs from it by up to a few degrees on a brisk head shake."""
    c = load_character(VRM)
    rows = _three_rotations(node, VRM, 24.0, 24, "springs", "30", "1", "Head")
    driver = head_shake(c, 24, 24.0, turn_deg=30.0, period=1.0)
    assert _angles(c, rows, simulate(c, driver, 24.0, stale_lengths=True)).max() < 1e-6
    spec = _angles(c, rows, simulate(c, driver, 24.0))
    assert 1e-4 < spec.max() < np.radians(3.0)


def test_three_vrm_swings_a_vrm0_character_as_we_do(node, tmp_path):
    """VRM 0.x: every listed node is a joint, the last swinging a 7 cm virtual tail, and collider
    offsets are stored with z flipped; a head sphere large enough to push the hair makes the
    offset count."""
    from hairtool.character import bundled
    from hairtool.character.glb import pack

    doc, binary = bundled.build_vrm0()
    vrm = doc["extensions"]["VRM"]
    sphere = vrm["secondaryAnimation"]["colliderGroups"][0]["colliders"][0]
    sphere["radius"], sphere["offset"]["z"] = 0.14, -0.04
    path = tmp_path / "zero.vrm"
    path.write_bytes(pack(doc, binary))
    c = load_character(path)
    rows = _three_rotations(node, path, 24.0, 24, "springs", "30", "1", "Head")
    assert len(rows[0]) == 14 * 5  # the last nodes swing too
    ours = simulate(c, head_shake(c, 24, 24.0, turn_deg=30.0, period=1.0), 24.0, stale_lengths=True)
    assert _angles(c, rows, ours).max() < 1e-6
