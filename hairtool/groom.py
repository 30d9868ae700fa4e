"""The strand model: a groom (static strands) and an animation (the same strands over frames).

Strands are stored the way USD's BasisCurves and the HAIR format store them: one float32
``(V, 3)`` array of points, strand after strand from root to tip, and the vertex count of each
strand. Every per-vertex quantity is a flat ``(V,)`` or ``(V, 3)`` array in the same order, so
kernels work on whole grooms at once instead of looping over Python lists of strands.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from functools import cached_property

import numpy as np
from numpy.typing import ArrayLike, NDArray

from hairtool.bounds import box
from hairtool.errors import GroomError
from hairtool.metadata import Metadata

F32 = NDArray[np.float32]
F64 = NDArray[np.float64]
I64 = NDArray[np.int64]

#: The most vertices one strand may have. Bounding every count (with fewer than 2^32 strands)
#: keeps their int64 sum from wrapping around: counts of 2^62 could otherwise add up to the
#: number of points and pass for a valid groom.
MAX_STRAND_VERTICES = 2**31 - 1


def _frozen(a: np.ndarray) -> np.ndarray:
    a.flags.writeable = False
    return a


class Topology:
    """Per-strand vertex counts and the index arrays derived from them (shared, immutable)."""

    def __init__(self, counts: ArrayLike) -> None:
        """Check the counts and derive the offsets once.

        Parameters
        ----------
        counts : array_like
            ``(S,)`` whole numbers, each strand's vertex count.

        Raises
        ------
        GroomError
            For counts that are not a 1-D array of whole numbers of at least one strand.
        """
        c = np.asarray(counts)
        if c.ndim != 1:
            raise GroomError(f"strand counts must be a 1-D array, got shape {c.shape}")
        if c.size == 0:
            raise GroomError("a groom needs at least one strand")
        if c.dtype.kind not in "iuf":
            raise GroomError(f"strand counts must be whole numbers, not {c.dtype}")
        if c.dtype.kind == "f" and (not np.all(np.isfinite(c)) or not np.all(c == np.round(c))):
            raise GroomError("strand counts must be whole numbers")
        if c.size >= 2**32:
            raise GroomError(f"a groom holds at most 2^32 - 1 strands, got {c.size}")
        # Range checks in the given dtype, before the cast: a uint64 or a float of 2^64 would wrap.
        if c.min() < 2:
            bad = int(np.argmin(c))
            raise GroomError(f"strand {bad} has {int(c[bad])} vertices; every strand needs at least 2")
        if c.max() > MAX_STRAND_VERTICES:
            bad = int(np.argmax(c))
            raise GroomError(f"strand {bad} has {int(c[bad])} vertices; the most is {MAX_STRAND_VERTICES}")
        c = c.astype(np.int64)
        self.counts: I64 = _frozen(c)

    @property
    def strand_count(self) -> int:
        return int(self.counts.size)

    @cached_property
    def offsets(self) -> I64:
        """``(S+1,)``: strand s owns vertices ``offsets[s]:offsets[s+1]``."""
        off = np.zeros(self.counts.size + 1, dtype=np.int64)
        np.cumsum(self.counts, out=off[1:])
        return _frozen(off)

    @property
    def vertex_count(self) -> int:
        return int(self.offsets[-1])

    @cached_property
    def strand_index(self) -> I64:
        """``(V,)``: the strand each vertex belongs to."""
        return _frozen(np.repeat(np.arange(self.counts.size, dtype=np.int64), self.counts))

    @cached_property
    def index_in_strand(self) -> I64:
        """``(V,)``: 0 at each root, N_s − 1 at each tip."""
        return _frozen(np.arange(self.vertex_count, dtype=np.int64) - self.offsets[self.strand_index])

    @cached_property
    def vertex_param(self) -> F32:
        """``(V,)``: root-to-tip parameter t = i / (N_s − 1)."""
        t = self.index_in_strand / (self.counts[self.strand_index] - 1)
        return _frozen(t.astype(np.float32))

    @cached_property
    def root_indices(self) -> I64:
        return _frozen(self.offsets[:-1].copy())

    @cached_property
    def tip_indices(self) -> I64:
        return _frozen(self.offsets[1:] - 1)

    @cached_property
    def segment_end(self) -> I64:
        """``(V−S,)``: the vertex at the far end of each segment (every non-root vertex)."""
        mask = np.ones(self.vertex_count, dtype=bool)
        mask[self.root_indices] = False
        return _frozen(np.flatnonzero(mask).astype(np.int64))

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Topology) and np.array_equal(self.counts, other.counts)

    def __hash__(self) -> int:
        return hash(self.counts.tobytes())


def _check_points(points: ArrayLike, vertex_count: int, what: str) -> F32:
    p = np.asarray(points)
    if p.ndim != 2 or p.shape[1] != 3:
        raise GroomError(f"{what} must have shape (V, 3), got {p.shape}")
    if p.shape[0] != vertex_count:
        raise GroomError(f"{what} has {p.shape[0]} vertices but the strand counts add up to {vertex_count}")
    out = _float32(p, what)
    if not np.all(np.isfinite(out)):
        bad = int(np.flatnonzero(~np.all(np.isfinite(out), axis=1))[0])
        raise GroomError(f"{what} has a non-finite or beyond-float32 coordinate at vertex {bad}")
    return out


def _float32(values: np.ndarray, what: str) -> F32:
    """A float32 copy; checked for finiteness by the caller *after* the cast, since a float64
    beyond ±3.4e38 is finite but becomes inf."""
    if values.dtype.kind not in "fiub":
        raise GroomError(f"{what} must hold numbers, not {values.dtype}")
    with np.errstate(over="ignore", invalid="ignore"):
        return np.array(values, dtype=np.float32, copy=True)


def _check_attribute(values: ArrayLike | None, vertex_count: int, width: int, name: str) -> F32 | None:
    if values is None:
        return None
    a = _float32(np.asarray(values), name)
    shape = (vertex_count,) if width == 1 else (vertex_count, width)
    if a.shape != shape:
        raise GroomError(f"{name} must have shape {shape}, got {a.shape}")
    if not np.all(np.isfinite(a)):
        raise GroomError(f"{name} has non-finite values")
    return _frozen(a)


class StrandSizes:
    """``counts``, ``strand_count`` and ``vertex_count`` of anything with a ``topology``: grooms,
    animations and the frame streams the writers take."""

    topology: Topology

    @property
    def counts(self) -> I64:
        return self.topology.counts

    @property
    def strand_count(self) -> int:
        return self.topology.strand_count

    @property
    def vertex_count(self) -> int:
        return self.topology.vertex_count


class _Attributes(StrandSizes):
    """Optional per-vertex thickness, transparency and colour, shared by Groom and Animation."""

    thickness: F32 | None
    transparency: F32 | None
    colors: F32 | None
    metadata: Metadata

    def _set_attributes(self, thickness, transparency, colors, vertex_count: int) -> None:
        self.thickness = _check_attribute(thickness, vertex_count, 1, "thickness")
        self.transparency = _check_attribute(transparency, vertex_count, 1, "transparency")
        self.colors = _check_attribute(colors, vertex_count, 3, "colors")

    def _set_metadata(self, metadata: Metadata | None, strand_count: int) -> None:
        """Up axis, unit, time codes and prims of the source (:mod:`hairtool.metadata`); defaults if None."""
        m = Metadata() if metadata is None else metadata
        if not isinstance(m, Metadata):
            raise GroomError(f"metadata must be a hairtool.metadata.Metadata, got {type(m).__name__}")
        held = sum(c.strands for c in m.curves)
        if m.curves and held != strand_count:
            raise GroomError(f"the metadata's curve prims hold {held} strands, not {strand_count}")
        self.metadata = m

    @property
    def attributes(self) -> dict[str, F32 | None]:
        """The optional per-vertex arrays by keyword: ``thickness`` and ``transparency`` ``(V,)``,
        ``colors`` ``(V, 3)``, float32 and read-only, or None where absent.

        The keys are the constructors' keywords, so ``Groom(points, topology, **g.attributes)``
        carries them over; a new dict each time, the arrays shared (not copied).
        """
        return {"thickness": self.thickness, "transparency": self.transparency, "colors": self.colors}


class Groom(_Attributes):
    """S strands of varying vertex counts; positions are float32 and immutable.

    Build a new groom with :meth:`with_points` rather than writing into ``points``: engines
    return new positions and the topology (and its cached index arrays) is shared.

    Parameters
    ----------
    points
        ``(V, 3)`` vertex positions, strand after strand, root first; stored as float32.
    counts
        ``(S,)`` vertices per strand (each at least 2, adding up to V), or a shared
        :class:`Topology`.
    thickness, transparency
        Optional ``(V,)`` per-vertex widths and transparency.
    colors
        Optional ``(V, 3)`` per-vertex RGB.
    metadata
        The source's scene description (up axis, unit, curve prims); None: the defaults.

    Raises
    ------
    GroomError
        A shape or count does not match, or a value is not finite.
    """

    def __init__(
        self,
        points: ArrayLike,
        counts: ArrayLike | Topology,
        *,
        thickness: ArrayLike | None = None,
        transparency: ArrayLike | None = None,
        colors: ArrayLike | None = None,
        metadata: Metadata | None = None,
    ) -> None:
        self.topology = counts if isinstance(counts, Topology) else Topology(counts)
        self.points: F32 = _frozen(_check_points(points, self.topology.vertex_count, "points"))
        self._set_attributes(thickness, transparency, colors, self.topology.vertex_count)
        if metadata is not None and metadata.time_codes is not None:
            metadata = metadata.with_(time_codes=None)
        self._set_metadata(metadata, self.topology.strand_count)

    @classmethod
    def from_strands(cls, strands: Sequence[ArrayLike], **attributes: ArrayLike | None) -> Groom:
        """Build from a list of ``(N_s, 3)`` polylines (2-D ``(N_s, 2)`` ones get z = 0).

        Parameters
        ----------
        strands : sequence of array_like
            One ``(N_s, 3)`` or ``(N_s, 2)`` polyline per strand, root first.
        **attributes : array_like, optional
            Per-vertex attributes (``widths``, ``colors``...) over all vertices, in strand order.

        Returns
        -------
        Groom
            The strands as one float32 points array with their counts.
        """
        if len(strands) == 0:
            raise GroomError("a groom needs at least one strand")
        arrays = []
        for i, s in enumerate(strands):
            a = np.asarray(s, dtype=np.float64)
            if a.ndim != 2 or a.shape[1] not in (2, 3):
                raise GroomError(f"strand {i} must have shape (N, 2) or (N, 3), got {a.shape}")
            if a.shape[1] == 2:
                a = np.column_stack([a, np.zeros(len(a))])
            arrays.append(a)
        counts = [len(a) for a in arrays]
        return cls(np.concatenate(arrays), counts, **attributes)

    def with_points(self, points: ArrayLike) -> Groom:
        """The same strands, attributes and metadata at new positions.

        Parameters
        ----------
        points : array_like
            ``(V, 3)`` new positions, one per vertex (cast to float32).

        Returns
        -------
        Groom
            A groom sharing this one's topology, attributes and metadata.
        """
        return Groom(points, self.topology, **self.attributes, metadata=self.metadata)

    def with_moved_rows(self, points: NDArray[np.float32], rows: ArrayLike) -> Groom:
        """:meth:`with_points` for points handed over whose rows other than ``rows`` (vertex ids)
        are values a groom already held: a float32 C-ordered ``(V, 3)`` array of its own that
        nobody writes afterwards (it is made read-only, not copied); ``rows`` alone are checked,
        and the attributes are shared. A brush move on millions of vertices changes a few
        thousand, and a copy and a check of all of them would cost more than the move. Anything
        else goes through :meth:`with_points`.

        Parameters
        ----------
        points : ndarray
            ``(V, 3)`` float32 C-ordered positions, handed over (not copied).
        rows : array_like
            The vertex ids whose values may differ from the ones this groom holds.

        Returns
        -------
        Groom
            The groom at ``points``; only ``rows`` are checked for finite values.
        """
        if not (
            isinstance(points, np.ndarray)
            and points.dtype == np.float32
            and points.shape == self.points.shape
            and points.flags.c_contiguous
            and points.flags.owndata
        ):
            return self.with_points(points)
        ids = np.asarray(rows, np.int64).reshape(-1)
        finite = np.all(np.isfinite(points[ids]), axis=1)
        if not finite.all():
            bad = int(ids[np.argmin(finite)])
            raise GroomError(f"points has a non-finite coordinate at vertex {bad}")
        g = object.__new__(Groom)
        g.topology = self.topology
        g.points = _frozen(points)
        g.thickness, g.transparency, g.colors = self.thickness, self.transparency, self.colors
        g.metadata = self.metadata
        return g

    # -- sizes -------------------------------------------------------------------------
    @property
    def offsets(self) -> I64:
        return self.topology.offsets

    def __len__(self) -> int:
        return self.strand_count

    def __repr__(self) -> str:
        return f"Groom({self.strand_count} strands, {self.vertex_count} vertices)"

    # -- per-strand --------------------------------------------------------------------
    @property
    def roots(self) -> F32:
        return self.points[self.topology.root_indices]

    @property
    def tips(self) -> F32:
        return self.points[self.topology.tip_indices]

    def strand(self, s: int) -> F32:
        """Read-only ``(N_s, 3)`` view of one strand.

        Parameters
        ----------
        s : int
            The strand's index.

        Returns
        -------
        ndarray
            ``(N_s, 3)`` float32, read-only: a view, not a copy.
        """
        o = self.offsets
        return self.points[o[s] : o[s + 1]]

    def strands(self) -> Iterator[F32]:
        for s in range(self.strand_count):
            yield self.strand(s)

    def with_metadata(self, metadata: Metadata) -> Groom:
        """The same groom with another source record (up axis, unit, prims).

        Parameters
        ----------
        metadata : Metadata
            The new source record.

        Returns
        -------
        Groom
            The same points and attributes with ``metadata``.
        """
        return Groom(self.points, self.topology, **self.attributes, metadata=metadata)

    def animate(self, frames: ArrayLike, fps: float) -> Animation:
        """An animation of these strands (a simulation, a cycle): their attributes and source
        record by construction, frames at time codes from the source's start (0 by default),
        so an engine that makes frames cannot drop the scene's space, unit or prims.

        Parameters
        ----------
        frames : array_like
            ``(F, V, 3)`` positions of these strands at each frame.
        fps : float
            Frames per second.

        Returns
        -------
        Animation
            The frames with this groom's attributes and source record.
        """
        n = int(np.shape(frames)[0]) if np.ndim(frames) == 3 else 0
        first = self.metadata.first_time_code()
        codes = None if first == 0.0 or n == 0 else first + np.arange(n, dtype=np.float64)
        meta = self.metadata.derived(time_codes=codes)
        return Animation(frames, self.topology, fps, **self.attributes, metadata=meta)

    def subset(self, strand_ids: ArrayLike) -> Groom:
        """A groom of the chosen strands, in the given order; its record holds each source prim's
        chosen strands (:meth:`~hairtool.metadata.Metadata.subset`).

        Parameters
        ----------
        strand_ids : array_like
            Indices of the strands to keep, in the order wanted (repeats allowed).

        Returns
        -------
        Groom
            The chosen strands with their attributes and record.
        """
        ids = np.asarray(strand_ids, dtype=np.int64).reshape(-1)
        if ids.size == 0:
            raise GroomError("a subset needs at least one strand")
        if ids.min() < 0 or ids.max() >= self.strand_count:
            raise GroomError(f"strand ids must lie in [0, {self.strand_count})")
        vids = vertex_ids_of(self.topology, ids)
        pick = {k: (None if v is None else v[vids]) for k, v in self.attributes.items()}
        return Groom(self.points[vids], self.counts[ids], **pick, metadata=self.metadata.subset(ids))

    # -- per-vertex --------------------------------------------------------------------
    @property
    def vertex_param(self) -> F32:
        """``(V,)`` t = i / (N_s − 1): 0 at the root, 1 at the tip."""
        return self.topology.vertex_param

    @cached_property
    def segment_vectors(self) -> F32:
        """``(V−S, 3)``: p[i] − p[i−1] for every non-root vertex, in vertex order."""
        end = self.topology.segment_end
        return _frozen(self.points[end] - self.points[end - 1])

    @cached_property
    def segment_lengths(self) -> F64:
        """``(V−S,)`` in float64, so arc lengths of long strands do not lose precision."""
        d = self.segment_vectors.astype(np.float64)
        return _frozen(np.sqrt(np.einsum("ij,ij->i", d, d)))

    @cached_property
    def arc_length(self) -> F64:
        """``(V,)`` distance from the strand's root along the strand."""
        u = np.zeros(self.vertex_count, dtype=np.float64)
        u[self.topology.segment_end] = self.segment_lengths
        u = np.cumsum(u)
        u -= u[self.topology.root_indices][self.topology.strand_index]
        return _frozen(u)

    @cached_property
    def strand_lengths(self) -> F64:
        return _frozen(self.arc_length[self.topology.tip_indices].copy())

    @cached_property
    def arc_param(self) -> F64:
        """``(V,)`` arc length normalised to [0, 1] per strand (t where a strand has no length)."""
        length = self.strand_lengths[self.topology.strand_index]
        with np.errstate(invalid="ignore", divide="ignore"):
            u = np.where(length > 0, self.arc_length / length, self.vertex_param)
        return _frozen(u)

    @cached_property
    def bounds(self) -> tuple[F32, F32]:
        """Axis-aligned bounding box ``(min, max)``."""
        lo, hi = box(self.points)
        return _frozen(lo), _frozen(hi)

    @property
    def is_planar(self) -> bool:
        """True for 2-D grooms: z is 0 everywhere."""
        return not np.any(self.points[:, 2])


def vertex_ids_of(topology: Topology, strand_ids: NDArray[np.int64]) -> I64:
    """Vertex indices of the given strands, concatenated in the given order.

    Parameters
    ----------
    topology : Topology
        The strands.
    strand_ids : ndarray
        int64 strand indices.

    Returns
    -------
    ndarray
        int64 vertex indices.
    """
    counts = topology.counts[strand_ids]
    starts = topology.offsets[strand_ids]
    local = np.arange(int(counts.sum()), dtype=np.int64) - np.repeat(np.cumsum(counts) - counts, counts)
    return np.repeat(starts, counts) + local


class Animation(_Attributes):
    """The same strands over F frames: ``frames`` is float32 ``(F, V, 3)``, ``fps`` frames/s.

    Parameters
    ----------
    frames
        ``(F, V, 3)`` vertex positions per frame, F ≥ 1; the first frame is the rest pose.
    counts
        ``(S,)`` vertices per strand, or a shared :class:`Topology`.
    fps
        Frames per second.
    thickness, transparency, colors, metadata
        As for :class:`Groom`; the metadata's time codes give each frame's time code in the
        source.

    Raises
    ------
    GroomError
        A shape or count does not match, or a value is not finite.
    """

    def __init__(
        self,
        frames: ArrayLike,
        counts: ArrayLike | Topology,
        fps: float = 24.0,
        *,
        thickness: ArrayLike | None = None,
        transparency: ArrayLike | None = None,
        colors: ArrayLike | None = None,
        metadata: Metadata | None = None,
    ) -> None:
        self.topology = counts if isinstance(counts, Topology) else Topology(counts)
        f = np.asarray(frames)
        v = self.topology.vertex_count
        if f.ndim != 3 or f.shape[2] != 3:
            raise GroomError(f"animation frames must have shape (F, V, 3), got {f.shape}")
        if f.shape[0] < 1:
            raise GroomError("an animation needs at least one frame")
        if f.shape[1] != v:
            raise GroomError(
                f"animation frames have {f.shape[1]} vertices but the strand counts add up to {v}"
            )
        frames32 = _float32(f, "animation frames")
        if not np.all(np.isfinite(frames32)):
            bad = int(np.flatnonzero(~np.all(np.isfinite(frames32), axis=(1, 2)))[0])
            raise GroomError(f"animation frame {bad} has a non-finite or beyond-float32 coordinate")
        fps = float(fps)
        if not np.isfinite(fps) or fps <= 0:
            raise GroomError(f"frame rate must be a positive number, got {fps}")
        self.frames: F32 = _frozen(frames32)
        self.fps = fps
        self._set_attributes(thickness, transparency, colors, v)
        self._set_metadata(metadata, self.topology.strand_count)
        codes = self.metadata.time_codes
        if codes is not None and len(codes) != f.shape[0]:
            raise GroomError(f"the metadata has {len(codes)} time codes for {f.shape[0]} frames")

    @classmethod
    def from_grooms(cls, grooms: Sequence[Groom], fps: float = 24.0) -> Animation:
        """Stack grooms of one topology into frames; attributes come from the first.

        Parameters
        ----------
        grooms : sequence of Groom
            The frames, all with the same strand counts.
        fps : float, default 24.0
            Frames per second.

        Returns
        -------
        Animation
            One frame per groom.
        """
        if len(grooms) == 0:
            raise GroomError("an animation needs at least one frame")
        top = grooms[0].topology
        for i, g in enumerate(grooms):
            if g.topology != top:
                raise GroomError(f"frame {i} has a different strand topology from frame 0")
        first = grooms[0]
        return cls(
            np.stack([g.points for g in grooms]), top, fps, **first.attributes, metadata=first.metadata
        )

    def with_frames(
        self, frames: ArrayLike, fps: float | None = None, time_codes: ArrayLike | None = None
    ) -> Animation:
        """New frames of the same strands; the time codes are kept while the frame count is,
        else they are ``time_codes`` (None: 0…F−1).

        Parameters
        ----------
        frames : array_like
            ``(F, V, 3)`` positions of the same strands.
        fps : float, optional
            Frames per second (None: this animation's).
        time_codes : array_like, optional
            ``(F,)`` time codes where the frame count changes (None: 0…F−1).

        Returns
        -------
        Animation
            The new frames with this animation's strands, attributes and record.
        """
        n = np.shape(frames)[0] if np.ndim(frames) else 0
        codes = self.metadata.time_codes if time_codes is None and n == self.n_frames else time_codes
        codes = None if codes is None else tuple(np.asarray(codes, dtype=np.float64).reshape(-1).tolist())
        return Animation(
            frames,
            self.topology,
            self.fps if fps is None else fps,
            **self.attributes,
            metadata=self.metadata.with_(time_codes=codes),
        )

    def with_metadata(self, metadata: Metadata) -> Animation:
        """The same animation with another source record (up axis, unit, time codes, prims).

        Parameters
        ----------
        metadata : Metadata
            The new source record.

        Returns
        -------
        Animation
            The same frames with ``metadata``.
        """
        return Animation(self.frames, self.topology, self.fps, **self.attributes, metadata=metadata)

    @property
    def n_frames(self) -> int:
        return int(self.frames.shape[0])

    @property
    def duration(self) -> float:
        """Seconds from the first frame to the last."""
        return (self.n_frames - 1) / self.fps

    @property
    def times(self) -> F64:
        return np.arange(self.n_frames, dtype=np.float64) / self.fps

    @property
    def time_codes(self) -> F64:
        """``(F,)`` the source's time code of each frame (0…F−1 when it had none)."""
        codes = self.metadata.time_codes
        return np.arange(self.n_frames, dtype=np.float64) if codes is None else np.array(codes)

    def frame(self, f: int) -> Groom:
        """Frame ``f`` as a groom (negative indices count from the end).

        Parameters
        ----------
        f : int
            The frame's index (negative: from the end).

        Returns
        -------
        Groom
            The strands at that frame, with the animation's attributes.
        """
        if not -self.n_frames <= f < self.n_frames:
            raise IndexError(f"frame {f} is outside 0..{self.n_frames - 1}")
        return Groom(self.frames[f], self.topology, **self.attributes, metadata=self.metadata)

    @property
    def rest(self) -> Groom:
        return self.frame(0)

    @property
    def bounds(self) -> tuple[F32, F32]:
        return self.frames.min(axis=(0, 1)), self.frames.max(axis=(0, 1))

    def __len__(self) -> int:
        return self.n_frames

    def __repr__(self) -> str:
        return (
            f"Animation({self.n_frames} frames at {self.fps:g} fps, "
            f"{self.strand_count} strands, {self.vertex_count} vertices)"
        )
