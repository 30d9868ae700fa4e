"""Where a batch's jobs run: a Dask cluster of local processes, or a running Dask scheduler.

Dask is imported here only, when a batch runs, so the library and the other commands work
without it; a missing Dask is one line saying how to install it.
"""

from __future__ import annotations

import contextlib
import logging
import os
import sys
import threading
from collections.abc import Iterator
from types import ModuleType

from hairtool import interrupts
from hairtool.errors import HairtoolError, ParameterError

INSTALL_HINT = "pip install 'hairtool[farm]' (or pip install 'dask[distributed]')"
#: Seconds to wait for a scheduler to answer before giving up.
CONNECT_TIMEOUT_S = 20.0
#: A job whose worker died this many times is reported failed (Dask's allowed-failures + 1).
ALLOWED_FAILURES = 3
#: Local workers' housekeeping, slowed: by default each samples its running task's stack every
#: 10 ms (the statistical profiler) and wakes its event loop every 20 ms to time it, taking the
#: GIL from the job each time; on a machine whose every core runs a job, that is the jobs' time.
QUIET_WORKERS = {
    "distributed.worker.profile.enabled": False,
    "distributed.admin.tick.interval": "1s",
    "distributed.admin.system-monitor.interval": "2s",
    "distributed.worker.memory.monitor-interval": "1s",
}


#: Distributed's own log lines on a local cluster that pass, in this process (its scheduler and
#: nannies) and in the workers: CRITICAL only. A killed worker makes it log ERROR tracebacks (a
#: result it held lost, its replacement's heartbeat to a cluster closing) that the batch recovers
#: from; what does fail reaches the user as one line per job (:mod:`hairtool.farm.batch`).
LOCAL_LOG_LEVEL = logging.CRITICAL


def require_dask() -> ModuleType:
    """``distributed``, or a :class:`HairtoolError` naming the missing extra."""
    try:
        import distributed
    except ImportError:
        raise HairtoolError(
            f"hairtool batch runs jobs on Dask, which is not installed; {INSTALL_HINT}"
        ) from None
    return distributed


def cores() -> int:
    """Cores this process may run on."""
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1


def local_workers(requested: int | None) -> int:
    """Worker processes of a local cluster: ``requested``, or one per core."""
    if requested is None:
        return cores()
    if requested < 1:
        raise ParameterError("workers", requested, "a whole number ≥ 1")
    return requested


#: Seconds a worker's line waits before it is passed on: a Ctrl+C reaches this process and the
#: workers at once, and what a worker prints after it must not follow the "interrupted" line.
HOLD_S = 0.3


def _forward(read_fd: int) -> None:
    """Pass what the workers write on to this process's stderr, each piece after
    :data:`HOLD_S`, and nothing once an interrupt has arrived."""
    import time

    with os.fdopen(read_fd, "rb", buffering=0) as pipe:
        while chunk := pipe.read(65536):
            time.sleep(HOLD_S)
            if interrupts.was_interrupted():
                continue  # drained, so no worker blocks on a full pipe
            try:
                os.write(2, chunk)
            except OSError:
                pass


@contextlib.contextmanager
def _workers_write_through_a_filter() -> Iterator[threading.Thread]:
    """The workers' fd 2 is a pipe this process passes on (:func:`_forward`), set while the local
    cluster starts its processes, which inherit it. Ctrl+C in the terminal reaches the whole
    process group: a worker then raises KeyboardInterrupt wherever it is (importing, or running
    a job), and its traceback must not stand beside the command's one "interrupted" line, while
    the lines distributed lets through (CRITICAL) still reach the terminal. (Ignoring SIGINT
    while the workers start, which they would inherit too, would lose a Ctrl+C pressed
    meanwhile in this process.)"""
    sys.stderr.flush()
    read_fd, write_fd = os.pipe()
    forward = threading.Thread(target=_forward, args=(read_fd,), name="hairtool-worker-stderr", daemon=True)
    forward.start()
    saved = os.dup(2)
    os.dup2(write_fd, 2)
    os.close(write_fd)
    try:
        yield forward  # ends once every worker has closed the pipe (join it after the cluster)
    finally:
        interrupts.restore_stderr(saved)  # this process's own stderr again; the pipe stays the workers'
        os.close(saved)


@contextlib.contextmanager
def open_client(scheduler: str | None = None, workers: int | None = None) -> Iterator[object]:
    """A ``distributed.Client``: connected to ``scheduler`` (``tcp://HOST:PORT``), or to a local
    cluster of ``workers`` processes with one thread each, started here and closed on exit."""
    distributed = require_dask()
    import dask

    if scheduler is not None:
        if "://" not in scheduler and ":" not in scheduler:
            raise ParameterError("scheduler", scheduler, "a Dask scheduler address such as tcp://HOST:8786")
        try:
            client = distributed.Client(scheduler, timeout=CONNECT_TIMEOUT_S)
        except (OSError, TimeoutError, ValueError) as e:
            raise HairtoolError(f"cannot reach the Dask scheduler at {scheduler}: {e}") from None
        try:
            yield client
        finally:
            client.close()
        return
    n = local_workers(workers)
    config = {"distributed.scheduler.allowed-failures": ALLOWED_FAILURES - 1, **QUIET_WORKERS}
    with dask.config.set(config), _workers_write_through_a_filter() as forward:
        try:
            cluster = distributed.LocalCluster(
                n_workers=n,
                threads_per_worker=1,
                processes=True,
                host="127.0.0.1",
                dashboard_address="127.0.0.1:0",  # its status pages: loopback, any free port
                silence_logs=LOCAL_LOG_LEVEL,
            )
        except (OSError, RuntimeError, TimeoutError, ValueError) as e:  # no ports, processes, memory
            raise HairtoolError(f"cannot start a local Dask cluster of {n} workers: {e}") from None
    try:
        client = distributed.Client(cluster)
        try:
            yield client
        finally:
            client.close()
    finally:
        cluster.close()
        forward.join(timeout=5.0)  # the workers' last lines passed on before the command goes on
