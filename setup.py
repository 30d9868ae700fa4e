"""Packages found, not listed: every package under hairtool/ and app/, plus the top-level
shaders/ and resources/ folders, installed as app.shaders and app.resources (see pyproject.toml)."""

from setuptools import find_packages, setup

found = find_packages(include=["hairtool", "hairtool.*", "app", "app.*"])
setup(packages=[*found, "app.shaders", "app.resources"])
