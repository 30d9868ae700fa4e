"""The manual is a site: it builds with ``mkdocs build --strict`` offline, its generated pages are
the ones the generator makes now, and the README stays a short door into it."""

from __future__ import annotations

import argparse
import importlib.util
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent.parent
DOCS = ROOT / "docs"


def _generator():
    spec = importlib.util.spec_from_file_location("docs_generate", DOCS / "generate.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_generated_pages_are_up_to_date():
    stale = [str(p.relative_to(ROOT)) for p in _generator().stale_pages()]
    assert not stale, f"stale: {stale}; regenerate them with: python docs/generate.py"


def test_a_changed_option_makes_the_cli_page_stale(monkeypatch):
    import hairtool.cli

    generate = _generator()
    page = DOCS / "cli" / "reference.md"
    original = hairtool.cli.command_parser

    def parser_with_one_more_option(name):
        parser = original(name)
        if name == "info":
            kwargs = {"prog": parser.prog, "description": parser.description, "add_help": False}
            parser = type(parser)(parents=[parser], **kwargs)
            parser.add_argument("--brand-new", help="an option the committed page does not know")
        return parser

    monkeypatch.setattr(hairtool.cli, "command_parser", parser_with_one_more_option)
    text = generate.cli_reference()
    assert "--brand-new" in text and text != page.read_text(encoding="utf-8")


def test_every_command_and_its_options_are_on_the_reference_page():
    from hairtool.cli import command_modules, command_parser

    page = (DOCS / "cli" / "reference.md").read_text(encoding="utf-8")
    for name in command_modules():
        assert f"## hairtool {name}\n" in page
        for action in command_parser(name)._actions:
            if action.help == argparse.SUPPRESS or isinstance(action, argparse._HelpAction):
                continue
            for option in action.option_strings:
                assert f"`{option}" in page or f", {option}" in page, f"hairtool {name} {option}"


def test_every_brush_has_its_section_on_the_brushes_page():
    from hairtool.frozen.brushes import BRUSHES

    page = (DOCS / "studio" / "brushes.md").read_text(encoding="utf-8")
    ids = re.findall(r"^## .*\{#brush-(\w+)\}$", page, re.M)
    assert sorted(ids) == sorted(BRUSHES), "one section per brush, each described once"
    for name in BRUSHES:  # and its picture, made by python -m app.figures.brushes resources
        section = page.split(f"{{#brush-{name}}}", 1)[1].split("\n## ", 1)[0]
        assert f"](../images/figure-brush-{name}.png)" in section, name
        assert (ROOT / "resources" / f"figure-brush-{name}.png").is_file(), name
        assert (DOCS / "images" / f"figure-brush-{name}.png").resolve() == (
            ROOT / "resources" / f"figure-brush-{name}.png"
        ).resolve(), f"docs/images/figure-brush-{name}.png links to the picture in resources/"


def test_the_readme_is_a_short_door_into_the_site():
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    assert len(readme.encode()) <= 10 * 1024
    studio, test = readme.index("./dev studio"), readme.index("./dev test")
    assert max(studio, test) < readme.index("](docs/"), "the two set-up commands come first"
    pictures = re.findall(r"!\[[^]]*\]\(([^)]+)\)", readme)
    assert len(pictures) == 1 and (ROOT / pictures[0]).is_file()
    for link in re.findall(r"\]\((docs/[^)#]+)", readme):
        assert (ROOT / link).is_file(), link


@pytest.mark.slow(seconds=20)
def test_the_site_builds_strict_without_the_network(tmp_path):
    env = dict(os.environ, PYTHONPATH=str(ROOT), NO_MKDOCS_2_WARNING="1")
    for var in ("HTTP_PROXY", "HTTPS_PROXY", "http_proxy", "https_proxy", "ALL_PROXY", "all_proxy"):
        env[var] = "http://127.0.0.1:9"  # a fetch at build time fails instead of reaching out
    env.pop("NO_PROXY", None)
    env.pop("no_proxy", None)
    site = tmp_path / "site"
    run = subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(site)],
        cwd=ROOT,
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert run.returncode == 0, run.stderr[-4000:]
    assert (site / "cli" / "reference" / "index.html").is_file()
    for picture in ("screenshot-studio.png", "screenshot-timeline.png", "figure-keys-jump.png"):
        assert (site / "images" / picture).is_file()
    api = (site / "api" / "io" / "index.html").read_text(encoding="utf-8")
    assert "Parameters" in api and "Returns" in api  # the docstrings' sections, rendered


def test_a_new_brush_gets_its_section_and_the_prose_stays(monkeypatch):
    """A registered brush the page does not know makes the page stale and gets a section of its
    own (heading, facts from its spec, a picture line) with no edit of the page; every
    hand-written paragraph of the committed page is still there."""
    from hairtool.frozen.brushes import registry
    from hairtool.frozen.brushes.spec import BrushSpec, Param, Studio

    generate = _generator()
    page = (DOCS / "studio" / "brushes.md").read_text(encoding="utf-8")
    new = BrushSpec(
        name="braid",
        order=99,
        signed=True,
        studio=Studio("Braid", "Shift+B", "Braids them", 0.3, ("Braid", "Unbraid"), "Braid or unbraid"),
        params=(Param("turns", int, 1, 12, 3, "turns", "a whole number of turns in [1, 12]"),),
    )
    specs = registry.specs()
    monkeypatch.setattr(registry, "specs", lambda: (*specs, new))
    text = generate.brushes_page()
    assert text != page
    section = text.split("{#brush-braid}", 1)[1].split("\n## ", 1)[0]
    assert "`Shift+B`" in section and "starting at 0.3" in section and "Braid or unbraid" in section
    assert "| `params.turns` | whole number | 1 … 12 | 3 |" in section
    assert "](../images/figure-brush-braid.png)" in section
    assert "| [Braid](#brush-braid) | `Shift+B` | signed | 0.3 | no | `braid` |" in text
    sections = page.split(generate.SECTIONS_START)[1].split(generate.SECTIONS_END)[0]
    for paragraph in generate.hand_prose(sections).values():
        assert paragraph.strip() in text


def test_the_prose_of_a_brush_no_longer_registered_is_not_dropped(monkeypatch):
    from hairtool.frozen.brushes import registry

    generate = _generator()
    specs = registry.specs()
    monkeypatch.setattr(registry, "specs", lambda: specs[1:])
    with pytest.raises(SystemExit, match="align"):
        generate.brushes_page()
