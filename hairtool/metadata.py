"""What a groom's source said about its space, time and curves, kept so that writing it back says the same.

A DCC's USD stage declares its up axis and unit (Blender: Z-up, metres), its time codes (an
animation sampled at time codes 1…48 at 24 per second) and how its curves are drawn (a cubic
Catmull-Rom basis, several prims under a head). hairtool's engines work on bare points; this
record rides along on :class:`~hairtool.groom.Groom` and :class:`~hairtool.groom.Animation` so
that ``hairtool convert`` and every writer put the groom back where it came from.

Defaults (a groom made by hairtool or read from a format that says nothing): Y-up, as the
samples, TressFX and the HAIR files are; ``meters_per_unit`` 0.01 (centimetres), which is
USD's own fallback when a stage leaves ``metersPerUnit`` out and the scale of TressFX and HAIR
models (a head is about 20 units across); one linear prim.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, replace

import numpy as np

from hairtool.errors import ParameterError, finite_number

UP_AXES = ("Y", "Z")
DEFAULT_UP_AXIS = "Y"
DEFAULT_METERS_PER_UNIT = 0.01
#: ``"linear"`` or the cubic basis of USD's BasisCurves.
BASES = ("linear", "bezier", "bspline", "catmullRom")
WRAPS = ("nonperiodic", "periodic", "pinned")
PURPOSES = ("default", "render", "proxy", "guide")  # UsdGeom's purpose tokens
#: The per-vertex attributes a prim may lack when several prims are merged into one groom.
ATTRIBUTES = ("thickness", "transparency", "colors")
#: Hair width where a source gives none: 80 µm, a typical human hair, in metres.
HAIR_WIDTH_M = 80e-6


def _positive(name: str, value: float | None) -> float | None:
    if value is None:
        return None
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ParameterError(name, value, "a positive number") from None
    if not (math.isfinite(v) and v > 0):
        raise ParameterError(name, value, "a positive number")
    return v


def _finite(name: str, value: float | None) -> float | None:
    return None if value is None else finite_number(name, value)


@dataclass(frozen=True)
class CurvesPrim:
    """One source curves prim: its path, how many strands (in order) it holds and its basis.

    ``basis`` is ``"linear"`` or a cubic basis (``BASES``); the strands' points are the
    curve's control points either way.
    """

    path: str
    strands: int
    basis: str = "linear"
    wrap: str = "nonperiodic"
    purpose: str = "default"  # USD's purpose: "guide" marks guide curves beside the render hair
    #: Attributes (of ATTRIBUTES) this prim did not author: merged with prims that did, its
    #: vertices hold defaults there, and a writer leaves them out of this prim again.
    lacks: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        if not isinstance(self.path, str) or not self.path.startswith("/") or len(self.path) < 2:
            raise ParameterError("prim path", self.path, "an absolute prim path such as /Groom/Strands")
        if isinstance(self.strands, bool) or not isinstance(self.strands, int) or self.strands < 1:
            raise ParameterError("prim strands", self.strands, "a whole number ≥ 1")
        if self.basis not in BASES:
            raise ParameterError("basis", self.basis, f"one of {', '.join(BASES)}")
        if self.wrap not in WRAPS:
            raise ParameterError("wrap", self.wrap, f"one of {', '.join(WRAPS)}")
        if self.purpose not in PURPOSES:
            raise ParameterError("purpose", self.purpose, f"one of {', '.join(PURPOSES)}")
        lacks = tuple(self.lacks) if isinstance(self.lacks, (list, tuple)) else None
        if lacks is None or any(a not in ATTRIBUTES for a in lacks) or len(set(lacks)) != len(lacks):
            raise ParameterError("lacks", self.lacks, f"distinct names from {', '.join(ATTRIBUTES)}")
        object.__setattr__(self, "lacks", tuple(a for a in ATTRIBUTES if a in lacks))

    @property
    def description(self) -> str:
        """``"linear"``, or e.g. ``"cubic catmullRom, pinned"`` as ``hairtool info`` prints it."""
        kind = "linear" if self.basis == "linear" else f"cubic {self.basis}"
        return kind if self.wrap == "nonperiodic" else f"{kind}, {self.wrap}"


@dataclass(frozen=True)
class Metadata:
    """Up axis, unit, time codes and curve prims of a groom's source (defaults when it had none).

    ``time_codes``: for an animation, the source's time code of each frame (None: 0…F−1);
    ``time_codes_per_second``, ``start_time_code``, ``end_time_code``: the stage's, when it
    authored them. ``curves``: the source prims in order, empty for one default prim.
    ``color_primvar``: the primvar the colours came from (``displayColor`` or Blender's ``color``).
    """

    up_axis: str = DEFAULT_UP_AXIS
    meters_per_unit: float = DEFAULT_METERS_PER_UNIT
    time_codes_per_second: float | None = None
    start_time_code: float | None = None
    end_time_code: float | None = None
    time_codes: tuple[float, ...] | None = None
    curves: tuple[CurvesPrim, ...] = ()
    color_primvar: str = "displayColor"
    #: ``(prim path, 16 numbers)``: the static local transforms (4×4, row vectors as USD's
    #: ``p' = p·M``) of the curves prims and their ancestors that had one, so that a writer puts
    #: them back and writes points in the prims' own space: the file then layers over its
    #: source without moving the hair twice. Empty when the source had none or animated them.
    xforms: tuple[tuple[str, tuple[float, ...]], ...] = ()

    def __post_init__(self) -> None:
        up = str(self.up_axis).upper()
        if up not in UP_AXES:
            raise ParameterError("up axis", self.up_axis, "Y or Z")
        object.__setattr__(self, "up_axis", up)
        object.__setattr__(self, "meters_per_unit", _positive("meters per unit", self.meters_per_unit))
        tcps = _positive("time codes per second", self.time_codes_per_second)
        object.__setattr__(self, "time_codes_per_second", tcps)
        start = _finite("start time code", self.start_time_code)
        end = _finite("end time code", self.end_time_code)
        if start is not None and end is not None and end < start:
            raise ParameterError("end time code", end, f"≥ the start time code {start}")
        object.__setattr__(self, "start_time_code", start)
        object.__setattr__(self, "end_time_code", end)
        if self.time_codes is not None:
            codes = tuple(float(t) for t in self.time_codes)
            if not codes or not all(math.isfinite(t) for t in codes):
                raise ParameterError(
                    "time codes", "non-finite or empty", "finite, strictly increasing numbers"
                )
            if any(b <= a for a, b in itertools.pairwise(codes)):
                raise ParameterError("time codes", codes[:8], "finite, strictly increasing numbers")
            object.__setattr__(self, "time_codes", codes)
        object.__setattr__(self, "curves", tuple(self.curves))
        paths = [c.path for c in self.curves]
        if len(set(paths)) != len(paths):
            raise ParameterError("prim paths", paths[:8], "one prim per path")
        if self.color_primvar not in ("displayColor", "color"):
            raise ParameterError("colour primvar", self.color_primvar, "displayColor or color")
        xforms = []
        for item in self.xforms:
            try:
                path, values = item
                m = np.asarray(values, dtype=np.float64).reshape(4, 4)
            except (TypeError, ValueError, OverflowError):
                raise ParameterError("transform", "an entry", "(prim path, 16 numbers)") from None
            if not isinstance(path, str) or not path.startswith("/"):
                raise ParameterError("transform path", path, "an absolute prim path")
            with np.errstate(all="ignore"):  # a determinant past float64 is refused, not warned of
                det = float(np.linalg.det(m[:3, :3])) if np.all(np.isfinite(m)) else np.nan
            if not (np.isfinite(det) and abs(det) >= 1e-12) or np.any(m[:3, 3] != 0):
                raise ParameterError("transform", path, "a finite, invertible affine 4×4 (row vectors)")
            xforms.append((path, tuple(float(v) for v in m.reshape(-1))))
        if len({p for p, _ in xforms}) != len(xforms):
            raise ParameterError("transforms", [p for p, _ in xforms][:8], "one per prim")
        object.__setattr__(self, "xforms", tuple(xforms))

    def with_(self, **changes) -> Metadata:
        """A copy with some fields changed (checked again)."""
        return replace(self, **changes)

    def for_strands(self, strand_count: int) -> Metadata:
        """The prims only while they still add up to the groom's strands (else one default prim)."""
        if self.curves and sum(c.strands for c in self.curves) != strand_count:
            return replace(self, curves=())
        return self

    def subset(self, strand_ids) -> Metadata:
        """The record of a groom of some of these strands (``strand_ids`` into the prims' strands,
        end to end): each prim keeps its path, basis, wrap and purpose and holds the strands
        chosen from it; a prim none is chosen from is left out. Ids that go back into an earlier
        prim (a reordering across prims) cannot be laid out prim by prim: one default prim then."""
        if not self.curves:
            return self
        ids = np.asarray(strand_ids, dtype=np.int64).reshape(-1)
        ends = np.cumsum([c.strands for c in self.curves])
        if ids.size == 0 or ids.min() < 0 or ids.max() >= ends[-1]:
            raise ParameterError("strand ids", f"{ids.size} ids", f"ids in [0, {int(ends[-1])})")
        owner = self.prim_of(ids)
        if np.any(np.diff(owner) < 0):
            return replace(self, curves=())
        held = np.bincount(owner, minlength=len(self.curves))
        prims = tuple(replace(c, strands=int(n)) for c, n in zip(self.curves, held, strict=True) if n)
        return replace(self, curves=prims)

    def prim_of(self, strand_ids) -> np.ndarray:
        """The index into :attr:`curves` of the prim holding each strand (empty prims: all 0)."""
        ids = np.asarray(strand_ids, dtype=np.int64).reshape(-1)
        if not self.curves:
            return np.zeros(ids.size, np.int64)
        return np.searchsorted(np.cumsum([c.strands for c in self.curves]), ids, side="right")

    def extended(self, prims) -> Metadata:
        """The record after strands were appended to the groom, ``prims[k]`` the prim (index
        into :attr:`curves`) the k-th new strand belongs to. Appended at the end, they can join
        the last prim only: new strands of an earlier prim leave one default prim."""
        owners = np.asarray(prims, dtype=np.int64).reshape(-1)
        if not self.curves or owners.size == 0:
            return self
        if np.any(owners != len(self.curves) - 1):
            return replace(self, curves=())
        last = replace(self.curves[-1], strands=self.curves[-1].strands + int(owners.size))
        return replace(self, curves=(*self.curves[:-1], last))

    # -- the scene's frame --------------------------------------------------------------
    @property
    def up(self) -> np.ndarray:
        """``(3,)`` the stage's up direction: +y or +z."""
        return self.frame[:, 1].copy()

    @property
    def frame(self) -> np.ndarray:
        """``(3, 3)`` rotation from hairtool's reference frame (x lateral, y up, z front, as the
        samples are built) to the scene's axes: the identity for Y-up; for Z-up the DCCs'
        convention (x, y, z) ↦ (x, −z, y), so up is +z and the front −y (Blender's front view).
        Directions the engines define in the reference frame (gravity, a head turn's axis, a
        gust's plane) are this matrix times their reference vector."""
        if self.up_axis == "Y":
            return np.eye(3)
        return np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])

    @property
    def units_per_meter(self) -> float:
        return 1.0 / self.meters_per_unit

    def world_matrix(self, path: str) -> np.ndarray | None:
        """``(4, 4)`` local-to-world of the prim at ``path`` from :attr:`xforms` (its own and its
        ancestors' transforms, row vectors), or None when none of them has one."""
        table = dict(self.xforms)
        parts = path.strip("/").split("/")
        chain = ["/" + "/".join(parts[: k + 1]) for k in range(len(parts))][::-1]  # prim first
        found = [np.asarray(table[p], np.float64).reshape(4, 4) for p in chain if p in table]
        if not found:
            return None
        m = np.eye(4)
        for local in found:
            m = m @ local
        return m

    def derived(self, *, time_codes=None, curves: tuple[CurvesPrim, ...] | None = None) -> Metadata:
        """The record of something made from this source (a simulation, a cycle, a frozen
        pose): the same space, unit, colour primvar and prims (``curves`` to replace them), and
        the new frames' ``time_codes`` (None: a static groom). The source's authored time code
        range and rate are dropped: the new stage declares its own."""
        return replace(
            self,
            time_codes=None if time_codes is None else tuple(float(t) for t in time_codes),
            time_codes_per_second=None,
            start_time_code=None,
            end_time_code=None,
            curves=self.curves if curves is None else tuple(curves),
        )

    def first_time_code(self) -> float:
        """Where frames made from this source start: its authored start time code, else 0."""
        return 0.0 if self.start_time_code is None else float(self.start_time_code)


def default_attribute(name: str, vertex_count: int, meters_per_unit: float) -> np.ndarray:
    """Where a prim authored no ``name`` but others merged with it did: widths of 80 µm (in
    scene units), no transparency, USD's fallback grey (``displayColor`` 0.5)."""
    if name == "thickness":
        return np.full(vertex_count, HAIR_WIDTH_M / meters_per_unit, np.float32)
    if name == "transparency":
        return np.zeros(vertex_count, np.float32)
    if name == "colors":
        return np.full((vertex_count, 3), 0.5, np.float32)
    raise ParameterError("attribute", name, f"one of {', '.join(ATTRIBUTES)}")


def join_attributes(
    parts: list[dict[str, np.ndarray | None]], vertex_counts: list[int], meters_per_unit: float
) -> tuple[dict[str, np.ndarray | None], list[tuple[str, ...]]]:
    """Per-vertex attributes of several parts (prims) laid end to end: an attribute some part
    has and another lacks is kept, the lacking part's vertices filled with
    :func:`default_attribute`. Returns the joined arrays (None where no part has one) and, per
    part, the attributes it lacked (for :attr:`CurvesPrim.lacks`)."""
    out: dict[str, np.ndarray | None] = {}
    lacks: list[list[str]] = [[] for _ in parts]
    for name in ATTRIBUTES:
        values = [a.get(name) for a in parts]
        if all(v is None for v in values):
            out[name] = None
            continue
        filled = []
        for k, (v, n) in enumerate(zip(values, vertex_counts, strict=True)):
            if v is None:
                lacks[k].append(name)
                v = default_attribute(name, n, meters_per_unit)
            filled.append(np.asarray(v, np.float32))
        out[name] = np.concatenate(filled)
    return out, [tuple(x) for x in lacks]


_RECORD_NUMBERS = ("meters_per_unit", "time_codes_per_second", "start_time_code", "end_time_code")
_RECORD_FIELDS = ("up_axis", *_RECORD_NUMBERS, "color_primvar", "time_codes", "curves", "xforms")
_PRIM_KEYS = ("path", "strands", "basis", "wrap", "purpose", "lacks")


def to_record(meta: Metadata) -> dict:
    """The record as plain JSON (a project file's ``scene``)."""
    return {
        "up_axis": meta.up_axis,
        **{k: getattr(meta, k) for k in _RECORD_NUMBERS},
        "color_primvar": meta.color_primvar,
        "time_codes": None if meta.time_codes is None else list(meta.time_codes),
        "curves": [
            {k: (list(v) if isinstance(v := getattr(c, k), tuple) else v) for k in _PRIM_KEYS}
            for c in meta.curves
        ],
        "xforms": [[path, list(m)] for path, m in meta.xforms],
    }


def from_record(record: object) -> Metadata:
    """The inverse of :func:`to_record`; anything else is a ParameterError naming the field."""
    if not isinstance(record, dict) or set(record) != set(_RECORD_FIELDS):
        raise ParameterError(
            "scene", type(record).__name__, f"a record of exactly {', '.join(_RECORD_FIELDS)}"
        )
    for k in _RECORD_NUMBERS:
        v = record[k]
        if v is not None and (isinstance(v, bool) or not isinstance(v, (int, float))):
            raise ParameterError(k.replace("_", " "), v, "a number or null")
    for k in ("up_axis", "color_primvar"):
        if not isinstance(record[k], str):
            raise ParameterError(k.replace("_", " "), record[k], "a string")
    codes = record["time_codes"]
    if codes is not None and (
        not isinstance(codes, list)
        or not all(isinstance(t, (int, float)) and not isinstance(t, bool) for t in codes)
    ):
        raise ParameterError("time codes", "…", "a list of numbers or null")
    items = record["curves"]
    if not isinstance(items, list):
        raise ParameterError("curves", type(items).__name__, "a list of prims")
    prims = []
    for item in items:
        if not isinstance(item, dict) or set(item) != set(_PRIM_KEYS) or not isinstance(item["lacks"], list):
            raise ParameterError("curves", "a prim", f"a record of exactly {', '.join(_PRIM_KEYS)}")
        prims.append(CurvesPrim(**{k: (tuple(v) if k == "lacks" else v) for k, v in item.items()}))
    fields = {k: record[k] for k in ("up_axis", *_RECORD_NUMBERS, "color_primvar")}
    xforms = record["xforms"]
    if not isinstance(xforms, list) or not all(isinstance(x, list) and len(x) == 2 for x in xforms):
        raise ParameterError("xforms", type(xforms).__name__, "a list of [prim path, 16 numbers]")
    for _, m in xforms:
        if not isinstance(m, list) or not all(
            isinstance(v, (int, float)) and not isinstance(v, bool) for v in m
        ):
            raise ParameterError("xforms", "a matrix", "16 numbers")
    codes_t = None if codes is None else tuple(codes)
    return Metadata(
        **fields, time_codes=codes_t, curves=tuple(prims), xforms=tuple((x[0], tuple(x[1])) for x in xforms)
    )


def to_reference(meta: Metadata, vectors: np.ndarray) -> np.ndarray:
    """Scene-axis vectors ``(..., 3)`` in hairtool's reference frame (the inverse of ``frame``)."""
    return np.asarray(vectors, dtype=np.float64) @ meta.frame
