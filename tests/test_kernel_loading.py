"""Loading a kernel's cached code before its first call: what the cache holds for the running
source is loaded without compiling; anything else is left for the call."""

from __future__ import annotations

import importlib
import os
import sys
import uuid
from pathlib import Path

import pytest
from numba import njit

from hairtool.kernel_loading import cached_signatures, load_cached

SOURCE = """
from numba import njit

@njit(cache=True)
def kernel(x):
    return x {op} 1
"""


@pytest.fixture
def module(tmp_path, monkeypatch):
    """``make(op)``: a module file with a cached kernel (``x op 1``), imported afresh each call."""
    monkeypatch.syspath_prepend(str(tmp_path))
    name = f"cached_kernel_{uuid.uuid4().hex}"
    path = tmp_path / f"{name}.py"

    writes = [0]

    def make(op: str = "+"):
        text = SOURCE.format(op=op)
        if not path.exists() or path.read_text() != text:
            path.write_text(text)
            # numba knows a source by its size and mtime: "+" and "-" are the same size, and two
            # writes within one tick of a loaded host's clock left the same mtime
            writes[0] += 1
            os.utime(path, (1_700_000_000 + writes[0], 1_700_000_000 + writes[0]))
        sys.modules.pop(name, None)
        importlib.invalidate_caches()
        return importlib.import_module(name)

    yield make
    sys.modules.pop(name, None)


def test_a_cached_overload_loads_without_compiling_and_runs(module):
    first = module().kernel
    assert first(2.0) == 3.0 and first(2) == 3  # two overloads, now in the cache
    kernel = module().kernel  # a new dispatcher of the same source: nothing loaded yet
    assert not kernel.overloads
    sigs = cached_signatures(kernel)
    assert len(sigs) == 2
    for sig in sigs:
        load_cached(kernel, sig)
    assert set(kernel.overloads) == set(sigs)
    assert not kernel._cache_misses and sum(kernel._cache_hits.values()) == 2  # loaded, none compiled
    assert kernel(4.0) == 5.0 and not kernel._cache_misses
    assert cached_signatures(kernel) == []  # what is loaded is not offered again


def test_the_cache_of_other_source_or_a_lost_data_file_offers_nothing(module, tmp_path):
    module("+").kernel(1.0)
    changed = module("-").kernel  # the source changed since the cache was written
    assert cached_signatures(changed) == []
    changed(1.0)  # (its own cache now)
    kernel = module("-").kernel
    assert len(cached_signatures(kernel)) == 1
    data = list(Path(kernel._cache._cache_path).glob("*.nbc"))  # wherever numba keeps it
    assert data
    for path in data:
        path.unlink()
    assert cached_signatures(kernel) == []


def test_a_kernel_without_a_cache_offers_nothing():
    @njit
    def plain(x):
        return x

    plain(1.0)
    assert cached_signatures(plain) == []
