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

Neighbours: the vertices of other strands within h·(1 + MARGIN) at the start of the update
are the candidates for all k iterations; each iteration uses those of them that are then
within h. (A pair farther apart than 1.1·h at the start never interacts in that update.)
:func:`clump` runs numba kernels on a cell-sorted list of them, built when the points change
(an update on the points of the last one, e.g. a clump-only parameter change or a cursor held
still, reuses it). :func:`clump_reference` is the plain numpy twin of the same definition.
While a brush drags, :mod:`hairtool.frozen.local` redoes a run only on the strands near the brush.

``keep_lengths``: after the k iterations every segment is set back to its length before
clumping, root to tip, direction kept (:mod:`hairtool.frozen.lengths`); off by default, as printed.

Clump strength (the clump brush): a per-strand s in [0, 1] scales the step (16) of each of the
strand's vertices, Δp = s·(Δt²/m)·f, before the gap correction, which then judges each pair by
the steps its two vertices will really take (r1 from s_p·Δp_p and s_q·Δq_q). It scales how far
a strand goes, not how hard it pulls: a strand painted to 0 stays exactly where it is and still
draws its neighbours, so clumps form around it; the paper's adhesion weight g (14) and the
automatic step (from Σg) stay as printed. All ones (the default) gives the printed bytes.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange
from numpy.typing import ArrayLike

from hairtool.errors import ParameterError
from hairtool.frozen.lengths import restore_lengths, restore_lengths_reference
from hairtool.frozen.neighbour_update import moved_vertices, update_list
from hairtool.frozen.noise import (
    CH_CLUMP,
    EPS,
    check_seed,
    hash_head_nb,
    hash_tail_u01_nb,
    hash_u01,
    seed_u64,
)
from hairtool.frozen.spatial import NeighbourList, pairs_within_reference
from hairtool.groom import Groom
from hairtool.serial_twins import twin_njit

GAP_MODES = ("printed", "text", "off")
_GAP_CODE = {"printed": 0, "text": 1, "off": 2}
MAX_ITERATIONS = 100
MARGIN = 0.1  # neighbour-list radius h·(1 + MARGIN)
STEP_FRACTION = 0.2  # auto Δt²/m = STEP_FRACTION·h / max(1, mean Σg at the first iteration)


def check_clump_params(radius: float, iterations: int, step: float | None, gap_mode: str) -> None:
    """A ParameterError naming the first of ClumpWithGaps' parameters out of its range.

    Parameters
    ----------
    radius : float
        The clump radius h, > 0.
    iterations : int
        Passes k, 0 … MAX_ITERATIONS.
    step : float or None
        Δt²/m, > 0 (None: automatic).
    gap_mode : str
        ``"printed"``, ``"text"`` or ``"off"``.
    """
    h = float(radius)
    if not np.isfinite(h) or h <= 0:
        raise ParameterError("clump_radius", radius, "a positive finite distance")
    if isinstance(iterations, bool) or int(iterations) != iterations or not 0 <= iterations <= MAX_ITERATIONS:
        raise ParameterError("clump_iterations", iterations, f"a whole number in [0, {MAX_ITERATIONS}]")
    if step is not None and (not np.isfinite(float(step)) or not 0.0 <= float(step) <= 1e6 * h):
        raise ParameterError("clump_step", step, "a non-negative finite number (Δt²/m)")
    if gap_mode not in GAP_MODES:
        raise ParameterError("gap_mode", gap_mode, " or ".join(GAP_MODES))


def vertex_strength(groom: Groom, strength: ArrayLike | None) -> np.ndarray:
    """``(V,)`` float64 clump strength of each vertex (its strand's), from ``(S,)`` values in
    [0, 1] (None: all ones); ParameterError naming ``clump_strength`` otherwise.

    Parameters
    ----------
    groom : Groom
        The strands.
    strength : array_like or None
        ``(S,)`` each strand's clump strength.

    Returns
    -------
    ndarray
        ``(V,)`` float64.
    """
    if strength is None:
        return np.ones(groom.vertex_count)
    s = np.asarray(strength, dtype=np.float64)
    if s.shape != (groom.strand_count,) or not np.all((s >= 0.0) & (s <= 1.0)):
        raise ParameterError("clump_strength", f"shape {s.shape}", f"{groom.strand_count} numbers in [0, 1]")
    return s[groom.topology.strand_index]


@twin_njit(nogil=True, parallel=True)
def keep_still(points, sv, out):
    """The vertices at clump strength 0 back to ``points`` in ``out`` after the length pass
    (which recomputes every segment and may round the last bit of an unmoved one)."""
    for i in prange(sv.size):
        if sv[i] == 0.0:
            for a in range(3):
                out[i, a] = points[i, a]


def keep_still_reference(points: np.ndarray, sv: np.ndarray, out: np.ndarray) -> np.ndarray:
    """Numpy twin of :func:`keep_still`.

    Parameters
    ----------
    points : ndarray
        ``(V, 3)`` the points before clumping.
    sv : ndarray
        ``(V,)`` clump strengths.
    out : ndarray
        ``(V, 3)`` the clumped points.

    Returns
    -------
    ndarray
        ``out`` with the unclumped vertices put back.
    """
    return np.where((sv == 0.0)[:, None], points, out).astype(out.dtype)


@twin_njit(nogil=True, parallel=True)
def _gather_inputs(points, sv, order, seed, gap, P, S, heads):
    """The points (float64), clump strengths and, with gaps on, ζ's hash heads (per original
    index) in the list's sorted order: one parallel loop (each is one more kernel to compile)."""
    for k in prange(order.size):
        i = order[k]
        for a in range(3):
            P[k, a] = points[i, a]
        S[k] = sv[i]
        if gap != 2:
            heads[k] = hash_head_nb(seed, i, CH_CLUMP)


@njit(cache=True, nogil=True, inline="always")
def _take(acc, j, r, s, ex, ey, ez, h, inv_h, stats):
    """One list entry j at distance r, weight s = g/(r + ε), difference e, into ``acc`` = (fx, fy,
    fz, nearest r, its index, whether another entry is exactly as near, within h, Σg). The
    nearest is a branch: a running minimum over a list in no distance order moves about ln(n)
    times in n entries, so the branch is well predicted (selects measured 1.13× slower on Sintel);
    exact ties are settled afterwards by :func:`_lowest_of_nearest`, since looking up original
    indices here costs 1.5×."""
    fx, fy, fz, br, bj, tie, c, wsum = acc
    fx += s * ex
    fy += s * ey
    fz += s * ez
    if r <= br:
        if r < br:
            br, bj, tie = r, j, False
        else:
            tie = True
    if stats:
        t = max(1.0 - r * inv_h, 0.0)
        c += np.int64(r < h)
        wsum += t * t
    return fx, fy, fz, br, bj, tie, c, wsum


@njit(cache=True, nogil=True, inline="always")
def _lowest_of_nearest(P, flat, a, b, px, py, pz, br, sorig, bj, bo):
    """Among the entries ``flat[a:b]`` exactly ``br`` away (the same arithmetic as
    :func:`vertex_force`), the one of lowest original index, against the best so far (bj, bo)."""
    for n in range(a, b):
        j = flat[n]
        ex = P[j, 0] - px
        ey = P[j, 1] - py
        ez = P[j, 2] - pz
        if np.sqrt(ex * ex + ey * ey + ez * ez) == br and sorig[j] < bo:
            bj, bo = j, sorig[j]
    return bj, bo


@njit(cache=True, nogil=True, inline="always")
def vertex_force(P, aflat, a0, a1, bflat, b0, b1, px, py, pz, root, h, inv_h, stats, sorig):
    """f (15) on p from the list entries ``aflat[a0:a1]`` then ``bflat[b0:b1]`` (none for a
    root), and its nearest neighbour within h (ties: the lower original index ``sorig``):
    ``(fx, fy, fz, nearest or −1, neighbours within h, Σg)``, the last two with ``stats``."""
    acc = (0.0, 0.0, 0.0, h, np.int64(-1), False, np.int64(0), 0.0)
    if not root:
        na = a1 - a0
        for k in range(na + b1 - b0):  # both runs in one loop: one loop exit to mispredict, not two
            j = aflat[a0 + k] if k < na else bflat[b0 + k - na]
            ex = P[j, 0] - px
            ey = P[j, 1] - py
            ez = P[j, 2] - pz
            r = np.sqrt(ex * ex + ey * ey + ez * ez)
            t = max(1.0 - r * inv_h, 0.0)  # list entries beyond h (the margin): g = 0
            acc = _take(acc, j, r, t * t / (r + EPS), ex, ey, ez, h, inv_h, stats)  # g (14), f (15)
    fx, fy, fz, br, bj, tie, c, wsum = acc
    if tie and bj >= 0:
        bj, bo = _lowest_of_nearest(P, aflat, a0, a1, px, py, pz, br, sorig, bj, sorig[bj])
        bj, bo = _lowest_of_nearest(P, bflat, b0, b1, px, py, pz, br, sorig, bj, bo)
    return fx, fy, fz, bj, c, wsum


BLOCKS = 64  # runs of vertices of about equal work that the pair and force passes share out


@njit(cache=True, nogil=True)
def work_blocks(acnt, bstart, both, n, blocks):
    """``blocks`` (n + 1,): bounds of n runs of consecutive vertices with about equal list
    entries (forward ones, with ``both`` backward ones too; one more per vertex). A parallel
    loop over vertices gives each thread an equal count of them, and the dense part of a groom
    sits in one part of the cell order (ponytail_back's second half holds 65 % of its entries:
    one thread did two thirds of the work); each thread's share of equal blocks is equal work."""
    v = acnt.size
    total = 0
    for i in range(v):
        total += acnt[i] + 1 + (bstart[i + 1] - bstart[i] if both else 0)
    blocks[0] = 0
    k = 1
    run = 0
    for i in range(v):
        run += acnt[i] + 1 + (bstart[i + 1] - bstart[i] if both else 0)
        while k < n and run * n >= total * k:
            blocks[k] = i + 1
            k += 1
    while k <= n:
        blocks[k] = v
        k += 1


def work_blocks_reference(acnt: np.ndarray, bstart: np.ndarray, both: bool, n: int) -> np.ndarray:
    """Numpy twin of :func:`work_blocks`.

    Parameters
    ----------
    acnt : ndarray
        ``(V,)`` forward entries per vertex.
    bstart : ndarray
        ``(V + 1,)`` backward run starts.
    both : bool
        Count the backward entries too.
    n : int
        Blocks.

    Returns
    -------
    ndarray
        ``(n + 1,)`` int64 bounds.
    """
    w = acnt.astype(np.int64) + 1 + (np.diff(bstart) if both else 0)
    run = np.cumsum(w)
    first = np.searchsorted(run * n, run[-1] * np.arange(1, n), side="left") + 1
    return np.concatenate([[0], first, [len(w)]]).astype(np.int64)


@twin_njit(nogil=True, parallel=True)
def _pair_kernel(P, aflat, aoff, acnt, inv_h, blocks, rs):
    """Each pair's distance r and weight g/(r + ε) (14)–(15), once, from its forward entry: a
    pair's two vertices compute the same r (their differences are each other's negatives), so
    :func:`_half_force_kernel` reads it for both and sums what :func:`vertex_force` sums. Side
    by side in ``rs`` (n, 2): a backward entry reads its pair's at a place in no order, one cache
    line for both (two arrays: two misses, and Sintel's half-force pass 1.23× slower). Over
    ``blocks`` of vertices of about equal work (:func:`work_blocks`)."""
    for blk in prange(blocks.size - 1):
        for i in range(blocks[blk], blocks[blk + 1]):
            px, py, pz = P[i, 0], P[i, 1], P[i, 2]
            for n in range(aoff[i], aoff[i] + acnt[i]):
                j = aflat[n]
                ex = P[j, 0] - px
                ey = P[j, 1] - py
                ez = P[j, 2] - pz
                r = np.sqrt(ex * ex + ey * ey + ez * ez)
                t = max(1.0 - r * inv_h, 0.0)
                rs[n, 0] = r
                rs[n, 1] = t * t / (r + EPS)


@njit(cache=True, nogil=True, inline="always")
def _lowest_stored(flat, a, b, emap, rs, br, sorig, bj, bo):
    """:func:`_lowest_of_nearest` on the stored distances."""
    same = emap.size == 0
    for n in range(a, b):
        j = flat[n]
        if rs[n if same else emap[n], 0] == br and sorig[j] < bo:
            bj, bo = j, sorig[j]
    return bj, bo


@twin_njit(nogil=True, parallel=True)
def _half_force_kernel(
    P, aflat, aoff, acnt, bflat, bstart, bmap, sroot, sorig, h, stats, blocks, rs, f, best, count, weight
):
    """f (15) of every vertex and its nearest neighbour within h (ties: the lower original
    index), as :func:`vertex_force` sums them, from the pair arrays of :func:`_pair_kernel`
    (the row grid's lists: forward runs, then backward runs whose pairs ``bmap`` finds among the
    forward entries), to the bit: half the square roots and divisions. With ``stats`` (the first
    iteration) also how many are within h and Σg. Over ``blocks`` of about equal work. The
    runs are summed here, not by a helper that takes the arrays: in this loop nest that helper
    made ratboy's serial pass 1.6× slower (numba's reference counting of the arrays passed)."""
    none = np.empty(0, np.int64)
    inv_h = 1.0 / h
    for blk in prange(blocks.size - 1):
        for i in range(blocks[blk], blocks[blk + 1]):
            acc = (0.0, 0.0, 0.0, h, np.int64(-1), False, np.int64(0), 0.0)
            a0, a1, b0, b1 = aoff[i], aoff[i] + acnt[i], bstart[i], bstart[i + 1]
            px, py, pz = P[i, 0], P[i, 1], P[i, 2]
            if not sroot[i]:
                for n in range(a0, a1):
                    j = aflat[n]
                    ex, ey, ez = P[j, 0] - px, P[j, 1] - py, P[j, 2] - pz
                    acc = _take(acc, j, rs[n, 0], rs[n, 1], ex, ey, ez, h, inv_h, stats)
                for n in range(b0, b1):
                    j = bflat[n]
                    m = bmap[n]
                    ex, ey, ez = P[j, 0] - px, P[j, 1] - py, P[j, 2] - pz
                    acc = _take(acc, j, rs[m, 0], rs[m, 1], ex, ey, ez, h, inv_h, stats)
            fx, fy, fz, br, bj, tie, c, wsum = acc
            if tie and bj >= 0:
                bj, bo = _lowest_stored(aflat, a0, a1, none, rs, br, sorig, bj, sorig[bj])
                bj, bo = _lowest_stored(bflat, b0, b1, bmap, rs, br, sorig, bj, bo)
            f[i, 0], f[i, 1], f[i, 2] = fx, fy, fz
            best[i] = bj
            if stats:
                count[i] = c
                weight[i] = wsum


@njit(cache=True, nogil=True, inline="always")
def gap_lambda(ex, ey, ez, gx, gy, gz, step, zeta, h, gap):
    """λ (17)–(19) of a vertex whose nearest neighbour lies e away, the two forces differing by
    g (that neighbour's minus its own); ``gap`` 0 "printed", 1 "text"."""
    r0 = np.sqrt(ex * ex + ey * ey + ez * ez)
    ex += step * gx
    ey += step * gy
    ez += step * gz
    r1 = np.sqrt(ex * ex + ey * ey + ez * ez)
    if gap == 0:
        delta = min(max((r1 - r0) / h, 0.0), 1.0)  # (17)
        return (1.0 - delta) * zeta + delta  # (18)
    delta = min(abs(r1 - r0) / h, 1.0)
    return (1.0 - delta) * zeta


@njit(cache=True, nogil=True, inline="always")
def next_iterate(px, py, pz, fx, fy, fz, si, ex, ey, ez, gx, gy, gz, near, step, zeta, h, gap):
    """A vertex's next iterate from its point p and force f: (16) scaled by its clump strength
    si, with the gap correction (17)–(19) against its nearest neighbour (``near``; e its offset,
    g the difference of the two scaled forces, that neighbour's minus its own; si all ones: the
    printed arithmetic, bit for bit). si = 0: not moved at all. Scalars only: numba counts
    references to each array passed to an inlined helper at every call, and a kernel that
    called such a helper per vertex spent most of its time there (the serial gap pass on
    ratboy's 71,232 vertices: 4.5 ms, 1.0 with the arrays read in the kernel)."""
    if si == 0.0:
        return px, py, pz
    lam = 1.0
    if gap != 2 and near:
        lam = gap_lambda(ex, ey, ez, gx, gy, gz, step, zeta, h, gap)
    lam *= si
    return px + lam * (step * fx), py + lam * (step * fy), pz + lam * (step * fz)  # (16), (19)


@twin_njit(nogil=True, parallel=True)
def _gap_kernel(P, f, S, step, best, heads, h, gap, it, Pout):
    """Every vertex's next iterate (:func:`next_iterate`), its ζ hashed from its original index
    and the iteration. The arrays are read here, not in an inlined helper (see there)."""
    for i in prange(P.shape[0]):
        j = best[i]
        si = S[i]
        near = gap != 2 and j >= 0 and si != 0.0
        zeta = 0.0
        ex = ey = ez = gx = gy = gz = 0.0
        if near:
            zeta = hash_tail_u01_nb(heads[i], it)  # = hash_u01(seed, original index, it, CH_CLUMP)
            sj = S[j]
            ex, ey, ez = P[j, 0] - P[i, 0], P[j, 1] - P[i, 1], P[j, 2] - P[i, 2]
            gx, gy, gz = sj * f[j, 0] - si * f[i, 0], sj * f[j, 1] - si * f[i, 1], sj * f[j, 2] - si * f[i, 2]
        Pout[i, 0], Pout[i, 1], Pout[i, 2] = next_iterate(
            P[i, 0], P[i, 1], P[i, 2], f[i, 0], f[i, 1], f[i, 2], si,
            ex, ey, ez, gx, gy, gz, near, step, zeta, h, gap,
        )  # fmt: skip


@njit(cache=True, nogil=True)
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


@twin_njit(nogil=True, parallel=True)
def _scatter(order, P, out):
    for k in prange(order.size):
        for a in range(3):
            out[order[k], a] = P[k, a]


@twin_njit(nogil=True, parallel=True)
def _scatter_record(order, f, best, count, weight, stats, out_f, out_best, out_count, out_weight):
    """An iteration's forces and nearest neighbours (and with ``stats`` the first one's counts
    and Σg) into a record."""
    for k in prange(order.size):
        i = order[k]
        for a in range(3):
            out_f[i, a] = f[k, a]
        out_best[i] = order[best[k]] if best[k] >= 0 else -1
        if stats:
            out_count[i] = count[k]
            out_weight[i] = weight[k]


@njit(cache=True, nogil=True)
def step_from_stats(h, w_sum, w_count):
    """The automatic Δt²/m from Σg summed over the vertices with neighbours (see :func:`auto_step`)."""
    return STEP_FRACTION * h / max(w_sum / max(w_count, 1), 1.0)


@twin_njit(nogil=True)
def _clump_run(points, strength, order, lists, sroot, h, iterations, step, gap, seed, bufs, out, record):
    """The k Jacobi iterations on the cell-sorted list, one call (no Python between kernels).
    ``step`` < 0: automatic. Writes the result to ``out`` (original order, float32); returns
    (mean neighbours within h per moving vertex, the step used). ``record`` = (iterates (k, V, 3),
    forces (k, V, 3), nearest neighbours (k, V), counts, Σg), in original order, for
    :mod:`hairtool.frozen.local`; empty arrays: not recorded."""
    P, Pn, f, best, count, weight, heads, S = bufs
    aflat, aoff, acnt, bflat, bstart, bmap, rs = lists
    rec_p, rec_f, rec_best, rec_count, rec_weight = record
    keep = rec_p.shape[0] > 0
    _gather_inputs(points, strength, order, seed, gap, P, S, heads)
    mean_nb = 0.0
    k_step = step
    inv_h = 1.0 / h
    nblk = max(1, min(BLOCKS, P.shape[0]))
    pair_blocks = np.empty(nblk + 1, np.int64)
    force_blocks = np.empty(nblk + 1, np.int64)
    work_blocks(acnt, bstart, False, nblk, pair_blocks)
    work_blocks(acnt, bstart, True, nblk, force_blocks)
    for it in range(iterations):
        if keep:
            _scatter(order, P, rec_p[it])
        _pair_kernel(P, aflat, aoff, acnt, inv_h, pair_blocks, rs)
        _half_force_kernel(
            P, aflat, aoff, acnt, bflat, bstart, bmap, sroot, order, h, it == 0, force_blocks, rs,
            f, best, count, weight,
        )  # fmt: skip
        if it == 0:
            pairs, moving, w_sum, w_count = _first_stats(count, weight, sroot)
            mean_nb = pairs / max(moving, 1)
            if step < 0.0:
                k_step = step_from_stats(h, w_sum, w_count)
        if keep:
            _scatter_record(
                order, f, best, count, weight, it == 0, rec_f[it], rec_best[it], rec_count, rec_weight
            )
        _gap_kernel(P, f, S, k_step, best, heads, h, gap, it, Pn)
        P, Pn = Pn, P
    _scatter(order, P, Pn)  # float64, as the record's: one specialisation of the kernel to compile
    for i in range(out.shape[0]):
        for a in range(3):
            out[i, a] = Pn[i, a]
    return mean_nb, k_step


_NO_RECORD = (
    np.zeros((0, 0, 3)),
    np.zeros((0, 0, 3)),
    np.zeros((0, 0), np.int64),
    np.zeros(0, np.int64),
    np.zeros(0),
)
RECORD_LIMIT = 12_000_000  # vertices × iterations at most in a record (2 × 24 + 8 bytes each): the
# largest research grooms (3.4M vertices) at the default 3 iterations, 570 MB; without a record
# every brush move redoes the whole groom (a 3.2M-vertex curly groom: 309 ms a move, not ~3)


class ClumpRecord:
    """What a run leaves for :mod:`hairtool.frozen.local` to redo only where its input changed:
    its parameters, input and output, and each iteration's points, forces and nearest neighbours,
    the first one's neighbour counts and Σg (original vertex order)."""

    def __init__(self, vertices: int, iterations: int) -> None:
        """Room for one run of ``iterations`` passes over ``vertices`` vertices (empty until a run fills it).

        Parameters
        ----------
        vertices : int
            V.
        iterations : int
            k.
        """
        self.key: tuple = ()
        self.points = np.empty((vertices, 3), np.float32)
        self.result = np.empty((vertices, 3), np.float32)
        self.iterates = np.empty((iterations, vertices, 3))
        self.forces = np.empty((iterations, vertices, 3))
        self.best = np.empty((iterations, vertices), np.int64)  # each vertex's nearest neighbour (−1: none)
        self.count = np.empty(vertices, np.int64)
        self.weight = np.empty(vertices)
        self.strength = np.empty(vertices)  # each vertex's clump strength in the run
        self.step = 0.0
        self.mean_neighbours = 0.0
        self.valid = False  # all of the above is one run's (False while being rewritten)

    def fits(self, vertices: int, iterations: int) -> bool:
        """Whether this record has room for a run of that size.

        Parameters
        ----------
        vertices : int
            V.
        iterations : int
            k.

        Returns
        -------
        bool
            True where its arrays have that shape.
        """
        return self.iterates.shape[:2] == (iterations, vertices)


def auto_step(h: float, weight: np.ndarray, count: np.ndarray) -> float:
    """Default Δt²/m: STEP_FRACTION·h over the mean kernel weight Σg of the vertices that have
    neighbours (at least 1), so that dense grooms, where (15) sums many terms, do not overshoot.

    Parameters
    ----------
    h : float
        The clump radius.
    weight : ndarray
        ``(V,)`` Σg of each vertex.
    count : ndarray
        ``(V,)`` its neighbours.

    Returns
    -------
    float
        Δt²/m.
    """
    has = count > 0
    mean_w = float(weight[has].sum()) / max(int(np.count_nonzero(has)), 1)
    return STEP_FRACTION * h / max(mean_w, 1.0)


class ClumpWorkspace:
    """What survives between updates: buffers, the neighbour list of the last points, and what
    the last run saw (for benchmarks and the studio)."""

    def __init__(self) -> None:
        self.neighbours = NeighbourList()
        self.mean_neighbours = 0.0  # other-strand vertices within h per moving vertex, first iteration
        self.step = 0.0  # Δt²/m used in the last run
        self.builds = 0  # neighbour lists built so far (the rest of the runs reused or updated one)
        self.updates = 0  # lists brought up to date where vertices moved (neighbour_update)
        self.record = False  # keep a ClumpRecord of each run (the studio's updates in a region)
        self.recorded: ClumpRecord | None = None  # kept for its buffers even when not valid
        self._mask_for: object = None
        self._mask = np.zeros(0, bool)
        self._buffers: tuple = ()
        self._pairs = np.empty((0, 2))
        self._built: tuple | None = None  # (topology, list radius, points at the build)

    def invalidate(self) -> None:
        """Forget the neighbour list: the next run builds one (benchmarks time the build)."""
        self._built = None

    def roots_mask(self, topology) -> np.ndarray:
        """``(V,)`` bool, the root vertices of ``topology`` (kept between calls).

        Parameters
        ----------
        topology : Topology
            The strands.

        Returns
        -------
        ndarray
            ``(V,)`` bool.
        """
        if self._mask_for is not topology:
            self._mask = np.zeros(topology.vertex_count, bool)
            self._mask[topology.root_indices] = True
            self._mask_for = topology
        return self._mask

    def neighbour_list(self, groom: Groom, h: float) -> NeighbourList:
        """The list of the vertices of other strands within h·(1 + MARGIN) at these points: the
        last one as it is when no point moved, brought up to date where some did
        (:mod:`hairtool.frozen.neighbour_update`: a stroke's release), built again otherwise.
        (A Verlet skin that lets a list outlive small moves was measured and left out: in a drag
        the dragged strands move farther than a skin worth its cost on every move.)

        Parameters
        ----------
        groom : Groom
            The strands at their current points.
        h : float
            The clump radius.

        Returns
        -------
        NeighbourList
            The list.
        """
        top = groom.topology
        radius = h * (1.0 + MARGIN)
        b = self._built
        if b is not None and b[0] is top and b[1] == radius:
            moved = moved_vertices(groom.points, b[2])  # against a copy: any array may be passed in
            if moved.size == 0:
                return self.neighbours
            self._built = None
            if update_list(
                self.neighbours, groom.points, b[2], top.strand_index, self.roots_mask(top), moved
            ):
                b[2][moved] = groom.points[moved]
                self._built = b
                self.updates += 1
                return self.neighbours
        self._built = None
        self.neighbours.build(groom.points, top.strand_index, self.roots_mask(top), radius)
        self._built = (top, radius, groom.points.copy())
        self.builds += 1
        return self.neighbours

    def pair_buffers(self, nl: NeighbourList) -> tuple:
        """(bmap, rs): one r and weight per forward entry of the list (``rs`` (n, 2)), reused. On the row
        grid a pair's backward entry reads its forward one's (``bmap``); the hashed grid's lists
        are whole (each pair in both, no backward runs), so there each entry has its own.
        (Computing each pair from both ends, as sparse lists once did, was a second force kernel
        to compile for the same bytes: 2.9 of the 14.7 CPU seconds ``_clump_run`` compiled.)

        Parameters
        ----------
        nl : NeighbourList
            The list.

        Returns
        -------
        tuple
            ``(bmap, rs)``.
        """
        n = nl.aflat.size
        if self._pairs.shape[0] < n:
            self._pairs = np.empty((n, 2))
        return nl.bmap, self._pairs  # (the hashed grid's backward runs are empty: never read)

    def buffers(self, v: int) -> tuple:
        """Iterates, f, nearest neighbour, counts, Σg, hash heads and clump strengths for V
        vertices, reused.

        Parameters
        ----------
        v : int
            Vertices.

        Returns
        -------
        tuple
            The arrays, reused between runs.
        """
        b = self._buffers
        if not b or len(b[0]) != v:
            self._buffers = (
                np.empty((v, 3)),
                np.empty((v, 3)),
                np.empty((v, 3)),
                np.empty(v, np.int64),
                np.empty(v, np.int64),
                np.empty(v),
                np.empty(v, np.uint64),
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
    keep_lengths: bool = False,
    strength: ArrayLike | None = None,
) -> np.ndarray:
    """:func:`clump` returning float32 ``(V, 3)`` points instead of a groom.

    Parameters
    ----------
    groom, radius, iterations, step, gap_mode, seed, keep_lengths, strength
        As :func:`clump` takes them.
    workspace : ClumpWorkspace, optional
        Buffers and the last neighbour list, reused between runs.

    Returns
    -------
    ndarray
        ``(V, 3)`` float32.
    """
    check_clump_params(radius, iterations, step, gap_mode)
    seed = check_seed(seed)
    sv = vertex_strength(groom, strength)
    ws = workspace or ClumpWorkspace()
    h = float(radius)
    ws.step = 0.0
    ws.mean_neighbours = 0.0
    last = ws.recorded
    if last is not None:
        last.valid = False
    if iterations == 0 or groom.strand_count < 2:
        return groom.points.copy()
    nl = ws.neighbour_list(groom, h)
    v, k = groom.vertex_count, int(iterations)
    out = np.empty((v, 3), np.float32)
    lists = (nl.aflat, nl.aoff, nl.acnt, nl.bflat, nl.bstart, *ws.pair_buffers(nl))
    rec = None
    if ws.record and v * k <= RECORD_LIMIT:
        rec = last if last is not None and last.fits(v, k) else ClumpRecord(v, k)
    ws.mean_neighbours, ws.step = _clump_run(
        groom.points, sv, nl.order, lists, nl.skip, h, k, -1.0 if step is None else float(step),
        _GAP_CODE[gap_mode], seed_u64(seed), ws.buffers(v), out,
        _NO_RECORD if rec is None else (rec.iterates, rec.forces, rec.best, rec.count, rec.weight),
    )  # fmt: skip
    if rec is not None:
        rec.key = record_key(groom, h, k, step, gap_mode, seed)
        rec.points[:] = groom.points
        rec.strength[:] = sv
        rec.result[:] = out
        rec.step, rec.mean_neighbours = ws.step, ws.mean_neighbours
        rec.valid = True
        ws.recorded = rec
    if keep_lengths:  # after the record: it holds the iterations' result, as region updates redo it
        out = restore_lengths(groom.points, out, groom.topology)
        keep_still(groom.points, sv, out)
    return out


def record_key(
    groom: Groom, h: float, iterations: int, step: float | None, gap_mode: str, seed: int
) -> tuple:
    """What must be the same for a record to be updated rather than redone.

    Parameters
    ----------
    groom : Groom
        The strands.
    h : float
        The clump radius.
    iterations : int
        Passes.
    step : float or None
        Δt²/m.
    gap_mode : str
        The gap rule.
    seed : int
        The seed.

    Returns
    -------
    tuple
        The key.
    """
    return (groom.topology, float(h), int(iterations), step, gap_mode, int(seed))


def clump(
    groom: Groom,
    radius: float,
    iterations: int = 3,
    step: float | None = None,
    gap_mode: str = "printed",
    seed: int = 0,
    workspace: ClumpWorkspace | None = None,
    keep_lengths: bool = False,
    strength: ArrayLike | None = None,
) -> Groom:
    """ClumpWithGaps: vertices pulled toward nearby vertices of other strands; roots stay.

    ``radius`` h (groom units), ``iterations`` k ∈ [0, 100], ``step`` Δt²/m (None: :func:`auto_step`),
    ``gap_mode`` "printed" | "text" | "off", ``seed`` for ζ. Pass a ``workspace`` to reuse
    buffers across updates and read ``mean_neighbours`` afterwards. ``keep_lengths``: segments
    back to their lengths before clumping afterwards (off: as printed, for the paper's figures).
    ``strength``: ``(S,)`` clump strength of each strand in [0, 1] (None: all 1, as printed).

    Parameters
    ----------
    groom
        The groom to clump (in the pipeline, the aligned groom).
    radius
        h of eqs. 14–19, > 0, in groom units: vertices of other strands within it pull.
    iterations
        k of eq. 16, in [0, 100].
    step
        Δt²/m of eq. 16; None: a fraction of h over the mean kernel weight, so dense grooms do not
        overshoot.
    gap_mode
        ``"printed"`` (eqs. 17–19 as printed), ``"text"`` (the reading that follows the paper's
        words) or ``"off"``.
    seed
        The seed of ζ.
    workspace
        Buffers and neighbour lists kept across calls.
    keep_lengths
        Give every segment back its length after clumping.
    strength
        ``(S,)`` per-strand clump strength in [0, 1]; None: every strand 1.

    Returns
    -------
    Groom
        A new groom; roots unchanged.

    Raises
    ------
    ParameterError
        A parameter is out of range; the message names it.
    """
    pts = clump_points(groom, radius, iterations, step, gap_mode, seed, workspace, keep_lengths, strength)
    return groom.with_points(pts)


def gap_factors_reference(i, j, r, P, dp, h, seed, it, gap_mode) -> np.ndarray:
    """The gap-keeping factor λ per vertex (eqs. 17-18) of one iteration, from the pairs
    ``(i, j)`` at distances ``r`` and the adhesion steps ``dp``: each vertex's nearest pair
    (ties: the lowest index) before and after the step; 1 where gaps are off or no pair.

    Parameters
    ----------
    i, j : ndarray
        The pairs' vertices.
    r : ndarray
        Their distances.
    P : ndarray
        ``(V, 3)`` the iterate.
    dp : ndarray
        ``(V, 3)`` the adhesion steps.
    h : float
        The clump radius.
    seed : int
        The seed of ζ.
    it : int
        The iteration.
    gap_mode : str
        The gap rule.

    Returns
    -------
    ndarray
        ``(V,)`` float64 λ.
    """
    lam = np.ones(len(P))
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
    return lam


def clump_reference(
    groom: Groom,
    radius: float,
    iterations: int = 3,
    step: float | None = None,
    gap_mode: str = "printed",
    seed: int = 0,
    keep_lengths: bool = False,
    strength: ArrayLike | None = None,
) -> Groom:
    """Plain numpy twin of :func:`clump`: candidate pairs from the start, filtered each iteration.

    Parameters
    ----------
    groom, radius, iterations, step, gap_mode, seed, keep_lengths, strength
        As :func:`clump` takes them.

    Returns
    -------
    Groom
        What :func:`clump` gives.
    """
    check_clump_params(radius, iterations, step, gap_mode)
    seed = check_seed(seed)
    sv = vertex_strength(groom, strength)
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
        dp = sv[:, None] * (k_step * f)  # (16), scaled by the clump strength
        lam = gap_factors_reference(i, j, r, P, dp, h, seed, it, gap_mode)
        P = P + lam[:, None] * dp  # (19)
    if keep_lengths and iterations > 0:
        P = restore_lengths_reference(groom.points, P.astype(np.float32), top)
        P = keep_still_reference(groom.points, sv, P)
    return groom.with_points(P)
