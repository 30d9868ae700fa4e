"""``hairtool batch`` on a local Dask cluster of processes: real shots and grooms, the report, a
second run that skips everything, a changed input, ``--force``, failures, and no Dask."""

from __future__ import annotations

import csv
import json
import os
import shutil
import sys

import pytest

from hairtool.cli import main
from hairtool.farm.manifest import MANIFEST_NAME
from hairtool.farm.report import CSV_COLUMNS
from hairtool.io import read, write
from hairtool.keys.export import read_keys_json

pytest.importorskip("distributed", reason="the farm extra (dask[distributed]) is not installed")

JOBS_TOML = """\
[[jobs]]
glob = "shots/*.npz"
command = "keys"
args = ["{path}", "--keys", "5", "--out", "out/{stem}.keys.json", "--export", "out/{stem}.keys.usda"]

[[jobs]]
command = "keys"
args = ["MOTION/pymo_walk.bvh", "--keys", "8", "--out", "out/walk.keys.json"]

[[jobs]]
command = "freeze"
args = ["GROOMS/ponytail_tail.tfx", "out/ponytail_frozen.npz", "--seed", "3"]

[[jobs]]
command = "convert"
args = ["grooms/scalp.npz", "out/scalp.usda"]
"""


def batch(capsys, *args: str) -> tuple[int, dict]:
    rc = main(["batch", *args, "--json"])
    return rc, json.loads(capsys.readouterr().out)


@pytest.mark.slow(seconds=11)
def test_a_local_batch_runs_resumes_and_reports(project, capsys, grooms_dir, motion_dir):
    jobs = project / "jobs.toml"
    jobs.write_text(JOBS_TOML.replace("MOTION", str(motion_dir)).replace("GROOMS", str(grooms_dir)))
    report = project / "report.json"
    rc, summary = batch(capsys, str(jobs), "--workers", "2", "--report", str(report))
    assert rc == 0
    assert summary["jobs"] == 6 and summary["done"] == 6 and summary["failed"] == 0
    assert summary["workers"] == 2 and summary["scheduler"] == "local"

    rows = json.loads(report.read_text())["jobs"]
    assert [r["status"] for r in rows] == ["done"] * 6
    assert [r["input"] for r in rows[:3]] == ["shots/a.npz", "shots/b.npz", "shots/c.npz"]
    assert all(r["worker"].rsplit(":", 1)[1].isdigit() and r["seconds"] > 0 for r in rows)
    for r, shot in zip(rows[:3], "abc", strict=True):
        record = read_keys_json(project / "out" / f"{shot}.keys.json")
        assert r["key_count"] == 5 == len(record["keys"])
        assert r["total_error"] <= r["uniform_total_error"]
        src, k = project / "shots" / f"{shot}.npz", [key["frame"] for key in record["keys"]]
        anim = read(src)  # the key poses alone in the input's own format (.npz), not the --export
        write(project / "poses.npz", anim.with_frames(anim.frames[k], time_codes=anim.time_codes[k]))
        assert r["storage_ratio"] == os.path.getsize(project / "poses.npz") / os.path.getsize(src)
    assert rows[3]["key_count"] == 8 and rows[3]["worst_error"] > 0 and rows[3]["storage_ratio"] is None
    frozen = read(project / "out" / "ponytail_frozen.npz")
    assert frozen.strand_count == read(grooms_dir / "ponytail_tail.tfx").strand_count
    assert read(project / "out" / "scalp.usda").strand_count == 60

    with open(project / "report.csv", newline="") as f:
        table = list(csv.DictReader(f))
    assert list(table[0]) == list(CSV_COLUMNS) and len(table) == 6
    assert table[0]["args"].startswith("shots/a.npz --keys 5") and table[0]["key_count"] == "5"
    assert (project / "out" / MANIFEST_NAME).is_file()

    # Again: nothing to do, so no cluster is started at all.
    stamps = {p.name: p.stat().st_mtime_ns for p in (project / "out").iterdir()}
    rc, summary = batch(capsys, str(jobs), "--report", str(report))
    assert rc == 0 and summary["skipped"] == 6 and summary["done"] == 0 and summary["workers"] == 0
    skipped = json.loads(report.read_text())["jobs"]
    assert [r["status"] for r in skipped] == ["skipped"] * 6
    assert [r["key_count"] for r in skipped[:4]] == [5, 5, 5, 8]  # the numbers of the run that made them
    assert {p.name: p.stat().st_mtime_ns for p in (project / "out").iterdir() if p.suffix != ".json"} == {
        k: v for k, v in stamps.items() if not k.endswith(".json")
    }

    # A new take of shot b: only its job runs.
    shutil.copyfile(project / "shots" / "c.npz", project / "shots" / "b.npz")
    rc, summary = batch(capsys, str(jobs), "--workers", "1")
    assert rc == 0 and summary["done"] == 1 and summary["skipped"] == 5
    assert read_keys_json(project / "out" / "b.keys.json")["frames"] == 30

    # --force runs everything.
    rc, summary = batch(capsys, str(jobs), "--workers", "2", "--force")
    assert rc == 0 and summary["done"] == 6 and summary["skipped"] == 0


def test_failed_jobs_are_reported_and_counted_in_the_exit_status(project, capsys):
    jobs = project / "jobs.json"
    jobs.write_text(
        json.dumps(
            {
                "jobs": [
                    {"command": "keys", "args": ["--keys", "999", "shots/a.npz", "--out", "out/a.json"]},
                    {"command": "convert", "args": ["grooms/scalp.npz", "out/scalp.hair"]},
                    {"command": "convert", "args": ["shots/missing.npz", "out/missing.usda"]},
                    {"command": "keys", "args": ["shots/b.npz", "--kees", "3"]},
                ]
            }
        )
    )
    report = project / "report.json"
    rc = main(["batch", str(jobs), "--workers", "2", "--report", str(report)])
    out, err = capsys.readouterr()
    assert rc == 3
    assert out.strip().startswith("4 jobs: 1 done, 0 skipped, 3 failed in ")
    lines = err.strip().splitlines()
    assert len(lines) == 3 and all(ln.startswith("hairtool batch: job ") for ln in lines)
    assert lines[0].startswith("hairtool batch: job 1 (keys shots/a.npz) failed: ")  # options first
    rows = json.loads(report.read_text())["jobs"]
    inputs = ["shots/a.npz", "grooms/scalp.npz", "shots/missing.npz", "shots/b.npz"]
    assert [r["input"] for r in rows] == inputs
    with open(project / "report.csv", newline="") as f:
        assert next(csv.DictReader(f))["input"] == "shots/a.npz"
    assert [r["status"] for r in rows] == ["failed", "done", "failed", "failed"]
    assert rows[0]["error"] == "hairtool keys: error: keys=999 is invalid: expected a whole number in [2, 24]"
    assert "missing.npz" in rows[2]["error"]
    assert rows[3]["error"] == "hairtool: error: unrecognized arguments: --kees 3"
    assert not (project / "out" / "missing.usda").exists()
    assert read(project / "out" / "scalp.hair").strand_count == 60


def test_without_dask_the_batch_says_how_to_install_it(project, capsys, monkeypatch):
    jobs = project / "jobs.json"
    jobs.write_text(json.dumps({"jobs": [{"command": "convert", "args": ["grooms/scalp.npz", "out/s.obj"]}]}))
    monkeypatch.setitem(sys.modules, "distributed", None)  # import distributed → ImportError
    assert main(["batch", str(jobs)]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "hairtool[farm]" in err and "Dask" in err
    assert not (project / "out" / "s.obj").exists()


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--report", "r.csv"], "report='r.csv' is invalid"),
        (["--workers", "0"], "workers=0 is invalid"),
        (["--job-threads", "0"], "job-threads=0 is invalid"),
        (["--scheduler", "tcp://127.0.0.1:9", "--workers", "2"], "no --workers with --scheduler"),
        (["--scheduler", "nowhere"], "scheduler='nowhere' is invalid"),
    ],
)
def test_bad_options_are_one_line(project, capsys, args, message):
    jobs = project / "jobs.json"
    jobs.write_text(json.dumps({"jobs": [{"command": "convert", "args": ["grooms/scalp.npz", "out/s.obj"]}]}))
    assert main(["batch", str(jobs), *args]) == 2
    err = capsys.readouterr().err.strip()
    assert message in err and "\n" not in err


def test_two_jobs_writing_one_file_are_warned_about(project, capsys):
    jobs = project / "jobs.json"
    template = {
        "glob": "shots/*.npz",
        "command": "keys",
        "args": ["{path}", "--keys", "3", "--out", "out/k.json"],
    }
    jobs.write_text(json.dumps({"jobs": [template]}))
    assert main(["batch", str(jobs), "--workers", "1"]) == 0
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 2  # three jobs, one file
    assert all(ln.startswith("hairtool batch: warning: job ") and ln.endswith("k.json") for ln in err)


def test_local_workers_keep_their_housekeeping_off_the_jobs():
    """A local cluster's workers neither profile their task nor wake their loop every 20 ms: on a
    machine whose every core runs a job, that would be taken from the jobs."""
    import dask

    from hairtool.farm.cluster import QUIET_WORKERS, open_client

    with open_client(None, 1) as client:
        seen = client.run(lambda: {k: dask.config.get(k) for k in QUIET_WORKERS})
    assert list(seen.values()) == [QUIET_WORKERS]
    assert QUIET_WORKERS["distributed.worker.profile.enabled"] is False


def _log_as_distributed(level: int, message: str) -> None:
    import logging

    logging.getLogger("distributed.worker").log(level, message)


def test_a_local_cluster_lets_only_critical_log_lines_of_distributed_through(capfd):
    """A worker killed mid-batch makes distributed log ERROR tracebacks the batch recovers from (a
    result lost with the worker, in the scheduler; its replacement's heartbeat to a cluster
    closing, in a worker): neither reaches stderr, while a CRITICAL line still would."""
    import io
    import logging

    from hairtool.farm.cluster import open_client

    capfd.readouterr()
    here = io.StringIO()  # this process's stderr, as distributed's own handler writes to it
    handler = logging.StreamHandler(here)
    handler.setLevel(logging.WARNING)
    logging.getLogger("distributed").addHandler(handler)
    try:
        with open_client(None, 1) as client:
            client.run(_log_as_distributed, logging.ERROR, "worker error line")
            logging.getLogger("distributed.scheduler").error("scheduler error line")
            client.run(_log_as_distributed, logging.CRITICAL, "worker critical line")
            logging.getLogger("distributed.scheduler").critical("scheduler critical line")
    finally:
        logging.getLogger("distributed").removeHandler(handler)
    err = capfd.readouterr().err  # the worker processes write to the file descriptor
    assert "worker critical line" in err and "error line" not in err
    assert here.getvalue() == "scheduler critical line\n"


def test_the_default_local_cluster_has_one_single_threaded_worker_per_core(project, capsys, monkeypatch):
    from hairtool.farm import cluster

    usable = os.sched_getaffinity(0) if hasattr(os, "sched_getaffinity") else range(os.cpu_count() or 1)
    assert cluster.cores() == len(usable)
    assert cluster.local_workers(None) == cluster.cores()
    # A core count unlike this machine's, so what starts is ours and not Dask's own default.
    n = 1 if cluster.cores() != 1 else 2
    monkeypatch.setattr(cluster, "cores", lambda: n)
    with cluster.open_client() as client:
        assert list(client.nthreads().values()) == [1] * n
    jobs = project / "jobs.json"
    jobs.write_text(json.dumps({"jobs": [{"command": "convert", "args": ["grooms/scalp.npz", "out/s.obj"]}]}))
    rc, summary = batch(capsys, str(jobs))
    assert rc == 0 and summary["done"] == 1 and summary["workers"] == n


def test_a_local_cluster_that_cannot_start_is_one_line(project, capsys, monkeypatch):
    import distributed

    def refuse(*args, **kwargs):
        raise OSError("no free port on 127.0.0.1")

    monkeypatch.setattr(distributed, "LocalCluster", refuse)
    jobs = project / "jobs.json"
    job = {"command": "convert", "args": ["grooms/scalp.npz", "out/s.usda"]}
    jobs.write_text(json.dumps({"jobs": [job]}))
    assert main(["batch", str(jobs), "--workers", "2"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "cannot start a local Dask cluster of 2 workers" in err
