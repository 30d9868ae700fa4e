"""Each Dask worker warms the kernel cache for the batch's commands once (hairtool.farm.warm)."""

from __future__ import annotations

import pytest

pytest.importorskip("distributed")

from hairtool import first_runs
from hairtool.farm import warm


@pytest.fixture
def warm_calls(monkeypatch):
    """``first_runs.warm_once`` recorded, and a fresh process's memory of what it warmed."""
    seen: list = []
    monkeypatch.setattr(first_runs, "warm_once", lambda commands=None, **kw: seen.append(commands) or [])
    monkeypatch.setattr(warm, "_warmed", set())
    return seen


def test_a_worker_warms_each_command_once_before_its_first_job(monkeypatch, warm_calls):
    monkeypatch.setenv(first_runs.WARM_WORKERS_VARIABLE, "1")
    assert warm.warm_before_job("keys") == []
    assert warm.warm_before_job("keys") is None
    assert warm.warm_before_job("freeze") == []
    assert warm.warm_before_job("info") is None  # no kernel recipe
    assert warm_calls == [["keys"], ["freeze"]]


def test_no_warm_up_when_turned_off(monkeypatch, warm_calls):
    monkeypatch.setenv(first_runs.WARM_WORKERS_VARIABLE, "0")
    assert warm.warm_before_job("freeze") is None
    assert warm_calls == []


def test_a_worker_without_a_writable_cache_folder_runs_its_jobs_unwarmed(monkeypatch, tmp_path):
    monkeypatch.setenv(first_runs.WARM_WORKERS_VARIABLE, "1")
    monkeypatch.setattr(warm, "_warmed", set())
    blocked = tmp_path / "file"
    blocked.write_text("")
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(blocked / "cache"))  # under a file: cannot be made
    assert warm.warm_before_job("freeze") is None
    assert warm.warm_before_job("freeze") is None  # and does not try again


@pytest.mark.slow(seconds=15)
def test_a_local_batch_warms_its_workers_once(project, capsys, monkeypatch, tmp_path):
    import os

    from hairtool.cli import main

    if os.environ.get("NUMBA_CACHE_DIR"):
        pytest.skip("the warm-up record would go into the shared NUMBA_CACHE_DIR")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    monkeypatch.setenv(first_runs.WARM_WORKERS_VARIABLE, "1")
    jobs = project / "jobs.toml"
    jobs.write_text('[[jobs]]\ncommand = "convert"\nargs = ["grooms/scalp.npz", "out/scalp.usda"]\n')
    assert main(["batch", str(jobs), "--workers", "1"]) == 0
    capsys.readouterr()
    assert first_runs.warmed() == {"sample", "convert"}
    assert (project / "out" / "scalp.usda").is_file()
