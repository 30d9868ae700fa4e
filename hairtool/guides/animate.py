"""Render-hair animations: the children of a binding at every frame of an animation of its
guides (a simulation, an anime cycle, recorded drags).

Simulations, cycles and recordings run on the guides; a frame of render hair is the binding
built on that frame's guides (:func:`hairtool.guides.children.build_points`, one thread per
child, so the bytes do not depend on the thread count), the children's roots carried by their
guides' roots (:mod:`hairtool.guides.root_motion`), then ClumpWithGaps among the children
when switched on (:class:`~hairtool.guides.render.RenderHair`). Frames are made one at a time
and never all held: 100,000 children × 16 vertices are 19 MB a frame and 1.9 GB over 100
frames, so a writer takes them frame by frame (:func:`hairtool.io.usd.write` writes a time
sample per frame); :meth:`RenderHairAnimation.animation` stacks them all for the formats that
need the whole array. :func:`render_frames_reference` is the numpy twin.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator

import numpy as np

from hairtool.errors import ParameterError
from hairtool.groom import Animation, Groom, StrandSizes, Topology
from hairtool.guides.binding import ChildBinding
from hairtool.guides.children import build_points, build_points_reference
from hairtool.guides.render import ChildClump, RenderHair
from hairtool.guides.root_motion import following
from hairtool.metadata import Metadata


def _check(binding: ChildBinding, guides: Animation) -> None:
    if not isinstance(guides, Animation):
        raise ParameterError("guides", type(guides).__name__, "an Animation of the guides")
    if guides.topology != binding.rest_guides.topology:
        raise ParameterError(
            "guides",
            f"an animation of {guides.strand_count} strands of {guides.vertex_count} vertices",
            f"the {binding.rest_guides.strand_count} guides the children were bound to, same vertex counts",
        )


class RenderHairAnimation(StrandSizes):
    """The render strands of ``binding`` at every frame of ``guides`` (an Animation of the
    guides), made on demand; ``clump``: ClumpWithGaps among the children on every frame."""

    def __init__(self, binding: ChildBinding, guides: Animation, clump: ChildClump | None = None) -> None:
        """Render hair following ``guides``, frame by frame.

        Parameters
        ----------
        binding : ChildBinding
            The children bound to the guides at rest.
        guides : Animation
            The guides' frames, the same strands.
        clump : ChildClump, optional
            The children's own clumping.
        """
        _check(binding, guides)
        self.binding, self.guides = binding, guides
        self.render = RenderHair(binding, clump, follow_roots=True)

    # -- what an Animation says about itself (writers read these) ---------------------------
    @property
    def topology(self) -> Topology:
        return self.binding.topology

    @property
    def n_frames(self) -> int:
        return self.guides.n_frames

    @property
    def fps(self) -> float:
        return self.guides.fps

    @property
    def time_codes(self) -> np.ndarray:
        return self.guides.time_codes

    @property
    def metadata(self) -> Metadata:
        """The guides animation's scene and time codes, the children's prims (if bound with any)."""
        return self.guides.metadata.with_(curves=self.binding.metadata.curves)

    @property
    def attributes(self) -> dict[str, np.ndarray | None]:
        """The children's widths, colours and transparency (constant over the frames)."""
        return self.binding.attributes

    @property
    def thickness(self) -> np.ndarray | None:
        return self.binding.attributes["thickness"]

    @property
    def transparency(self) -> np.ndarray | None:
        return self.binding.attributes["transparency"]

    @property
    def colors(self) -> np.ndarray | None:
        return self.binding.attributes["colors"]

    @property
    def frame_bytes(self) -> int:
        """Bytes of one frame's points (float32)."""
        return self.vertex_count * 12

    def guides_frame(self, f: int) -> Groom:
        """Frame ``f`` of the guides as a groom.

        Parameters
        ----------
        f : int
            The frame.

        Returns
        -------
        Groom
            The guides.
        """
        return Groom(self.guides.frames[f], self.guides.topology, metadata=self.guides.metadata)

    def frame_points(self, f: int, out: np.ndarray | None = None) -> np.ndarray:
        """``(V, 3)`` float32 points of the children at frame ``f``: a new array, or written
        into ``out`` (a C-contiguous float32 ``(V, 3)``, e.g. rows of a larger frame).

        Parameters
        ----------
        f : int
            The frame.
        out : ndarray, optional
            Where to write.

        Returns
        -------
        ndarray
            ``(V, 3)`` float32.
        """
        if out is not None and (out.shape != (self.vertex_count, 3) or out.dtype != np.float32):
            raise ParameterError("out", f"{out.dtype} {out.shape}", f"float32 ({self.vertex_count}, 3)")
        if out is not None and not out.flags.c_contiguous:
            raise ParameterError("out", "a strided array", "a C-contiguous array")
        g = self.guides_frame(f)
        c = self.render.clump
        if c is None or c.iterations == 0:
            return build_points(following(self.binding, g), g, out=out)
        points = self.render.update(g).points
        if out is None:
            return np.array(points)
        out[:] = points
        return out

    def frame(self, f: int) -> Groom:
        """Frame ``f`` of the children as a groom, with their attributes.

        Parameters
        ----------
        f : int
            The frame.

        Returns
        -------
        Groom
            The children.
        """
        return Groom(self.frame_points(f), self.topology, **self.attributes, metadata=self.metadata)

    def __iter__(self) -> Iterator[np.ndarray]:
        for f in range(self.n_frames):
            yield self.frame_points(f)

    def __len__(self) -> int:
        return self.n_frames

    def animation(self, progress: Callable[[int, int], object] | None = None) -> Animation:
        """Every frame in one Animation (F × V × 12 bytes, and a copy while it is checked: for
        formats that take the whole array; USD takes the frames one by one). ``progress(done,
        total)`` after each frame; an exception it raises stops the build.

        Parameters
        ----------
        progress : callable, optional
            ``progress(done, total)`` after each frame.

        Returns
        -------
        Animation
            Every frame.
        """
        frames = np.empty((self.n_frames, self.vertex_count, 3), np.float32)
        for f in range(self.n_frames):
            self.frame_points(f, frames[f])
            if progress is not None:
                progress(f + 1, self.n_frames)
        return Animation(frames, self.topology, self.fps, **self.attributes, metadata=self.metadata)


def render_frames_reference(binding: ChildBinding, guides: Animation) -> np.ndarray:
    """``(F, V, 3)`` float32: :func:`~hairtool.guides.children.build_points_reference` on every
    frame of the guides (no clumping), the numpy twin of :class:`RenderHairAnimation`.

    Parameters
    ----------
    binding : ChildBinding
        The children bound to the guides at rest.
    guides : Animation
        The guides' frames.

    Returns
    -------
    ndarray
        ``(F, V, 3)`` float32.
    """
    _check(binding, guides)
    poses = (Groom(p, guides.topology, metadata=guides.metadata) for p in guides.frames)
    return np.stack([build_points_reference(following(binding, g), g) for g in poses])
