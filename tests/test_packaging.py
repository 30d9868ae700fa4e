"""The install layout: every package ships, and the studio finds its shaders from an install."""

from __future__ import annotations

import re
import subprocess
import sys
import zipfile
from email.parser import Parser
from importlib import resources
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
STUDIO_ONLY = {"pyside6-essentials", "moderngl", "pyrr", "imageio", "imageio-ffmpeg", "pillow"}


@pytest.fixture(scope="module")
def wheel(tmp_path_factory) -> zipfile.ZipFile:
    """The wheel ``pip install .`` would install, built from this checkout."""
    out = tmp_path_factory.mktemp("wheel")
    subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation", "-q", "-w", out, ROOT],
        check=True,
        capture_output=True,
        timeout=300,
    )
    (path,) = out.glob("hairtool-*.whl")
    with zipfile.ZipFile(path) as z:
        yield z


def test_every_python_package_ships_in_the_wheel(wheel):
    mapped = {"shaders": "app.shaders", "resources": "app.resources"}
    found = set()
    for top in ("hairtool", "app", "shaders", "resources"):
        for init in (ROOT / top).rglob("__init__.py"):
            rel = init.parent.relative_to(ROOT)
            found.add(mapped.get(".".join(rel.parts), ".".join(rel.parts)))
    inits = [n for n in wheel.namelist() if n.endswith("/__init__.py")]
    shipped = {n[: -len("/__init__.py")].replace("/", ".") for n in inits}
    assert found == shipped
    assert any(n.startswith("app/shaders/") and n.endswith(".glsl") for n in wheel.namelist())
    assert "app/resources/sintel_hair.tfx" in wheel.namelist()
    assert "app/resources/bunches.vrm" in wheel.namelist()  # the bundled character


def test_the_library_installs_without_the_studio(wheel):
    """``pip install hairtool`` on a farm node: no Qt, no OpenGL; ``hairtool[studio]`` adds them."""
    (meta,) = [n for n in wheel.namelist() if n.endswith(".dist-info/METADATA")]
    requires = Parser().parsestr(wheel.read(meta).decode()).get_all("Requires-Dist")
    def name(r: str) -> str:
        return r.split(";")[0].split(">")[0].split("=")[0].strip().lower()

    base = {name(r) for r in requires if "extra ==" not in r}
    studio = {name(r) for r in requires if 'extra == "studio"' in r}
    assert base == {"numpy", "numba", "usd-core", "pygltflib"}  # pygltflib: characters (glTF, VRM)
    assert studio == STUDIO_ONLY


def test_the_farm_extra_is_dask_distributed_and_the_test_command_installs_it(wheel):
    """``pip install "hairtool[farm]"`` gives ``hairtool batch`` its Dask; the README's test command
    (``./dev test``, which CI runs) installs that extra, so the batch tests run instead of skipping."""
    (meta,) = [n for n in wheel.namelist() if n.endswith(".dist-info/METADATA")]
    requires = Parser().parsestr(wheel.read(meta).decode()).get_all("Requires-Dist")
    farm = {re.split(r"[<>=;\s]", r, maxsplit=1)[0] for r in requires if 'extra == "farm"' in r}
    assert farm == {"dask[distributed]"}

    readme = (ROOT / "README.md").read_text()
    assert re.search(r"^\./dev test\b", readme, re.M), "the README's test command is ./dev test"
    dev = (ROOT / "dev").read_text()
    case = re.search(r"^\s*test\)\n(.*?);;", dev, re.M | re.S)
    assert case, "./dev has a test) case"
    setup = re.search(r"^\s*setup ([\w,]+)\s*$", case.group(1), re.M)
    assert setup and {"test", "farm"} <= set(setup.group(1).split(","))
    assert re.search(r'pip install [^\n]*-e "\.\[\$extras\]"', dev), "setup installs the extras it is given"
    assert "./dev test" in (ROOT / ".ci" / "run").read_text()


def test_shaders_are_package_data():
    files = [f.name for f in resources.files("app.shaders").iterdir() if f.name.endswith(".glsl")]
    assert files, "no GLSL programs found through importlib.resources"


def test_the_default_scene_ships_unchanged_with_its_credits():
    from app import resources as bundled

    for name in (bundled.SINTEL_HAIR, bundled.SINTEL_HEAD):
        shipped = bundled.path(name)
        assert shipped.is_file(), f"{name} is not package data"
        assert shipped.read_bytes() == (ROOT / "tests" / "data" / "grooms" / name).read_bytes()
    credits = bundled.path("CREDITS-sintel.txt").read_text()
    assert "Blender Foundation" in credits and "CC BY 3.0" in credits


def test_the_studio_says_which_extra_it_needs_when_qt_is_missing():
    script = (
        "import sys\n"
        "class Block:\n"
        "    def find_spec(self, name, path=None, target=None):\n"
        "        if name.split('.')[0] in ('PySide6', 'moderngl'):\n"
        "            raise ImportError(name)\n"
        "sys.meta_path.insert(0, Block())\n"
        "import importlib.util\n"
        "importlib.util.find_spec = lambda name, *a: None if name in ('PySide6', 'moderngl') else 1\n"
        "from app.main import main\n"
        "sys.exit(main([]))\n"
    )
    r = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=60)
    assert r.returncode == 2
    assert r.stderr.count("\n") == 1 and 'pip install "hairtool[studio]"' in r.stderr
    assert "PySide6, moderngl" in r.stderr
