"""Where a batch's jobs run: a Dask cluster of local processes, or a running Dask scheduler.

Dask is imported here only, when a batch runs, so the library and the other commands work
without it; a missing Dask is one line saying how to install it.
"""

from __future__ import annotations

import contextlib
import logging
import os
import sys
from collections.abc import Iterator
from types import ModuleType

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


@contextlib.contextmanager
def _workers_write_no_tracebacks() -> Iterator[None]:
    """fd 2 pointed at /dev/null while the local cluster starts its worker processes, which
    inherit it. Ctrl+C in the terminal reaches the whole process group: a worker then raises
    KeyboardInterrupt wherever it is (importing, or running a job), and its traceback must not
    stand beside the command's one "interrupted" line. A worker has nothing else to say on fd 2:
    its logs are silenced (:data:`LOCAL_LOG_LEVEL`) and a job's output comes back as its result.
    (Ignoring SIGINT while the workers start, which they would inherit too, would lose a Ctrl+C
    pressed meanwhile in this process.)"""
    sys.stderr.flush()
    saved = os.dup(2)
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, 2)
    os.close(devnull)
    try:
        yield
    finally:
        os.dup2(saved, 2)
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
    with dask.config.set(config), _workers_write_no_tracebacks():
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
