"""Every public function the API reference renders says what it takes: a numpy ``Parameters``
section (issue 42). The pages' ``::: path`` blocks are read as mkdocstrings reads them (their
``members`` option, else the object's public members: a package's ``__all__``, a module's own
functions and classes), and each function, method and ``__init__`` (merged into its class's
page) with a parameter beyond ``self`` is looked up in griffe's parse of its docstring."""

from __future__ import annotations

import re
from pathlib import Path

import griffe
import pytest

ROOT = Path(__file__).resolve().parent.parent.parent
API = ROOT / "docs" / "api"
BLOCK = re.compile(r"^::: ([\w.]+)\n((?:    .*\n)*)", re.M)
MEMBERS = re.compile(r"^\s+members:\s*\[([^\]]*)\]", re.M)
NOT_YET: tuple[str, ...] = ()


@pytest.fixture(scope="module")
def package() -> griffe.Module:
    return griffe.load("hairtool", search_paths=[str(ROOT)], docstring_parser="numpy", allow_inspection=False)


def _target(obj: griffe.Object | griffe.Alias) -> griffe.Object:
    return obj.final_target if obj.is_alias else obj


def _public(obj: griffe.Object) -> list[griffe.Object]:
    """What mkdocstrings shows of ``obj`` with no ``members`` option."""
    if obj.is_module:
        if obj.exports is not None:
            names = [n if isinstance(n, str) else n.name for n in obj.exports]
            return [_target(obj.members[n]) for n in names if n in obj.members]
        return [m for n, m in obj.members.items() if not n.startswith("_") and not m.is_alias]
    return [
        m for n, m in obj.members.items() if (not n.startswith("_") or n == "__init__") and not m.is_alias
    ]


def rendered(package: griffe.Module) -> list[tuple[str, griffe.Object]]:
    """(page, object) for every object the API pages render, classes' members included."""
    out: list[tuple[str, griffe.Object]] = []
    for page in sorted(API.glob("*.md")):
        for path, options in BLOCK.findall(page.read_text(encoding="utf-8")):
            obj = _target(package[path.removeprefix("hairtool.")] if path != "hairtool" else package)
            listed = MEMBERS.search(options)
            if listed:
                names = [n.strip() for n in listed.group(1).split(",") if n.strip()]
                members = [_target(obj.members[n]) for n in names]
            else:
                members = _public(obj) if obj.is_module else [obj]
            todo = list(members) if obj.is_module else [obj]
            while todo:
                m = todo.pop()
                out.append((page.name, m))
                if m.is_class:
                    todo.extend(x for x in _public(m) if x.is_function)
    return out


def _needs_parameters(f: griffe.Function) -> bool:
    return any(p.name not in ("self", "cls") for p in f.parameters)


def _has(docstring: griffe.Docstring | None, kind: str) -> bool:
    return docstring is not None and any(s.kind.value == kind for s in docstring.parsed)


def missing_parameters(package: griffe.Module) -> list[str]:
    """``page: path`` of each rendered function with parameters and no Parameters section (an
    ``__init__``'s may stand in its class's docstring, as the page merges them)."""
    out = []
    for page, obj in rendered(package):
        if not obj.is_function or not _needs_parameters(obj) or obj.path.startswith(NOT_YET):
            continue
        if obj.name == "__init__" and not obj.lineno:  # a dataclass's: its fields are the attributes shown
            continue
        docs = [obj.docstring]
        if obj.name == "__init__":
            docs.append(obj.parent.docstring)
        if not any(_has(d, "parameters") for d in docs):
            out.append(f"{page}: {obj.path}")
    return sorted(set(out))


def test_every_rendered_function_has_a_parameters_section(package):
    missing = missing_parameters(package)
    assert not missing, f"{len(missing)} without a Parameters section:\n" + "\n".join(missing)


def test_the_walk_sees_what_the_pages_render(package):
    paths = {obj.path for _, obj in rendered(package)}
    assert {"hairtool.io.read", "hairtool.keys.session.KeySession.keys_for", "hairtool.groom.Groom"} <= paths
