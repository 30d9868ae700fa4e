"""The install layout: every package ships, and the studio finds its shaders from an install."""

from __future__ import annotations

import tomllib
from importlib import resources
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def _declared() -> set[str]:
    config = tomllib.loads((ROOT / "pyproject.toml").read_text())
    return set(config["tool"]["setuptools"]["packages"])


def test_every_python_package_is_declared_in_pyproject():
    mapped = {"shaders": "app.shaders", "resources": "app.resources"}
    found = set()
    for top in ("hairtool", "app", "shaders", "resources"):
        for init in (ROOT / top).rglob("__init__.py"):
            rel = init.parent.relative_to(ROOT)
            name = ".".join(rel.parts)
            found.add(mapped.get(name, name))
    assert found == _declared()


def test_shaders_are_package_data():
    files = [f.name for f in resources.files("app.shaders").iterdir() if f.name.endswith(".glsl")]
    assert files, "no GLSL programs found through importlib.resources"
