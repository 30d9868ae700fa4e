"""Which side of a head mesh a point is on, decided where the closest point is.

The side of a point p whose closest mesh point is q is the sign of (p − q)·N, with N the
normal *of the feature q lies on*: the face's own normal inside a face, the sum of the two
faces' normals on an edge, and on a corner the faces' normals weighted by their angles there
(Bærentzen and Aanæs' angle-weighted pseudo-normals). For p near a concave fold or a sharp
ridge the closest point lies on an edge or a corner, and the smooth normal the brushes slide
on (the vertex normals blended across the face) can point the wrong way there: a point just
inside a fold then read as outside and was never pushed out. The faces' normals follow their
winding, turned round as a whole where most faces disagree with the vertex normals (a mesh wound
clockwise): a hard crease's vertex normals, one wall's, do not turn the other wall's faces.
"""

from __future__ import annotations

import numpy as np

from hairtool.io.obj import Mesh

ON_EDGE = 1e-6  # a barycentric coordinate below this puts the closest point on the opposite edge


class PseudoNormals:
    """The face, edge and corner normals of a mesh (float64, unit), for :meth:`side`."""

    def __init__(self, mesh: Mesh) -> None:
        """The normals of every face, edge and corner of ``mesh``.

        Parameters
        ----------
        mesh : Mesh
            The head.
        """
        v = mesh.vertices.astype(np.float64)
        f = mesh.faces.astype(np.int64)
        a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
        fn = np.cross(b - a, c - a)
        outward = mesh.normals.astype(np.float64)[f].sum(axis=1)
        if np.sum(np.einsum("ij,ij->i", fn, outward) < 0) * 2 > len(f):
            fn = -fn  # a mesh wound the other way round
        area = np.linalg.norm(fn, axis=1)
        flat = area < 1e-300  # a face without area: its corners' normals
        fn[flat] = outward[flat]
        self.face = _unit(fn)
        # corners: each face's normal times its angle at the corner, summed per vertex
        corner = np.zeros_like(v)
        for k in range(3):
            p, q, r = v[f[:, k]], v[f[:, (k + 1) % 3]], v[f[:, (k + 2) % 3]]
            e1, e2 = _unit(q - p), _unit(r - p)
            angle = np.arccos(np.clip(np.einsum("ij,ij->i", e1, e2), -1.0, 1.0))
            np.add.at(corner, f[:, k], angle[:, None] * self.face)
        self.corner = _unit(corner)
        # edges: slot k of a face is the edge from corner k to corner k + 1 (opposite k + 2)
        ends = np.stack([f, np.roll(f, -1, axis=1)], axis=2).reshape(-1, 2)
        _, which = np.unique(np.sort(ends, axis=1), axis=0, return_inverse=True)
        edge = np.zeros((int(which.max()) + 1, 3))
        np.add.at(edge, which, np.repeat(self.face, 3, axis=0))
        self.edge = _unit(edge[which]).reshape(-1, 3, 3)  # (F, slot, xyz)
        self.faces = f
        self.vertices = v

    def normals_at(self, q: np.ndarray, face: np.ndarray) -> np.ndarray:
        """``(P, 3)`` the pseudo-normal of the feature of ``face`` that ``q`` (on it) lies on.

        Parameters
        ----------
        q : ndarray
            ``(P, 3)`` points on the mesh.
        face : ndarray
            ``(P,)`` the face each lies on.

        Returns
        -------
        ndarray
            ``(P, 3)`` float64 unit normals.
        """
        f = self.faces[face]
        a, b, c = self.vertices[f[:, 0]], self.vertices[f[:, 1]], self.vertices[f[:, 2]]
        w = barycentric(q, a, b, c)  # (P, 3) weights of corners 0, 1, 2
        low = w < ON_EDGE
        n = self.face[face].copy()
        rows = np.arange(len(face))
        on_edge = low.sum(axis=1) == 1
        if on_edge.any():  # the edge opposite the low corner k is slot k + 1
            slot = (np.argmax(low[on_edge], axis=1) + 1) % 3
            n[on_edge] = self.edge[face[on_edge], slot]
        at_corner = low.sum(axis=1) >= 2
        if at_corner.any():
            k = np.argmax(w[at_corner], axis=1)
            n[at_corner] = self.corner[f[rows[at_corner], k]]
        return n


def barycentric(q: np.ndarray, a: np.ndarray, b: np.ndarray, c: np.ndarray) -> np.ndarray:
    """``(P, 3)`` weights of ``q`` on triangles ``abc`` (a third each where a triangle is degenerate).

    Parameters
    ----------
    q : ndarray
        ``(P, 3)`` points.
    a, b, c : ndarray
        ``(P, 3)`` the triangles' corners.

    Returns
    -------
    ndarray
        ``(P, 3)`` float64 weights.
    """
    e0, e1, e2 = b - a, c - a, q - a
    d00, d01, d11 = (e0 * e0).sum(1), (e0 * e1).sum(1), (e1 * e1).sum(1)
    d20, d21 = (e2 * e0).sum(1), (e2 * e1).sum(1)
    den = d00 * d11 - d01 * d01
    ok = np.abs(den) > 1e-300
    den = np.where(ok, den, 1.0)
    v = np.where(ok, (d11 * d20 - d01 * d21) / den, 1.0 / 3.0)
    w = np.where(ok, (d00 * d21 - d01 * d20) / den, 1.0 / 3.0)
    return np.column_stack([1.0 - v - w, v, w])


def _unit(x: np.ndarray) -> np.ndarray:
    n = np.linalg.norm(x, axis=1, keepdims=True)
    return x / np.maximum(n, 1e-300)
