"""``anime`` and ``interpolate`` as batch jobs on a local cluster: a sample groom and the bundled
Sintel guides with a few hundred children, written into folders that do not exist yet; every
output equals the command run by hand."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from hairtool.cli import main
from hairtool.groom import Animation
from hairtool.io import read

pytest.importorskip("distributed", reason="the farm extra (dask[distributed]) is not installed")

RESOURCES = Path(__file__).resolve().parents[2] / "resources"
SINTEL = str(RESOURCES / "sintel_hair.tfx")  # 228 guides
HEAD = str(RESOURCES / "sintel_head.obj")
#: (command, args with OUT/ for the output folder): the first input a sample spec, options first
#: in the last job.
JOBS = [
    ("anime", ["sample:scalp:40:8", "OUT/anime/wave.usda", "--frames", "12", "--seed", "1"]),
    ("anime", [SINTEL, "OUT/anime/sintel.npz", "--frames", "6", "--count", "300", "--scalp", HEAD]),
    ("interpolate", [SINTEL, "OUT/render/sintel.usda", "--count", "300", "--scalp", HEAD, "--seed", "2"]),
    ("interpolate", ["--count", "50", "--seed", "3", "sample:scalp:20:6", "OUT/render/scalp.hair"]),
]


def _args(args: list[str], out: str) -> list[str]:
    return [a.replace("OUT", out) for a in args]


def _same(a: Path, b: Path) -> None:
    x, y = read(a), read(b)
    assert type(x) is type(y) and np.array_equal(x.counts, y.counts), a.name
    assert np.array_equal(
        x.frames if isinstance(x, Animation) else x.points, y.frames if isinstance(y, Animation) else y.points
    ), a.name


def test_anime_and_interpolate_jobs_write_what_the_commands_write_by_hand(project, capsys):
    jobs = project / "jobs.json"
    entries = [{"command": c, "args": _args(a, "out/new")} for c, a in JOBS]
    jobs.write_text(json.dumps({"jobs": entries}))
    report = project / "report.json"
    rc = main(["batch", str(jobs), "--workers", "2", "--json", "--report", str(report)])
    summary = json.loads(capsys.readouterr().out)
    rows = json.loads(report.read_text())["jobs"]
    assert rc == 0 and summary["done"] == 4, [r["error"] for r in rows]
    assert [r["input"] for r in rows] == ["sample:scalp:40:8", SINTEL, SINTEL, "sample:scalp:20:6"]
    new = project / "out" / "new"
    assert sorted(rows[1]["outputs"]) == [
        str(new / "anime" / "sintel.guides.npz"),
        str(new / "anime" / "sintel.npz"),
    ]

    wave, sintel = read(new / "anime" / "wave.usda"), read(new / "anime" / "sintel.npz")
    assert isinstance(wave, Animation) and (wave.n_frames, wave.strand_count) == (12, 40)
    assert isinstance(sintel, Animation) and (sintel.n_frames, sintel.strand_count) == (6, 300)
    assert read(new / "anime" / "sintel.guides.npz").strand_count == 228
    assert read(new / "render" / "sintel.usda").strand_count == 300 + 228  # the guides: a prim of their own
    assert read(new / "render" / "scalp.hair").strand_count == 50

    hand = project / "hand"
    for command, args in JOBS:
        assert main([command, *_args(args, str(hand))]) == 0
    capsys.readouterr()
    for path in sorted(p for p in hand.rglob("*") if p.is_file()):
        _same(path, new / path.relative_to(hand))
    assert len(list(new.rglob("*.*"))) == 5 + 2  # the outputs and a manifest in each folder
