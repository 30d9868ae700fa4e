"""The child definition: what render strands are made of, without their points.

A :class:`ChildBinding` holds, per child, its root, vertex count, k guides and weights
(:mod:`hairtool.guides.nearest`), a length scale and local offsets in the nearest guide's
frames (:mod:`hairtool.guides.children`), and the guides at rest. Three ways to make one:

- :func:`bind_scalp`: guides and a scalp mesh → N children scattered on the region where hair
  grows (:mod:`hairtool.guides.scatter`), guides by distance along the surface;
- :func:`bind_roots`: guides and given roots (or, with none, roots around the guide roots);
- :func:`bind_dense`: a dense groom → G guides by farthest-point sampling of its roots, every
  strand bound with its offset from the blend, so the guides at rest give back its bytes.

Per-child variation (seeded): length scale s ∈ [1 − v, 1 + v] uniform, and frizz, a curl across
the strand whose radius grows from 0 at the root to ``frizz`` × the child's length at the tip
(1 to 3 turns, random phase). With frizz 0 a child is s × the weighted length of its guides.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from hairtool.errors import ParameterError
from hairtool.frozen.noise import check_seed
from hairtool.groom import Groom, Topology, vertex_ids_of
from hairtool.guides import children as _children
from hairtool.guides.limits import (  # re-exported: the binding's callers import them from here
    DEFAULT_FRIZZ,
    DEFAULT_K,
    DEFAULT_LENGTH_VARIATION,
    MAX_CHILDREN,
    MAX_FRIZZ,
    MAX_LENGTH_VARIATION,
)
from hairtool.guides.nearest import euclidean_nearest, farthest_point_sampling, weights
from hairtool.guides.scatter import (
    CH_VARIATION,
    check_mesh,
    default_region,
    generator,
    scatter_around,
    scatter_on_mesh,
)
from hairtool.guides.surface import closest_points, surface_nearest
from hairtool.io.obj import Mesh
from hairtool.metadata import Metadata


@dataclass(eq=False)
class ChildBinding:
    """N children bound to G guides (arrays as the kernels read them)."""

    rest_guides: Groom
    counts: np.ndarray  # (N,) int64 vertices per child
    roots: np.ndarray  # (N, 3) float64
    guide_ids: np.ndarray  # (N, k) int64, nearest first
    weights: np.ndarray  # (N, k) float64, rows sum to 1
    scale: np.ndarray  # (N,) float64 length scale
    local: np.ndarray | None  # (V, 3) float32 offsets in the nearest guide's frames (t, n, b), or none
    faces: np.ndarray | None = None  # (N,) the scalp triangle of each root, when on a mesh
    exact_points: np.ndarray | None = None  # (V, 3) float32: a dense groom's points …
    exact_blend: np.ndarray | None = None  # … and its float64 blend at rest (see children)
    frizz: float = 0.0  # the curl that made ``local``: its radius at the tip / child length …
    frizz_phase: np.ndarray | None = None  # … (N,) each child's starting angle, radians …
    frizz_turns: np.ndarray | None = None  # … (N,) and its turns root to tip
    #: a dense groom's own per-vertex thickness / transparency / colours (None: the guides' blend)
    exact_attributes: dict | None = None
    #: the prims the bound hair came from (render hair read beside its guides), kept on write
    hair_prims: tuple = ()
    _tangents: dict = field(default_factory=dict, repr=False)
    _attributes: dict = field(default_factory=dict, repr=False)

    def __post_init__(self) -> None:
        self.offsets = np.zeros(len(self.counts) + 1, np.int64)
        np.cumsum(self.counts, out=self.offsets[1:])
        self.vertex_counts = [int(n) for n in np.unique(self.counts)]
        self.topology = Topology(self.counts)

    @property
    def child_count(self) -> int:
        return len(self.counts)

    @property
    def vertex_count(self) -> int:
        return int(self.offsets[-1])

    @property
    def guides_per_child(self) -> int:
        return int(self.guide_ids.shape[1])

    @property
    def authored(self) -> bool:
        """Whether the children are strands somebody made (a dense groom's, render hair read
        beside its guides), bound to come back bit for bit, rather than grown from the guides.
        Authored hair is never clumped by default: it is shaped already (and hair a studio
        saved clumped would be clumped twice), while grown children are clumped, as XGen's
        and Blender's interpolated hair are (:func:`clumps_by_default`)."""
        return self.exact_points is not None

    def rest_tangents(self, n: int) -> np.ndarray:
        """``(G, 3)`` the rest guides' root tangents at n vertices (cached).

        Parameters
        ----------
        n : int
            Vertices per guide the tangents are taken at.

        Returns
        -------
        ndarray
            ``(G, 3)`` float64 unit tangents.
        """
        if n not in self._tangents:
            self._tangents[n] = _children.root_tangents_of(self.rest_guides, n)
        return self._tangents[n]

    def check_guides(self, guides: Groom) -> None:
        """A ParameterError unless ``guides`` are the strands the children were bound to (same counts).

        Parameters
        ----------
        guides : Groom
            The guides about to drive the children.
        """
        if guides.topology != self.rest_guides.topology:
            raise ParameterError(
                "guides",
                f"{guides.strand_count} strands of {guides.vertex_count} vertices",
                f"the {self.rest_guides.strand_count} guides the children were bound to, same vertex counts",
            )

    def subset(self, child_ids: np.ndarray) -> ChildBinding:
        """The children ``child_ids`` only (e.g. every tenth, for a display percentage while
        dragging): they build to the same points as in the whole binding.

        Parameters
        ----------
        child_ids : ndarray
            Indices of the children to keep.

        Returns
        -------
        ChildBinding
            A binding of those children to the same guides.
        """
        ids = np.asarray(child_ids, np.int64).reshape(-1)
        if ids.size == 0 or ids.min() < 0 or ids.max() >= self.child_count:
            raise ParameterError("children", f"{ids.size} ids", f"child indices in [0, {self.child_count})")
        vids = vertex_ids_of(self.topology, ids)

        def pick(a: np.ndarray | None) -> np.ndarray | None:
            return None if a is None else a[vids]

        def per_child(a: np.ndarray | None) -> np.ndarray | None:
            return None if a is None else a[ids]

        out = ChildBinding(
            self.rest_guides, self.counts[ids], self.roots[ids], self.guide_ids[ids], self.weights[ids],
            self.scale[ids], pick(self.local), per_child(self.faces), pick(self.exact_points),
            pick(self.exact_blend), self.frizz, per_child(self.frizz_phase), per_child(self.frizz_turns),
        )  # fmt: skip
        out._tangents = self._tangents
        if self.exact_attributes is not None:
            out.exact_attributes = {k: pick(v) for k, v in self.exact_attributes.items()}
        return out

    @property
    def attributes(self) -> dict[str, np.ndarray | None]:
        """The children's thickness, transparency and colours (:mod:`hairtool.guides.attributes`:
        a dense strand's own, else the guides' blended root to tip; None where the guides have
        none), computed once: they follow the rest guides, not their pose."""
        if not self._attributes:
            from hairtool.guides.attributes import child_attributes

            self._attributes.update(child_attributes(self))
        return dict(self._attributes)

    @property
    def metadata(self) -> Metadata:
        """The children's record: the guides' space, unit and colour primvar; the bound hair's
        prims where it came with its own."""
        meta = self.rest_guides.metadata.with_(curves=())
        prims = tuple(self.hair_prims)
        if prims and sum(c.strands for c in prims) == self.child_count:
            meta = meta.with_(curves=prims)
        return meta

    def build(self, guides: Groom | None = None) -> Groom:
        """The children from the guides' current shapes (the rest guides by default), with
        their widths and colours (:attr:`attributes`) and the guides' scene (:attr:`metadata`).

        Parameters
        ----------
        guides : Groom, optional
            The guides' current shapes, the same strands as the rest guides (None: the rest guides).

        Returns
        -------
        Groom
            The children.
        """
        pose = self.rest_guides if guides is None else guides
        return Groom(
            _children.build_points(self, pose), self.topology, **self.attributes, metadata=self.metadata
        )


def check_k(k: int, guide_count: int) -> int:
    """``k`` as an int, or a ParameterError unless it is a whole number in [1, guide_count].

    Parameters
    ----------
    k : int
        Guides per child.
    guide_count : int
        G.

    Returns
    -------
    int
        ``k``.
    """
    if isinstance(k, bool) or int(k) != k or not 1 <= k <= guide_count:
        raise ParameterError("guides_per_child", k, f"a whole number in [1, {guide_count}] (the guide count)")
    return int(k)


def check_count(count: int, name: str = "count") -> int:
    """``count`` as an int, or a ParameterError unless it is a whole number in [1, MAX_CHILDREN].

    Parameters
    ----------
    count : int
        Children.
    name : str, default "count"
        The parameter, named in a refusal.

    Returns
    -------
    int
        ``count``.
    """
    if isinstance(count, bool) or int(count) != count or not 1 <= count <= MAX_CHILDREN:
        raise ParameterError(name, count, f"a whole number of children in [1, {MAX_CHILDREN}]")
    return int(count)


def _check_variation(length_variation: float, frizz: float) -> None:
    v = float(length_variation)
    if not np.isfinite(v) or not 0 <= v <= MAX_LENGTH_VARIATION:
        raise ParameterError("length_variation", length_variation, f"a number in [0, {MAX_LENGTH_VARIATION}]")
    f = float(frizz)
    if not np.isfinite(f) or not 0 <= f <= MAX_FRIZZ:
        raise ParameterError("frizz", frizz, f"a fraction of the strand length in [0, {MAX_FRIZZ}]")


def _vertices(guides: Groom, vertices: int | None) -> int:
    n = int(guides.counts.max()) if vertices is None else vertices
    if isinstance(n, bool) or int(n) != n or not 2 <= n <= 1024:
        raise ParameterError("vertices", vertices, "a whole number of vertices per child in [2, 1024]")
    return int(n)


def _bind(
    guides: Groom,
    roots: np.ndarray,
    near: tuple[np.ndarray, np.ndarray],
    n: int,
    k: int,
    seed: int,
    length_variation: float,
    frizz: float,
    faces: np.ndarray | None,
) -> ChildBinding:
    # Children in order of their nearest guide: the kernel then reads the same guide rows
    # child after child (about 20 % faster on 100,000 children than in scatter order).
    order = np.argsort(near[0][:, 0], kind="stable")
    roots, near = roots[order], (near[0][order], near[1][order])
    faces = None if faces is None else faces[order]
    ids, w = weights(*near, k)
    count = len(roots)
    rng = generator(seed, CH_VARIATION)
    scale = 1.0 + length_variation * (2.0 * rng.random(count) - 1.0)
    phase = 2.0 * np.pi * rng.random(count)
    turns = 1.0 + 2.0 * rng.random(count)
    counts = np.full(count, n, np.int64)
    b = ChildBinding(guides, counts, roots, ids, w, scale, None, faces)
    if frizz > 0:
        b.frizz, b.frizz_phase, b.frizz_turns = float(frizz), phase, turns
        curl(b)
    return b


def curl(b: ChildBinding) -> None:
    """``b.local`` from its frizz: a helix across the nearest guide's frames whose radius grows
    from 0 at the root to ``frizz`` × the child's rest length at the tip. A few numbers per child
    make it, so a project stores those and curls the children again on loading.

    Parameters
    ----------
    b : ChildBinding
        A binding whose ``local`` is set here.
    """
    n = int(b.counts[0])
    count = b.child_count
    b.local = None
    q = _children.build_points(b, b.rest_guides, np.float64).reshape(count, n, 3)
    local = np.zeros((count * n, 3), np.float32)
    length = np.linalg.norm(np.diff(q, axis=1), axis=2).sum(axis=1)
    u = np.arange(n) / (n - 1)
    a = (b.frizz * length)[:, None] * u[None, :]
    ang = 2.0 * np.pi * b.frizz_turns[:, None] * u[None, :] + b.frizz_phase[:, None]
    local[:, 1] = (a * np.cos(ang)).reshape(-1)
    local[:, 2] = (a * np.sin(ang)).reshape(-1)
    b.local = local


def _nearest(guides: Groom, roots: np.ndarray, k: int, mesh: Mesh | None) -> tuple:
    """The k+1 nearest guides of each root: in space, or along the surface of ``mesh`` (the
    roots taken to the closest point of their face first; every face tried, so slow for
    hundreds of thousands of roots on a large mesh)."""
    if mesh is None:
        return euclidean_nearest(guides.roots, roots, k), None
    check_mesh(mesh)
    on, faces = closest_points(mesh, roots)
    near = surface_nearest(mesh, guides.roots.astype(np.float64), on, faces, k)
    if np.any(near[0][:, 0] < 0):
        raise ParameterError("scalp", "faces no guide root reaches", "a mesh connected to the guides' roots")
    return near, faces


def bind_roots(
    guides: Groom,
    roots: np.ndarray | None = None,
    count: int | None = None,
    *,
    k: int = DEFAULT_K,
    vertices: int | None = None,
    seed: int = 0,
    length_variation: float = DEFAULT_LENGTH_VARIATION,
    frizz: float = DEFAULT_FRIZZ,
    mesh: Mesh | None = None,
) -> ChildBinding:
    """Children at given ``roots`` ``(N, 3)``, or ``count`` of them around the guide roots,
    bound to their k nearest guide roots in space (along the surface of ``mesh`` if given);
    ``vertices`` per child (default: the guides' largest count). The children come in order
    of their nearest guide (their roots are ``binding.roots``), not in the order of ``roots``.

    Parameters
    ----------
    guides : Groom
        The guides at rest.
    roots : ndarray, optional
        ``(N, 3)`` finite child roots.
    count : int, optional
        Without ``roots``: how many children to scatter around the guide roots.
    k : int, default DEFAULT_K
        Guides each child blends.
    vertices : int, optional
        Vertices per child (None: the guides' largest count).
    seed : int, default 0
        The seed of the scatter, the length variation and the frizz.
    length_variation : float, default DEFAULT_LENGTH_VARIATION
        v: child lengths × [1 − v, 1 + v].
    frizz : float, default DEFAULT_FRIZZ
        The curl radius at a child's tip, a share of its length.
    mesh : Mesh, optional
        The head: nearest guides are found along its surface.

    Returns
    -------
    ChildBinding
        The children's binding; :meth:`ChildBinding.build` makes their strands.
    """
    k = check_k(k, guides.strand_count)
    seed = check_seed(seed)
    _check_variation(length_variation, frizz)
    n = _vertices(guides, vertices)
    if roots is None:
        roots = scatter_around(guides, check_count(count if count is not None else 0), seed)
    roots = np.asarray(roots, np.float64)
    if roots.ndim != 2 or roots.shape[1] != 3 or len(roots) == 0:
        raise ParameterError("roots", f"shape {roots.shape}", "(N ≥ 1, 3) child roots")
    if not np.all(np.isfinite(roots)):
        raise ParameterError("roots", "non-finite coordinates", "finite child roots")
    check_count(len(roots))
    near, faces = _nearest(guides, roots, k, mesh)
    return _bind(guides, roots, near, n, k, seed, length_variation, frizz, faces)


def bind_scalp(
    guides: Groom,
    mesh: Mesh,
    count: int,
    *,
    k: int = DEFAULT_K,
    vertices: int | None = None,
    seed: int = 0,
    length_variation: float = DEFAULT_LENGTH_VARIATION,
    frizz: float = DEFAULT_FRIZZ,
    region: np.ndarray | str | None = None,
    density: np.ndarray | None = None,
) -> ChildBinding:
    """``count`` children scattered on the scalp ``mesh`` (over ``region``: a face set's name,
    a face mask or indices, default :func:`~hairtool.guides.scatter.default_region`; by area × ``density``),
    each bound to its k nearest guides along the surface.

    Parameters
    ----------
    guides
        The guide strands; their roots should lie on or near the mesh.
    mesh
        The scalp or head the children grow on.
    count
        How many children.
    k
        Guides each child follows (its nearest, along the surface).
    vertices
        Vertices per child, 2 … 1024; None: the guides' largest count.
    seed
        Seed of the scattering, the length variation and the frizz.
    length_variation
        Seeded spread of the children's lengths.
    frizz
        Seeded waviness of the children.
    region
        Where children grow: a face set's name, a face mask or face indices; None: the triangles
        near the guide roots.
    density
        Per-face weights of the scattering.

    Returns
    -------
    ChildBinding
        The children's definition: ``build(guides)`` gives their points for any pose of the
        guides.

    Raises
    ------
    ParameterError
        A count, k or option is out of range; the message names it.
    """
    check_mesh(mesh)
    k = check_k(k, guides.strand_count)
    count = check_count(count)
    seed = check_seed(seed)
    _check_variation(length_variation, frizz)
    n = _vertices(guides, vertices)
    if region is None:
        region = default_region(mesh, guides)
    roots, faces = scatter_on_mesh(mesh, count, seed, region, density)
    near = surface_nearest(mesh, guides.roots.astype(np.float64), roots, faces, k)
    if np.any(near[0][:, 0] < 0):
        raise ParameterError("region", "faces no guide root reaches", "faces connected to the guides' roots")
    return _bind(guides, roots, near, n, k, seed, length_variation, frizz, faces)


def choose_guides(dense: Groom, guide_count: int, seed: int = 0) -> np.ndarray:
    """``(G,)`` strands of ``dense`` to serve as guides: farthest-point sampling of the roots
    from a seeded first strand.

    Parameters
    ----------
    dense : Groom
        The render hair.
    guide_count : int
        G, 1 … the strand count.
    seed : int, default 0
        Picks the first strand.

    Returns
    -------
    ndarray
        ``(G,)`` int64 strand indices.
    """
    s = dense.strand_count
    if isinstance(guide_count, bool) or int(guide_count) != guide_count or not 1 <= guide_count <= s:
        raise ParameterError("guides", guide_count, f"a whole number in [1, {s}] (the strand count)")
    first = int(generator(check_seed(seed), CH_VARIATION).integers(0, s))
    return farthest_point_sampling(dense.roots, int(guide_count), first)


def bind_dense(
    dense: Groom, guide_count: int, *, k: int = DEFAULT_K, seed: int = 0, mesh: Mesh | None = None
) -> tuple[Groom, ChildBinding]:
    """A dense groom as G guides and every strand bound to them (guides by root distance, along
    the surface of ``mesh`` if given): ``(guides, binding)``; the binding built on the guides
    at rest gives back ``dense``'s points bit for bit.

    Parameters
    ----------
    dense : Groom
        The render hair.
    guide_count : int
        G, 1 … the strand count.
    k : int, default DEFAULT_K
        Guides each strand blends.
    seed : int, default 0
        Picks the first guide.
    mesh : Mesh, optional
        The head: nearest guides are found along its surface.

    Returns
    -------
    tuple of (Groom, ChildBinding)
        The guides and every strand's binding to them.
    """
    guides = dense.subset(choose_guides(dense, guide_count, seed))
    return guides, bind_to_guides(dense, guides, k=k, mesh=mesh)


def bind_to_guides(
    hair: Groom, guides: Groom, *, k: int = DEFAULT_K, mesh: Mesh | None = None
) -> ChildBinding:
    """Every strand of ``hair`` bound to the given ``guides`` (its k nearest by root distance,
    along the surface of ``mesh`` if given), storing its offset from their blend: render hair
    read beside its guides (a USD file's guide prim) follows them, and comes back bit for bit
    while they are untouched.

    Parameters
    ----------
    hair : Groom
        The render hair.
    guides : Groom
        Its guides.
    k : int, default DEFAULT_K
        Guides each strand blends.
    mesh : Mesh, optional
        The head: nearest guides are found along its surface.

    Returns
    -------
    ChildBinding
        Every strand's binding; built on the guides at rest it gives ``hair`` back.
    """
    k = check_k(k, guides.strand_count)
    roots = hair.roots.astype(np.float64)
    near, faces = _nearest(guides, roots, k, mesh)
    ids_k, w = weights(*near, k)
    scale = np.ones(hair.strand_count)
    b = ChildBinding(guides, hair.counts.copy(), roots, ids_k, w, scale, None, faces)
    bind_exactly(b, hair.points)
    b.exact_attributes = hair.attributes
    b.hair_prims = tuple(
        c for c in hair.metadata.for_strands(hair.strand_count).curves if c.purpose != "guide"
    )
    return b


def bind_exactly(b: ChildBinding, points: np.ndarray) -> None:
    """Give ``b`` (one child per dense strand, no offsets yet) the dense strands' ``points``
    exactly: each vertex's offset from the blend in its nearest guide's frames (``local``), the
    float64 blend at rest those offsets give (``exact_blend``) and the points themselves. The
    first two follow from the points and the rest guides, so a project stores the points alone
    and binds them again on loading.

    Parameters
    ----------
    b : ChildBinding
        One child per dense strand, no offsets yet.
    points : ndarray
        ``(V, 3)`` the dense strands' points.
    """
    guides = b.rest_guides
    b.local = b.exact_points = b.exact_blend = None  # the plain blend first
    q = _children.build_points(b, guides, np.float64)
    tables = _children.GuideTables(guides, b)
    near_row = tables.child_base(b) + b.guide_ids[:, 0] * b.counts
    rows = np.repeat(near_row, b.counts) + b.topology.index_in_strand
    fr = tables.frames[rows]  # (V, 9): each vertex's frame on its nearest guide
    r = points.astype(np.float64) - q
    local = np.column_stack([np.einsum("ij,ij->i", r, fr[:, 3 * a : 3 * a + 3]) for a in range(3)])
    b.local = local.astype(np.float32)  # the rest blend below uses these very offsets
    b.exact_blend = _children.build_points(b, guides, np.float64)
    b.exact_points = points


def clumps_by_default(binding: ChildBinding) -> bool:
    """Whether render hair of ``binding`` runs ClumpWithGaps among its children unless told
    otherwise: grown children do (interpolated hair without adhesion reads as a fuzz of
    parallel strands), authored ones (:attr:`ChildBinding.authored`) do not.

    Parameters
    ----------
    binding : ChildBinding
        The children.

    Returns
    -------
    bool
        True for grown children.
    """
    return not binding.authored
