"""``hairtool batch`` on a local Dask cluster against the same jobs one after another in one process.

One row per data set and worker count: ``jobs`` keys jobs (``--out`` and ``--export``, as a
studio would key a sequence); ``wall_s``, the batch's median wall time on a started cluster
(skip checks, submission and manifests included; the cluster's start-up is ``start_s``,
apart); ``serial_s``, the same jobs run by :func:`~hairtool.farm.runner.run_job` one after
another in one process with numba threads on every core (``serial_threads``), one of the
row's own workers (the others idle), so that both sides run in the environment Dask gives its
workers (one BLAS thread, which a loaded machine needs); ``speedup``, their ratio; ``overhead_ms``, the
worker time per job not spent inside a job, (workers × wall − Σ job seconds) / jobs, which
also counts a worker idling at the end of the batch; ``split_s`` and ``split_speedup``, the
same jobs dealt out to the workers in equal shares, one task per worker run one after
another: the speed-up the machine's free cores allow at that moment, the batch's ceiling.
Serial, split and batch passes alternate, so a busy moment of a shared machine falls on all,
and all run warm (kernels compiled and loaded before timing); each worker count is timed on a
cluster of its own, the only one open then. ``load_1m`` is the machine's
load average when the row was taken (another's work leaves the workers fewer cores).

Data: ``synthetic``, shots simulated from the scalp sample; ``mocap``, the BVH captures in
``shared/data/motion`` (short jobs, where the overhead shows).
"""

from __future__ import annotations

import argparse
import os
import statistics
import tempfile
import time
from pathlib import Path

from hairtool.bench import MOTION_DIR, add_common_arguments

HELP = "hairtool batch: keys jobs on 1-2 local Dask workers against one process, speedup and overhead"

DATA = ("synthetic", "mocap")
#: (strands, frames) of the synthetic shots; four shots, each keyed with four key counts.
SHOT_SIZE = (400, 120)
QUICK_SHOT_SIZE = (80, 48)
KEY_COUNTS = (6, 8, 10, 12)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--jobs", type=int, default=16, help="keys jobs per batch (default 16)")
    parser.add_argument(
        "--workers", type=int, nargs="+", default=None, help="local worker counts to time (default 1 2)"
    )
    parser.add_argument("--data", nargs="+", choices=DATA, default=None, help="data sets (default both)")
    add_common_arguments(parser, quick="small synthetic shots, 2 workers, one run", repeat=4)


def _synthetic_inputs(folder: Path, quick: bool) -> list[Path]:
    from hairtool.farm.jobs import Job
    from hairtool.farm.runner import run_job

    strands, frames = QUICK_SHOT_SIZE if quick else SHOT_SIZE
    shots = []
    for i, motion in enumerate(("turn", "nod", "shake", "turn,nod")):
        path = folder / f"shot{i}.npz"
        args = (f"sample:scalp:{strands}:24", path.name, "--frames", str(frames), "--motion", motion)
        made = run_job(Job(i, "simulate", (*args, "--gusts", "2", "--seed", str(i)), str(folder)))
        if made["status"] != "done":
            raise RuntimeError(f"could not simulate {path}: {made['error']}")
        shots.append(path)
    return shots


def _jobs(inputs: list[Path], n: int, folder: Path, export: bool):
    from hairtool.farm.jobs import Job

    jobs = []
    for i in range(n):
        source = inputs[i % len(inputs)]
        keys = KEY_COUNTS[(i // len(inputs)) % len(KEY_COUNTS)]
        args = [str(source), "--keys", str(keys), "--out", f"out/{i:02d}.keys.json"]
        if export:
            args += ["--export", f"out/{i:02d}.keys.usdc"]
        jobs.append(Job(i, "keys", tuple(args), str(folder)))
    (folder / "out").mkdir(exist_ok=True)
    return jobs


def _warm_jobs(jobs):
    """One job per input: enough to compile or load every kernel the batch uses."""
    return list({j.args[0]: j for j in reversed(jobs)}.values())


def serial_pass(jobs, threads: int) -> float:
    """Seconds to run ``jobs`` one after another in this process (submitted to a worker)."""
    from hairtool.farm.runner import run_job

    t0 = time.perf_counter()
    for job in jobs:
        if run_job(job, threads)["status"] != "done":
            raise RuntimeError(f"{job.describe()} failed in the serial run")
    return time.perf_counter() - t0


def _batch_pass(client, jobs, threads) -> tuple[float, float]:
    """``(wall seconds, Σ seconds inside the jobs)`` of one batch on ``client``."""
    from hairtool.farm.batch import run_batch

    result = run_batch(jobs, client=client, threads=threads, force=True)
    if result.count("done") != len(jobs):
        raise RuntimeError(f"{result.count('failed')} jobs failed on the cluster")
    return result.seconds, sum(r["seconds"] for r in result.rows)


def _split_pass(client, jobs, threads) -> float:
    """Seconds for every worker to run its share of ``jobs`` one after another, all at once: the
    parallel time the machine allows now, without a task per job."""
    workers = sorted(client.nthreads())
    t0 = time.perf_counter()
    futures = [
        client.submit(serial_pass, jobs[i :: len(workers)], threads, workers=[w], pure=False)
        for i, w in enumerate(workers)
    ]
    client.gather(futures)
    return time.perf_counter() - t0


def _measure(jobs, worker_counts: list[int], repeat: int) -> dict[int, dict]:
    """Per worker count, on a cluster of its own that alone is open while it is timed: the
    median serial pass (on one of its workers, numba threads on every core), the median batch
    pass, the median split pass, and the start-up. Serial, batch and split passes are taken in
    turn, so a busy moment of the machine falls on all three, and batch and split take turns
    right after the serial pass: on this 2-core VM whichever parallel pass follows one core's
    idling (the serial pass, or 3 s of rest) runs 10-25 % slower, a split as much as a batch,
    and always putting the batch there had charged it to the batch. One cluster at a time: the idle
    workers, nannies and scheduler of another cluster cost a 2-core machine a few per cent,
    which a real batch does not pay."""
    from hairtool.farm.batch import default_threads
    from hairtool.farm.cluster import cores, open_client
    from hairtool.farm.runner import run_job

    warm = _warm_jobs(jobs)
    timed = {}
    for w in worker_counts:
        t0 = time.perf_counter()
        with open_client(None, w) as client:
            start_s = time.perf_counter() - t0
            threads = default_threads(None, w)
            client.run(lambda: [run_job(j, cores()) for j in warm])  # kernels loaded at both counts
            client.run(lambda threads=threads: [run_job(j, threads) for j in warm])
            first = sorted(client.nthreads())[:1]
            serial, runs, split = [], [], []
            for i in range(repeat):
                serial.append(client.submit(serial_pass, jobs, cores(), workers=first, pure=False).result())
                if i % 2 == 0:
                    runs.append(_batch_pass(client, jobs, threads))
                    split.append(_split_pass(client, jobs, threads))
                else:
                    split.append(_split_pass(client, jobs, threads))
                    runs.append(_batch_pass(client, jobs, threads))
        timed[w] = {  # medians, the same statistic on every side
            "start_s": start_s,
            "serial_s": statistics.median(serial),
            "wall_s": statistics.median(r[0] for r in runs),
            "busy_s": statistics.median(r[1] for r in runs),
            "split_s": statistics.median(split),
        }
    return timed


def run(args: argparse.Namespace) -> list[dict]:
    from hairtool.bench import ratio, setup
    from hairtool.errors import ParameterError
    from hairtool.farm.cluster import cores

    repeat = setup(args)
    if args.jobs < 1:
        raise ParameterError("jobs", args.jobs, "a whole number ≥ 1")
    worker_counts = args.workers or ([2] if args.quick else [1, 2])
    if any(w < 1 for w in worker_counts):
        raise ParameterError("workers", worker_counts, "whole numbers ≥ 1")
    data = args.data or (["synthetic"] if args.quick else list(DATA))
    rows = []
    with tempfile.TemporaryDirectory(prefix="hairtool-bench-batch-") as tmp:
        for name in data:
            folder = Path(tmp, name)
            folder.mkdir()
            if name == "synthetic":
                inputs, export = _synthetic_inputs(folder, args.quick), True
            else:
                inputs, export = sorted(MOTION_DIR.glob("*.bvh")), False
                if not inputs:
                    raise ParameterError("data", name, f"BVH captures in {MOTION_DIR}")
            jobs = _jobs(inputs, args.jobs, folder, export)
            by_workers = _measure(jobs, worker_counts, repeat)
            serial_threads = cores()
            for workers, timed in by_workers.items():
                serial_s = timed["serial_s"]
                rows.append(
                    {
                        "data": name,
                        "jobs": len(jobs),
                        "workers": workers,
                        "wall_s": timed["wall_s"],
                        "serial_s": serial_s,
                        "serial_threads": serial_threads,
                        "speedup": ratio(serial_s, timed["wall_s"]),
                        "split_s": timed["split_s"],
                        "split_speedup": ratio(serial_s, timed["split_s"]),
                        "overhead_ms": 1e3 * (workers * timed["wall_s"] - timed["busy_s"]) / len(jobs),
                        "start_s": timed["start_s"],
                        "load_1m": round(os.getloadavg()[0], 2),
                    }
                )
    return rows
