"""One job, run in the process that calls :func:`run_job` (a Dask worker, or the client itself).

The job is the ``hairtool`` command line, run in-process through :func:`hairtool.cli.main`
(no new interpreter, and numba's compiled kernels stay loaded from one job to the next), in
the jobs file's folder, with its output captured. Commands that take ``--json`` get it (and
``keys`` its ``--storage``: :func:`~hairtool.farm.fields.report_options`), so the report can
carry their numbers (:mod:`hairtool.farm.fields`). What the job wrote is learned
from the atomic writes themselves (:func:`hairtool.io.atomic.recording_writes`), and what it
read from the arguments naming existing files; the client records both in the manifest.

The working folder, ``sys.stdout`` and ``sys.stderr`` belong to the whole process, so jobs in
one process run one at a time (a lock); run one worker thread per process and as many
processes as the machine's cores allow.
"""

from __future__ import annotations

import contextlib
import io
import json
import os
import socket
import threading
import time

from hairtool.farm.fields import report_fields, report_options
from hairtool.farm.jobs import Job
from hairtool.farm.manifest import file_state, input_state, named_paths

_LOCK = threading.Lock()


def _error_line(rc: int, stderr: str) -> str:
    """The command's own one-line message (the last line it printed on stderr)."""
    lines = [ln.strip() for ln in stderr.splitlines() if ln.strip()]
    return lines[-1] if lines else f"exit status {rc}"


def _call(argv: list[str]) -> tuple[int, str, str]:
    """``(exit status, stdout, stderr)`` of ``hairtool ARGV`` run in this process."""
    from hairtool.cli import main

    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            rc = main(argv)
        except SystemExit as e:  # argparse: a bad option (its message on stderr), or --help
            rc = 0 if e.code is None else e.code if isinstance(e.code, int) else 1
        except Exception as e:  # a bug, not bad input: still one line in the report
            print(f"hairtool {argv[0]}: internal error: {type(e).__name__}: {e}", file=err)
            rc = 1
    return rc, out.getvalue(), err.getvalue()


def _set_threads(threads: int | None) -> None:
    if threads is None:
        return
    import numba

    numba.set_num_threads(max(1, min(int(threads), numba.config.NUMBA_NUM_THREADS)))


def run_job(job: Job, threads: int | None = None) -> dict:
    """Run ``job`` here; a plain dict the client turns into a report row and a manifest entry.

    ``{"index", "status": "done" | "failed", "error", "seconds", "inputs", "outputs",
    "fields", "stderr", "worker"}``: ``inputs`` maps each existing file the arguments name
    (but the outputs) to :func:`~hairtool.farm.manifest.input_state`, ``outputs`` each file
    written to :func:`~hairtool.farm.manifest.file_state`; ``fields`` are the report's
    numbers from the command's ``--json`` object (:mod:`hairtool.farm.fields`). ``threads``:
    numba threads for this job.
    """
    from hairtool.farm.warm import warm_before_job
    from hairtool.io.atomic import recording_writes, stale_temporaries

    argv = job.argv + [o for o in report_options(job.command) if o not in job.args]
    with _LOCK:
        warm_before_job(job.command)  # once per command in this process, before its clock starts
        previous = os.getcwd()
        t0 = time.perf_counter()
        try:
            os.chdir(job.base)
            named = {str(p.resolve()) for p in named_paths(job.args, job.base) if p.is_file()}
            before = {p: input_state(p) for p in sorted(named)}
            _set_threads(threads)
            with recording_writes() as written:
                rc, stdout, stderr = _call(argv)
        except OSError as e:  # the jobs folder or an input vanished under the job
            rc, stdout, stderr, written, before = 1, "", f"{e.strerror or e}: {e.filename}", [], {}
        finally:
            os.chdir(previous)
        seconds = time.perf_counter() - t0
    outputs = {}
    for path in dict.fromkeys(str(p.resolve()) for p in written):
        for stale in stale_temporaries(path):  # left by an attempt whose worker was killed
            with contextlib.suppress(OSError):
                stale.unlink()
        with contextlib.suppress(OSError):
            outputs[path] = file_state(path)
    summary = None
    if rc == 0 and stdout.lstrip().startswith("{"):
        with contextlib.suppress(ValueError):
            summary = json.loads(stdout)
    inputs = {p: s for p, s in before.items() if p not in outputs}
    return {
        "index": job.index,
        "status": "done" if rc == 0 else "failed",
        "error": None if rc == 0 else _error_line(rc, stderr),
        "seconds": seconds,
        "inputs": inputs,
        "outputs": outputs,
        "fields": report_fields(job, summary),
        "stderr": stderr.strip()[-2000:],
        "worker": f"{socket.gethostname()}:{os.getpid()}",
    }
