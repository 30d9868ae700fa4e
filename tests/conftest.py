"""Suite-wide set-up: a virtual X display for the GUI tests when none is given, and data paths."""

from __future__ import annotations

import ctypes
import importlib.util
import os
import shutil
import signal
import subprocess
import sys
from pathlib import Path

import pytest

# numba's parallel kernels run on GNU OpenMP here, whose idle threads spin at every barrier. Two
# xdist workers, each with a pool per core, then spin against each other's work: the brush
# pictures took 31 s of CPU where passive waiting takes 3 s. Set before any kernel loads libgomp,
# and inherited by the commands the tests run as children.
os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

ROOT = Path(__file__).resolve().parent.parent
TEST_DATA = ROOT / "tests" / "data"  # real grooms, captures and Blender exports, licences beside
GROOMS = TEST_DATA / "grooms"
MOTION = TEST_DATA / "motion"

_xvfb: subprocess.Popen | None = None
_OWN_DISPLAY = "HAIRTOOL_TEST_XVFB"  # set where this conftest started the display


def _end_with_parent() -> None:
    """In the Xvfb child before it starts (Linux): SIGTERM when the process that started it
    ends, so the display outlives the tests' QApplication, which Qt tears down only as the
    interpreter exits: a display ended in ``pytest_unconfigure`` broke its X connection first
    ("The X11 connection broke", and a segfault of a single-process run at exit)."""
    libc = ctypes.CDLL(None, use_errno=True)
    libc.prctl(1, signal.SIGTERM)  # PR_SET_PDEATHSIG


def _start_xvfb() -> None:
    """Start ``Xvfb -displayfd`` and export DISPLAY, so plain ``pytest`` runs the GUI tests, on a
    1366×768 screen: the laptop size the studio must fit. Each xdist worker gets a display of
    its own: with no window manager, windows of two workers on one display took the keyboard
    focus from each other (a test waiting for its window to be active timed out under load)."""
    global _xvfb
    ours = os.environ.get(_OWN_DISPLAY) and os.environ.get("PYTEST_XDIST_WORKER")
    if (os.environ.get("DISPLAY") and not ours) or shutil.which("Xvfb") is None:
        return
    read_fd, write_fd = os.pipe()
    _xvfb = subprocess.Popen(
        ["Xvfb", "-displayfd", str(write_fd), "-screen", "0", "1366x768x24", "-nolisten", "tcp"],
        pass_fds=(write_fd,),
        preexec_fn=_end_with_parent if sys.platform.startswith("linux") else None,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    os.close(write_fd)
    with os.fdopen(read_fd) as f:
        number = f.readline().strip()
    if not number:
        raise RuntimeError("Xvfb did not report a display number")
    os.environ["DISPLAY"] = f":{number}"
    os.environ[_OWN_DISPLAY] = "1"


def missing_system_packages() -> str | None:
    """``.ci/check-packages``'s one line naming the Debian packages the GUI tests lack, or None."""
    script = ROOT / ".ci" / "check-packages"
    if not script.is_file() or shutil.which("bash") is None:
        return None
    done = subprocess.run(["bash", str(script), "test"], capture_output=True, text=True, check=False)
    if done.returncode != 1:
        return None
    return done.stdout.strip() or None


def _register_xdist_recovery(config: pytest.Config) -> None:
    """Where xdist runs the suite, its file scheduling that finishes after a worker dies
    (``tests/xdist_recovery.py`` says why)."""
    if not config.pluginmanager.hasplugin("xdist") or config.pluginmanager.has_plugin("xdist-recovery"):
        return
    path = Path(__file__).with_name("xdist_recovery.py")
    spec = importlib.util.spec_from_file_location("hairtool_xdist_recovery", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    config.pluginmanager.register(module.Plugin(), "xdist-recovery")


def pytest_configure(config: pytest.Config) -> None:
    _register_xdist_recovery(config)
    config.missing_system_packages = missing_system_packages()
    if config.missing_system_packages is not None and os.environ.get("CI"):
        # CI runs the GUI and render tests for real: a missing package fails the run, loudly
        raise pytest.UsageError(f"CI needs the GUI's system packages: {config.missing_system_packages}")
    if config.missing_system_packages is None:
        _start_xvfb()


def pytest_report_header(config: pytest.Config) -> str | None:
    return config.missing_system_packages


def _slow_seconds(item: pytest.Item) -> float:
    """What a test's ``slow`` mark says it takes (``seconds=``, a warm run here), 0 unmarked."""
    marks = list(item.iter_markers("slow"))
    return max((float(m.kwargs.get("seconds", 10)) for m in marks), default=0.0)


def _slowest_files_first(items: list[pytest.Item]) -> None:
    """The workers take whole files in this order (``./dev test`` turns off xdist's reordering by
    test count): the files whose slow tests add up to the most start first, so the run does not
    end with one worker alone on a two-minute file while the others wait."""
    seconds: dict[Path, float] = {}
    for item in items:
        seconds[item.path] = seconds.get(item.path, 0.0) + _slow_seconds(item)
    items.sort(key=lambda item: -seconds[item.path])  # stable: a file's tests keep their order


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """The slowest files first (:func:`_slowest_files_first`). Without Qt's system libraries (on a
    developer's machine: CI refuses to start) the GUI and render tests are skipped with the one
    line that names the packages (Qt would otherwise abort the whole run at the first window)."""
    _slowest_files_first(items)
    reason = config.missing_system_packages
    if reason is None:
        return
    needs_gui = (ROOT / "tests" / "gui", ROOT / "tests" / "render")
    skip = pytest.mark.skip(reason=reason)
    for item in items:
        if item.get_closest_marker("gui") or any(d in Path(str(item.path)).parents for d in needs_gui):
            item.add_marker(skip)


def pytest_unconfigure(config: pytest.Config) -> None:
    if _xvfb is not None and not sys.platform.startswith("linux"):  # on Linux: it ends with us
        _xvfb.terminate()
        _xvfb.wait(timeout=10)


@pytest.fixture(autouse=True)
def _budget_factor_restored():
    """Each test starts with the budget's limits as set outside the suite: ``--raise-limits``
    (``budget.set_factor``) writes the factor to the environment, and a test that raised it
    in-process made a later one on the same worker pass its limits."""
    before = os.environ.get("HAIRTOOL_BUDGET")
    yield
    if before is None:
        os.environ.pop("HAIRTOOL_BUDGET", None)
    else:
        os.environ["HAIRTOOL_BUDGET"] = before


@pytest.fixture(scope="session")
def grooms_dir() -> Path:
    if not GROOMS.is_dir():
        pytest.fail(f"real grooms are expected in {GROOMS}")
    return GROOMS


@pytest.fixture(scope="session")
def motion_dir() -> Path:
    if not MOTION.is_dir():
        pytest.fail(f"motion captures are expected in {MOTION}")
    return MOTION


@pytest.fixture
def quick_bench(capsys):
    """``quick_bench(NAME, *ARGS, times=COLUMNS)``: the JSON rows of ``hairtool bench NAME --quick
    --json ARGS``, each of ``times`` checked to be a positive finite number or None (not run).

    Benchmark tests check what a bench reports, never how fast it ran.
    """
    import json
    import math

    from hairtool.cli import main

    def run(name: str, *args: str, times: tuple[str, ...] = ()) -> list[dict]:
        assert main(["bench", name, "--quick", "--json", *args]) == 0
        rows = json.loads(capsys.readouterr().out)
        assert rows, f"bench {name} returned no rows"
        for row in rows:
            for key in times:
                v = row[key]
                assert v is None or (math.isfinite(v) and v > 0), f"{key} = {v!r} in {row}"
        return rows

    return run
