"""The paper's Table 1 measures between two motions of the same character's chains.

Mean angular error (degrees) and node displacement (% of chain length), as
:func:`hairtool.anime.metrics.chain_errors` defines them, computed chain by chain on the chains'
world node positions and averaged over chains, so chains of different lengths can be compared.
It is a reproducible measure of how differently two motions move the hair, not a verdict.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from hairtool.anime.metrics import chain_errors
from hairtool.character.cycle import chain_points
from hairtool.character.model import Character
from hairtool.errors import ParameterError

F64 = NDArray[np.float64]


def compare_motions(character: Character, motion: F64, reference: F64) -> dict:
    """Angular and positional errors of ``motion`` against ``reference``, both ``(F, J, 4)`` rotations.

    Parameters
    ----------
    character : Character
        The character.
    motion, reference : ndarray
        ``(F, J, 4)`` local rotations.

    Returns
    -------
    dict
        The errors.
    """
    if motion.shape != reference.shape or motion.ndim != 3:
        raise ParameterError("reference", reference.shape, f"rotations of the motion's shape {motion.shape}")
    wa, wb = character.nodes.world(motion), character.nodes.world(reference)
    per_chain = []
    for ch in character.chains:
        a = chain_points(character, ch, wa)[:, None]
        b = chain_points(character, ch, wb)[:, None]
        e = chain_errors(a, b)
        per_chain.append((ch.name, e.angular_deg, e.position_pct))
    ang = float(np.mean([p[1] for p in per_chain]))
    pos = float(np.mean([p[2] for p in per_chain]))
    return {
        "angular_error_deg": ang,
        "position_error_pct": pos,
        "frames": int(motion.shape[0]),
        "chains": [{"name": n, "angular_error_deg": a, "position_error_pct": p} for n, a, p in per_chain],
    }
