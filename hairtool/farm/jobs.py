"""The jobs file of ``hairtool batch``: a list of CLI commands, written out or made from a glob.

``{"jobs": [{"command": "keys", "args": ["shot01.usdc", "--out", "shot01.keys.json"]},
{"glob": "shots/*.usdc", "command": "keys", "args": ["{path}", "--out", "{dir}/{stem}.keys.json"]}]}``
in JSON, or the same tables in TOML (``[[jobs]]``); a file holding one glob entry at the top
level is read as a list of one. Any command of ``hairtool`` but ``batch`` and ``bench`` is a
job, so a command added later needs nothing here. Relative paths are relative to the jobs
file's folder: the job runs there (:mod:`hairtool.farm.runner`).

Every mistake is a :class:`~hairtool.errors.FormatError` naming the file and the entry.
"""

from __future__ import annotations

import argparse
import contextlib
import functools
import glob
import hashlib
import json
import os
import re
from dataclasses import dataclass
from pathlib import Path

from hairtool.errors import FormatError, quoted
from hairtool.io import user_text

#: Commands a job may not run: a batch inside a worker would start a cluster of its own, and a
#: benchmark's numbers mean nothing on a shared worker.
NOT_JOBS = ("batch", "bench")
ENTRY_KEYS = ("command", "args", "glob")
#: A jobs file larger than this is not one (100,000 jobs of 200 characters are 20 MB).
MAX_JOBS_BYTES = 64 << 20
#: A glob's length and its path components: more is a mistake, and Python's glob recurses once
#: per component (a pattern of 1,000 components ends in a RecursionError).
MAX_GLOB_CHARS = 1024
MAX_GLOB_PARTS = 32
#: Placeholders of a glob entry's args, for a match ``shots/a.usdc``.
PLACEHOLDERS = {
    "path": "the match, shots/a.usdc",
    "dir": "its folder, shots",
    "name": "its file name, a.usdc",
    "stem": "its name without the extension, a",
    "suffix": "its extension, .usdc",
}
_TEMPLATE = re.compile(r"\{\{|\}\}|\{([^{}]*)\}")


@dataclass(frozen=True)
class Job:
    """One command line to run; ``args`` as given (paths relative to ``base``)."""

    index: int
    command: str
    args: tuple[str, ...]
    base: str  # absolute folder of the jobs file: the job's working folder

    @property
    def argv(self) -> list[str]:
        return [self.command, *self.args]

    @functools.cached_property
    def input(self) -> str | None:
        """The input the command reads from ``args`` (:func:`job_input`)."""
        return job_input(self.command, self.args)

    @property
    def key(self) -> str:
        """Names the job in manifests: its command, arguments and working folder."""
        text = json.dumps([self.command, list(self.args), self.base], separators=(",", ":"))
        return hashlib.sha256(text.encode()).hexdigest()[:32]

    def describe(self) -> str:
        return f"job {self.index + 1} ({self.command} {self.input or ''}".rstrip() + ")"


@functools.cache
def _input_dest(command: str) -> str | None:
    """The command's input positional: the one named ``input``, else its first (``info FILE``)."""
    from hairtool.cli import quiet_parser

    positionals = [a.dest for a in quiet_parser(command)._actions if not a.option_strings]
    return "input" if "input" in positionals else next(iter(positionals), None)


def job_input(command: str, args: tuple[str, ...] | list[str]) -> str | None:
    """The value of the command's input positional as its own parser reads ``args`` (so
    ``--keys 4 shot.usdc`` gives ``shot.usdc``, not ``4``); None when it takes none or was
    given none. Arguments the command will refuse (the job then fails with argparse's message)
    still show the input when the parser met it before the mistake."""
    from hairtool.cli import quiet_parser

    dest = _input_dest(command)
    if dest is None:
        return None
    seen = argparse.Namespace()  # filled as the parser goes, kept when it stops at a mistake
    with contextlib.suppress(ValueError):
        quiet_parser(command).parse_known_args(list(args), seen)
    value = getattr(seen, dest, None)
    return None if value is None else str(value)


def job_commands() -> list[str]:
    """The commands a job may run: every ``hairtool`` command but :data:`NOT_JOBS`."""
    from hairtool.cli import command_names

    return [c for c in command_names() if c not in NOT_JOBS]


def _parse(path: Path) -> object:
    suffix = path.suffix.lower()
    if suffix not in (".json", ".toml"):
        raise FormatError(path, "a jobs file is .json or .toml")
    return user_text.read(path, "a jobs file", suffix[1:], MAX_JOBS_BYTES)


def _args(path: Path, where: str, value: object) -> list[str]:
    if value is None:
        return []
    if not isinstance(value, list):
        raise FormatError(path, f"{where}: args must be a list of strings, as on the command line")
    out = []
    for i, a in enumerate(value):
        if isinstance(a, bool) or not isinstance(a, (str, int, float)):
            raise FormatError(path, f"{where}: args[{i}] must be a string or a number, not {a!r}")
        out.append(a if isinstance(a, str) else str(a))
    return out


def _fill(path: Path, where: str, arg: str, values: dict[str, str]) -> str:
    """``arg`` with ``{name}`` placeholders replaced; ``{{`` and ``}}`` are literal braces."""

    def replace(m: re.Match[str]) -> str:
        if m.group(0) in ("{{", "}}"):
            return m.group(0)[0]
        name = m.group(1)
        if name not in values:
            valid = ", ".join("{" + p + "}" for p in PLACEHOLDERS)
            shown = quoted("{" + name + "}")
            raise FormatError(path, f"{where}: unknown placeholder {shown} in {quoted(arg)} (valid: {valid})")
        return values[name]

    return _TEMPLATE.sub(replace, arg)


def _shown(text: str, limit: int = 80) -> str:
    """``text`` quoted for a message, its middle cut when it is long."""
    return repr(text if len(text) <= limit else text[: limit // 2] + "…" + text[-limit // 4 :])


def _expand_glob(path: Path, where: str, pattern: object, args: list[str], base: str) -> list[list[str]]:
    if not isinstance(pattern, str) or not pattern:
        raise FormatError(path, f"{where}: glob must be a non-empty string such as shots/*.usdc")
    if len(pattern) > MAX_GLOB_CHARS:
        long = f"{len(pattern)} characters long"
        raise FormatError(path, f"{where}: glob {_shown(pattern)} is {long}; at most {MAX_GLOB_CHARS}")
    parts = len(re.split(r"[/\\]+", pattern.strip("/\\")))
    if parts > MAX_GLOB_PARTS:
        raise FormatError(
            path, f"{where}: glob {_shown(pattern)} has {parts} path components; at most {MAX_GLOB_PARTS}"
        )
    if pattern.count("**") > 2:  # each ** walks the whole tree again below the last
        raise FormatError(path, f"{where}: glob {_shown(pattern)} has more than two **")
    matches = sorted(
        m for m in glob.glob(pattern, root_dir=base, recursive=True) if os.path.isfile(os.path.join(base, m))
    )
    if not matches:
        raise FormatError(path, f"{where}: glob {_shown(pattern)} matches no file in {base}")
    filled = []
    for m in matches:
        p = Path(m)
        values = {
            "path": m,
            "dir": str(p.parent),
            "name": p.name,
            "stem": p.stem,
            "suffix": p.suffix,
        }
        filled.append([_fill(path, where, a, values) for a in args])
    return filled


def _entries(path: Path, data: object) -> list[object]:
    if not isinstance(data, dict):
        raise FormatError(path, 'expected an object with a "jobs" list')
    if "jobs" in data:
        extra = sorted(set(data) - {"jobs"})
        if extra:
            raise FormatError(path, f"unknown top-level key {extra[0]!r} (expected only jobs)")
        jobs = data["jobs"]
        if not isinstance(jobs, list):
            raise FormatError(path, '"jobs" must be a list of {"command", "args"} or {"glob", ...} entries')
        return jobs
    if "command" in data:
        return [data]
    raise FormatError(path, 'expected a "jobs" list (or one {"glob", "command", "args"} entry)')


def load_jobs(path: str | os.PathLike[str]) -> list[Job]:
    """The jobs of a ``.json`` or ``.toml`` jobs file, globs expanded, in file order."""
    path = Path(path)
    base = str(path.absolute().parent)
    commands = job_commands()
    jobs: list[Job] = []
    seen: dict[str, str] = {}
    for i, entry in enumerate(_entries(path, _parse(path))):
        where = f"jobs[{i}]"
        if not isinstance(entry, dict):
            raise FormatError(path, f"{where}: expected an object with command and args")
        unknown = sorted(set(entry) - set(ENTRY_KEYS))
        if unknown:
            raise FormatError(path, f"{where}: unknown key {unknown[0]!r} (expected {', '.join(ENTRY_KEYS)})")
        command = entry.get("command")
        if command not in commands:
            shown = "missing" if command is None else repr(command)
            raise FormatError(path, f"{where}: command {shown} is not one of {', '.join(commands)}")
        args = _args(path, where, entry.get("args"))
        lists = _expand_glob(path, where, entry["glob"], args, base) if "glob" in entry else [args]
        for a in lists:
            job = Job(len(jobs), command, tuple(a), base)
            if job.key in seen:
                raise FormatError(path, f"{where}: repeats {seen[job.key]} ({command} {' '.join(a)})")
            seen[job.key] = where
            jobs.append(job)
    if not jobs:
        raise FormatError(path, "no jobs")
    return jobs
