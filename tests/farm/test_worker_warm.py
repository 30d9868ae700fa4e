"""Each Dask worker warms the kernel cache for the batch's commands once (hairtool.farm.warm)."""

from __future__ import annotations

import pickle

import pytest

pytest.importorskip("distributed")

from hairtool import first_runs
from hairtool.farm import warm


class _Client:
    def __init__(self) -> None:
        self.plugins: list = []

    def register_plugin(self, plugin) -> None:
        self.plugins.append(pickle.loads(pickle.dumps(plugin)))  # as it travels to the workers


def test_workers_warm_the_batch_commands_they_know(monkeypatch):
    monkeypatch.setenv(first_runs.WARM_WORKERS_VARIABLE, "1")
    client = _Client()
    warm.warm_workers(client, ["keys", "freeze", "info"])  # info runs no kernel recipe
    (plugin,) = client.plugins
    assert plugin.commands == ("freeze", "keys")
    assert plugin.name == "hairtool-warm:freeze,keys"
    seen = []
    monkeypatch.setattr(first_runs, "warm_once", lambda commands=None, **kw: seen.append(commands) or [])
    plugin.setup(worker=None)
    assert seen == [("freeze", "keys")] and plugin.failed == []


@pytest.mark.parametrize(("value", "commands"), [("0", ["freeze"]), ("1", ["info"]), ("1", [])])
def test_no_warm_up_when_turned_off_or_nothing_to_warm(monkeypatch, value, commands):
    monkeypatch.setenv(first_runs.WARM_WORKERS_VARIABLE, value)
    client = _Client()
    warm.warm_workers(client, commands)
    assert client.plugins == []


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
