"""The moments of a start, for ``python -m app.bench --cold-start`` (no Qt here: the warm-up
process writes them too).

With ``HAIRTOOL_STARTUP_TRACE`` set, :func:`mark` writes one line per moment on standard error::

    startup MOMENT wall=<seconds since the epoch> cpu=<this process's CPU seconds> pid=<its id> [LABEL]

``MOMENT`` is ``window-shown``, ``engine-ready`` or ``render-hair`` (the first frame drawn with
render hair) from the studio, ``warmup-step`` (LABEL: the step) and ``warmup-done`` from the
kernel warm-up. The CPU seconds are the process's own, all its threads: on a machine shared with
other work they say what a start costs where the wall clock says how long it waited for a core.
Without the variable nothing is written.
"""

from __future__ import annotations

import os
import sys
import time

ENV = "HAIRTOOL_STARTUP_TRACE"
MOMENTS = ("window-shown", "engine-ready", "render-hair", "warmup-step", "warmup-done")


def enabled() -> bool:
    return bool(os.environ.get(ENV))


def mark(moment: str, label: str = "") -> None:
    """Write ``moment`` (one of :data:`MOMENTS`) on standard error when tracing is on."""
    if not enabled():
        return
    line = f"startup {moment} wall={time.time():.3f} cpu={time.process_time():.3f} pid={os.getpid()}"
    try:
        print(f"{line} {label}".rstrip(), file=sys.stderr, flush=True)
    except (OSError, ValueError):  # nobody reads standard error any more
        pass


def parse(line: str) -> tuple[str, float, float, int, str] | None:
    """``(moment, wall, cpu, pid, label)`` of a line :func:`mark` wrote, else None."""
    parts = line.strip().split(maxsplit=5)
    if len(parts) < 5 or parts[0] != "startup" or parts[1] not in MOMENTS:
        return None
    try:
        wall = float(parts[2].removeprefix("wall="))
        cpu = float(parts[3].removeprefix("cpu="))
        pid = int(parts[4].removeprefix("pid="))
    except ValueError:
        return None
    return parts[1], wall, cpu, pid, parts[5] if len(parts) > 5 else ""
