"""Distances on a scalp mesh: how far a child's root is from each guide's root *along the
surface*, so a child behind the ear is not bound to a guide in front of it.

The surface distance is the shortest path along the mesh's edges (Dijkstra), entering and
leaving the mesh through the corners of the face a root lies on; on one face it is the straight
line. For each mesh vertex :func:`nearest_sources` keeps the K nearest guide roots (a Dijkstra
whose heap carries (distance, guide, vertex) and where a vertex takes at most K guides: a guide
among the K nearest of a vertex is among the K nearest of every vertex on the shortest path to
it, so the labels are exact). Guide roots that do not lie on the mesh are first moved to its
closest point (:func:`closest_points`).
"""

from __future__ import annotations

import heapq

import numpy as np
from numba import njit, prange

from hairtool.errors import ParameterError
from hairtool.frozen.brushes.first_hit import face_ts_reference, first_hit
from hairtool.frozen.brushes.sight import FaceGrid
from hairtool.guides.inside import barycentric
from hairtool.io.obj import Mesh
from hairtool.serial_twins import twin_njit


@njit(cache=True, nogil=True)
def _closest_on_triangle(px, py, pz, ax, ay, az, bx, by, bz, cx, cy, cz):
    """Closest point of triangle abc to p (Ericson, Real-Time Collision Detection, 5.1.5)."""
    abx, aby, abz = bx - ax, by - ay, bz - az
    acx, acy, acz = cx - ax, cy - ay, cz - az
    apx, apy, apz = px - ax, py - ay, pz - az
    d1 = abx * apx + aby * apy + abz * apz
    d2 = acx * apx + acy * apy + acz * apz
    if d1 <= 0.0 and d2 <= 0.0:
        return ax, ay, az
    bpx, bpy, bpz = px - bx, py - by, pz - bz
    d3 = abx * bpx + aby * bpy + abz * bpz
    d4 = acx * bpx + acy * bpy + acz * bpz
    if d3 >= 0.0 and d4 <= d3:
        return bx, by, bz
    vc = d1 * d4 - d3 * d2
    if vc <= 0.0 and d1 >= 0.0 and d3 <= 0.0:
        v = d1 / (d1 - d3)
        return ax + v * abx, ay + v * aby, az + v * abz
    cpx, cpy, cpz = px - cx, py - cy, pz - cz
    d5 = abx * cpx + aby * cpy + abz * cpz
    d6 = acx * cpx + acy * cpy + acz * cpz
    if d6 >= 0.0 and d5 <= d6:
        return cx, cy, cz
    vb = d5 * d2 - d1 * d6
    if vb <= 0.0 and d2 >= 0.0 and d6 <= 0.0:
        w = d2 / (d2 - d6)
        return ax + w * acx, ay + w * acy, az + w * acz
    va = d3 * d6 - d5 * d4
    if va <= 0.0 and (d4 - d3) >= 0.0 and (d5 - d6) >= 0.0:
        w = (d4 - d3) / ((d4 - d3) + (d5 - d6))
        return bx + w * (cx - bx), by + w * (cy - by), bz + w * (cz - bz)
    denom = 1.0 / (va + vb + vc)
    v = vb * denom
    w = vc * denom
    return ax + abx * v + acx * w, ay + aby * v + acy * w, az + abz * v + acz * w


@twin_njit(nogil=True, parallel=True)
def _closest_kernel(points, vertices, faces, out, face_of):
    for k in prange(points.shape[0]):
        px, py, pz = points[k, 0], points[k, 1], points[k, 2]
        best = np.inf
        for f in range(faces.shape[0]):
            a, b, c = faces[f, 0], faces[f, 1], faces[f, 2]
            qx, qy, qz = _closest_on_triangle(
                px, py, pz, vertices[a, 0], vertices[a, 1], vertices[a, 2], vertices[b, 0], vertices[b, 1],
                vertices[b, 2], vertices[c, 0], vertices[c, 1], vertices[c, 2],
            )  # fmt: skip
            d = (qx - px) ** 2 + (qy - py) ** 2 + (qz - pz) ** 2
            if d < best:  # ties: the lower face
                best = d
                out[k, 0], out[k, 1], out[k, 2] = qx, qy, qz
                face_of[k] = f


def usable_faces(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Indices of the faces with an area: a degenerate face (``f 1 1 4``, common in real heads,
    or three points on a line) has none, and the closest-point kernels would divide by its zero
    edge or area. Skipping it loses nothing: its points lie on its neighbours' edges.

    Parameters
    ----------
    vertices : ndarray
        ``(Vm, 3)`` the mesh's vertices.
    faces : ndarray
        ``(F, 3)`` its triangles.

    Returns
    -------
    ndarray
        int64 face indices.
    """
    v = np.asarray(vertices, np.float64)
    f = np.asarray(faces, np.int64)
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    area2 = np.einsum("ij,ij->i", *(2 * [np.cross(b - a, c - a)]))
    return np.flatnonzero(area2 > 0)


def finite_points(points: np.ndarray, what: str = "points") -> np.ndarray:
    """``points`` as a float64 ``(P, 3)`` array, or a :class:`ParameterError` where one is not
    finite (no kernel is asked where NaN is closest).

    Parameters
    ----------
    points : ndarray
        Points, reshaped to ``(P, 3)``.
    what : str, default "points"
        Their name in a refusal.

    Returns
    -------
    ndarray
        ``(P, 3)`` float64.
    """
    pts = np.ascontiguousarray(points, np.float64).reshape(-1, 3)
    if not np.all(np.isfinite(pts)):
        raise ParameterError(what, "a non-finite point", "finite coordinates")
    return pts


def closest_points(mesh: Mesh, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(P, 3)`` float64 closest points on the mesh and ``(P,)`` the face of each (every face
    with an area tried: meant for guide roots, a few thousand at most).

    Parameters
    ----------
    mesh : Mesh
        The head.
    points : ndarray
        ``(P, 3)`` finite points.

    Returns
    -------
    tuple of (ndarray, ndarray)
        The closest points and their faces.
    """
    pts = finite_points(points)
    out = np.empty_like(pts)
    face_of = np.empty(len(pts), np.int64)
    keep = usable_faces(mesh.vertices, mesh.faces)
    if keep.size == 0:
        raise ParameterError("mesh", "a mesh whose every face is degenerate", "a triangle with an area")
    faces = mesh.faces.astype(np.int64)[keep]
    _closest_kernel(pts, mesh.vertices.astype(np.float64), faces, out, face_of)
    return out, keep[face_of]


def edge_graph(mesh: Mesh) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The mesh's edges as CSR ``(indptr, neighbours, lengths)`` (float64 lengths, both ways,
    each vertex's neighbours in increasing order).

    Parameters
    ----------
    mesh : Mesh
        The head.

    Returns
    -------
    tuple of (ndarray, ndarray, ndarray)
        ``indptr``, ``neighbours`` and ``lengths``.
    """
    f = mesh.faces.astype(np.int64)
    e = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
    e = np.concatenate([e, e[:, ::-1]])
    e = np.unique(e[e[:, 0] != e[:, 1]], axis=0)  # sorted by (from, to)
    v = mesh.vertices.astype(np.float64)
    lengths = np.linalg.norm(v[e[:, 1]] - v[e[:, 0]], axis=1)
    indptr = np.zeros(len(v) + 1, np.int64)
    np.cumsum(np.bincount(e[:, 0], minlength=len(v)), out=indptr[1:])
    return indptr, e[:, 1].copy(), lengths


def _seeds(mesh: Mesh, roots: np.ndarray, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(vertex, guide, distance) where each guide's root enters the graph: its face's corners."""
    corners = mesh.faces[faces].astype(np.int64)  # (G, 3)
    d = np.linalg.norm(mesh.vertices.astype(np.float64)[corners] - roots[:, None, :], axis=2)
    g = np.repeat(np.arange(len(roots)), 3)
    return corners.reshape(-1), g, d.reshape(-1)


@njit(cache=True, nogil=True)
def _k_nearest_kernel(indptr, nbr, length, seed_v, seed_g, seed_d, k, label_g, label_d, count):
    heap = [(seed_d[0], seed_g[0], seed_v[0])]
    for s in range(1, seed_v.size):
        heapq.heappush(heap, (seed_d[s], seed_g[s], seed_v[s]))
    while len(heap) > 0:
        d, g, v = heapq.heappop(heap)
        c = count[v]
        if c >= k:
            continue
        seen = False
        for m in range(c):
            if label_g[v, m] == g:
                seen = True
                break
        if seen:
            continue
        label_g[v, c] = g
        label_d[v, c] = d
        count[v] = c + 1
        for e in range(indptr[v], indptr[v + 1]):
            u = nbr[e]
            if count[u] < k:
                heapq.heappush(heap, (d + length[e], g, u))


def nearest_sources(
    mesh: Mesh, roots: np.ndarray, faces: np.ndarray, k: int
) -> tuple[np.ndarray, np.ndarray]:
    """For every mesh vertex its k nearest guides along the surface (ties: the lower guide):
    ``(Vm, k)`` int64 guides (−1 where fewer are reachable) and float64 distances (inf there).

    Parameters
    ----------
    mesh : Mesh
        The head.
    roots : ndarray
        ``(G, 3)`` guide roots.
    faces : ndarray
        ``(G,)`` the face each root lies on.
    k : int
        Guides per vertex.

    Returns
    -------
    tuple of (ndarray, ndarray)
        ``(Vm, k)`` guides and distances.
    """
    indptr, nbr, length = edge_graph(mesh)
    sv, sg, sd = _seeds(mesh, roots, faces)
    nv = len(mesh.vertices)
    label_g = np.full((nv, k), -1, np.int64)
    label_d = np.full((nv, k), np.inf)
    _k_nearest_kernel(indptr, nbr, length, sv, sg, sd, k, label_g, label_d, np.zeros(nv, np.int64))
    return label_g, label_d


def nearest_sources_reference(
    mesh: Mesh, roots: np.ndarray, faces: np.ndarray, k: int
) -> tuple[np.ndarray, np.ndarray]:
    """Numpy twin of :func:`nearest_sources`: one full Dijkstra per guide, then the k smallest
    (distance, guide) per vertex.

    Parameters
    ----------
    mesh, roots, faces, k
        As :func:`nearest_sources` takes them.

    Returns
    -------
    tuple of (ndarray, ndarray)
        As :func:`nearest_sources` gives them.
    """
    indptr, nbr, length = edge_graph(mesh)
    sv, sg, sd = _seeds(mesh, roots, faces)
    nv, ng = len(mesh.vertices), len(roots)
    dist = np.full((ng, nv), np.inf)
    for g in range(ng):
        heap = [(float(d), int(v)) for v, gg, d in zip(sv, sg, sd, strict=True) if gg == g]
        heapq.heapify(heap)
        while heap:
            d, v = heapq.heappop(heap)
            if d >= dist[g, v]:
                continue
            dist[g, v] = d
            for e in range(indptr[v], indptr[v + 1]):
                if d + length[e] < dist[g, nbr[e]]:
                    heapq.heappush(heap, (d + length[e], int(nbr[e])))
    order = np.lexsort((np.broadcast_to(np.arange(ng)[:, None], dist.shape), dist), axis=0)[:k].T  # (nv, k)
    d = np.take_along_axis(dist.T, order, axis=1)
    return np.where(np.isfinite(d), order, -1), d


@twin_njit(nogil=True, parallel=True)
def _child_kernel(points, cface, faces, vertices, label_g, label_d, groots, gface, k, out_g, out_d):
    """Per child: the k+1 nearest guides along the surface through its face's corners (the
    straight line for a guide on the same face), sorted by (distance, guide)."""
    kk = out_g.shape[1]
    lab = label_g.shape[1]
    for c in prange(points.shape[0]):
        px, py, pz = points[c, 0], points[c, 1], points[c, 2]
        for m in range(kk):
            out_g[c, m] = -1
            out_d[c, m] = np.inf
        f = cface[c]
        for corner in range(3):
            v = faces[f, corner]
            dv = np.sqrt((vertices[v, 0] - px) ** 2 + (vertices[v, 1] - py) ** 2 + (vertices[v, 2] - pz) ** 2)
            for m in range(lab):
                g = label_g[v, m]
                if g < 0:
                    break
                d = label_d[v, m] + dv
                if gface[g] == f:
                    d = np.sqrt(
                        (groots[g, 0] - px) ** 2 + (groots[g, 1] - py) ** 2 + (groots[g, 2] - pz) ** 2
                    )
                insert_nearest(out_g, out_d, c, g, d, kk)


@njit(cache=True, nogil=True)
def insert_nearest(out_g, out_d, c, g, d, kk):
    """Put (d, g) into row c's sorted list of the kk best (a guide already there keeps the
    smaller distance).

    Parameters
    ----------
    out_g, out_d : ndarray
        ``(R, kk)`` the rows' guides and distances, sorted.
    c : int
        The row.
    g : int
        The guide.
    d : float
        Its distance.
    kk : int
        The list's length.
    """
    for m in range(kk):
        if out_g[c, m] == g:
            if d >= out_d[c, m]:
                return
            for q in range(m, kk - 1):  # take it out, then insert again below
                out_g[c, q] = out_g[c, q + 1]
                out_d[c, q] = out_d[c, q + 1]
            out_g[c, kk - 1] = -1
            out_d[c, kk - 1] = np.inf
            break
    pos = kk
    for m in range(kk):
        if d < out_d[c, m] or (d == out_d[c, m] and (out_g[c, m] < 0 or g < out_g[c, m])):
            pos = m
            break
    if pos == kk:
        return
    for q in range(kk - 1, pos, -1):
        out_g[c, q] = out_g[c, q - 1]
        out_d[c, q] = out_d[c, q - 1]
    out_g[c, pos] = g
    out_d[c, pos] = d


def surface_nearest(
    mesh: Mesh,
    guide_roots: np.ndarray,
    child_roots: np.ndarray,
    child_faces: np.ndarray,
    k: int,
) -> tuple[np.ndarray, np.ndarray]:
    """``(N, k+1)`` the nearest guides of each child root (on face ``child_faces``) along the
    surface, and their distances, sorted; −1 / inf where fewer are reachable.

    Parameters
    ----------
    mesh : Mesh
        The head.
    guide_roots : ndarray
        ``(G, 3)``.
    child_roots : ndarray
        ``(N, 3)``.
    child_faces : ndarray
        ``(N,)`` the face each child root lies on.
    k : int
        Guides per child.

    Returns
    -------
    tuple of (ndarray, ndarray)
        ``(N, k+1)`` guides and distances.
    """
    on_mesh, gface = closest_points(mesh, guide_roots)
    label_g, label_d = nearest_sources(mesh, on_mesh, gface, k + 1)
    n = len(child_roots)
    out_g = np.empty((n, k + 1), np.int64)
    out_d = np.empty((n, k + 1))
    _child_kernel(
        np.ascontiguousarray(child_roots, np.float64), child_faces.astype(np.int64),
        mesh.faces.astype(np.int64), mesh.vertices.astype(np.float64), label_g, label_d, on_mesh, gface,
        k + 1, out_g, out_d,
    )  # fmt: skip
    return out_g, out_d


def nearest_guide_distance(mesh: Mesh, guide_roots: np.ndarray) -> np.ndarray:
    """``(Vm,)`` each mesh vertex's distance along the surface to the nearest guide root.

    Parameters
    ----------
    mesh : Mesh
        The head.
    guide_roots : ndarray
        ``(G, 3)``.

    Returns
    -------
    ndarray
        ``(Vm,)`` float64.
    """
    on_mesh, gface = closest_points(mesh, guide_roots)
    _, d = nearest_sources(mesh, on_mesh, gface, 1)
    return d[:, 0]


GRID_CELLS = 48  # cells along the mesh's longest side in MeshSurface's grid of faces


@njit(cache=True, nogil=True)
def _bin_faces(vertices, faces, lo, cell, dims, start, items):  # pragma: no cover - compiled
    """Faces into the grid cells their bounding boxes overlap: CSR ``start`` (cells + 1) and
    ``items`` (None: counting pass, ``start`` gets the counts)."""
    fill = start.copy()
    for f in range(faces.shape[0]):
        c0 = np.empty(3, np.int64)
        c1 = np.empty(3, np.int64)
        for a in range(3):
            x0 = min(vertices[faces[f, 0], a], vertices[faces[f, 1], a], vertices[faces[f, 2], a])
            x1 = max(vertices[faces[f, 0], a], vertices[faces[f, 1], a], vertices[faces[f, 2], a])
            c0[a] = min(max(int(np.floor((x0 - lo[a]) / cell)), 0), dims[a] - 1)
            c1[a] = min(max(int(np.floor((x1 - lo[a]) / cell)), 0), dims[a] - 1)
        for i in range(c0[0], c1[0] + 1):
            for j in range(c0[1], c1[1] + 1):
                for k in range(c0[2], c1[2] + 1):
                    c = (i * dims[1] + j) * dims[2] + k
                    if items.size == 0:
                        start[c + 1] += 1
                    else:
                        items[fill[c]] = f
                        fill[c] += 1


@njit(cache=True, nogil=True)
def _empty_rings_kernel(start, dims, rings):  # pragma: no cover - compiled
    """``rings[c]``: the Chebyshev distance in cells from cell ``c`` to the nearest cell holding a
    face (0 for such a cell), by sweeping the 26-neighbour minimum until nothing changes."""
    big = dims[0] + dims[1] + dims[2]
    for c in range(rings.size):
        rings[c] = 0 if start[c + 1] > start[c] else big
    n, forward, changed = rings.size, True, True
    while changed:  # sweeps forward then backward (a chamfer): a few passes, not one per cell
        changed = False
        for t in range(n):
            c = t if forward else n - 1 - t
            i, rest = c // (dims[1] * dims[2]), c % (dims[1] * dims[2])
            j, k = rest // dims[2], rest % dims[2]
            best = rings[c]
            for di in range(max(i - 1, 0), min(i + 1, dims[0] - 1) + 1):
                for dj in range(max(j - 1, 0), min(j + 1, dims[1] - 1) + 1):
                    for dk in range(max(k - 1, 0), min(k + 1, dims[2] - 1) + 1):
                        best = min(best, rings[(di * dims[1] + dj) * dims[2] + dk] + 1)
            if best < rings[c]:
                rings[c] = best
                changed = True
        forward = not forward


def empty_rings_numpy(start: np.ndarray, dims: np.ndarray) -> np.ndarray:
    """:func:`_empty_rings_kernel`'s twin: grow the non-empty cells one 3×3×3 dilation at a time.

    Parameters
    ----------
    start : ndarray
        ``(C + 1,)`` the grid's cell starts (a cell is empty where the next start is its own).
    dims : ndarray
        ``(3,)`` the grid's cells per axis.

    Returns
    -------
    ndarray
        ``(C,)`` int64 rings from each cell to a non-empty one (−1 where none is reached).
    """
    shape = tuple(int(d) for d in dims)
    full = (np.diff(start) > 0).reshape(shape)
    rings = np.where(full, 0, -1)
    reached, r = full.copy(), 0
    while not reached.all() and reached.any():
        r += 1
        pad = np.pad(reached, 1)
        grown = np.zeros_like(reached)
        for di in (0, 1, 2):
            for dj in (0, 1, 2):
                for dk in (0, 1, 2):
                    grown |= pad[di : di + shape[0], dj : dj + shape[1], dk : dk + shape[2]]
        rings[grown & ~reached] = r
        reached = grown
    return rings.reshape(-1).astype(np.int64)


@njit(cache=True, nogil=True)
def _closest_one(  # pragma: no cover - compiled
    k, points, vertices, faces, lo, cell, dims, start, items, rings, out, face_of
):
    """:func:`closest_points` (same ties: the lower face, whatever the order faces are met in)
    for points inside the grid's box, visiting shells of cells outward, from the first shell
    that can hold a face (``rings``), until no unvisited cell can hold a closer one; face −1 for
    points outside the box. Only a shell's cells are visited: a point far from the mesh costs
    the shells' surfaces, not their volumes."""
    px, py, pz = points[k, 0], points[k, 1], points[k, 2]
    ci = np.empty(3, np.int64)
    inside = True
    for a in range(3):
        f = (points[k, a] - lo[a]) / cell
        if not (0.0 <= f < dims[a]):
            inside = False
        else:
            ci[a] = int(f)
    face_of[k] = -1
    if not inside:
        return
    best, bf = np.inf, -1
    r = rings[(ci[0] * dims[1] + ci[1]) * dims[2] + ci[2]]  # the shells inside hold no face
    while True:
        for i in range(max(ci[0] - r, 0), min(ci[0] + r, dims[0] - 1) + 1):
            for j in range(max(ci[1] - r, 0), min(ci[1] + r, dims[1] - 1) + 1):
                row = (i * dims[1] + j) * dims[2]
                # a side of the shell: all of its column; inside its cross-section: the two ends
                step = 1 if (abs(i - ci[0]) == r or abs(j - ci[1]) == r) else max(2 * r, 1)
                for kk in range(ci[2] - r, ci[2] + r + 1, step):
                    if kk < 0 or kk >= dims[2]:
                        continue
                    c = row + kk
                    for t in range(start[c], start[c + 1]):
                        f = items[t]
                        a, b, e = faces[f, 0], faces[f, 1], faces[f, 2]
                        va, vb, ve = vertices[a], vertices[b], vertices[e]
                        qx, qy, qz = _closest_on_triangle(
                            px, py, pz, va[0], va[1], va[2], vb[0], vb[1], vb[2], ve[0], ve[1], ve[2]
                        )
                        d = (qx - px) ** 2 + (qy - py) ** 2 + (qz - pz) ** 2
                        if d < best or (d == best and f < bf):
                            best, bf = d, f
                            out[k, 0], out[k, 1], out[k, 2] = qx, qy, qz
        # the nearest an unvisited cell can be: across the visited block's unclipped sides
        reach = np.inf
        for a in range(3):
            if ci[a] - r > 0:
                reach = min(reach, points[k, a] - (lo[a] + (ci[a] - r) * cell))
            if ci[a] + r < dims[a] - 1:
                reach = min(reach, lo[a] + (ci[a] + r + 1) * cell - points[k, a])
        if reach == np.inf or (bf >= 0 and best <= reach * reach):
            break
        r += 1
    face_of[k] = bf


@twin_njit(nogil=True, parallel=True)
def _grid_closest_kernel(  # pragma: no cover - compiled
    points, vertices, faces, lo, cell, dims, start, items, rings, out, face_of
):
    """:func:`_closest_one` for every point, on every thread (a whole groom's ask)."""
    for k in prange(points.shape[0]):
        _closest_one(k, points, vertices, faces, lo, cell, dims, start, items, rings, out, face_of)


@njit(cache=True, nogil=True)
def _grid_closest_serial(  # pragma: no cover - compiled
    points, vertices, faces, lo, cell, dims, start, items, rings, out, face_of
):
    """:func:`_closest_one` for every point on the calling thread: the collision pass asks a few
    dozen points at a time, vertex by vertex along the strands, where waking the other threads
    costs more than the ask (ten times more on a busy machine)."""
    for k in range(points.shape[0]):
        _closest_one(k, points, vertices, faces, lo, cell, dims, start, items, rings, out, face_of)


SERIAL_POINTS = 512  # asks of fewer points than this run on the calling thread


class MeshSurface:
    """A head mesh as the surface the frozen brushes slide roots on
    (:class:`hairtool.frozen.brushes.slide.Surface`): the closest point of the mesh and the smooth normal
    there (the vertex normals interpolated barycentrically, the face's own normal where they
    cancel)."""

    def __init__(self, mesh: Mesh) -> None:
        """A grid over the mesh's usable faces, for closest points and signed distances.

        Parameters
        ----------
        mesh : Mesh
            The head, with at least one face (ParameterError otherwise).
        """
        if len(mesh.faces) == 0:
            raise ParameterError("scalp", "a mesh without faces", "a mesh with at least one triangle")
        if not np.all(np.isfinite(mesh.vertices)):
            raise ParameterError("scalp", "a mesh with non-finite vertices", "finite vertex coordinates")
        self.mesh = mesh
        self._pseudo = None  # the inside test's normals, made when first asked
        self._face_grid: FaceGrid | None = None
        self._corners: tuple | None = None  # the faces' corners for ray_hit_reference, made when first asked
        self._v = mesh.vertices.astype(np.float64)
        self._n = mesh.normals.astype(np.float64)
        self._f = mesh.faces.astype(np.int64)
        self._keep = usable_faces(self._v, self._f)  # the kernels see these; ids map back
        if self._keep.size == 0:
            raise ParameterError("scalp", "a mesh whose every face is degenerate", "a triangle with an area")
        self._kf = np.ascontiguousarray(self._f[self._keep])
        lo, hi = self._v.min(axis=0), self._v.max(axis=0)
        self.cell = max(float((hi - lo).max()) / GRID_CELLS, 1e-12)
        self.lo = lo - self.cell  # one cell of margin around the mesh
        self.dims = (np.floor((hi - self.lo) / self.cell).astype(np.int64) + 2).clip(1, None)
        self._start = np.zeros(int(np.prod(self.dims)) + 1, np.int64)
        _bin_faces(self._v, self._kf, self.lo, self.cell, self.dims, self._start, np.zeros(0, np.int64))
        np.cumsum(self._start, out=self._start)
        self._items = np.empty(int(self._start[-1]), np.int64)
        _bin_faces(self._v, self._kf, self.lo, self.cell, self.dims, self._start, self._items)
        self._rings = np.empty(int(np.prod(self.dims)), np.int64)
        _empty_rings_kernel(self._start, self.dims, self._rings)

    @property
    def face_grid(self) -> FaceGrid:
        """The usable faces in this surface's grid, as the brushes' sight test walks them
        (:mod:`hairtool.frozen.brushes.sight`)."""
        if self._face_grid is None:
            self._face_grid = FaceGrid(
                self._v, self._kf, self.lo, self.cell, self.dims, self._start, self._items
            )
        return self._face_grid

    def nearest(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """:func:`closest_points` through the grid of faces (the same bytes): ``(P, 3)`` points
        and ``(P,)`` faces, face −1 (and NaN points) for points outside the mesh's box (plus a
        cell), which lie outside the head.

        Parameters
        ----------
        points : ndarray
            ``(P, 3)`` finite points.

        Returns
        -------
        tuple of (ndarray, ndarray)
            Closest points and faces.
        """
        pts = finite_points(points)
        out = np.full_like(pts, np.nan)
        face_of = np.full(len(pts), -1, np.int64)
        kernel = _grid_closest_serial if len(pts) < SERIAL_POINTS else _grid_closest_kernel
        kernel(
            pts, self._v, self._kf, self.lo, self.cell, self.dims, self._start, self._items, self._rings,
            out, face_of,
        )
        return out, np.where(face_of >= 0, self._keep[face_of], -1)

    def project(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(P, 3)`` float64 closest points on the mesh and ``(P, 3)`` unit normals there.

        Parameters
        ----------
        points : ndarray
            ``(P, 3)`` finite points.

        Returns
        -------
        tuple of (ndarray, ndarray)
            Closest points and normals.
        """
        q, face = self.nearest(points)
        far = face < 0
        if far.any():
            q[far], face[far] = closest_points(self.mesh, np.asarray(points, np.float64)[far])
        return q, self._normals(q, face)

    def signed_distance(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(P,)`` signed distance to the head (< 0 inside: behind the pseudo-normal of the
        face, edge or corner the closest point lies on, :mod:`hairtool.guides.inside`), the
        closest points and those normals, the way out; points outside the mesh's box get +inf
        (and NaN points and normals).

        Parameters
        ----------
        points : ndarray
            ``(P, 3)`` finite points.

        Returns
        -------
        tuple of (ndarray, ndarray, ndarray)
            Signed distances, closest points and normals.
        """
        if self._pseudo is None:
            from hairtool.guides.inside import PseudoNormals

            self._pseudo = PseudoNormals(self.mesh)
        pts = np.asarray(points, np.float64)
        q, face = self.nearest(pts)
        n = np.full_like(q, np.nan)
        near = face >= 0
        n[near] = self._pseudo.normals_at(q[near], face[near])
        sd = np.full(len(pts), np.inf)
        d = pts[near] - q[near]
        side = np.einsum("ij,ij->i", d, n[near])
        sd[near] = np.copysign(np.sqrt(np.einsum("ij,ij->i", d, d)), side) * (side != 0)
        return sd, q, n

    def ray_hit(self, origin, direction) -> np.ndarray | None:
        """The first point where the ray from ``origin`` along ``direction`` meets the mesh, or
        None: what a brush on the head touches under the mouse. The ray walks the grid of faces
        (:func:`~hairtool.frozen.brushes.first_hit.first_hit`, watertight: a ray through an edge
        or a corner meets the faces there), trying only the faces of the cells it crosses up to
        the first face met.

        Parameters
        ----------
        origin : array_like
            ``(3,)`` the ray's start.
        direction : array_like
            ``(3,)`` its direction (not zero).

        Returns
        -------
        ndarray or None
            ``(3,)`` float64 ``origin + t · direction`` at the nearest ``t > 0``, or None for a
            miss.
        """
        t, _ = first_hit(self.face_grid, origin, direction)
        return self._ray_point(origin, direction, t)

    def ray_hit_reference(self, origin, direction) -> np.ndarray | None:
        """Numpy twin of :meth:`ray_hit`: every face tried, each face's corners gathered once
        per surface."""
        if self._corners is None:
            self._corners = tuple(np.ascontiguousarray(self._v[self._kf[:, j]]) for j in range(3))
        ts = face_ts_reference(self._corners, origin, direction)
        return self._ray_point(origin, direction, float(ts.min()))

    @staticmethod
    def _ray_point(origin, direction, t: float) -> np.ndarray | None:
        if not np.isfinite(t):
            return None
        return np.asarray(origin, np.float64).reshape(3) + t * np.asarray(direction, np.float64).reshape(3)

    def _normals(self, q: np.ndarray, face: np.ndarray) -> np.ndarray:
        tri = self._f[face]
        a, b, c = self._v[tri[:, 0]], self._v[tri[:, 1]], self._v[tri[:, 2]]
        e0, e1 = b - a, c - a
        u, v, w = barycentric(q, a, b, c).T
        nv = self._n
        n = u[:, None] * nv[tri[:, 0]] + v[:, None] * nv[tri[:, 1]] + w[:, None] * nv[tri[:, 2]]
        length = np.linalg.norm(n, axis=1)
        flat = length < 1e-9
        if flat.any():  # opposite vertex normals (a fold): the face's own
            n[flat] = np.cross(e0[flat], e1[flat])
            length[flat] = np.linalg.norm(n[flat], axis=1)
        return n / np.maximum(length, 1e-300)[:, None]
