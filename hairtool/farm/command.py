"""Run a batch of hairtool commands (keys, freeze, convert, simulate, anime, …) on Dask.

JOBS is a .json or .toml file: {"jobs": [{"command": "keys", "args": ["shot01.usdc", "--keys",
"12", "--out", "shot01.keys.json"]}, …]}, or entries with a glob of inputs and one template:
{"glob": "shots/*.usdc", "command": "keys", "args": ["{path}", "--out", "{dir}/{stem}.keys.json"]}
({path}, {dir}, {name}, {stem}, {suffix}; {{ and }} for braces). Relative paths are relative
to the jobs file. Without --scheduler the jobs run on a local Dask cluster of one process per
core, started and stopped here; --scheduler tcp://HOST:8786 sends them to a running cluster
(workers need hairtool and the same paths). Jobs whose outputs are there and whose inputs and
arguments are unchanged since they ran are skipped (a manifest, hairtool-batch.json, lies
beside the outputs); --force runs them again. Exit status: the number of failed jobs (at most
125); a bad jobs file is 2, as any bad input.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

HELP = "run a batch of commands on Dask (local processes or a scheduler), resumable, with a report"
#: Exit statuses above this are taken by shells (126 and up) and signals.
MAX_EXIT = 125


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.formatter_class = argparse.RawDescriptionHelpFormatter
    parser.add_argument("jobs", metavar="JOBS", type=Path, help="jobs file (.json or .toml)")
    parser.add_argument(
        "--scheduler", metavar="ADDRESS", help="a running Dask scheduler, tcp://HOST:8786 (default: local)"
    )
    parser.add_argument(
        "--workers", type=int, metavar="N", help="local worker processes (default: one per core)"
    )
    parser.add_argument(
        "--job-threads",
        type=int,
        metavar="N",
        help="numba threads per job (default: the cores shared among local workers; "
        "on a scheduler, each worker's NUMBA_NUM_THREADS)",
    )
    parser.add_argument("--force", action="store_true", help="run every job, even those already done")
    parser.add_argument(
        "--report", metavar="REPORT.json", type=Path, help="write the report (and .csv beside)"
    )
    parser.add_argument(
        "--json", action="store_true", help="print a JSON summary instead of the progress line"
    )


def run(args: argparse.Namespace) -> int:
    from hairtool.errors import ParameterError
    from hairtool.farm.batch import run_batch
    from hairtool.farm.cluster import require_dask
    from hairtool.farm.jobs import load_jobs
    from hairtool.farm.progress import Progress, format_seconds
    from hairtool.farm.report import check_report_path, write_report

    if args.scheduler is not None and args.workers is not None:
        raise ParameterError(
            "workers", args.workers, "no --workers with --scheduler (the cluster has its own)"
        )
    if args.job_threads is not None and args.job_threads < 1:
        raise ParameterError("job-threads", args.job_threads, "a whole number ≥ 1")
    report = check_report_path(args.report) if args.report is not None else None
    jobs = load_jobs(args.jobs)
    require_dask()  # say so before any work, even when every job turns out to be done
    progress = Progress(enabled=False if args.json else None)
    result = run_batch(
        jobs,
        scheduler=args.scheduler,
        workers=args.workers,
        threads=args.job_threads,
        force=args.force,
        progress=progress,
    )
    summary = result.summary()
    if report is not None:
        json_path, csv_path = write_report(report, result.rows, summary)
        summary["report"] = [str(json_path), str(csv_path)]
    failed = [r for r in result.rows if r["status"] == "failed"]
    for r in failed:
        print(
            f"hairtool batch: job {r['index'] + 1} ({r['command']} {r['input'] or ''}) failed: {r['error']}",
            file=sys.stderr,
        )
    if args.json:
        print(json.dumps(summary, indent=1))
    else:
        line = (
            f"{summary['jobs']} jobs: {summary['done']} done, {summary['skipped']} skipped, "
            f"{summary['failed']} failed in {format_seconds(result.seconds)}"
        )
        print(line + (f"; report {summary['report'][0]}" if report is not None else ""))
    return min(len(failed), MAX_EXIT)
