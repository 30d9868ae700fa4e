"""The core library works with Qt and OpenGL absent: every hairtool module imports, the CLI runs."""

from __future__ import annotations

import subprocess
import sys
import textwrap

SCRIPT = textwrap.dedent(
    """
    import sys

    BLOCKED = ("PySide6", "shiboken6", "moderngl")

    class Block:
        def find_spec(self, name, path=None, target=None):
            if name.split(".")[0] in BLOCKED:
                raise ImportError(f"{name} is blocked in this test")
            return None

    sys.meta_path.insert(0, Block())

    import importlib
    import pkgutil

    import hairtool

    names = [m.name for m in pkgutil.walk_packages(hairtool.__path__, "hairtool.")]
    for name in names:
        if name != "hairtool.__main__":  # runs the CLI on import
            importlib.import_module(name)
    assert not any(m.split(".")[0] in BLOCKED for m in sys.modules), "a blocked module got in"

    from hairtool.cli import main

    out = sys.argv[1]
    assert main(["sample", "portrait", out, "--strands", "12", "--vertices", "6"]) == 0
    assert main(["info", out, "--json"]) == 0
    print("imported", len(names), "modules")
    """
)


def test_core_imports_and_cli_run_without_qt_or_gl(tmp_path):
    r = subprocess.run(
        [sys.executable, "-c", SCRIPT, str(tmp_path / "s.npz")],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert r.returncode == 0, r.stderr
    assert '"strands": 12' in r.stdout
    count = int(r.stdout.rsplit("imported", 1)[1].split()[0])
    assert count >= 10  # errors, groom, io.*, cli.* at least
    assert (tmp_path / "s.npz").is_file()
