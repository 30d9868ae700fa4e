"""One regression test per class of hostile file in issue 17 (section 2), through the command line.

Each runs ``hairtool`` in a child process capped at 1.5 GB of address space and expects exit
status 2, exactly one line on stderr naming the file, and under 2 s of CPU time (wall time on a
shared machine says little; it is only bounded against a hang). The message is
checked too: under the cap an unbounded allocation would also end in a one-line error (the
reader turns MemoryError into "cannot read"), so the tests require the size check's own words.
"""

from __future__ import annotations

import os
import resource
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

from . import hostile

pytestmark = pytest.mark.skipif(sys.platform != "linux", reason="wait4 and RLIMIT_AS as on Linux")

MEMORY_CAP = int(1.5 * 2**30)
CPU_LIMIT_S = 2.0
WALL_LIMIT_S = 30.0  # only against a hang; a busy shared machine stretches wall time, not CPU time


@dataclass
class Run:
    status: int
    stdout: str
    stderr_lines: list[str]
    cpu_s: float
    wall_s: float
    max_rss_mb: float


def _cap_memory() -> None:
    resource.setrlimit(resource.RLIMIT_AS, (MEMORY_CAP, MEMORY_CAP))


# The CLI's entry point, noting the process's peak resident memory (VmHWM) as it exits: the
# rusage of a child counts the memory of the process it was forked from.
_ENTRY = """
import atexit, sys
status, sys.argv = sys.argv[1], ["hairtool", *sys.argv[2:]]
atexit.register(lambda: open(status, "w").write(open("/proc/self/status").read()))
from hairtool.cli import entry
entry()
"""


def run_cli(tmp_path: Path, *argv: object) -> Run:
    """``hairtool ARGV`` in a child under the memory cap, with its own CPU time and peak memory."""
    out, err, status_file = tmp_path / "stdout.txt", tmp_path / "stderr.txt", tmp_path / "status.txt"
    start = time.perf_counter()
    with open(out, "wb") as fo, open(err, "wb") as fe:
        p = subprocess.Popen(
            [sys.executable, "-c", _ENTRY, str(status_file), *map(str, argv)],
            stdout=fo,
            stderr=fe,
            preexec_fn=_cap_memory,
        )
        try:
            _, status, usage = os.wait4(p.pid, 0)
        finally:
            p.returncode = 0  # reaped by wait4; keep Popen from waiting again
    wall = time.perf_counter() - start
    peak_kb = next(
        int(line.split()[1]) for line in status_file.read_text().splitlines() if line.startswith("VmHWM:")
    )
    return Run(
        os.waitstatus_to_exitcode(status),
        out.read_text(errors="replace"),
        err.read_text(errors="replace").splitlines(),
        usage.ru_utime + usage.ru_stime,
        wall,
        peak_kb / 1024,
    )


def assert_one_line_error(run: Run, command: str, path: Path, *words: str) -> None:
    assert run.status == 2, run.stderr_lines
    assert len(run.stderr_lines) == 1, run.stderr_lines
    line = run.stderr_lines[0]
    assert line.startswith(f"hairtool {command}: error: {path}: "), line
    for w in words:
        assert w in line, line
    assert "cannot read" not in line and "allocate" not in line, line
    assert run.cpu_s < CPU_LIMIT_S and run.wall_s < WALL_LIMIT_S, (run.cpu_s, run.wall_s)


# -- BVH ---------------------------------------------------------------------------------------
@pytest.mark.parametrize(
    ("frames", "words"),
    [
        ("nan", "not a positive whole number"),
        ("1e400", "not a positive whole number"),
        ("inf", "not a positive whole number"),
        ("-3", "not a positive whole number"),
        ("2.5", "not a positive whole number"),
        ("1e15", "too large"),
        ("100000", "truncated"),  # more frames than the file's bytes can hold
        ("12x", "not a number"),
    ],
)
def test_bvh_frames_field(tmp_path, frames, words):
    path = hostile.write_bvh_frames(tmp_path / "frames.bvh", frames)
    assert_one_line_error(run_cli(tmp_path, "keys", path), "keys", path, words)


def test_bvh_joints_without_channels_times_frames(tmp_path):
    """Found while fixing the class above: channel-less joints cost no bytes per frame, but
    forward kinematics holds every joint in every frame (a 600 KB file asked for 11 GB)."""
    path = hostile.write_bvh_wide(tmp_path / "wide.bvh")
    assert_one_line_error(run_cli(tmp_path, "keys", path), "keys", path, "5000 frames of 20000 joints")


def test_bvh_nested_1200_deep_reads_and_keys(tmp_path):
    """A valid chain deeper than Python's recursion limit is read (and keyed), not refused."""
    path = hostile.write_bvh_deep(tmp_path / "deep.bvh", 1200)
    run = run_cli(tmp_path, "keys", path, "--keys", "2")
    assert run.status == 0 and run.stderr_lines == [], run.stderr_lines
    assert "2 keys of 3 frames" in run.stdout


# -- float64 beyond float32's range --------------------------------------------------------------
@pytest.mark.parametrize("member", ["points", "thickness"])
def test_npz_float64_beyond_float32(tmp_path, member):
    path = hostile.write_npz_beyond_float32(tmp_path / "big.npz", member)
    assert_one_line_error(run_cli(tmp_path, "info", path), "info", path, member, "float32")


def test_obj_coordinate_beyond_float32(tmp_path):
    path = hostile.write_obj_beyond_float32(tmp_path / "big.obj")
    assert_one_line_error(run_cli(tmp_path, "info", path), "info", path, "float32")


# -- int64 strand counts whose sum wraps around --------------------------------------------------
@pytest.mark.parametrize("out", ["back.npz", "back.obj", "back.usda"])
def test_wrapping_counts_are_refused_and_nothing_is_written(tmp_path, out):
    path = hostile.write_npz_wrapping_counts(tmp_path / "wrap.npz")
    assert np.int64(hostile.wrapping_counts(10).sum()) == 10  # the trap: the int64 sum wraps to V
    run = run_cli(tmp_path, "convert", path, tmp_path / out)
    assert_one_line_error(run, "convert", path, "strand 0 claims")
    assert not (tmp_path / out).exists()


# -- .hair without a segments array claiming 2^31 strands ------------------------------------------
@pytest.mark.parametrize("strands", [2**31, 2**28, 2**32 - 1])
def test_hair_claiming_strands_without_segments(tmp_path, strands):
    path = hostile.write_hair_claiming_strands(tmp_path / "claim.hair", strands)
    run = run_cli(tmp_path, "info", path)
    assert_one_line_error(run, "info", path, f"{strands} strands", "header says 4")
    assert run.max_rss_mb < 500


# -- hairtool keys on an .npz holding a raw array X ---------------------------------------------
def test_keys_feature_array_with_a_huge_header(tmp_path):
    path = hostile.write_npz_huge_feature_header(tmp_path / "x.npz", 10**12)
    run = run_cli(tmp_path, "keys", path)
    assert_one_line_error(run, "keys", path, "'X.npy'", "does not match its stored size")
    assert run.max_rss_mb < 500
