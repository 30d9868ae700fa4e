"""Keys of a baked spring-bone motion are exact: the DP's keys against every key set tried."""

from __future__ import annotations

from itertools import combinations, pairwise
from pathlib import Path

import numpy as np
import pytest

from hairtool.character import load_character
from hairtool.character.bvh import chains_motion
from hairtool.character.springs import head_shake, simulate
from hairtool.keys.session import find_keys
from hairtool.mocap.costs import motion_features

CHARACTER = load_character(Path(__file__).resolve().parents[1] / "data" / "characters" / "bunches.vrm")
FRAMES = 10


def _linear_error(x: np.ndarray, keys: tuple[int, ...]) -> float:
    """The oracle: squared distance of every frame to the straight line between its keys."""
    total = 0.0
    for a, b in pairwise(keys):
        for t in range(a + 1, b):
            u = (t - a) / (b - a)
            total += float(np.sum((x[t] - ((1 - u) * x[a] + u * x[b])) ** 2))
    return total


@pytest.mark.parametrize(("turn", "period"), [(40.0, 0.5), (25.0, 0.3)])
def test_keys_of_baked_springs_are_the_best_key_sets(turn, period):
    baked = simulate(CHARACTER, head_shake(CHARACTER, FRAMES, 24.0, turn_deg=turn, period=period), 24.0)
    x = motion_features(chains_motion(CHARACTER, baked, 24.0), "rotations")
    for k in range(2, 7):
        sel = find_keys(x, keys=k)
        best = min(
            (_linear_error(x, (0, *inner, FRAMES - 1)), (0, *inner, FRAMES - 1))
            for inner in combinations(range(1, FRAMES - 1), k - 2)
        )
        assert sel.cost == pytest.approx(best[0], rel=1e-9, abs=1e-12)
        assert tuple(sel.keys.tolist()) == best[1]
