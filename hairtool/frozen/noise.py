"""Counter-based noise shared by the frozen-hair stages: a hash of (seed, a, b, channel).

The noise is never a running generator, so a strand's look does not depend on the thread count,
on other strands, or on how often the groom was updated; each use draws from its own channel.
``*_nb`` functions run inside kernels; :func:`hash_u01` is their numpy twin.
"""

from __future__ import annotations

import numpy as np
from numba import njit
from numpy.typing import ArrayLike, NDArray

from hairtool.errors import ParameterError

EPS = 1e-12  # the papers' epsilon in denominators (float64)

# Noise channels: one independent uniform stream per use of the hash.
CH_STRETCH = 1
CH_BEND = 2
CH_STRAND = 3
CH_DRAW = 4
CH_CLUMP = 5

_M1 = np.uint64(0xBF58476D1CE4E5B9)
_M2 = np.uint64(0x94D049BB133111EB)
_GOLD = np.uint64(0x9E3779B97F4A7C15)
_S30, _S27, _S31, _S11 = np.uint64(30), np.uint64(27), np.uint64(31), np.uint64(11)
_INV53 = 1.0 / 9007199254740992.0  # 2**-53


def _mix_py(z):
    """splitmix64's finaliser: works on numba uint64 scalars and on numpy uint64 arrays alike."""
    z = (z ^ (z >> _S30)) * _M1
    z = (z ^ (z >> _S27)) * _M2
    return z ^ (z >> _S31)


def _hash_py(seed, a, b, channel):
    h = _mix_py(seed ^ _mix_py(channel ^ _GOLD))
    h = _mix_py(h ^ _mix_py(a + _GOLD))
    return _mix_py(h ^ b)


_mix = njit(cache=True, inline="always")(_mix_py)


@njit(cache=True, nogil=True, inline="always")
def hash_head_nb(seed: np.uint64, a: int, channel: int) -> np.uint64:
    """The part of :func:`hash_u01_nb` that depends on (seed, a, channel) only: kernels that
    draw many b for one a (a strand's vertices, a vertex's iterations) compute it once.

    Parameters
    ----------
    seed : numpy.uint64
        The seed.
    a : int
        The first index.
    channel : int
        The draw's channel.

    Returns
    -------
    numpy.uint64
        The head.
    """
    h = _mix(seed ^ _mix(np.uint64(channel) ^ _GOLD))
    return _mix(h ^ _mix(np.uint64(a) + _GOLD))


@njit(cache=True, nogil=True, inline="always")
def hash_tail_u01_nb(head: np.uint64, b: int) -> float:
    """Uniform [0, 1) from a :func:`hash_head_nb` and b: ``hash_u01_nb(seed, a, b, channel)``.

    Parameters
    ----------
    head : numpy.uint64
        From :func:`hash_head_nb`.
    b : int
        The second index.

    Returns
    -------
    float
        In [0, 1).
    """
    h = _mix(head ^ np.uint64(b))
    return float(h >> _S11) * _INV53


@njit(cache=True, nogil=True, inline="always")
def hash_u01_nb(seed: np.uint64, a: int, b: int, channel: int) -> float:
    """Uniform [0, 1) from (seed, a, b, channel) inside kernels.

    Parameters
    ----------
    seed : numpy.uint64
        The seed.
    a, b : int
        The indices.
    channel : int
        The draw's channel.

    Returns
    -------
    float
        In [0, 1).
    """
    return hash_tail_u01_nb(hash_head_nb(seed, a, channel), b)


def hash_u01(seed: int, a: ArrayLike, b: ArrayLike, channel: int) -> NDArray[np.float64]:
    """The numpy twin of :func:`hash_u01_nb`: uniform [0, 1) per (a, b), broadcast.

    Parameters
    ----------
    seed : int
        The seed.
    a, b : array_like
        The indices, broadcast.
    channel : int
        The draw's channel.

    Returns
    -------
    ndarray
        float64 in [0, 1).
    """
    a64, b64 = np.broadcast_arrays(np.atleast_1d(np.asarray(a, np.int64)), np.atleast_1d(np.asarray(b)))
    h = _hash_py(
        np.full(a64.shape, seed_u64(seed), np.uint64),
        a64.astype(np.uint64),
        b64.astype(np.int64).astype(np.uint64),
        np.full(a64.shape, channel, np.uint64),
    )
    return (h >> _S11).astype(np.float64) * _INV53


def seed_u64(seed: int) -> np.uint64:
    """``seed`` as the uint64 the kernels hash (its low 64 bits).

    Parameters
    ----------
    seed : int
        The seed.

    Returns
    -------
    numpy.uint64
        The seed.
    """
    return np.uint64(int(seed) & 0xFFFFFFFFFFFFFFFF)


def draw_seed(seed: int, draw: int) -> int:
    """The seed of the ``draw``-th noise redraw (draw 0 is ``seed`` itself).

    Parameters
    ----------
    seed : int
        The seed.
    draw : int
        The redraw, ≥ 0.

    Returns
    -------
    int
        Its seed.
    """
    if draw == 0:
        return int(seed)
    return int(hash_u01(seed, [draw], [0], CH_DRAW)[0] * 2.0**53)


def check_seed(seed: object) -> int:
    """``seed`` as an int, or a ParameterError unless it is a whole number in [0, 2**63).

    Parameters
    ----------
    seed : object
        The seed given.

    Returns
    -------
    int
        The seed.
    """
    if isinstance(seed, bool) or not isinstance(seed, int | np.integer) or not 0 <= int(seed) < 2**63:
        raise ParameterError("seed", seed, "a whole number in [0, 2**63)")
    return int(seed)
