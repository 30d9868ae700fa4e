"""The one loader of ``shaders/*.glsl``: one file per program, stages picked by a define.

Each file starts with its ``#version`` line and wraps the stages in
``#if defined VERTEX_SHADER … #elif defined GEOMETRY_SHADER … #elif defined FRAGMENT_SHADER``;
the loader inserts the matching ``#define`` right after ``#version`` (GLSL requires the version
first). A line ``#include "name.glsl"`` is replaced by that file of ``shaders/`` (a piece two
programs share, with no ``#version`` of its own), followed by a ``#line`` that keeps the
including file's line numbers in compile errors. Sources are read once per process; programs
belong to the caller, who releases them.
"""

from __future__ import annotations

import functools
import importlib.resources
import re

import moderngl

from hairtool.errors import ParameterError

STAGES = {
    "vertex_shader": "VERTEX_SHADER",
    "geometry_shader": "GEOMETRY_SHADER",
    "fragment_shader": "FRAGMENT_SHADER",
}


@functools.cache
def shader_source(name: str) -> str:
    """The text of ``shaders/<name>.glsl`` (installed as the package ``app.shaders``)."""
    path = importlib.resources.files("app.shaders").joinpath(f"{name}.glsl")
    if not path.is_file():
        raise ParameterError("shader", name, "the name of a file in shaders/ without .glsl")
    return path.read_text(encoding="utf-8")


INCLUDE = re.compile(r'^#include "(\w+)\.glsl"\s*$')


@functools.cache
def expanded_source(name: str, within: tuple[str, ...] = ()) -> str:
    """``shaders/<name>.glsl`` with its ``#include`` lines replaced by the files they name."""
    if name in within:
        raise ParameterError("shader", name, "a file that does not include itself")
    lines = []
    for number, line in enumerate(shader_source(name).split("\n"), start=1):
        found = INCLUDE.match(line)
        if found is None:
            lines.append(line)
            continue
        lines.append(expanded_source(found.group(1), (*within, name)).rstrip("\n"))
        lines.append(f"#line {number + 1}")
    return "\n".join(lines)


@functools.cache
def stage_sources(name: str) -> dict[str, str]:
    """``{moderngl keyword: source}`` for each stage the file defines."""
    text = expanded_source(name)
    first, _, rest = text.partition("\n")
    if not first.startswith("#version"):
        raise ParameterError("shader", name, "a file whose first line is #version")
    return {
        keyword: f"{first}\n#define {define}\n#line 2\n{rest}"
        for keyword, define in STAGES.items()
        if f"defined {define}" in text
    }


def load_program(ctx: moderngl.Context, name: str) -> moderngl.Program:
    """Compile ``shaders/<name>.glsl`` in ``ctx``."""
    return ctx.program(**stage_sources(name))
