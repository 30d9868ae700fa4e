"""One regression test per class of hostile file in issue 17 (section 2), through the command line.

Each runs ``hairtool`` in a child process capped at 1.5 GB of address space (forked from one
that imported the command line once: :data:`_SERVER`) and expects exit status 2, exactly one
line on stderr naming the file, and under 2 s of CPU time (wall time on a shared machine says
little; it is only bounded against a hang). The message is checked too: under the cap an
unbounded allocation would also end in a one-line error (the reader turns MemoryError into
"cannot read"), so the tests require the size check's own words.
"""

from __future__ import annotations

import json
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

from hairtool import io as hairtool_io
from hairtool.errors import FormatError

from . import hostile

pytestmark = pytest.mark.skipif(sys.platform != "linux", reason="wait4 and RLIMIT_AS as on Linux")

MEMORY_CAP = int(1.5 * 2**30)
CPU_LIMIT_S = 4.0  # against runaway reads (minutes); a refusal took 2.04-2.13 s on a slow host
WALL_LIMIT_S = 30.0  # only against a hang; a busy shared machine stretches wall time, not CPU time


@dataclass
class Run:
    status: int
    stdout: str
    stderr_lines: list[str]
    cpu_s: float
    wall_s: float
    max_rss_mb: float


# The CLI's entry point, forked once per run from a server that imported it and every command
# module once, usd-core's too (each run then pays its own read, not Python's start and the
# imports again: about 0.6 s of CPU each, fifty-odd runs). The forked child caps its address
# space, points fd 1 and 2 at the run's files and notes its peak resident memory (VmHWM, the
# imports included) as it exits; the server reaps it with wait4, so its CPU time is the
# command's alone. Whatever the server itself prints on fd 2 (a warning while importing) fails
# the module: it would have been a second line of every run.
_SERVER = """
import atexit, json, os, resource, sys
import importlib
from hairtool.cli import command_modules, entry
for module in sorted(set(command_modules().values())) + ["hairtool.io.usd", "pxr.Usd"]:
    importlib.import_module(module)
cap = int(sys.argv[1])
for line in sys.stdin:
    status, out, err, argv = json.loads(line)
    pid = os.fork()
    if pid == 0:
        resource.setrlimit(resource.RLIMIT_AS, (cap, cap))
        for fd, name in ((1, out), (2, err)):
            os.dup2(os.open(name, os.O_WRONLY | os.O_CREAT | os.O_TRUNC), fd)
        os.dup2(os.open(os.devnull, os.O_RDONLY), 0)
        sys.argv = ["hairtool", *argv]
        atexit.register(lambda: open(status, "w").write(open("/proc/self/status").read()))
        entry()  # ends the child through SystemExit, as the program ends
        sys.exit(0)
    _, code, usage = os.wait4(pid, 0)
    cpu = usage.ru_utime + usage.ru_stime
    print(json.dumps([os.waitstatus_to_exitcode(code), cpu]), flush=True)
"""


class _CliServer:
    def __init__(self, folder: Path) -> None:
        self.errors = folder / "server-stderr.txt"
        with open(self.errors, "wb") as fe:
            self.process = subprocess.Popen(
                [sys.executable, "-c", _SERVER, str(MEMORY_CAP)],
                stdin=subprocess.PIPE,
                stdout=subprocess.PIPE,
                stderr=fe,
                text=True,
            )

    def run(self, status: Path, out: Path, err: Path, argv: list[str]) -> tuple[int, float]:
        self.process.stdin.write(json.dumps([str(status), str(out), str(err), argv]) + "\n")
        self.process.stdin.flush()
        answer = self.process.stdout.readline()
        assert answer, f"the CLI server ended: {self.errors.read_text()[-2000:]}"
        code, cpu = json.loads(answer)
        return code, cpu

    def close(self) -> str:
        self.process.stdin.close()
        self.process.wait(timeout=60)
        return self.errors.read_text()


_server: _CliServer | None = None


@pytest.fixture(scope="module", autouse=True)
def cli_server(tmp_path_factory):
    """The module's one CLI server (:data:`_SERVER`); nothing on its own stderr by the end."""
    global _server
    _server = _CliServer(tmp_path_factory.mktemp("cli-server"))
    yield _server
    server, _server = _server, None
    assert server.close() == "", "the CLI server printed while importing"


def run_cli(tmp_path: Path, *argv: object) -> Run:
    """``hairtool ARGV`` in a child under the memory cap, with its own CPU time and peak memory."""
    out, err, status_file = tmp_path / "stdout.txt", tmp_path / "stderr.txt", tmp_path / "status.txt"
    start = time.perf_counter()
    code, cpu = _server.run(status_file, out, err, [str(a) for a in argv])
    wall = time.perf_counter() - start
    peak_kb = next(
        int(line.split()[1]) for line in status_file.read_text().splitlines() if line.startswith("VmHWM:")
    )
    return Run(
        code,
        out.read_text(errors="replace"),
        err.read_text(errors="replace").splitlines(),
        cpu,
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
    assert "allocate" not in line, line
    assert "cannot read" not in line.replace("usd-core cannot read it", ""), line  # MemoryError's words
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
    forward kinematics holds every joint in every frame (a 600 KB file asked for 11 GB); its
    20,000 joints are now past the joint limit, and the pose tables are budgeted besides."""
    path = hostile.write_bvh_wide(tmp_path / "wide.bvh")
    assert_one_line_error(run_cli(tmp_path, "keys", path), "keys", path, "more than 10000 joints")


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


# -- issue 27: jobs files ------------------------------------------------------------------------
@pytest.mark.parametrize("suffix", [".json", ".toml"])
def test_jobs_file_nested_100000_deep(tmp_path, suffix):
    path = hostile.write_jobs_nested(tmp_path / f"deep{suffix}", 100_000)
    assert_one_line_error(run_cli(tmp_path, "batch", path), "batch", path, "levels deep", "at most 64")


@pytest.mark.parametrize("header", [True, False], ids=["table", "key"])
def test_jobs_file_dotted_key_of_100000_parts(tmp_path, header):
    """tomllib took 22 GB (key) and 27 s (table header) on these 200 KB files."""
    key = ".".join(["a"] * 100_000)
    path = tmp_path / "dotted.toml"
    path.write_text(f"[{key}]\nx = 1\n" if header else f"{key} = 1\n")
    run = run_cli(tmp_path, "batch", path)
    assert_one_line_error(run, "batch", path, "a dotted key of 100000 parts")
    assert run.max_rss_mb < 500


@pytest.mark.parametrize("suffix", [".json", ".toml"])
def test_jobs_file_integer_of_5000_digits(tmp_path, suffix):
    path = hostile.write_jobs_huge_int(tmp_path / f"int{suffix}", 5000)
    assert_one_line_error(run_cli(tmp_path, "batch", path), "batch", path, "5000 digits")


@pytest.mark.parametrize(
    ("pattern", "words"),
    [
        ("shots/*.usdc" * 1000, "of 12000 characters; at most 4096"),  # every user string
        ("*/" * 1000 + "x", "characters long"),
        ("a/" * 400 + "*.usdc", "path components"),
        ("**/" * 4 + "*.usdc", "more than two **"),
    ],
    ids=["repeated-1000", "components-1000", "components-400", "double-star"],
)
def test_jobs_glob_pattern_bounded(tmp_path, pattern, words):
    path = hostile.write_jobs_glob(tmp_path / "glob.json", pattern)
    run = run_cli(tmp_path, "batch", path)
    assert_one_line_error(run, "batch", path, words)
    assert len(run.stderr_lines[0]) < 400  # the pattern is shown cut, not whole


# -- issue 27: stroke logs -----------------------------------------------------------------------
def _freeze_with_strokes(tmp_path: Path, log: Path) -> tuple[Run, Path]:
    from hairtool.io import write

    groom = tmp_path / "groom.npz"
    write(groom, hostile_groom())
    out = tmp_path / "frozen.npz"
    return run_cli(tmp_path, "freeze", groom, out, "--strokes", log), out


def hostile_groom():
    from hairtool.groom import Groom

    return Groom(np.random.default_rng(0).standard_normal((20, 3)), [5, 5, 5, 5])


@pytest.mark.parametrize(
    ("strokes", "words"),
    [
        ([hostile.stroke(radius=10**400)], "401 digits"),
        ([hostile.stroke(falloff=[[0, 1], [0.5], [1, 0]])], "falloff[1]"),
        ([hostile.stroke(falloff=[[0, 1], [0.5, [1, 2]], [1, 0]])], "falloff"),
        ([hostile.stroke(falloff=[[i / 10**5, 0.5] for i in range(10**5 + 1)])], "at most 1028"),
        ([hostile.stroke(falloff=[[0, 10**30], [1, 0]])], "weights in [0, 1]"),
        ([hostile.stroke(falloff=[[0, "heavy"], [1, 0]])], "a finite number"),
        ([hostile.stroke(radius="x" * 100_000)], "of 100000 characters; at most 4096"),
    ],
    ids=["radius-10^400", "ragged", "ragged-nested", "huge-falloff", "falloff-10^30", "falloff-text",
         "radius-long-text"],
)  # fmt: skip
def test_stroke_log_refused_in_one_line_and_nothing_written(tmp_path, strokes, words):
    log = hostile.write_strokes(tmp_path / "log.json", *strokes)
    run, out = _freeze_with_strokes(tmp_path, log)
    assert_one_line_error(run, "freeze", log, words)
    assert len(run.stderr_lines[0]) < 400
    assert not out.exists()


def test_stroke_log_nested_100000_deep(tmp_path):
    log = hostile.write_strokes_nested(tmp_path / "deep.json")
    run, out = _freeze_with_strokes(tmp_path, log)
    assert_one_line_error(run, "freeze", log, "levels deep")
    assert not out.exists()


# -- issue 27: project manifests (the studio reads them; no command does) -------------------------
def _deep_settings(m: dict) -> str:
    return json.dumps(m).replace('"settings": {}', '"settings": ' + '{"a": ' * 100_000 + "1" + "}" * 100_000)


def _set(section: str, key: str, value: object):
    def change(m: dict) -> None:
        m[section][key] = value

    return change


@pytest.mark.parametrize(
    ("change", "words"),
    [
        (_deep_settings, "100001 levels deep"),
        (lambda m: json.dumps(m).replace('"fps": 24.0', '"fps": 1' + "0" * 400), "401 digits"),
        (_set("animation", "fps", 10**30), None),  # a number, just a very fast one: it reads
        (_set("params", "seed", [1, [2, 3]]), "engine parameter 'seed' is a JSON list"),
        (_set("params", "strand_variation", [[0.1], [0.2, 0.3]]), "strand_variation must be a number"),
        (_set("params", "strand_variation", "lots"), "strand_variation must be a number"),
        (_set("strokes", "count", "2"), "bad 'strokes' section"),
        (_set("groom", "attributes", {"thickness": 1}), "bad attribute list"),
    ],
    ids=["deep-settings", "fps-10^400", "fps-10^30", "seed-ragged", "variation-ragged", "variation-text",
         "count-text", "attributes-object"],
)  # fmt: skip
def test_project_manifest_hostile_values(tmp_path, change, words):
    from hairtool.errors import FormatError
    from hairtool.project import load

    path = hostile.write_project_manifest(tmp_path / "p.hairproj", change)
    if words is None:
        assert load(path).animation.fps == 1e30
        return
    with pytest.raises(FormatError) as e:
        load(path)
    assert str(e.value).startswith(f"{path}: ") and "\n" not in str(e.value), e.value
    assert words in str(e.value), e.value


# -- issue 27: USD that usd-core warns about: its lines folded into ours, or dropped -------------
@pytest.mark.parametrize(
    ("old", "new", "words"),
    [
        ("[4, 3]", "[4, " + "9" * 30 + "]", "usd-core warned: Integer literal"),
        ('["xformOp:translate", "xformOp:rotateZ"]', '["xformOp:banana"]', "usd-core warned: Unable to get"),
    ],
    ids=["integer-literal", "xform-op"],
)
def test_usd_core_warnings_fold_into_the_one_line(tmp_path, old, new, words):
    path = hostile.write_usda(tmp_path / "warned.usda", old, new)
    assert_one_line_error(run_cli(tmp_path, "info", path), "info", path, words)


def test_usd_core_warning_on_a_file_that_reads_is_dropped(tmp_path):
    """An integer literal out of range in a time sample: usd-core reads it as a double and warns."""
    path = hostile.write_usda(tmp_path / "t.usda", "{1: 0, 2: 30}", "{1: 0, 99999999999999999999999: 30}")
    run = run_cli(tmp_path, "info", path)
    assert run.status == 0 and run.stderr_lines == [], run.stderr_lines
    assert "2 at" in run.stdout  # two frames


def test_usdc_with_an_invalid_prim_name(tmp_path):
    path = hostile.write_usdc_bad_prim_name(tmp_path / "name.usdc")
    out = tmp_path / "out.npz"
    run = run_cli(tmp_path, "convert", path, out)
    assert_one_line_error(run, "convert", path, "usd-core warned: Invalid prim name")
    assert not out.exists()



@pytest.mark.parametrize("which", ["points", "counts"])
def test_usdc_array_claiming_2_34_elements(tmp_path, which):
    """A crate array's length prefix is read before its values: the count is checked against the
    bytes after it before usd-core sizes the array (raw or compressed)."""
    path = hostile.write_usdc_array_count(tmp_path / f"{which}.usdc", which)
    run = run_cli(tmp_path, "info", path)
    assert_one_line_error(run, "info", path, "claims 17179869184 values; the")
    assert run.max_rss_mb < 600, run.max_rss_mb


def test_usda_of_ten_million_widths_is_refused_before_usd_core_parses_it(tmp_path):
    """A 20 MB file: usd-core's text parser peaked at 1.9 GB on it before the reader refused it."""
    path = hostile.write_usda_widths(tmp_path / "widths.usda", 10**7)
    assert path.stat().st_size > 20e6
    out = tmp_path / "out.npz"
    run = run_cli(tmp_path, "convert", path, out)
    words = "line 16: widths holds 10000000 values for curves of at most 7 points"
    assert_one_line_error(run, "convert", path, words)
    assert run.max_rss_mb < 600, run.max_rss_mb  # the imports alone take about 260 MB
    assert not out.exists()



def test_usd_animation_larger_than_memory_is_refused_before_allocating(tmp_path, monkeypatch):
    """Frames come from the union of every time sample, so a small file can ask for terabytes;
    the reader compares frames × points with half of the memory it may use before allocating."""
    from hairtool.io import usd

    samples = ", ".join(f"{t}: {t % 360}" for t in range(1, 1001))
    path = hostile.write_usda(tmp_path / "long.usda", "{1: 0, 2: 30}", "{" + samples + "}")
    monkeypatch.setattr(usd, "_memory_bytes", lambda: 2 * 1000 * 7 * 12 - 2)  # one byte short
    with pytest.raises(FormatError, match=r"1,000 time samples of 7 points need .* half of the memory") as e:
        hairtool_io.read(path)
    assert e.value.path == str(path)
    monkeypatch.setattr(usd, "_memory_bytes", lambda: 2 * 1000 * 7 * 12)  # exactly enough
    assert hairtool_io.read(path).frames.shape == (1000, 7, 3)


def test_usd_transform_sampled_100000_times_under_a_memory_cap(tmp_path):
    """1.3 MB of text asking for 840 MB of frames, under the 1.5 GB address-space cap: one line."""
    points = ", ".join(f"({i % 2}, 0, {i // 2})" for i in range(700))
    samples = ", ".join(f"{t}: {t % 360}" for t in range(1, 100_001))
    text = hostile.USDA_CURVES.replace("{1: 0, 2: 30}", "{" + samples + "}").replace("[4, 3]", "[350, 350]")
    start = text.index("point3f[] points = [")
    text = text[:start] + f"point3f[] points = [{points}" + text[text.index("]\n", start) :]
    path = tmp_path / "long.usda"
    path.write_text(text)
    assert_one_line_error(run_cli(tmp_path, "info", path), "info", path, "100,000 time samples of 700 points")
