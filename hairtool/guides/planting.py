"""New strands on a head, shaped like the strands around them: what the add brush plants.

:class:`HeadSurface` is a :class:`~hairtool.guides.surface.MeshSurface` that also plants: N roots
scattered uniformly over the disc of the brush's radius in the surface's tangent plane at the
surface point closest to the cursor, each moved to the surface; then each new strand is built as
a render-hair child of the groom's strands (:func:`~hairtool.guides.binding.bind_roots`: its k
nearest strands' shapes carried in their root frames, blended by inverse distance), with no
random length variation or frizz, so its length is the neighbours' (interpolated as the shape
is). The draws come from the seed and the cursor's bytes, so one sample always plants the same
strands and a replay the same bytes.

Under a perspective camera (a sample's ``eye``) the disc is centred instead where the line from
the eye through the cursor first meets the head (:meth:`HeadSurface.aimed`): the spot the artist
sees under the mouse, which the closest point misses where the head turns away from the eye
(the closest point to a cursor held at the stroke's depth slides off along the surface, and
toward the edge of a wide view the line of sight is far from the camera's axis).
"""

from __future__ import annotations

import numpy as np

from hairtool.errors import ParameterError
from hairtool.frozen.brushes.sight import hidden_points
from hairtool.frozen.root_grid import nearest_root
from hairtool.groom import Groom
from hairtool.guides.binding import DEFAULT_K, bind_roots
from hairtool.guides.nearest import euclidean_nearest
from hairtool.guides.surface import MeshSurface

MAX_PLANT = 1000  # strands one sample may plant


def _generator(seed: int, cursor) -> np.random.Generator:
    bits = np.asarray(cursor, np.float64).view(np.uint32)
    return np.random.default_rng([int(seed) & 0xFFFFFFFF, *(int(b) for b in bits), 0xADD])


def _basis(n: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    a = np.eye(3)[int(np.argmin(np.abs(n)))]
    u = np.cross(n, a)
    u /= np.linalg.norm(u)
    return u, np.cross(n, u)


class HeadSurface(MeshSurface):
    """A head mesh the brushes slide on, collide with and plant strands on."""

    def plant(
        self,
        groom: Groom,
        cursor,
        radius: float,
        count: int,
        seed: int,
        view=None,
        visible: bool = False,
        eye=None,
    ) -> Groom | None:
        """``count`` new strands around the surface point closest to ``cursor`` (module
        docstring), or None where the surface there faces away from a camera looking along
        ``view``. With ``visible``, front faces only by sight instead: the same roots are drawn
        and those the head hides from the camera are left out (None where it hides them all),
        whichever way the surface faces (:mod:`hairtool.frozen.brushes.sight`).

        Parameters
        ----------
        groom : Groom
            The strands the new ones are shaped like.
        cursor : array_like
            The brush's cursor.
        radius : float
            The brush radius.
        count : int
            New strands.
        seed : int
            The draws' seed (with the cursor's bytes).
        view : array_like, optional
            The camera's direction (None: no facing test).
        visible : bool, default False
            Judge the roots by sight (True) or the surface point under the cursor by its
            normal (False: every log written before the choice).
        eye : array_like, optional
            A perspective camera's eye: the disc's centre is on the line from it through the
            cursor (:meth:`aimed`), and by sight each root's ray goes to it. None: an
            orthographic camera (the closest point, rays against ``view``).

        Returns
        -------
        Groom or None
            The new strands.
        """
        if isinstance(count, bool) or int(count) != count or not 1 <= count <= MAX_PLANT:
            raise ParameterError("count", count, f"a whole number of strands in [1, {MAX_PLANT}]")
        q, n = self.aimed(cursor, eye)
        by_sight = view is not None and visible
        if view is not None and not by_sight and float(n[0] @ np.asarray(view, np.float64)) > 0:
            return None
        u, v = _basis(n[0])
        rng = _generator(seed, cursor)
        r = radius * np.sqrt(rng.random(int(count)))
        t = 2.0 * np.pi * rng.random(int(count))
        roots, _ = self.project(q[0] + r[:, None] * (np.cos(t)[:, None] * u + np.sin(t)[:, None] * v))
        if by_sight:
            roots = roots[~hidden_points(roots, view, self.face_grid, eye)]
            if len(roots) == 0:
                return None
        return self.grow(groom, roots)

    def aimed(self, cursor, eye=None) -> tuple[np.ndarray, np.ndarray]:
        """``(1, 3)`` the head's point a brush at ``cursor`` works around and ``(1, 3)`` its
        normal: where the line from a perspective camera's ``eye`` through the cursor first meets
        the head, or (no eye, or a line that misses the head) the point closest to the cursor."""
        c = np.asarray(cursor, np.float64).reshape(1, 3)
        if eye is not None:
            e = np.asarray(eye, np.float64).reshape(3)
            hit = self.ray_hit(e, c[0] - e)
            if hit is not None:
                c = hit.reshape(1, 3)
        return self.project(c)

    def grow(self, groom: Groom, roots: np.ndarray) -> Groom:
        """New strands at ``roots`` shaped like the groom's strands around them (render-hair
        children of them with no random length variation or frizz), in the order of ``roots``.

        Parameters
        ----------
        groom : Groom
            The strands the new ones are shaped like.
        roots : ndarray
            ``(N, 3)`` their roots.

        Returns
        -------
        Groom
            The new strands.
        """
        roots = np.asarray(roots, np.float64)
        k = min(DEFAULT_K, groom.strand_count)
        # Only the strands some new root blends (or weighs against) are tabulated: building
        # from the whole groom cost every strand's frames at each sample. Their order is kept,
        # so each root finds the same nearest strands, ties and weights, and the same points.
        near = euclidean_nearest(groom.roots, roots, k)[0]
        used = np.unique(near[near >= 0])
        guides = groom if len(used) == groom.strand_count else groom.subset(used)
        n = int(groom.counts.max())
        binding = bind_roots(guides, roots, k=k, vertices=n, length_variation=0.0, frizz=0.0)
        built = binding.build(guides)
        # the binding orders children by their nearest strand: back to the order asked for
        order = np.argsort(nearest_root(roots, binding.roots))
        return built.subset(order)
