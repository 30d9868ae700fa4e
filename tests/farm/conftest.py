"""Shots for the batch tests: small animations made with ``hairtool simulate`` and a groom made
with ``hairtool sample``, once per session; each test copies them into its own folder."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from hairtool.cli import main
from hairtool.first_runs import WARM_WORKERS_VARIABLE

#: name → ``hairtool simulate`` arguments of a 24-frame shot.
SHOTS = {
    "a": ["sample:scalp:40:8", "--frames", "24", "--motion", "turn"],
    "b": ["sample:scalp:40:8", "--frames", "24", "--motion", "nod", "--gusts", "1", "--seed", "1"],
    "c": ["sample:scalp:30:10", "--frames", "30", "--motion", "shake"],
}


@pytest.fixture(autouse=True)
def _no_worker_warmup(monkeypatch):
    """The batch tests' jobs are tiny: their workers skip the kernel warm-up (its own tests:
    tests/farm/test_worker_warm.py)."""
    monkeypatch.setenv(WARM_WORKERS_VARIABLE, "0")


@pytest.fixture(scope="session")
def made_shots(tmp_path_factory) -> Path:
    root = tmp_path_factory.mktemp("made")
    (root / "shots").mkdir()
    (root / "grooms").mkdir()
    for name, args in SHOTS.items():
        assert main(["simulate", args[0], str(root / "shots" / f"{name}.npz"), *args[1:]]) == 0
    assert main(["sample", "scalp", str(root / "grooms" / "scalp.npz"), "--strands", "60"]) == 0
    return root


@pytest.fixture
def project(made_shots, tmp_path, capsys) -> Path:
    """A folder with ``shots/{a,b,c}.npz``, ``grooms/scalp.npz`` and an empty ``out/``."""
    shutil.copytree(made_shots, tmp_path, dirs_exist_ok=True)
    (tmp_path / "out").mkdir()
    capsys.readouterr()
    return tmp_path
