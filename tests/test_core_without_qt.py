"""The core library works without the studio's packages (Qt, OpenGL, pyrr, imageio, Pillow), as on a
render-farm node with ``pip install hairtool``: every module imports, and info, freeze, keys and
anime run."""

from __future__ import annotations

import subprocess
import sys
import textwrap

import pytest

SCRIPT = textwrap.dedent(
    """
    import sys

    BLOCKED = ("PySide6", "shiboken6", "moderngl", "pyrr", "imageio", "imageio_ffmpeg", "PIL")

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
    folder = out.rsplit("/", 1)[0]
    assert main(["sample", "portrait", out, "--strands", "12", "--vertices", "6"]) == 0
    assert main(["info", out, "--json"]) == 0
    assert main(["freeze", out, folder + "/frozen.usda", "--align", "0,1,0"]) == 0
    assert main(["anime", out, folder + "/cycle.npz", "--period", "0.5", "--hold", "2"]) == 0
    assert main(["keys", folder + "/cycle.npz", "--keys", "4", "--out", folder + "/keys.json"]) == 0
    assert not any(m.split(".")[0] in BLOCKED for m in sys.modules), "a blocked module got in"
    print("imported", len(names), "modules")
    """
)


@pytest.mark.slow(seconds=20)  # a fresh clone: the child compiles the kernels freeze and anime run
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
    for name in ("s.npz", "frozen.usda", "cycle.npz", "keys.json"):
        assert (tmp_path / name).is_file(), name
