"""Each Dask worker warms the kernel cache once, before its first job.

A new farm machine (a fresh container) has an empty kernel cache, and every worker on it would
compile the same kernels side by side for its first job: on two workers of a 2-core machine,
twice the compile time, with both cores busy. :class:`WarmWorker` is a worker plugin: when a
worker starts (or joins later), it runs :func:`hairtool.first_runs.warm_once` for the batch's
commands. The workers of one machine take turns on a lock, so the first one compiles and the
others find its record and load the kernels at their first call; a worker of a machine already
warmed (the image ran ``hairtool cache warm``) does nothing.
``HAIRTOOL_WARM_WORKERS=0`` leaves it out (a batch whose every job is tiny).
"""

from __future__ import annotations

import os

from distributed import WorkerPlugin


class WarmWorker(WorkerPlugin):
    """Runs the warm-up of ``commands`` (``hairtool`` command names) on the worker, once."""

    def __init__(self, commands: list[str]) -> None:
        self.commands = tuple(sorted(set(commands)))
        self.name = "hairtool-warm:" + ",".join(self.commands)
        self.failed: list[str] | None = None

    def setup(self, worker=None) -> None:
        from hairtool import first_runs

        self.failed = first_runs.warm_once(commands=self.commands)


def enabled() -> bool:
    from hairtool.first_runs import WARM_WORKERS_VARIABLE

    return os.environ.get(WARM_WORKERS_VARIABLE, "1").strip() != "0"


def warm_workers(client, commands: list[str]) -> None:
    """Register :class:`WarmWorker` for ``commands`` on ``client``'s workers (they warm before
    taking a job; a warm-up that fails leaves the jobs to compile what they need)."""
    from hairtool import first_runs

    known = {args[0] for _, args in first_runs.RECIPES}
    wanted = [c for c in commands if c in known]
    if not enabled() or not wanted:
        return
    client.register_plugin(WarmWorker(wanted))
