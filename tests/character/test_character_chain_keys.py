"""Keys on bones: per chain, exact against every key set tried (quaternion distance), written on
each chain's own bones; and the anime cycle's keys exactly at its drawings."""

from __future__ import annotations

import json
from itertools import combinations, pairwise
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from hairtool.anime.wave import WaveParams
from hairtool.character import load_character
from hairtool.character.chain_keys import chain_motion, chain_weights, node_keys
from hairtool.character.cycle import character_cycle
from hairtool.character.export import animated_nodes, hold_keys, key_times, write_animated
from hairtool.character.springs import head_shake, simulate
from hairtool.cli import main
from hairtool.keys.session import find_keys
from hairtool.mocap.costs import rotation_cost_table, rotation_cost_table_reference

VRM = Path(__file__).resolve().parents[1] / "data" / "characters" / "bunches.vrm"
CHARACTER = load_character(VRM)
FRAMES = 10
SPRINGS = simulate(CHARACTER, head_shake(CHARACTER, FRAMES, 24.0, turn_deg=40.0, period=0.5), 24.0)
SHAKE = simulate(CHARACTER, head_shake(CHARACTER, 16, 24.0, turn_deg=35.0, period=0.6), 24.0)


def _best(table: np.ndarray, k: int) -> tuple[float, tuple[int, ...]]:
    """The oracle: every key set of k keys through both ends, its segments' costs summed."""
    return min(
        (sum(table[a, b] for a, b in pairwise((0, *inner, FRAMES - 1))), (0, *inner, FRAMES - 1))
        for inner in combinations(range(1, FRAMES - 1), k - 2)
    )


@pytest.mark.parametrize("chain", [0, 6, 13])
def test_each_chains_keys_are_the_best_key_sets_by_quaternion_distance(chain):
    motion = chain_motion(CHARACTER, SPRINGS, 24.0, chain)
    assert motion.joint_names[2:] == [CHARACTER.nodes.names[j] for j in CHARACTER.chains[chain].nodes[:-1]]
    w = chain_weights(motion)
    assert w[:2].tolist() == [0.0, 0.0] and w.sum() == pytest.approx(1.0)
    table = rotation_cost_table(motion, w)
    oracle = rotation_cost_table_reference(motion, w)
    for k in range(2, 6):
        sel = find_keys(np.zeros((FRAMES, 1)), keys=k, table=table)
        cost, keys = _best(oracle, k)
        assert sel.cost == pytest.approx(cost, rel=1e-9, abs=1e-12)
        assert tuple(sel.keys.tolist()) == keys


def test_nodes_take_their_chains_keys_and_the_rest_every_chains():
    per_chain = [np.array([0, c % 5 + 1, FRAMES - 1]) for c in range(len(CHARACTER.chains))]
    nodes = animated_nodes(SPRINGS, CHARACTER.nodes.rotation)
    keys = node_keys(CHARACTER, nodes, per_chain)
    assert set(keys) == set(nodes)
    for c, chain in enumerate(CHARACTER.chains):
        for j in set(chain.nodes) & set(nodes):
            assert keys[j].tolist() == per_chain[c].tolist()
    head = CHARACTER.nodes.names.index("Head")
    assert keys[head].tolist() == [0, 1, 2, 3, 4, 5, FRAMES - 1]


@pytest.mark.parametrize("interp", ["linear", "hermite-fit"])
def test_hairtool_keys_per_chain_writes_each_chain_on_its_own_keys(tmp_path, capsys, interp):
    src = tmp_path / "springs.glb"
    write_animated(VRM, src, SHAKE, CHARACTER.nodes.rotation, 24.0, name="springs", step=False)
    out = tmp_path / "keys.vrm"
    features = "quaternion" if interp == "linear" else "rotations"
    args = ["keys", str(src), "--per-chain", "--penalty", "0.02", "--bvh-features", features]
    assert main([*args, "--interp", interp, "--export", str(out), "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    assert [c["chain"] for c in result["chains"]] == [c.name for c in CHARACTER.chains]
    assert len({tuple(c["keys"]) for c in result["chains"]}) > 1  # the chains do not all key alike
    assert result["written"]["keys"] == len(result["union"])
    back = load_character(out)
    clip = back.clips[-1]
    for c, chain in enumerate(CHARACTER.chains):
        for j in chain.nodes:
            if j in clip.rotations:
                assert np.array_equal(
                    clip.rotations[j][0], key_times(np.array(result["chains"][c]["keys"]), 24.0)
                )
    played = clip.frames(back.nodes, 24.0)
    for c, chain in enumerate(CHARACTER.chains):
        at = np.array(result["chains"][c]["keys"])
        ids = [j for j in chain.nodes if j in clip.rotations]
        dots = np.abs(np.sum(played[at][:, ids] * SHAKE[at][:, ids], axis=-1))
        assert dots.min() > 1 - 1e-6  # each chain's bones pass through its key poses


def test_per_chain_is_for_a_character(tmp_path, capsys):
    src = tmp_path / "springs.glb"
    write_animated(VRM, src, SPRINGS, CHARACTER.nodes.rotation, 24.0, name="springs", step=False)
    for extra in (["--per-channel"], ["--bvh-features", "channels"], ["--export", str(tmp_path / "k.bvh")]):
        assert main(["keys", str(src), "--per-chain", "--penalty", "0.1", *extra]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and "per-chain" in err[0], err
    assert not (tmp_path / "k.bvh").exists()


@settings(max_examples=15, deadline=None)
@given(
    period=st.floats(0.3, 1.2),
    fps=st.sampled_from([12.0, 24.0, 30.0]),
    hold=st.integers(1, 3),
    cycles=st.integers(1, 3),
)
def test_the_anime_cycles_keys_sit_exactly_at_its_drawings(tmp_path_factory, period, fps, hold, cycles):
    """The keys of held drawings are the frames where a drawing starts, and the file's STEP keys
    sit there (at the largest float32 not above frame/fps), one closing the loop."""
    cyc = character_cycle(CHARACTER, WaveParams(period=period), fps=fps, hold=hold)
    shot = cycles * cyc.schedule.n_frames
    exposure = cyc.schedule.shot_exposure(shot)
    drawings = np.concatenate([[0], 1 + np.flatnonzero(exposure[1:] != exposure[:-1])])
    frames = cyc.frames(shot)
    assert hold_keys(frames).tolist() == drawings.tolist()
    out = tmp_path_factory.mktemp("anime") / "cycle.glb"
    write_animated(VRM, out, frames, CHARACTER.nodes.rotation, fps, name="cycle", step=True, loop_frames=shot)
    clip = load_character(out).clips[-1]
    expected = key_times(np.concatenate([drawings, [shot]]), fps)
    assert clip.rotations and all(np.array_equal(t, expected) for t, _ in clip.rotations.values())
    assert clip.step == frozenset(clip.rotations)
