"""ClumpWithGaps (Kim 2026, eqs. 14–19): wet-hair adhesion between strands, with gaps kept.

Each non-root vertex p is pulled toward the vertices q of *other* strands within h by
f = Σ g(|q − p|)·(q − p)/(|q − p| + ε), g(r) = (1 − r/h)² (14)–(15), and moved by
Δp = (Δt²/m)·f (16), k times, Jacobi style (all forces from the previous iterate).

Gap correction (17)–(19), per vertex, on the pair (p, q*) with q* its strongest neighbour (the
nearest; ties to the lower vertex index): r0 = |q* − p| before, r1 = |q* + Δq* − p − Δp| after
the trial step, ζ ~ U(0,1) hashed from (seed, vertex, iteration), Δp ← λ·Δp with

- ``"printed"`` (default): δ = clamp((r1 − r0)/h, 0, 1), λ = (1 − δ)ζ + δ, as printed;
- ``"text"``: δ = clamp(|r1 − r0|/h, 0, 1), λ = (1 − δ)ζ — the paper's prose: a large change of
  distance gives a small λ;
- ``"off"``: λ = 1, plain adhesion (for comparison).

Neighbours (a Verlet list): the vertices of other strands within h·(1 + MARGIN) at the start
of the update are the candidates for all k iterations; each iteration uses those of them that
are then within h. (A pair farther apart than 1.1·h at the start never interacts in that
update.) :func:`clump` runs numba kernels on a cell-sorted list built once per update;
:func:`clump_reference` is the plain numpy twin of the same definition.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from hairtool.errors import ParameterError
from hairtool.freeze import CH_CLUMP, EPS, check_seed, hash_u01, hash_u01_nb, seed_u64
from hairtool.groom import Groom
from hairtool.spatial import NeighbourList, pairs_within_reference

GAP_MODES = ("printed", "text", "off")
_GAP_CODE = {"printed": 0, "text": 1, "off": 2}
MAX_ITERATIONS = 100
MARGIN = 0.1  # neighbour-list radius h·(1 + MARGIN)
STEP_FRACTION = 0.2  # auto Δt²/m = STEP_FRACTION·h / max(1, mean Σg at the first iteration)


def check_clump_params(radius: float, iterations: int, step: float | None, gap_mode: str) -> None:
    h = float(radius)
    if not np.isfinite(h) or h <= 0:
        raise ParameterError("clump_radius", radius, "a positive finite distance")
    if isinstance(iterations, bool) or int(iterations) != iterations or not 0 <= iterations <= MAX_ITERATIONS:
        raise ParameterError("clump_iterations", iterations, f"a whole number in [0, {MAX_ITERATIONS}]")
    if step is not None and (not np.isfinite(float(step)) or not 0.0 <= float(step) <= 1e6 * h):
        raise ParameterError("clump_step", step, "a non-negative finite number (Δt²/m)")
    if gap_mode not in GAP_MODES:
        raise ParameterError("gap_mode", gap_mode, " or ".join(GAP_MODES))


@njit(cache=True, parallel=True)
def _force_kernel(P, nbr, cnt, sroot, sorig, h, dp, best, count, weight):
    for i in prange(P.shape[0]):
        dp[i, 0] = dp[i, 1] = dp[i, 2] = 0.0
        best[i] = -1
        count[i] = 0
        weight[i] = 0.0
        if sroot[i]:
            continue
        fx = fy = fz = 0.0
        br = np.inf
        bj = -1
        c = 0
        wsum = 0.0
        inv_h = 1.0 / h
        for n in range(cnt[i]):
            j = nbr[i, n]
            ex = P[j, 0] - P[i, 0]
            ey = P[j, 1] - P[i, 1]
            ez = P[j, 2] - P[i, 2]
            r = np.sqrt(ex * ex + ey * ey + ez * ez)
            # Branch-free: list entries beyond h (the margin) get g = 0.
            g = max(1.0 - r * inv_h, 0.0) ** 2  # (14)
            s = g / (r + EPS)  # (15)
            fx += s * ex
            fy += s * ey
            fz += s * ez
            c += np.int64(r < h)
            wsum += g
            if r < br or (r == br and sorig[j] < sorig[bj]):
                br = r
                bj = j
        if br >= h:
            bj = -1
        dp[i, 0], dp[i, 1], dp[i, 2] = fx, fy, fz  # f (15); Δp = step·f (16)
        best[i] = bj
        count[i] = c
        weight[i] = wsum


@njit(cache=True, parallel=True)
def _gap_kernel(P, f, step, best, sorig, h, gap, seed, it, Pout):
    for i in prange(P.shape[0]):
        lam = 1.0
        j = best[i]
        if gap != 2 and j >= 0:
            ex, ey, ez = P[j, 0] - P[i, 0], P[j, 1] - P[i, 1], P[j, 2] - P[i, 2]
            r0 = np.sqrt(ex * ex + ey * ey + ez * ez)
            ex += step * (f[j, 0] - f[i, 0])
            ey += step * (f[j, 1] - f[i, 1])
            ez += step * (f[j, 2] - f[i, 2])
            r1 = np.sqrt(ex * ex + ey * ey + ez * ez)
            zeta = hash_u01_nb(seed, sorig[i], it, CH_CLUMP)
            if gap == 0:
                delta = min(max((r1 - r0) / h, 0.0), 1.0)  # (17)
                lam = (1.0 - delta) * zeta + delta  # (18)
            else:
                delta = min(abs(r1 - r0) / h, 1.0)
                lam = (1.0 - delta) * zeta
        for a in range(3):
            Pout[i, a] = P[i, a] + lam * (step * f[i, a])  # (16), (19)


def auto_step(h: float, weight: np.ndarray, count: np.ndarray) -> float:
    """Default Δt²/m: STEP_FRACTION·h over the mean kernel weight Σg of the vertices that have
    neighbours (at least 1), so that dense grooms, where (15) sums many terms, do not overshoot."""
    has = count > 0
    mean_w = float(weight[has].sum()) / max(int(np.count_nonzero(has)), 1)
    return STEP_FRACTION * h / max(mean_w, 1.0)


class ClumpWorkspace:
    """Buffers reused between updates, and what the last run saw (for benchmarks and the studio)."""

    def __init__(self) -> None:
        self.neighbours = NeighbourList()
        self.mean_neighbours = 0.0  # other-strand vertices within h per moving vertex, first iteration
        self.step = 0.0  # Δt²/m used in the last run
        self._mask_for: object = None
        self._mask = np.zeros(0, bool)
        self._buffers: tuple = ()
        self.built_for: tuple | None = None  # (points, list radius) of the current neighbour list

    def roots_mask(self, topology) -> np.ndarray:
        if self._mask_for is not topology:
            self._mask = np.zeros(topology.vertex_count, bool)
            self._mask[topology.root_indices] = True
            self._mask_for = topology
        return self._mask

    def buffers(self, v: int) -> tuple:
        """Iterates (2), Δp, nearest neighbour, counts and weights for V vertices, reused."""
        if not self._buffers or len(self._buffers[0]) != v:
            self._buffers = (
                np.empty((v, 3)),
                np.empty((v, 3)),
                np.empty((v, 3)),
                np.empty(v, np.int64),
                np.empty(v, np.int64),
                np.empty(v),
            )
        return self._buffers


def clump_points(
    groom: Groom,
    radius: float,
    iterations: int = 3,
    step: float | None = None,
    gap_mode: str = "printed",
    seed: int = 0,
    workspace: ClumpWorkspace | None = None,
) -> np.ndarray:
    """:func:`clump` returning float32 ``(V, 3)`` points instead of a groom."""
    check_clump_params(radius, iterations, step, gap_mode)
    seed = check_seed(seed)
    ws = workspace or ClumpWorkspace()
    h = float(radius)
    top = groom.topology
    ws.step = 0.0
    ws.mean_neighbours = 0.0
    if iterations == 0 or groom.strand_count < 2:
        return groom.points.copy()
    is_root = ws.roots_mask(top)
    nl = ws.neighbours
    key = (groom.points, h * (1.0 + MARGIN))
    if ws.built_for is None or ws.built_for[0] is not key[0] or ws.built_for[1] != key[1]:
        # Grooms are immutable: the same points object needs no new list (clump-only changes).
        ws.built_for = None
        nl.build(groom.points, top.strand_index, is_root, key[1])
        ws.built_for = key
    order = nl.order
    sroot, sorig = nl.skip, order
    P, Pn, dp, best, count, weight = ws.buffers(groom.vertex_count)
    P[:] = nl.points
    su = seed_u64(seed)
    gap = _GAP_CODE[gap_mode]
    for it in range(iterations):
        _force_kernel(P, nl.nbr, nl.cnt, sroot, sorig, h, dp, best, count, weight)
        if it == 0:
            pairs, moving, w_sum, w_count = _first_stats(count, weight, sroot)
            ws.mean_neighbours = pairs / max(moving, 1)
            auto = STEP_FRACTION * h / max(w_sum / max(w_count, 1), 1.0)
            ws.step = k_step = auto if step is None else float(step)
        _gap_kernel(P, dp, k_step, best, sorig, h, gap, su, it, Pn)
        P, Pn = Pn, P
    out = np.empty((len(P), 3), np.float32)
    _scatter(order, P, out)
    return out


@njit(cache=True)
def _first_stats(count, weight, sroot):
    """Pairs within h, moving vertices, and Σg over the vertices with neighbours (for auto_step)."""
    pairs = 0
    moving = 0
    w_sum = 0.0
    w_count = 0
    for i in range(count.size):
        pairs += count[i]
        if not sroot[i]:
            moving += 1
        if count[i] > 0:
            w_sum += weight[i]
            w_count += 1
    return pairs, moving, w_sum, w_count


@njit(cache=True, parallel=True)
def _scatter(order, P, out):
    for k in prange(order.size):
        for a in range(3):
            out[order[k], a] = P[k, a]


def clump(
    groom: Groom,
    radius: float,
    iterations: int = 3,
    step: float | None = None,
    gap_mode: str = "printed",
    seed: int = 0,
    workspace: ClumpWorkspace | None = None,
) -> Groom:
    """ClumpWithGaps: vertices pulled toward nearby vertices of other strands; roots stay.

    ``radius`` h (groom units), ``iterations`` k ∈ [0, 100], ``step`` Δt²/m (None: :func:`auto_step`),
    ``gap_mode`` "printed" | "text" | "off", ``seed`` for ζ. Pass a ``workspace`` to reuse
    buffers across updates and read ``mean_neighbours`` afterwards.
    """
    return groom.with_points(clump_points(groom, radius, iterations, step, gap_mode, seed, workspace))


def clump_reference(
    groom: Groom,
    radius: float,
    iterations: int = 3,
    step: float | None = None,
    gap_mode: str = "printed",
    seed: int = 0,
) -> Groom:
    """Plain numpy twin of :func:`clump`: candidate pairs from the start, filtered each iteration."""
    check_clump_params(radius, iterations, step, gap_mode)
    seed = check_seed(seed)
    h = float(radius)
    top = groom.topology
    strand = top.strand_index
    v = groom.vertex_count
    moving = np.ones(v, bool)
    moving[top.root_indices] = False
    P = groom.points.astype(np.float64)
    if groom.strand_count < 2:
        return groom.with_points(P)
    ci, cj = pairs_within_reference(groom.points, strand, h * (1.0 + MARGIN))
    keep = moving[ci]
    ci, cj = ci[keep], cj[keep]
    for it in range(iterations):
        d = P[cj] - P[ci]
        r = np.sqrt(d[:, 0] * d[:, 0] + d[:, 1] * d[:, 1] + d[:, 2] * d[:, 2])
        near = r < h
        i, j, d, r = ci[near], cj[near], d[near], r[near]
        g = (1.0 - r / h) ** 2  # (14)
        f = np.zeros((v, 3))
        for a in range(3):
            f[:, a] = np.bincount(i, weights=g / (r + EPS) * d[:, a], minlength=v)  # (15)
        if it == 0:
            wsum = np.bincount(i, weights=g, minlength=v)
            k_step = auto_step(h, wsum, np.bincount(i, minlength=v)) if step is None else float(step)
        dp = k_step * f  # (16)
        lam = np.ones(v)
        if gap_mode != "off" and len(i):
            first = np.lexsort((j, r, i))  # per vertex: nearest, then lowest index
            i_s = i[first]
            head = np.r_[True, i_s[1:] != i_s[:-1]]
            pi, qj = i_s[head], j[first][head]
            r0 = np.linalg.norm(P[qj] - P[pi], axis=1)
            r1 = np.linalg.norm(P[qj] + dp[qj] - P[pi] - dp[pi], axis=1)
            zeta = hash_u01(seed, pi, it, CH_CLUMP)
            if gap_mode == "printed":
                delta = np.clip((r1 - r0) / h, 0.0, 1.0)  # (17)
                lam[pi] = (1.0 - delta) * zeta + delta  # (18)
            else:
                delta = np.clip(np.abs(r1 - r0) / h, 0.0, 1.0)
                lam[pi] = (1.0 - delta) * zeta
        P = P + lam[:, None] * dp  # (19)
    return groom.with_points(P)
