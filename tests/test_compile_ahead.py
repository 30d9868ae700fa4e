"""Kernels compiled ahead in a forked process: the call waits for it and loads the kernel from
the cache instead of compiling it; a process whose kernels were not needed is stopped."""

from __future__ import annotations

import importlib
import signal
import sys
import uuid

import pytest
from numba.core import types

from hairtool import compile_ahead

SOURCE = """
from numba import njit

@njit(cache=True)
def kernel(x):
    return x + 1
"""

pytestmark = pytest.mark.skipif(not compile_ahead.can_fork(), reason="forks (Linux)")


@pytest.fixture
def kernel(tmp_path, monkeypatch):
    """A cached kernel (``x + 1``) of a module file of its own, nothing compiled yet."""
    monkeypatch.syspath_prepend(str(tmp_path))
    name = f"ahead_kernel_{uuid.uuid4().hex}"
    (tmp_path / f"{name}.py").write_text(SOURCE)
    importlib.invalidate_caches()
    yield importlib.import_module(name).kernel
    sys.modules.pop(name, None)


def test_a_kernel_compiled_ahead_is_loaded_at_its_call_not_compiled(kernel):
    plan = [(kernel, (types.float64,))]
    assert compile_ahead.cold_entries(plan) == plan
    ahead = compile_ahead.start(plan)
    assert ahead is not None and ahead.pid is not None
    assert kernel(2.0) == 3.0  # waits for the forked process, then loads its work
    assert ahead.pid is None and ahead.status == 0
    assert not kernel._cache_misses and sum(kernel._cache_hits.values()) == 1
    assert "compile" not in vars(kernel)  # numba's own compile again, for any other type
    assert kernel(2) == 3 and sum(kernel._cache_misses.values()) == 1
    assert compile_ahead.cold_entries(plan) == [] and compile_ahead.start(plan) is None


def test_closing_stops_the_process_and_the_call_still_gets_its_kernel(kernel):
    ahead = compile_ahead.start([(kernel, (types.float64,)), (kernel, (types.int64,))])
    ahead.close()  # whether or not it had finished: reaped, and the kernel compiles as usual
    assert ahead.pid is None and ahead.status in (0, -signal.SIGKILL)
    assert "compile" not in vars(kernel)
    assert kernel(2) == 3 and kernel(2.5) == 3.5
    ahead.close()  # (twice is harmless)


def test_a_kernel_in_this_process_is_not_compiled_again(kernel):
    kernel(1.0)
    assert compile_ahead.start([(kernel, (types.float64,))]) is None


def test_a_forked_process_past_the_wait_limit_is_stopped_and_the_call_compiles(kernel, monkeypatch):
    monkeypatch.setattr(compile_ahead, "WAIT_LIMIT_S", 0.0)
    ahead = compile_ahead.start([(kernel, (types.float64,))])
    assert kernel(2.0) == 3.0  # the compile takes far longer than no time at all: stopped
    assert ahead.status == -signal.SIGKILL and ahead.pid is None
    assert sum(kernel._cache_misses.values()) == 1  # compiled here
