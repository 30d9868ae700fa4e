"""Ctrl+C at any moment of a command that loads usd-core ends in one "interrupted" line and exit
status 130 (issue 45): a sweep of children, each sent SIGINT at its own delay from its start,
through the program's start, its imports, usd-core's plugin loading, the read and the write.

The program is the ``hairtool`` script as pip writes it from ``pyproject.toml``'s
``[project.scripts]``. Before its first line runs, the interrupt is Python's, out of any
program's reach, and two outcomes are Python's own: in its first instants the child ends by the
signal itself with nothing said (a shell reports 130 for it), and while Python imports its
``site`` module it prints Python's traceback; where the interrupt lands in a ``.pth`` file's
import (an editable install's finder takes most of the start-up here), ``site`` prints "Error
processing line …", swallows it and the command runs on, never told (as Python does with one
raised in an import lock's callback: "Exception ignored in …"). Such a traceback may pass
through the program's first lines only (the package's ``__init__``, ``errors``, ``interrupts``
and ``__main__``, before the handler is installed); one through any other hairtool module, or
anything else once the handler is in, fails. About 15 s in CI: the children run four at a time.
"""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import time
import tomllib
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
USDA = ROOT / "tests" / "data" / "interop" / "b.usda"
# 0, 10 … 600 ms: Python's start-up and the program's imports; then usd-core and the write
DELAYS = (*(i / 100 for i in range(61)), 0.9, 1.2, 1.5, 1.8, 2.1, 2.4, 2.7, 3.0)
FIRST_LINES = {"__init__.py", "errors.py", "interrupts.py", "__main__.py"}
FRAME = re.compile(r'^  File "([^"]+)", line', re.M)


def _script(folder: Path) -> Path:
    """The ``hairtool`` script pip writes for the entry point pyproject.toml names."""
    target = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["scripts"]["hairtool"]
    module, function = target.split(":")
    script = folder / "hairtool"
    script.write_text(
        f"#!{sys.executable}\nimport re\nimport sys\nfrom {module} import {function}\n"
        f"if __name__ == '__main__':\n    sys.exit({function}())\n"
    )
    script.chmod(0o755)
    return script


def _interrupted_at(script: Path, out: Path, delay: float) -> tuple[float, int, str, bool]:
    """(delay, exit status, stderr, whether the child still ran when the signal was sent: on an
    idle machine the command can be done before the sweep's last delays)."""
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    p = subprocess.Popen(
        [script, "convert", USDA, out], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, env=env
    )
    time.sleep(delay)
    running = p.poll() is None
    if running:
        p.send_signal(signal.SIGINT)
    _, err = p.communicate(timeout=120)
    return delay, p.returncode, err.decode(errors="replace"), running


def _pythons_own(err: str) -> bool:
    """A traceback of Python's default handler raised before the program's handler was in."""
    files = FRAME.findall(err)
    ours = [f for f in files if Path(f).resolve().is_relative_to(ROOT / "hairtool")]
    return (
        "KeyboardInterrupt" in err
        and not err.count(": interrupted\n")
        and all(Path(f).parent == ROOT / "hairtool" and Path(f).name in FIRST_LINES for f in ours)
        and not any(f.endswith("interrupts.py") and "_handler" in err for f in ours)
    )


def _solo_seconds(script: Path, out: Path) -> float:
    """How long the command takes uninterrupted, alone (the sweep's children, four at a time,
    take longer)."""
    t0 = time.perf_counter()
    subprocess.run([script, "convert", USDA, out], check=True, capture_output=True, timeout=120,
                   env={**os.environ, "PYTHONPATH": str(ROOT)})  # fmt: skip
    return time.perf_counter() - t0


@pytest.mark.slow(seconds=30)
def test_ctrl_c_at_any_moment_of_a_usd_command_is_one_line_and_130(tmp_path):
    script = _script(tmp_path)
    (tmp_path / "solo").mkdir()
    solo = _solo_seconds(script, tmp_path / "solo" / "o.npz")
    outs = [tmp_path / f"out{i}" / "o.npz" for i in range(len(DELAYS))]
    with ThreadPoolExecutor(4) as pool:
        results = list(pool.map(_interrupted_at, [script] * len(DELAYS), outs, DELAYS))
    said = 0
    # well past Python's start-up, even on a loaded host, and well before the command is done
    # (on an idle machine a signal near its end lands while the interpreter ends, its work written)
    late = [r[:3] for r in results if 1.5 <= r[0] < 0.6 * solo and r[3]]
    for (delay, status, err, running), out in zip(results, outs, strict=True):
        where = f"SIGINT at {delay * 1000:.0f} ms: exit {status}, stderr {err[-1500:]!r}"
        done = status == 0 and err == "" and out.is_file()
        if not running or (done and delay >= 0.6 * solo):  # done before the signal counted
            assert done, where
            continue
        if err.endswith(": interrupted\n") and err.count("\n") == 1:
            assert status == 130, where
            said += 1
        elif err == "":
            assert status == -signal.SIGINT or (status == 0 and out.is_file()), where
        else:  # swallowed (0: the command was never told), or Python's traceback at its start
            assert _pythons_own(err) and status in (0, 1, -signal.SIGINT), where
            assert status != 0 or out.is_file(), where
        if status != 0:  # no partial output, no temporary file left: nothing, or (a signal that
            # came after the write was renamed into place) the whole output, as alone
            left = list(out.parent.iterdir()) if out.parent.exists() else []
            assert left in ([], [out]), where
            assert not left or out.read_bytes() == (tmp_path / "solo" / "o.npz").read_bytes(), where
    for delay, status, err in late:
        assert status == 130 and err.endswith(": interrupted\n"), (delay, status, err[-1500:])
    assert said >= max(len(late), 1)


def test_a_swallowed_interrupt_commits_no_file(tmp_path, monkeypatch):
    """An interrupt a library swallowed (usd-core's plugin loading) is recorded: the write that
    follows it is not renamed into place, and it ends as the interrupt."""
    from hairtool import interrupts
    from hairtool.io.atomic import atomic_open

    target = tmp_path / "out.bin"
    with atomic_open(target) as f:
        f.write(b"before")
    monkeypatch.setattr(interrupts, "_interrupted", True)
    with pytest.raises(KeyboardInterrupt), atomic_open(target) as f:
        f.write(b"after")
    assert target.read_bytes() == b"before" and [p.name for p in tmp_path.iterdir()] == ["out.bin"]


def test_the_line_in_a_caller_s_own_process_is_said_each_time(capfd):
    """:func:`hairtool.cli.main` called in a process that did not install the handling (a
    script, a test) says the line each time and keeps its stderr."""
    from hairtool import interrupts

    assert not interrupts._installed
    assert interrupts.report("hairtool info") == 130 and interrupts.report("hairtool keys") == 130
    signal.signal(signal.SIGINT, signal.default_int_handler)
    print("still here", file=sys.stderr)
    assert capfd.readouterr().err == "hairtool info: interrupted\nhairtool keys: interrupted\nstill here\n"
