"""Loading a kernel's cached machine code before its first call.

numba loads a ``cache=True`` kernel from its on-disk cache only when the kernel is first called
(a few milliseconds each: the code is unpickled and linked). A brush's first move calls a dozen
kernels nobody has called yet, so the first move of an artist's first comb stroke on the bear
took 110-130 ms more than the next ones (2-core VM), all of it in numba's cache loading. The
studio loads them ahead, one per idle turn of its event loop (:mod:`app.ui.kernel_preload`).

Only what the cache holds for the running code is loaded: an entry whose data file is missing or
that was written for other source or another machine is left for numba to compile at the call,
as it would have anyway.
"""

from __future__ import annotations

import os

from numba.core.dispatcher import Dispatcher


def cache_index(kernel: object) -> dict:
    """numba's on-disk index of ``kernel``'s cache (index key → data file name); empty when the
    kernel has no cache, its index is missing or was written for other source, or numba's cache
    internals moved. The one place that reads them."""
    files = getattr(getattr(kernel, "_cache", None), "_cache_file", None)
    if files is None:
        return {}
    try:
        return files._load_index()
    except Exception:  # an unreadable index, or internals that moved: as if nothing were cached
        return {}


def cached_signatures(kernel: Dispatcher) -> list[tuple]:
    """The argument types of every overload of ``kernel`` its cache can load without compiling,
    less those already loaded; empty for a kernel without a cache or with an unreadable one."""
    index = cache_index(kernel)
    if not index:
        return []
    try:
        cache, codegen = kernel._cache, kernel.targetctx.codegen()
        out = []
        for key, data_name in index.items():
            sig = key[0]
            if sig in kernel.overloads or cache._index_key(sig, codegen) != key:
                continue
            if os.path.exists(cache._cache_file._data_path(data_name)):
                out.append(sig)
        return out
    except Exception:  # numba's cache internals moved: load at the call
        return []


def load_cached(kernel: Dispatcher, sig: tuple) -> None:
    """Load one overload :func:`cached_signatures` named (numba's own path: a call with these
    types would take it; were the data file to have gone bad since, numba compiles it now, as it
    would have at the call)."""
    kernel.compile(sig)
