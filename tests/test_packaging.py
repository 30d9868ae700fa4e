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


def test_the_default_scene_ships_unchanged_with_its_credits():
    from app import resources as bundled

    for name in (bundled.SINTEL_HAIR, bundled.SINTEL_HEAD):
        shipped = bundled.path(name)
        assert shipped.is_file(), f"{name} is not package data"
        original = ROOT.parent / "shared" / "data" / "grooms" / name
        if original.is_file():
            assert shipped.read_bytes() == original.read_bytes()
    credits = bundled.path("CREDITS-sintel.txt").read_text()
    assert "Blender Foundation" in credits and "CC BY 3.0" in credits
