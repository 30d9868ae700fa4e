"""``hairtool batch --scheduler``: a real ``dask scheduler`` and two ``dask worker`` processes on
127.0.0.1, one of them killed (SIGKILL) while it runs a job; the job runs again on the other
worker and every output is whole and equal to the command run by hand."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from hairtool.cli import main
from hairtool.io import read
from hairtool.io.atomic import stale_temporaries

distributed = pytest.importorskip("distributed", reason="the farm extra (dask[distributed]) is not installed")

START_TIMEOUT_S = 90
BATCH_TIMEOUT_S = 240
#: A job of a few seconds, so the worker can be killed in the middle of it.
SIMULATE = ["sample:scalp:500:24", "--frames", "48", "--substeps", "96", "--motion", "turn,nod"]


def _wait_for(predicate, timeout: float, what: str) -> None:
    deadline = time.monotonic() + timeout
    while not predicate():
        if time.monotonic() > deadline:
            raise TimeoutError(f"timed out waiting for {what}")
        time.sleep(0.1)


@pytest.fixture
def dask_pair(tmp_path):
    """``(address, client, worker pids by address)`` of a scheduler and two workers without
    nannies on 127.0.0.1 (random ports), stopped afterwards whatever happens."""
    logs = tmp_path / "dask-logs"
    logs.mkdir()
    scheduler_file = logs / "scheduler.json"
    env = {**os.environ, "NUMBA_NUM_THREADS": "1"}
    procs: list[subprocess.Popen] = []

    def start(name: str, *args: str) -> None:
        with open(logs / f"{name}.log", "wb") as log:
            procs.append(
                subprocess.Popen(
                    [sys.executable, "-m", "dask", *args], stdout=log, stderr=subprocess.STDOUT, env=env
                )
            )

    client = None
    try:
        start(
            "scheduler",
            "scheduler",
            "--host",
            "127.0.0.1",
            "--port",
            "0",
            "--no-dashboard",
            "--scheduler-file",
            str(scheduler_file),
            "--idle-timeout",
            "600",
        )
        _wait_for(scheduler_file.exists, START_TIMEOUT_S, "the scheduler's address")
        _wait_for(lambda: json.loads(scheduler_file.read_text() or "{}").get("address"), 10, "the address")
        address = json.loads(scheduler_file.read_text())["address"]
        assert address.startswith("tcp://127.0.0.1:")
        for i in range(2):
            start(
                f"worker{i}",
                "worker",
                address,
                "--host",
                "127.0.0.1",
                "--nthreads",
                "1",
                "--no-nanny",
                "--no-dashboard",
                "--name",
                f"worker{i}",
                "--death-timeout",
                "120",
            )
        client = distributed.Client(address, timeout=START_TIMEOUT_S)
        client.wait_for_workers(2, timeout=START_TIMEOUT_S)
        yield address, client, client.run(os.getpid)
    finally:
        if client is not None:
            client.close()
        for p in reversed(procs):
            if p.poll() is None:
                p.terminate()
        for p in procs:
            try:
                p.wait(timeout=15)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait()


def _kill_a_worker_running_a_job(client, pids: dict[str, int], thread: threading.Thread) -> tuple[str, int]:
    """SIGKILL the worker process that has been running one of the batch's jobs for a moment;
    ``(worker address, job index)``."""
    deadline = time.monotonic() + BATCH_TIMEOUT_S
    seen: dict[str, str] = {}
    while time.monotonic() < deadline and thread.is_alive():
        for worker, keys in client.processing().items():
            jobs = [str(k) for k in keys if str(k).startswith("hairtool-batch-")]
            if not jobs:
                continue
            if seen.get(worker) == jobs[0]:  # still the same job half a second later
                os.kill(pids[worker], signal.SIGKILL)
                return worker, int(jobs[0].rsplit("-", 1)[1])
            seen[worker] = jobs[0]
        time.sleep(0.5)
    raise AssertionError("no worker was seen running a job")


@pytest.mark.slow(seconds=15)
def test_a_batch_on_a_running_scheduler_survives_a_killed_worker_and_resumes(
    project, dask_pair, capsys, grooms_dir
):
    address, client, pids = dask_pair
    jobs = project / "jobs.json"
    entries = [
        {"command": "simulate", "args": [*SIMULATE[:1], f"out/sim{i}.npz", *SIMULATE[1:]]} for i in range(3)
    ]
    entries.append(
        {
            "glob": "shots/*.npz",
            "command": "keys",
            "args": ["{path}", "--keys", "4", "--out", "out/{stem}.json"],
        }
    )
    entries.append({"command": "freeze", "args": [str(grooms_dir / "ponytail_tail.tfx"), "out/tail.usda"]})
    jobs.write_text(json.dumps({"jobs": entries}))
    report = project / "report.json"

    status: list[int] = []
    thread = threading.Thread(
        target=lambda: status.append(
            main(["batch", str(jobs), "--scheduler", address, "--json", "--report", str(report)])
        )
    )
    thread.start()
    try:
        killed_worker, killed_job = _kill_a_worker_running_a_job(client, pids, thread)
    finally:
        thread.join(BATCH_TIMEOUT_S)
    assert not thread.is_alive(), "the batch did not finish"
    assert status == [0]
    summary = json.loads(capsys.readouterr().out)
    assert summary["done"] == 7 and summary["failed"] == 0 and summary["scheduler"] == address

    rows = json.loads(report.read_text())["jobs"]
    assert [r["status"] for r in rows] == ["done"] * 7
    killed_pid = f":{pids[killed_worker]}"
    # The job it was running was run again elsewhere (jobs it finished before it died stay done).
    assert not rows[killed_job]["worker"].endswith(killed_pid)
    assert rows[killed_job]["status"] == "done"
    assert [r["key_count"] for r in rows[3:6]] == [4, 4, 4]
    assert (
        read(project / "out" / "tail.usda").strand_count
        == read(grooms_dir / "ponytail_tail.tfx").strand_count
    )

    assert main(["simulate", SIMULATE[0], str(project / "by_hand.npz"), *SIMULATE[1:]]) == 0
    expected = read(project / "by_hand.npz").frames
    for i in range(3):
        out = project / "out" / f"sim{i}.npz"
        assert np.array_equal(read(out).frames, expected), f"{out.name} differs from the command run by hand"
        assert stale_temporaries(out) == []
    assert not [p.name for p in Path(project / "out").iterdir() if ".tmp" in p.name]

    # Again: everything is done; the scheduler is not even needed.
    capsys.readouterr()
    assert main(["batch", str(jobs), "--scheduler", address, "--json"]) == 0
    again = json.loads(capsys.readouterr().out)
    assert again["skipped"] == 7 and again["done"] == 0
