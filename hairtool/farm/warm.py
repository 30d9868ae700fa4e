"""Each Dask worker warms the kernel cache once, before its first job of a command.

A new farm machine (a fresh container) has an empty kernel cache, and every worker on it would
compile the same kernels side by side for its first job: on two workers of a 2-core machine,
twice the compile time, with both cores busy. Before a worker process runs its first job of a
command, :func:`warm_before_job` runs :func:`hairtool.first_runs.warm_once` for that command.
The workers of one machine take turns on a lock, so the first one compiles and the others find
its record and load the kernels at their first call; a worker of a machine already warmed (its
image ran ``hairtool cache warm``) does nothing. The warm-up runs inside the job's task, not as
a worker plugin: a Ctrl+C or a lost worker then ends it as it ends a job.
``HAIRTOOL_WARM_WORKERS=0`` leaves it out (a batch whose every job is tiny).
"""

from __future__ import annotations

import os
import threading

from hairtool import first_runs

_warmed: set[str] = set()  # the commands this process has warmed (or found warm)
_lock = threading.Lock()


def enabled() -> bool:
    return os.environ.get(first_runs.WARM_WORKERS_VARIABLE, "1").strip() != "0"


def warm_before_job(command: str) -> list[str] | None:
    """Warm the kernels of ``command`` once in this process (nothing for a command without a
    recipe, or when turned off). The recipes that failed (the job then compiles what it needs),
    None when nothing ran."""
    known = {args[0] for _, args in first_runs.RECIPES}
    if command not in known or not enabled():
        return None
    with _lock:
        if command in _warmed:
            return None
        _warmed.add(command)
        try:
            return first_runs.warm_once(commands=[command])
        except OSError:  # no writable cache folder here: the job compiles what it needs, as before
            return None
