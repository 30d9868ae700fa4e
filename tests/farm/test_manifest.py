"""The manifest beside the outputs: a job is done while its outputs are as written and its inputs
have the same content; anything else runs it again."""

from __future__ import annotations

import json
import os
import shutil

from hairtool.farm.jobs import Job
from hairtool.farm.manifest import MANIFEST_NAME, Manifests
from hairtool.farm.runner import run_job


def done(project, job: Job) -> Manifests:
    result = run_job(job)
    assert result["status"] == "done", result["error"]
    manifests = Manifests()
    assert manifests.record(job, result) == project / "out" / MANIFEST_NAME
    return manifests


def keys_job(project, name: str = "a", index: int = 0) -> Job:
    return Job(index, "keys", (f"shots/{name}.npz", "--keys", "4", "--out", f"out/{name}.json"), str(project))


def test_a_recorded_job_is_done_for_a_new_reader_and_names_its_files(project):
    job = keys_job(project)
    done(project, job)
    entry = Manifests().find_done(job)
    assert entry is not None
    assert list(entry["inputs"]) == [str(project / "shots" / "a.npz")]
    assert list(entry["outputs"]) == [str(project / "out" / "a.json")]
    assert entry["fields"]["key_count"] == 4
    other_options = Job(0, "keys", ("shots/a.npz", "--keys", "5", "--out", "out/a.json"), str(project))
    assert Manifests().find_done(other_options) is None


def test_a_changed_or_missing_output_runs_the_job_again(project):
    job = keys_job(project)
    done(project, job)
    out = project / "out" / "a.json"
    out.write_text(out.read_text() + " ")
    assert Manifests().find_done(job) is None
    done(project, job)
    out.unlink()
    assert Manifests().find_done(job) is None


def test_inputs_are_compared_by_content(project):
    job = keys_job(project)
    done(project, job)
    a = project / "shots" / "a.npz"
    os.utime(a, ns=(1_000_000_000, 1_000_000_000))  # touched, same bytes: still done
    assert Manifests().find_done(job) is not None
    shutil.copyfile(project / "shots" / "b.npz", a)  # another shot under the same name
    assert Manifests().find_done(job) is None
    data = bytearray(a.read_bytes())
    done(project, job)
    data[-100] ^= 1  # same size, one bit changed, new time
    a.write_bytes(bytes(data))
    assert Manifests().find_done(job) is None


def test_jobs_of_one_folder_share_its_manifest_and_a_second_writer_keeps_the_first(project):
    first, second = keys_job(project, "a"), keys_job(project, "b", 1)
    writer_1, writer_2 = Manifests(), Manifests()
    assert writer_1.find_done(first) is None and writer_2.find_done(second) is None  # both read it empty
    writer_1.record(first, run_job(first))
    writer_2.record(second, run_job(second))
    data = json.loads((project / "out" / MANIFEST_NAME).read_text())
    assert len(data["jobs"]) == 2
    assert Manifests().find_done(first) and Manifests().find_done(second)


def test_a_writer_that_wrote_before_reads_the_file_again_when_another_wrote_since(project):
    a, b, c = keys_job(project, "a"), keys_job(project, "b", 1), keys_job(project, "c", 2)
    writer_1, writer_2 = Manifests(), Manifests()
    writer_1.record(a, run_job(a))
    writer_2.record(b, run_job(b))  # after writer_1's write: writer_1's own copy is out of date
    writer_1.record(c, run_job(c))
    data = json.loads((project / "out" / MANIFEST_NAME).read_text())
    assert len(data["jobs"]) == 3
    assert all(Manifests().find_done(job) for job in (a, b, c))


def test_jobs_that_finish_together_share_one_write(project, monkeypatch):
    import hairtool.farm.manifest as manifest

    jobs = [keys_job(project, name, i) for i, name in enumerate("abc")]
    results = [run_job(job) for job in jobs]
    opened, real = [], manifest.atomic_open

    def counted(path, *args, **kwargs):
        opened.append(path)
        return real(path, *args, **kwargs)

    monkeypatch.setattr(manifest, "atomic_open", counted)
    assert Manifests().record_many(list(zip(jobs, results, strict=True))) == [project / "out" / MANIFEST_NAME]
    assert len(opened) == 1
    assert all(Manifests().find_done(job) for job in jobs)


def test_a_damaged_manifest_only_means_the_jobs_run_again(project):
    job = keys_job(project)
    for damaged in ('{"format": "hairtool batch manifest", "jobs": [', "[" * 100_000 + "]" * 100_000):
        done(project, job)
        (project / "out" / MANIFEST_NAME).write_text(damaged)
        assert Manifests().find_done(job) is None
        done(project, job)
        assert Manifests().find_done(job) is not None


def test_a_job_that_wrote_nothing_is_not_recorded(project):
    job = Job(0, "info", ("shots/a.npz",), str(project))
    result = run_job(job)
    assert result["status"] == "done" and result["outputs"] == {}
    assert Manifests().record(job, result) is None
    assert Manifests().find_done(job) is None


def test_the_manifest_text_is_the_entries_one_job_a_line():
    import json

    from hairtool.farm.manifest import FORMAT, VERSION, manifest_text

    entries = {"keys a": {"inputs": {"shots/ä.npz": {"bytes": 3}}, "outputs": {}}, 'odd "key"': {}}
    text = manifest_text(entries)
    assert json.loads(text) == {"format": FORMAT, "version": VERSION, "jobs": entries}
    assert text.count("\n") == len(entries) + 2 and "ä" in text
    assert json.loads(manifest_text({}))["jobs"] == {}


def test_a_rewrite_reuses_the_lines_of_unchanged_entries_and_encodes_replaced_ones():
    import json

    from hairtool.farm.manifest import manifest_text

    kept, old = {"seconds": 1.0}, {"seconds": 2.0}
    encoded: dict = {}
    first = manifest_text({"a": kept, "b": old}, encoded)
    assert encoded["a"][0] is kept and encoded["b"][0] is old
    line_a = encoded["a"][1]
    second = manifest_text({"a": kept, "b": {"seconds": 3.0}, "c": {}}, encoded)
    assert encoded["a"][1] is line_a  # not encoded again
    assert json.loads(second)["jobs"] == {"a": kept, "b": {"seconds": 3.0}, "c": {}}
    assert json.loads(first)["jobs"] == {"a": kept, "b": old}
    assert second == manifest_text({"a": kept, "b": {"seconds": 3.0}, "c": {}})
