"""A cold command's kernels compiled on both cores: a forked process compiles some of them into
the cache while this one goes on with the command.

numba compiles one kernel at a time, on one core (a global lock in the process). On an empty
cache nearly all of a first ``hairtool freeze`` is compiling, so a 2-core machine leaves a core
idle for most of it. :func:`start` forks a process that compiles a plan's kernels, each for its
argument types (what the command will call them with), into numba's cache; this process goes on
compiling the others as the command reaches them. The first time it needs a kernel of the plan
it waits for the forked process and loads that kernel from the cache instead of compiling it.

Only the time changes: the machine code is the same code compiled for the same types. A plan
entry whose types drifted from the call's is compiled in vain and the call compiles its own;
where the forked process failed or could not write the cache, the call compiles the kernel here,
as it would have. Where the cache already holds every kernel of the plan, nothing is forked.
"""

from __future__ import annotations

import os
import signal
import sys
import time

from numba.core.caching import NullCache
from numba.core.dispatcher import Dispatcher

from hairtool.kernel_loading import cached_signatures

#: (kernel, argument types): one compile of a plan.
Entry = tuple[Dispatcher, tuple]
#: Seconds a call waits for the forked process before stopping it and compiling the kernel
#: itself (the plan's 5 CPU seconds took under a minute on a VM loaded eightfold).
WAIT_LIMIT_S = 300.0


def cold_entries(plan: list[Entry]) -> list[Entry]:
    """The entries of ``plan`` that neither this process nor the cache holds."""
    return [(k, sig) for k, sig in plan if sig not in k.overloads and sig not in cached_signatures(k)]


def can_fork() -> bool:
    """Linux only: the forked process is a copy of this one, numba loaded and nothing to import
    (elsewhere fork is unsafe or absent)."""
    return sys.platform.startswith("linux") and hasattr(os, "fork")


class Ahead:
    """The forked process compiling a plan's kernels; :meth:`wait` for it, :meth:`close` at
    the end of the command's part that calls them."""

    def __init__(self, pid: int, kernels: list[Dispatcher]) -> None:
        self.pid: int | None = pid
        self.kernels = kernels
        self.status: int | None = None  # the forked process's exit status, once waited for
        for kernel in kernels:  # numba calls ``self.compile`` for a new type at a call or in typing
            kernel.compile = _Waiting(self, kernel)

    def wait(self) -> None:
        """Wait for the forked process to finish, at most :data:`WAIT_LIMIT_S` (then stop it),
        and let every kernel of the plan load or compile as usual from then on."""
        for kernel in self.kernels:
            kernel.__dict__.pop("compile", None)
        if self.pid is None:
            return
        deadline = time.monotonic() + WAIT_LIMIT_S
        done, status = os.waitpid(self.pid, os.WNOHANG)
        while not done and time.monotonic() < deadline:
            time.sleep(0.005)
            done, status = os.waitpid(self.pid, os.WNOHANG)
        if not done:
            os.kill(self.pid, signal.SIGKILL)
            _, status = os.waitpid(self.pid, 0)
        self.pid, self.status = None, os.waitstatus_to_exitcode(status)

    def close(self) -> None:
        """Stop the forked process if it is still compiling kernels the command did not need,
        and reap it (numba writes a cache file under a temporary name and renames it, so a kill
        leaves at most that temporary file; an index entry without its data is compiled anew)."""
        if self.pid is not None:
            try:
                os.kill(self.pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
        self.wait()


class _Waiting:
    """A plan kernel's ``compile`` until the forked process is done."""

    def __init__(self, ahead: Ahead, kernel: Dispatcher) -> None:
        self.ahead, self.kernel = ahead, kernel

    def __call__(self, sig):
        self.ahead.wait()
        return type(self.kernel).compile(self.kernel, sig)


def start(plan: list[Entry]) -> Ahead | None:
    """Fork a process that compiles the cold entries of ``plan`` (in its order) into the cache;
    None where nothing is cold, a kernel has no cache, or this platform cannot fork."""
    cold = cold_entries(plan)
    uncached = any(isinstance(getattr(k, "_cache", None), (NullCache, type(None))) for k, _ in cold)
    if not cold or uncached or not can_fork():
        return None
    sys.stdout.flush()
    sys.stderr.flush()
    pid = os.fork()
    if pid == 0:  # the forked process: compile, write the cache, and leave without cleanup
        status = 0
        try:
            signal.signal(signal.SIGINT, signal.SIG_DFL)
            for kernel, sig in cold:
                kernel.compile(sig)
        except BaseException:
            status = 1
        os._exit(status)
    return Ahead(pid, list(dict.fromkeys(k for k, _ in cold)))
