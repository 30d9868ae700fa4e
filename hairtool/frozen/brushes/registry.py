"""The brushes there are (:class:`~.spec.Brush` objects): every module of this package that
holds a ``BRUSH``, found at run time (as the command line finds its commands), in the order their specs give.

Adding a brush is adding its module; the name lists the rest of the code reads
(:func:`names`, :func:`names_where`) are derived from the specs.
"""

from __future__ import annotations

import functools
import importlib
import pkgutil
from typing import Any


@functools.cache
def _brushes() -> dict[str, Any]:
    package = __name__.rpartition(".")[0]
    path = importlib.import_module(package).__path__
    found: list[Any] = []
    for info in pkgutil.iter_modules(path):
        module = importlib.import_module(f"{package}.{info.name}")
        brush = getattr(module, "BRUSH", None)
        if brush is not None and hasattr(brush, "spec"):
            found.append(brush)
    found.sort(key=lambda b: b.spec.order)
    orders = [b.spec.order for b in found]
    names = [b.spec.name for b in found]
    if len(set(orders)) != len(orders) or len(set(names)) != len(names):
        raise RuntimeError(f"two brushes share a name or an order: {list(zip(names, orders, strict=True))}")
    return {b.spec.name: b for b in found}


def names() -> tuple[str, ...]:
    """Every brush's name, in order (align first)."""
    return tuple(_brushes())


def brush_of(name: str) -> Any:
    """The brush called ``name`` (KeyError for none)."""
    return _brushes()[name]


def spec_of(name: str) -> Any:
    """The spec of the brush called ``name`` (KeyError for none)."""
    return _brushes()[name].spec


def specs() -> tuple[Any, ...]:
    """Every brush's spec, in order."""
    return tuple(b.spec for b in _brushes().values())


def names_where(**flags: bool) -> tuple[str, ...]:
    """The brushes whose spec has each of ``flags`` (e.g. ``moves_points=False``), in order."""
    return tuple(s.name for s in specs() if all(getattr(s, k) == v for k, v in flags.items()))


def name_of(sample) -> str | None:
    """The brush a sample belongs to (an AlignSample has no ``brush`` field: align; a selection
    step belongs to none)."""
    name = getattr(sample, "brush", None)
    return name if name is not None else ("align" if hasattr(sample, "intensity") else None)
