"""The warm-up recipes (hairtool.first_runs), ``hairtool cache warm`` and ``hairtool bench cold``."""

from __future__ import annotations

import json

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from hairtool import first_runs, serial_twins
from hairtool.cli import command_names, main
from hairtool.samples import HEAD_RADIUS

COMMANDS = sorted({args[0] for _, args in first_runs.RECIPES})


def test_every_recipe_names_a_command_and_reads_what_an_earlier_one_wrote(tmp_path):
    written = {str(tmp_path / "head.obj")}
    for label in first_runs.labels():
        args = first_runs.argv(label, tmp_path)
        assert args[0] in command_names()
        reads = [a for a in args[1:] if a.startswith(str(tmp_path))]
        outputs = reads[1:] if args[0] not in ("keys", "sample") else []
        if args[0] == "sample":
            outputs = reads
        inputs = [a for a in reads if a not in outputs]
        assert set(inputs) <= written, label
        written.update(outputs)


@settings(max_examples=60, deadline=None)
@given(st.lists(st.sampled_from([*COMMANDS, "info", "batch"]), unique=True))
def test_for_commands_keeps_recipe_order_and_what_each_reads(commands):
    chosen = first_runs.for_commands(commands)
    assert chosen == [label for label in first_runs.labels() if label in chosen]  # recipe order
    assert "sample" in chosen
    for label, args in first_runs.RECIPES:
        if args[0] in commands:
            assert label in chosen
            assert set(first_runs.NEEDS.get(label, ())) <= set(chosen)
        elif label not in ("sample",) and not any(label in first_runs.NEEDS.get(c, ()) for c in chosen):
            assert label not in chosen


def test_for_no_commands_given_is_every_recipe():
    assert first_runs.for_commands(None) == first_runs.labels()


def test_with_inputs_adds_the_recipes_that_write_what_the_chosen_ones_read():
    assert first_runs.with_inputs(["freeze large"]) == ["sample large", "freeze large"]
    assert first_runs.with_inputs(["keys", "convert"]) == ["sample", "simulate", "keys", "convert"]
    assert first_runs.with_inputs(["sample large"]) == ["sample large"]
    assert first_runs.with_inputs([]) == []
    large = dict(first_runs.RECIPES)["sample large"]
    vertices = int(large[large.index("--strands") + 1]) * int(large[large.index("--vertices") + 1])
    assert vertices >= serial_twins.PARALLEL_FROM_VERTICES  # its freeze runs the parallel kernels


def test_the_scalp_mesh_is_a_closed_cap_of_the_sample_head(tmp_path):
    from hairtool.io.obj import read_mesh

    path = tmp_path / "head.obj"
    first_runs.write_scalp(path)
    mesh = read_mesh(path)
    vertices = mesh.vertices.astype(np.float64)
    assert np.allclose(np.linalg.norm(vertices, axis=1), HEAD_RADIUS, atol=1e-6)
    assert vertices[:, 1].min() >= -1e-6
    assert len(mesh.faces) == first_runs.SCALP_SEGMENTS * (2 * first_runs.SCALP_RINGS - 1)
    assert np.all(np.einsum("ij,ij->i", mesh.normals, vertices) > 0)  # facing out


@pytest.fixture
def fake_warm(monkeypatch, tmp_path):
    """``first_runs.warm`` replaced by a recorder (no child processes), the stamp in tmp_path."""
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path / "cache"))
    calls: list[list[str]] = []
    fail: set[str] = set()

    def warm(folder, cache_dir=None, report=None, chosen=None):
        chosen = first_runs.labels() if chosen is None else chosen
        calls.append(list(chosen))
        for label in chosen:
            if report is not None:
                report(label, 1 if label in fail else 0, 0.5, "boom" if label in fail else "")
        return [c for c in chosen if c in fail]

    monkeypatch.setattr(first_runs, "warm", warm)
    return calls, fail


def test_warm_once_warms_each_recipe_once_per_source(fake_warm, monkeypatch):
    calls, fail = fake_warm
    fail.add("anime")
    assert first_runs.warm_once(commands=["freeze"]) == []
    assert first_runs.warm_once(commands=["freeze"]) is None
    assert first_runs.warm_once(commands=["anime", "freeze"]) == ["anime"]
    assert first_runs.warmed() >= set(first_runs.for_commands(["freeze"]))
    assert "anime" not in first_runs.warmed()  # failed: warmed again next time
    fail.clear()
    assert first_runs.warm_once(commands=["anime"]) == []
    assert first_runs.warm_once(commands=["anime"]) is None
    assert len(calls) == 3
    monkeypatch.setattr(first_runs, "source_digest", lambda: "other code")
    assert first_runs.warmed() == set()
    assert first_runs.warm_once(commands=["anime"]) == []
    assert first_runs.warm_once(force=True, commands=["anime"]) == []
    assert len(calls) == 5


def test_cache_warm_command(fake_warm, capsys):
    assert "cache" in command_names()
    assert main(["cache", "warm", "--if-needed"]) == 0
    out = capsys.readouterr().out
    assert "freeze: 0.5 s" in out and "the kernel cache is warm" in out
    assert main(["cache", "warm", "--if-needed"]) == 0
    assert capsys.readouterr().out.strip() == "the kernel cache is warm already"
    fake_warm[1].add("keys")
    assert main(["cache", "warm"]) == 1
    captured = capsys.readouterr()
    assert "keys: failed (boom)" in captured.out
    assert captured.err.strip() == "hairtool cache: error: not warmed: keys"


def test_cache_warm_without_a_writable_cache_folder_is_one_line_and_2(monkeypatch, tmp_path, capsys):
    blocked = tmp_path / "file"
    blocked.write_text("")
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(blocked / "cache"))
    assert main(["cache", "warm"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("hairtool cache: error: ") and str(blocked) in err and err.count("\n") == 1


def test_bench_cold_times_a_command_cold_then_warm(capsys):
    assert main(["bench", "cold", "--commands", "sample", "--repeat", "1", "--kernels", "2", "--json"]) == 0
    (row,) = json.loads(capsys.readouterr().out)
    assert row["command"] == "sample" and row["status"] == 0
    assert row["cold_s"] > 0 and row["warm_s"] > 0
    assert row["compile_share"] == pytest.approx(1 - row["warm_s"] / row["cold_s"])
    assert row["compile_cpu_s"] >= 0 and isinstance(row["slowest"], str)  # (sample compiles nothing)


def test_a_recorded_cold_run_times_each_kernel_it_compiles(tmp_path):
    groom = tmp_path / "groom.hair"
    assert main(["sample", "scalp", str(groom), "--strands", "20", "--vertices", "4"]) == 0
    log = tmp_path / "kernels.json"
    env = first_runs.child_env(tmp_path / "cache")  # empty: convert compiles the box kernel
    args = [str(log), "convert", str(groom), str(tmp_path / "groom.usda")]
    rc, _, message = first_runs.run_child(args, env, module="hairtool.bench.cold")
    assert rc == 0, message
    seconds = json.loads(log.read_text())
    assert seconds["hairtool.bounds:_box"] > 0 and all(s >= 0 for s in seconds.values())
