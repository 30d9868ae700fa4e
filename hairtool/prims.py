"""Each curve prim of a scene is a groom of its own: hair and eyebrows are never clumped together.

A DCC scene may hold several hair systems (hair under the head, eyebrows under their own
parent), each a curve prim. A command works on each prim picked (``--prim PATH``, repeatable,
``fnmatch`` globs such as ``/root/*/Brows*``; all of them by default) as one groom, and lays the
results back in the source's order; the prims not picked pass through as they were. A prim's
result keeps its path, basis, wrap and purpose, whatever its strand count became.
"""

from __future__ import annotations

import fnmatch
from collections.abc import Callable, Sequence

import numpy as np

from hairtool.errors import ParameterError
from hairtool.groom import Groom
from hairtool.metadata import CurvesPrim, join_attributes


def prim_paths(groom: Groom) -> list[str]:
    """The paths of the groom's source prims, in order (empty for a groom of one default prim).

    Parameters
    ----------
    groom : Groom
        A groom read from a scene.

    Returns
    -------
    list of str
        Its prims' paths.
    """
    return [c.path for c in groom.metadata.for_strands(groom.strand_count).curves]


def picked(groom: Groom, patterns: Sequence[str] | None) -> list[bool]:
    """Per source prim, whether one of ``patterns`` (globs over prim paths) picks it; None or
    empty picks all. A pattern that picks no prim is refused, naming the prims there are.

    Parameters
    ----------
    groom : Groom
        A groom read from a scene.
    patterns : sequence of str or None
        fnmatch globs over prim paths (``--prim``).

    Returns
    -------
    list of bool
        One per prim (one for a groom of one default prim).
    """
    paths = prim_paths(groom)
    if not patterns:
        return [True] * max(len(paths), 1)
    if not paths:
        raise ParameterError("prim", patterns[0], "a prim path of the input; it holds no named prims")
    for p in patterns:
        if not any(fnmatch.fnmatchcase(path, p) for path in paths):
            shown = ", ".join(paths[:8]) + (" …" if len(paths) > 8 else "")
            raise ParameterError("prim", p, f"a path or glob matching a prim of the input ({shown})")
    return [any(fnmatch.fnmatchcase(path, p) for p in patterns) for path in paths]


def split(groom: Groom) -> list[Groom]:
    """The groom of each source prim, in order (the groom itself where it has one prim).

    Parameters
    ----------
    groom : Groom
        A groom read from a scene.

    Returns
    -------
    list of Groom
        One groom per prim.
    """
    prims = groom.metadata.for_strands(groom.strand_count).curves
    if len(prims) <= 1:
        return [groom]
    ends = np.cumsum([c.strands for c in prims])
    return [groom.subset(np.arange(e - c.strands, e)) for c, e in zip(prims, ends, strict=True)]


def _as_prim(source: Groom, result: Groom) -> CurvesPrim | None:
    """The prim ``result`` (made from ``source``, one prim) is written as: the source's prim,
    holding the result's strands."""
    prims = source.metadata.for_strands(source.strand_count).curves
    if not prims:
        return None
    (prim,) = prims
    return CurvesPrim(prim.path, result.strand_count, prim.basis, prim.wrap, prim.purpose, prim.lacks)


def join(sources: Sequence[Groom], results: Sequence[Groom]) -> Groom:
    """The prims' results end to end as one groom, in the record of the first source, each
    result written as its source's prim. Attributes present in every source are joined; one a
    result lacks is taken from nowhere, so the results must carry what their sources did.

    Parameters
    ----------
    sources : sequence of Groom
        The prims' grooms as :func:`split` gave them.
    results : sequence of Groom
        What a command made of each, in the same order.

    Returns
    -------
    Groom
        One groom on the sources' prims.
    """
    if len(results) == 1:
        prim = _as_prim(sources[0], results[0])
        meta = results[0].metadata.with_(curves=() if prim is None else (prim,))
        return results[0].with_metadata(meta)
    attrs = {}
    for name in ("thickness", "transparency", "colors"):
        values = [getattr(r, name) for r in results]
        if all(v is None for v in values):
            attrs[name] = None
        elif any(v is None for v in values):
            raise ParameterError(name, "on some prims", "a result of every prim carrying it")
        else:
            attrs[name] = np.concatenate(values)
    prims = tuple(_as_prim(s, r) for s, r in zip(sources, results, strict=True))
    meta = sources[0].metadata.with_(curves=prims)
    points = np.concatenate([r.points for r in results])
    counts = np.concatenate([r.counts for r in results])
    return Groom(points, counts, **attrs, metadata=meta)


def per_prim(
    groom: Groom, work: Callable[[Groom], Groom | None], patterns: Sequence[str] | None = None
) -> Groom:
    """``work`` run on the groom of each picked prim (:func:`picked`), the others passed through
    as they were, laid back in the source's order (:func:`join`). ``work`` returns None for a
    prim it emptied (every strand deleted): that prim is left out, the caller saying so; a
    scene of none left is refused.

    Parameters
    ----------
    groom : Groom
        A groom read from a scene.
    work : callable
        Groom → groom (or None: emptied), run on each picked prim.
    patterns : sequence of str, optional
        fnmatch globs over prim paths (None: every prim).

    Returns
    -------
    Groom
        The results and the prims passed through, in the source's order.
    """
    chosen = picked(groom, patterns)
    parts = split(groom)
    results = [work(g) if pick else g for g, pick in zip(parts, chosen, strict=True)]
    kept = [(g, r) for g, r in zip(parts, results, strict=True) if r is not None]
    if not kept:
        raise ParameterError(
            "strokes", "every strand of every prim", "strokes that leave at least one strand"
        )
    return join([g for g, _ in kept], [r for _, r in kept])


def concat(parts: Sequence[Groom]) -> Groom:
    """Grooms each on prims of their own (render hair beside its guides, one part per source
    prim) end to end as one groom, every part's prims kept; an attribute some parts lack is
    filled with defaults there and those parts' prims say they lack it, so a writer leaves it
    out of them again.

    Parameters
    ----------
    parts : sequence of Groom
        Grooms, each on prims of its own.

    Returns
    -------
    Groom
        One groom holding every part's prims.
    """
    if len(parts) == 1:
        return parts[0]
    meta = parts[0].metadata
    attrs, lacks = join_attributes(
        [dict(p.attributes) for p in parts], [p.vertex_count for p in parts], meta.meters_per_unit
    )
    curves = []
    for part, lack in zip(parts, lacks, strict=True):
        prims = part.metadata.for_strands(part.strand_count).curves
        if not prims:
            raise ParameterError("prims", repr(part), "a part on prims of its own")
        curves += [
            CurvesPrim(c.path, c.strands, c.basis, c.wrap, c.purpose, tuple(sorted(set(c.lacks) | set(lack))))
            for c in prims
        ]
    points = np.concatenate([p.points for p in parts])
    counts = np.concatenate([p.counts for p in parts])
    return Groom(points, counts, **attrs, metadata=meta.with_(curves=tuple(curves)))


def shares(total: int, weights: Sequence[int]) -> list[int]:
    """``total`` split in proportion to ``weights`` (largest remainders), each share at least 1.

    Parameters
    ----------
    total : int
        What is shared out.
    weights : sequence of int
        One weight per share, > 0 in total.

    Returns
    -------
    list of int
        The shares, summing to ``total`` where it is at least their count.
    """
    w = np.asarray(weights, np.float64)
    exact = total * w / w.sum()
    out = np.maximum(np.floor(exact).astype(np.int64), 1)
    order = np.argsort(-(exact - np.floor(exact)), kind="stable")
    for k in order[: max(total - int(out.sum()), 0)]:
        out[k] += 1
    return [int(v) for v in out]
