"""``.ci/check-packages``: one line naming the Debian packages the GUI lacks, the list ``.ci/run``
installs."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
CI = ROOT / ".ci"

pytestmark = pytest.mark.skipif(shutil.which("dpkg-query") is None, reason="not a Debian machine")


def listed() -> list[str]:
    names = []
    for line in (CI / "debian-packages").read_text().splitlines():
        if line.strip() and not line.startswith("#"):
            names.append(line.split()[0])
    return names


def check(tmp_path: Path, extra: list[str], mode: str = "all") -> subprocess.CompletedProcess:
    shutil.copy(CI / "check-packages", tmp_path / "check-packages")
    (tmp_path / "debian-packages").write_text("\n".join(["# a comment", *extra, ""]))
    return subprocess.run(
        ["bash", str(tmp_path / "check-packages"), mode], capture_output=True, text=True, check=False
    )


def test_a_missing_package_is_named_in_one_line(tmp_path):
    installed = subprocess.run(
        ["dpkg-query", "-W", "-f=${Package}\\n", "bash"], capture_output=True, text=True, check=True
    ).stdout.split()
    done = check(tmp_path, [*installed, "hairtool-no-such-package0", "hairtool-no-such-package1 *"])
    assert done.returncode == 1
    lines = done.stdout.splitlines()
    assert len(lines) == 1 and lines[0].endswith(
        "sudo apt-get install --no-install-recommends hairtool-no-such-package0 hairtool-no-such-package1"
    )
    assert "bash" not in lines[0].split(":", 1)[1]
    studio = check(tmp_path, ["hairtool-no-such-package1 *"], "studio")  # Xvfb is for the tests only
    assert studio.returncode == 0 and studio.stdout == ""


def test_nothing_said_when_everything_is_there(tmp_path):
    done = check(tmp_path, ["bash"])
    assert (done.returncode, done.stdout, done.stderr) == (0, "", "")


def test_ci_installs_exactly_the_checked_list():
    run = (CI / "run").read_text()
    assert ".ci/debian-packages" in run and "apt-get install" in run
    assert {"xvfb", "libxcb-cursor0", "libgl1-mesa-dri", "libgomp1"} <= set(listed())
    assert len(listed()) == len(set(listed()))
