"""One job in this process: the command's own outputs and numbers, what it read and wrote, and
its one-line error when it fails."""

from __future__ import annotations

import json
import os

import pytest

from hairtool.cli import main
from hairtool.farm.jobs import Job
from hairtool.farm.manifest import file_sha256
from hairtool.farm.runner import run_job
from hairtool.io import read, write
from hairtool.io.atomic import atomic_open, recording_writes, stale_temporaries
from hairtool.keys.export import read_keys_json


def keys_job(project, *extra: str, index: int = 0) -> Job:
    args = ("shots/a.npz", "--keys", "5", "--out", "out/a.keys.json", "--export", "out/a.keys.usda", *extra)
    return Job(index, "keys", args, str(project))


def test_a_keys_job_matches_the_command_run_by_hand(project, capsys, monkeypatch):
    result = run_job(keys_job(project))
    assert result["status"] == "done" and result["error"] is None
    a = str(project / "shots" / "a.npz")
    assert result["inputs"] == {
        a: {"sha256": file_sha256(a), "bytes": os.path.getsize(a), "mtime_ns": os.stat(a).st_mtime_ns}
    }
    assert sorted(result["outputs"]) == [
        str(project / "out" / "a.keys.json"),
        str(project / "out" / "a.keys.usda"),
    ]
    batch_keys = read_keys_json(project / "out" / "a.keys.json")

    monkeypatch.chdir(project)
    assert main(["keys", "shots/a.npz", "--keys", "5", "--json", "--out", "by_hand.json"]) == 0
    by_hand = json.loads(capsys.readouterr().out)
    assert read_keys_json(project / "by_hand.json")["keys"] == batch_keys["keys"]

    fields = result["fields"]
    assert fields["key_count"] == 5 == len(by_hand["keys"])
    assert fields["frames"] == by_hand["frames"]
    assert fields["total_error"] == by_hand["cost"]
    assert fields["uniform_total_error"] == by_hand["uniform"]["cost"]
    assert fields["worst_error"] == by_hand["position_errors"]["keys"]["max"]
    assert fields["uniform_worst_error"] == by_hand["position_errors"]["uniform"]["max"]
    assert fields["uniform_total_error"] >= fields["total_error"]  # the DP keys are optimal
    # The key poses alone in the input's own format (.npz), not the --export .usda.
    shot, k = read(a), by_hand["keys"]
    write(project / "poses.npz", shot.with_frames(shot.frames[k], time_codes=shot.time_codes[k]))
    assert fields["storage_ratio"] == os.path.getsize(project / "poses.npz") / os.path.getsize(a)
    assert 0 < fields["storage_ratio"] < 1


def test_every_keys_job_of_an_animation_has_a_storage_ratio_and_leaves_no_file(project, monkeypatch):
    import tempfile

    scratch = project / "scratch"
    scratch.mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(scratch))
    result = run_job(Job(0, "keys", ("--keys", "4", "shots/b.npz"), str(project)))
    assert result["status"] == "done" and result["outputs"] == {}
    assert 0 < result["fields"]["storage_ratio"] < 1
    assert list(scratch.iterdir()) == []


def test_the_job_runs_in_the_jobs_folder_and_leaves_the_working_folder_as_it_was(
    project, tmp_path_factory, monkeypatch
):
    elsewhere = tmp_path_factory.mktemp("elsewhere")
    monkeypatch.chdir(elsewhere)
    result = run_job(Job(0, "convert", ("grooms/scalp.npz", "out/scalp.obj"), str(project)))
    assert os.getcwd() == str(elsewhere)
    assert result["status"] == "done", result["error"]
    assert list(result["outputs"]) == [str(project / "out" / "scalp.obj")]
    assert not (elsewhere / "out").exists()


def test_a_failing_job_gives_the_commands_one_line(project):
    bad = run_job(Job(3, "keys", ("shots/a.npz", "--keys", "999"), str(project)))
    assert bad["status"] == "failed" and bad["index"] == 3
    assert bad["error"] == "hairtool keys: error: keys=999 is invalid: expected a whole number in [2, 24]"
    assert bad["outputs"] == {}

    unknown = run_job(Job(0, "keys", ("shots/a.npz", "--kees", "4"), str(project)))
    assert unknown["status"] == "failed"
    assert unknown["error"] == "hairtool: error: unrecognized arguments: --kees 4"

    missing = run_job(Job(0, "convert", ("shots/none.npz", "out/x.usda"), str(project)))
    assert missing["status"] == "failed" and "none.npz" in missing["error"] and "\n" not in missing["error"]
    assert not (project / "out" / "x.usda").exists()


def test_a_job_makes_its_missing_output_folders_and_a_blocked_one_names_the_output(project):
    keys = ("shots/a.npz", "--keys", "4", "--export")
    made = run_job(Job(0, "keys", (*keys, "out/new/v1/a.csv"), str(project)))
    assert made["status"] == "done", made["error"]
    assert list(made["outputs"]) == [str(project / "out" / "new" / "v1" / "a.csv")]
    (project / "out" / "taken").write_text("a file, not a folder")
    blocked = run_job(Job(1, "keys", (*keys, "out/taken/a.csv"), str(project)))
    assert blocked["status"] == "failed" and blocked["outputs"] == {}
    assert blocked["error"] == (
        "hairtool keys: error: out/taken/a.csv: cannot write: [Errno 20] a file is in the way of the folder: "
        "'out/taken'"
    )
    assert not [p for p in project.rglob("*") if ".tmp" in p.name]


def test_a_job_without_json_still_runs_and_commands_with_json_report_numbers(project):
    result = run_job(Job(0, "sample", ("comb", "out/comb.hair", "--strands", "9"), str(project)))
    assert result["status"] == "done" and result["fields"] == {}  # sample prints no JSON
    sim = run_job(
        Job(
            0,
            "simulate",
            ("grooms/scalp.npz", "out/s.npz", "--frames", "3", "--motion", "still"),
            str(project),
        )
    )
    assert sim["status"] == "done", sim["error"]
    assert sim["fields"]["summary"]["frames"] == 3 and sim["fields"]["summary"]["strands"] == 60


def test_stale_temporaries_of_an_output_are_removed_once_the_job_has_written_it(project):
    out = project / "out" / "a.keys.json"
    stale = project / "out" / ".a.keys.json.a1b2c3-999999.0123abcd.tmp.json"  # a killed attempt's,
    unrelated = project / "out" / ".other.json.a1b2c3-999999.0123abcd.tmp.json"  # on another host
    stale.write_text("{")
    unrelated.write_text("{")
    assert stale_temporaries(out) == [stale]
    assert run_job(keys_job(project))["status"] == "done"
    assert not stale.exists() and unrelated.exists()


def test_atomic_writes_are_recorded_only_when_they_finish(tmp_path):
    with recording_writes() as outer:
        with atomic_open(tmp_path / "a.txt", "w") as f:
            f.write("a")
        with recording_writes() as inner:
            with atomic_open(tmp_path / "b.txt", "w") as f:
                f.write("b")
            try:
                with atomic_open(tmp_path / "c.txt", "w") as f:
                    raise RuntimeError("writer failed")
            except RuntimeError:
                pass
    assert outer == [tmp_path / "a.txt", tmp_path / "b.txt"]
    assert inner == [tmp_path / "b.txt"]
    with atomic_open(tmp_path / "d.txt", "w") as f:
        f.write("d")
    assert outer == [tmp_path / "a.txt", tmp_path / "b.txt"]  # the block has ended


def test_a_job_whose_workers_kept_dying_or_that_could_not_run_is_a_failed_row():
    distributed = pytest.importorskip("distributed")
    from hairtool.farm.batch import _collect
    from hairtool.farm.manifest import Manifests

    class Finished:
        def __init__(self, error: BaseException) -> None:
            self.error = error

        def result(self):
            raise self.error

    job = Job(2, "keys", ("shots/a.npz",), "/nowhere")
    worker = type("WorkerState", (), {"address": "tcp://127.0.0.1:4567"})()
    killed = _collect(Finished(distributed.KilledWorker("k", worker, 2)), job, Manifests(), [])
    assert killed["status"] == "failed" and killed["index"] == 2
    assert (
        killed["error"] == "the worker running it died 3 times (the last: tcp://127.0.0.1:4567); Dask gave up"
    )
    missing = _collect(Finished(ModuleNotFoundError("No module named 'hairtool'")), job, Manifests(), [])
    assert missing["error"] == "ModuleNotFoundError: No module named 'hairtool'"


def test_input_bytes_weighs_a_job_by_the_files_it_names(project):
    from hairtool.farm.batch import input_bytes

    shot = project / "shots" / "a.npz"
    job = Job(0, "keys", ("shots/a.npz", "--keys", "4", "--out", "out/missing.json"), str(project))
    assert input_bytes(job) == shot.stat().st_size  # the output does not exist yet; options are no files
    both = Job(1, "keys", ("shots/a.npz", "--export=shots/b.npz"), str(project))
    assert input_bytes(both) == shot.stat().st_size + (project / "shots" / "b.npz").stat().st_size
    assert input_bytes(Job(2, "keys", ("nothing.npz",), str(project))) == 0
