"""The anime cycle on a character's chains: the same shapes as the strand cycle, the paper's timing."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from hairtool.anime.wave import Bunches, WaveParams, pose_pictures
from hairtool.character import bundled, load_character
from hairtool.character.cycle import ChainWave, chain_axis, chain_points, character_cycle, picture_rotations
from hairtool.character.glb import pack
from hairtool.groom import Groom

CHARACTER = load_character(Path(__file__).resolve().parents[1] / "data" / "characters" / "bunches.vrm")


def twisted(tmp_path_factory) -> object:
    """The bundled character with a turned head and every node at a seeded, non-identity rest rotation."""
    doc, binary = bundled.build(vrm=True)
    rng = np.random.default_rng(7)
    for node in doc["nodes"]:
        if "translation" in node:
            q = rng.normal(size=4)
            node["rotation"] = (q / np.linalg.norm(q)).tolist()
    path = tmp_path_factory.mktemp("twisted") / "twisted.vrm"
    path.write_bytes(pack(doc, binary))
    return load_character(path)


def _posed_chains(rotations, character=CHARACTER):
    world = character.nodes.world(rotations)
    return [chain_points(character, ch, world) for ch in character.chains]


def test_the_papers_figure_2_timing_six_drawings_over_eleven_frames():
    cyc = character_cycle(CHARACTER, WaveParams(period=0.45), fps=24, hold=2)
    assert (cyc.schedule.n_pictures, cyc.schedule.n_frames) == (6, 11)
    frames = cyc.frames()
    assert frames.shape == (11, CHARACTER.nodes.count, 4)
    held = [0, 0, 1, 1, 2, 2, 3, 3, 4, 4, 5]
    for f, pic in enumerate(held):
        assert np.array_equal(frames[f], cyc.pictures[pic])


@settings(max_examples=25, deadline=None)
@given(
    a=st.floats(-1.5, 1.5),
    k=st.floats(0.3, 3.0),
    s=st.sampled_from([-1.5, 0.8, 1.2, 3.0]),
    p=st.floats(0.0, 3.0),
    scale=st.floats(0.2, 2.0),
    phase=st.floats(0.0, 1.0),
    chain=st.integers(0, 13),
    t=st.floats(0.0, 1.0),
)
def test_a_chain_takes_the_shape_the_strand_cycle_gives_its_rest_points(a, k, s, p, scale, phase, chain, t):
    _same_shape(CHARACTER, a, k, s, p, scale, phase, chain, t)


def test_rest_rotations_that_are_not_identity_give_the_same_shapes(tmp_path_factory):
    character = twisted(tmp_path_factory)
    for chain in range(0, 14, 3):
        _same_shape(character, 0.8, 1.0, 1.2, 1.0, 1.0, 0.1 * chain, chain, 0.1)


def _same_shape(character, a, k, s, p, scale, phase, chain, t):
    params = WaveParams(amplitude=a, wavelength=k, gravity=s, profile=p, period=0.45)
    wave = ChainWave(amplitude_scale=scale, phase=phase)
    rot = picture_rotations(character, params, np.array([t]), {chain: wave})
    got = _posed_chains(rot[0], character)[chain]
    rest = chain_points(character, character.chains[chain])
    groom = Groom.from_strands([rest])
    axis = chain_axis(rest, wave)
    bunches = Bunches(np.zeros(1, dtype=np.int64), axis[None], np.array([scale]), np.array([phase]))
    expect = pose_pictures(groom, params, [t], bunches, use_numba=False)[0]
    np.testing.assert_allclose(got, expect, atol=2e-6)  # float32 groom vs float64 chain


def test_only_chain_nodes_turn_and_segment_lengths_stay():
    cyc = character_cycle(CHARACTER)
    moved = np.any(np.abs(cyc.pictures - CHARACTER.nodes.rotation) > 1e-12, axis=(0, 2))
    chain_nodes = {n for ch in CHARACTER.chains for n in ch.nodes[:-1]}
    assert set(np.flatnonzero(moved).tolist()) == chain_nodes
    for pic in cyc.pictures:
        for ch, pts in zip(CHARACTER.chains, _posed_chains(pic), strict=True):
            rest = chain_points(CHARACTER, ch)
            np.testing.assert_allclose(
                np.linalg.norm(np.diff(pts, axis=0), axis=1),
                np.linalg.norm(np.diff(rest, axis=0), axis=1),
                rtol=1e-9,
            )
