"""A local cluster's worker process killed (SIGKILL) in the middle of a job: the job runs again,
every output is whole and equal to the command run by hand, no temporary is left, the batch
says nothing on stderr, and a second run skips everything."""

from __future__ import annotations

import contextlib
import io
import json
import logging
import os
import shutil
import signal
import threading
import time

import numpy as np
import pytest

from hairtool.cli import main
from hairtool.farm.batch import run_batch
from hairtool.farm.jobs import load_jobs
from hairtool.io import read
from hairtool.keys.export import read_keys_json

pytest.importorskip("distributed", reason="the farm extra (dask[distributed]) is not installed")

#: About two seconds of work: long enough to be caught running, short enough for a quick test.
SIMULATE = ["sample:scalp:500:24", "--frames", "48", "--substeps", "96", "--motion", "turn,nod"]
TIMEOUT_S = 120


@contextlib.contextmanager
def _logged_here():
    """What distributed logs at WARNING and up in this process (a local cluster's scheduler and
    nannies), as a stream handler of the user's would get it."""
    here = io.StringIO()
    handler = logging.StreamHandler(here)
    handler.setLevel(logging.WARNING)
    logging.getLogger("distributed").addHandler(handler)
    try:
        yield here
    finally:
        logging.getLogger("distributed").removeHandler(handler)


def _executing(dask_worker) -> list[str]:
    """The tasks a worker is running now (not only assigned to it): runs in the worker."""
    return [str(ts.key) for ts in dask_worker.state.executing]


def _kill_a_worker_running(client, pids: dict[str, int], wanted: set[int], thread) -> tuple[int, int]:
    """SIGKILL the worker process that runs one of the ``wanted`` jobs; ``(pid, job index)``."""
    deadline = time.monotonic() + TIMEOUT_S
    while time.monotonic() < deadline and thread.is_alive():
        for worker, keys in client.run(_executing).items():
            running = [int(k.rsplit("-", 1)[1]) for k in keys if k.startswith("hairtool-batch-")]
            if running and running[0] in wanted:
                os.kill(pids[worker], signal.SIGKILL)
                return pids[worker], running[0]
        time.sleep(0.05)
    raise AssertionError("no worker was seen running a simulate job")


@pytest.mark.slow(seconds=12)
def test_a_local_batch_survives_a_worker_killed_mid_job_and_resumes(made_shots, tmp_path, capfd):
    from hairtool.farm.cluster import open_client

    project = tmp_path  # the shots, as the project fixture gives them (it takes capsys, not capfd)
    shutil.copytree(made_shots, project, dirs_exist_ok=True)
    entries = [
        {"command": "simulate", "args": [SIMULATE[0], f"out/sim{i}.npz", *SIMULATE[1:]]} for i in range(2)
    ]
    keys = ["{path}", "--keys", "4", "--out", "out/{stem}.json"]
    entries.append({"glob": "shots/*.npz", "command": "keys", "args": keys})
    (project / "jobs.json").write_text(json.dumps({"jobs": entries}))
    jobs = load_jobs(project / "jobs.json")
    capfd.readouterr()

    results = []
    with _logged_here() as here, open_client(None, 2) as client:
        pids = client.run(os.getpid)
        # Unpickling ``_executing`` imports this module (and hairtool's CLI) in each worker: done
        # here, while the workers are idle. Polled first while a job imports its command's modules
        # on the worker's other thread, the two imports could meet halfway (Python then hands one
        # thread a partly initialised module: an ImportError that is the test's, not the batch's).
        client.run(_executing)
        thread = threading.Thread(target=lambda: results.append(run_batch(jobs, client=client, threads=1)))
        thread.start()
        try:
            killed_pid, killed_job = _kill_a_worker_running(client, pids, {0, 1}, thread)
        finally:
            thread.join(TIMEOUT_S)
        assert not thread.is_alive(), "the batch did not finish"
    (result,) = results
    rows = result.rows
    assert [r["status"] for r in rows] == ["done"] * 5, [r["error"] for r in rows]
    assert not rows[killed_job]["worker"].endswith(f":{killed_pid}")  # it ran again elsewhere
    # Distributed's tracebacks about the dead worker stay quiet, here and in the worker processes.
    assert here.getvalue() == "" and capfd.readouterr().err == ""

    assert main(["simulate", SIMULATE[0], str(project / "by_hand.npz"), *SIMULATE[1:]]) == 0
    expected = read(project / "by_hand.npz").frames
    for i in range(2):
        assert np.array_equal(read(project / "out" / f"sim{i}.npz").frames, expected)
    for shot in "abc":
        by_hand = project / "by_hand.json"
        shot_file = project / "shots" / f"{shot}.npz"
        assert main(["keys", str(shot_file), "--keys", "4", "--out", str(by_hand)]) == 0
        assert read_keys_json(project / "out" / f"{shot}.json")["keys"] == read_keys_json(by_hand)["keys"]
    assert not [p.name for p in project.rglob("*") if ".tmp" in p.name]

    again = run_batch(load_jobs(project / "jobs.json"))
    assert [r["status"] for r in again.rows] == ["skipped"] * 5 and again.workers == 0
