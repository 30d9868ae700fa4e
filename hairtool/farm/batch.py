"""A batch from jobs to report rows: skip what the manifests show done, send the rest to Dask as
one task each, and record every job that finishes.

A job that fails is a row with its one-line error, and the batch goes on. A worker killed
while it runs a job makes Dask's scheduler run the task again on another worker (the job is
whole, its outputs atomic, so nothing is half-written); when the scheduler gives up (after
:data:`~hairtool.farm.cluster.ALLOWED_FAILURES` deaths on a local cluster) it is reported failed. Every job
that finishes is written into its manifest at once, so a batch stopped half-way resumes.
"""

from __future__ import annotations

import contextlib
import secrets
import stat
import sys
import time
from collections.abc import Sequence
from dataclasses import dataclass, field

from hairtool.errors import HairtoolError
from hairtool.farm.jobs import Job
from hairtool.farm.manifest import Manifests, named_paths
from hairtool.farm.progress import Progress


@dataclass
class BatchResult:
    rows: list[dict]
    seconds: float
    scheduler: str  # "local" or the address given
    workers: int = 0  # worker processes seen when the batch started (0: nothing ran)
    warnings: list[str] = field(default_factory=list)

    def count(self, status: str) -> int:
        return sum(r["status"] == status for r in self.rows)

    def summary(self) -> dict:
        return {
            "jobs": len(self.rows),
            "done": self.count("done"),
            "skipped": self.count("skipped"),
            "failed": self.count("failed"),
            "seconds": round(self.seconds, 3),
            "scheduler": self.scheduler,
            "workers": self.workers,
        }


def row(job: Job, status: str, seconds: float | None, error: str | None = None, **extra) -> dict:
    """A report row: the job, its status and time, then the command's own numbers."""
    return {
        "index": job.index,
        "command": job.command,
        "args": list(job.args),
        "input": job.input,
        "status": status,
        "error": error,
        "seconds": None if seconds is None else round(seconds, 4),
        **extra,
    }


def _skipped(job: Job, entry: dict) -> dict:
    return row(job, "skipped", 0.0, outputs=sorted(entry["outputs"]), **entry.get("fields", {}))


def _finished(job: Job, result: dict) -> dict:
    return row(
        job,
        result["status"],
        result["seconds"],
        result["error"],
        outputs=sorted(result["outputs"]),
        worker=result["worker"],
        **result["fields"],
    )


def shared_outputs(rows: list[dict]) -> list[str]:
    """One line per file that two jobs of the batch wrote (say, a glob template without
    ``{stem}``): only the job that finished last left its output there."""
    writer: dict[str, int] = {}
    lines = []
    for r in rows:
        if r["status"] != "done":
            continue
        for path in r.get("outputs", ()):
            if path in writer:
                lines.append(f"job {writer[path] + 1} and job {r['index'] + 1} both wrote {path}")
            writer.setdefault(path, r["index"])
    return lines


def default_threads(scheduler: str | None, workers: int) -> int | None:
    """Numba threads per job: the local cores shared among the local workers; a remote
    worker's own setting (``NUMBA_NUM_THREADS``) on a scheduler."""
    from hairtool.farm.cluster import cores

    return None if scheduler is not None else max(1, cores() // workers)


def _outcome(future, job: Job) -> tuple[dict, dict | None]:
    """The report row of a finished task and, when the job is done, its
    :func:`~hairtool.farm.runner.run_job` result (for the manifest)."""
    from distributed import CancelledError, KilledWorker

    try:
        result = future.result()
    except KilledWorker as e:  # the scheduler's allowed-failures ran out
        last = getattr(e.last_worker, "address", "unknown")
        deaths = (
            f"{e.allowed_failures + 1} times" if isinstance(e.allowed_failures, int) else "again and again"
        )
        return row(
            job, "failed", None, f"the worker running it died {deaths} (the last: {last}); Dask gave up"
        ), None
    except CancelledError:
        lost = "cancelled: the scheduler lost the job (restarted or shut down?)"
        return row(job, "failed", None, lost), None
    except Exception as e:  # the task could not run at all (say, hairtool missing on a worker)
        return row(job, "failed", None, f"{type(e).__name__}: {e}".splitlines()[0]), None
    return _finished(job, result), result if result["status"] == "done" else None


def _record(manifests: Manifests, done: list[tuple[Job, dict]], warnings: list[str]) -> None:
    try:
        manifests.record_many(done)
    except HairtoolError as e:
        warnings.append(str(e))


def _collect(future, job: Job, manifests: Manifests, warnings: list[str]) -> dict:
    """The report row of one finished task, its job recorded in the manifest when done."""
    r, result = _outcome(future, job)
    if result is not None:
        _record(manifests, [(job, result)], warnings)
    return r


def input_bytes(job: Job) -> int:
    """Bytes of the existing files the job's arguments name: how long it will run, roughly."""
    total = 0
    for p in named_paths(job.args, job.base):
        with contextlib.suppress(OSError):
            st = p.stat()
            if stat.S_ISREG(st.st_mode):
                total += st.st_size
    return total


def _run_on_dask(client, todo: list[Job], threads, manifests, rows, progress, warnings) -> None:
    """One task per job, the largest inputs first: a batch ends when its last job does, and a long
    job started last would leave the other workers idle while it runs (the short ones fill in at the
    end instead). Results are taken as they arrive; those that arrive together go into their
    manifest in one write."""
    from distributed import as_completed

    from hairtool.farm.runner import run_job

    batch_id = secrets.token_hex(4)
    sizes = {job.index: input_bytes(job) for job in todo}
    order = sorted(todo, key=lambda job: -sizes[job.index])  # stable: equal sizes keep file order
    futures = {
        client.submit(
            run_job,
            job,
            threads,
            key=f"hairtool-batch-{batch_id}-{job.index}",
            pure=False,
            priority=len(order) - rank,
        ): job
        for rank, job in enumerate(order)
    }
    slots = max(1, sum(client.nthreads().values()))
    left = len(futures)
    progress.update(running=min(left, slots))
    try:
        for finished in as_completed(futures).batches():
            done = []
            for future in finished:
                job = futures[future]
                r, result = _outcome(future, job)
                rows[job.index] = r
                if result is not None:
                    done.append((job, result))
                future.release()
            if done:
                _record(manifests, done, warnings)
            for future in finished:
                left -= 1
                ok = rows[futures[future].index]["status"] == "done"
                progress.update(done=int(ok), failed=int(not ok), running=min(left, slots))
    except BaseException:
        client.cancel(list(futures))
        raise


def run_batch(
    jobs: Sequence[Job],
    *,
    scheduler: str | None = None,
    workers: int | None = None,
    threads: int | None = None,
    force: bool = False,
    progress: Progress | None = None,
    client=None,
) -> BatchResult:
    """Run ``jobs`` (those not already done, all with ``force``) and return one row per job.

    ``client``: a ``distributed.Client`` to use as it is; else one is opened on ``scheduler``
    or on a local cluster of ``workers`` processes (:func:`~hairtool.farm.cluster.open_client`).
    ``threads``: numba threads per job (default :func:`default_threads`).
    """
    from hairtool.farm.cluster import local_workers, open_client

    t0 = time.perf_counter()
    progress = progress or Progress(enabled=False)
    manifests = Manifests()
    rows: dict[int, dict] = {}
    todo = []
    for job in jobs:
        entry = None if force else manifests.find_done(job)
        if entry is not None:
            rows[job.index] = _skipped(job, entry)
        else:
            todo.append(job)
    result = BatchResult([], 0.0, scheduler or "local")
    progress.start(len(jobs), len(rows))
    try:
        if todo:
            if client is not None:
                result.workers = len(client.nthreads())
                _run_on_dask(client, todo, threads, manifests, rows, progress, result.warnings)
            else:
                n = local_workers(workers) if scheduler is None else 0
                if threads is None:
                    threads = default_threads(scheduler, n)
                with open_client(scheduler, n or None) as c:
                    result.workers = len(c.nthreads())
                    _run_on_dask(c, todo, threads, manifests, rows, progress, result.warnings)
    finally:
        progress.finish()
    result.rows = [rows[job.index] for job in jobs if job.index in rows]
    result.seconds = time.perf_counter() - t0
    result.warnings += shared_outputs(result.rows)
    for w in result.warnings:
        print(f"hairtool batch: warning: {w}", file=sys.stderr)
    return result
