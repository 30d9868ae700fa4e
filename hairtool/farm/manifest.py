"""The manifest beside a batch's outputs: which jobs are done, from which inputs, with which options.

Each folder that received outputs holds one ``hairtool-batch.json``; its entry for a job (by
:attr:`~hairtool.farm.jobs.Job.key`, which covers the command, its arguments and the working
folder) lists every input with its sha256, size and modification time, and every output with
its size and modification time. A job is done, and skipped, when a manifest beside one of the
paths its arguments name has its entry, every output is still the file the job wrote, and
every input has the same content: the same size and time (not read again), or else the same
sha256 (a file touched or copied back). A file rewritten in place that keeps both its size and
its time to the nanosecond is not noticed; ``--force`` reruns everything.

Only the batch's client writes manifests, atomically, one write for the jobs that finished
together; it re-reads the file first unless the file is still the one it wrote itself (same
inode, size and time to the nanosecond), so entries another batch wrote in the meantime are
kept without parsing the whole manifest again after every job.
"""

from __future__ import annotations

import hashlib
import json
import os
import time
from pathlib import Path

from hairtool import __version__
from hairtool.errors import FormatError
from hairtool.farm.jobs import Job
from hairtool.io.atomic import atomic_open

MANIFEST_NAME = "hairtool-batch.json"
FORMAT = "hairtool batch manifest"
VERSION = 1


def file_state(path: str | os.PathLike[str]) -> dict:
    """``{"bytes", "mtime_ns"}`` of a file (what an output is checked against)."""
    st = os.stat(path)
    return {"bytes": st.st_size, "mtime_ns": st.st_mtime_ns}


def file_sha256(path: str | os.PathLike[str]) -> str:
    with open(path, "rb") as f:
        return hashlib.file_digest(f, "sha256").hexdigest()


def input_state(path: str | os.PathLike[str]) -> dict:
    """``{"sha256", "bytes", "mtime_ns"}`` of an input file."""
    state = file_state(path)
    return {"sha256": file_sha256(path), **state}


def named_paths(args: list[str] | tuple[str, ...], base: str | os.PathLike[str]) -> list[Path]:
    """Every argument that could be a path (and the value of ``--option=value``), under ``base``."""
    out = []
    for a in args:
        if a.startswith("-"):
            if "=" not in a:
                continue
            a = a.split("=", 1)[1]
        if a:
            out.append(Path(base, a))
    return out


class Manifests:
    """The manifests a batch reads and writes, each loaded once."""

    def __init__(self) -> None:
        self._entries: dict[Path, dict] = {}
        self._hashes: dict[tuple[str, int, int], str] = {}
        self._written: dict[Path, dict] = {}  # per folder: the entries this object last wrote
        self._identity: dict[Path, tuple | None] = {}  # and the file it wrote them to
        self._lines: dict[Path, dict[str, tuple[dict, str]]] = {}  # per folder: entries' encodings

    @staticmethod
    def _read(folder: Path) -> dict:
        """The entries of ``folder``'s manifest; none when it is missing or unreadable (it is
        only a record of work done: the jobs then run again and a new one is written)."""
        try:
            with open(folder / MANIFEST_NAME, encoding="utf-8") as f:
                data = json.load(f)
        except (OSError, ValueError, RecursionError):  # RecursionError: JSON nested 100,000 deep
            return {}
        if not isinstance(data, dict) or data.get("format") != FORMAT or data.get("version") != VERSION:
            return {}
        jobs = data.get("jobs")
        return jobs if isinstance(jobs, dict) else {}

    def _folder(self, folder: Path) -> dict:
        if folder not in self._entries:
            self._entries[folder] = self._read(folder)
        return self._entries[folder]

    def _same_input(self, path: str, recorded: dict) -> bool:
        try:
            now = file_state(path)
        except OSError:
            return False
        if now["bytes"] != recorded.get("bytes"):
            return False
        if now["mtime_ns"] == recorded.get("mtime_ns"):
            return True
        cache_key = (path, now["bytes"], now["mtime_ns"])
        if cache_key not in self._hashes:
            self._hashes[cache_key] = file_sha256(path)
        return self._hashes[cache_key] == recorded.get("sha256")

    def is_current(self, entry: dict) -> bool:
        """Every output still as written and every input unchanged."""
        outputs, inputs = entry.get("outputs"), entry.get("inputs")
        if not isinstance(outputs, dict) or not outputs or not isinstance(inputs, dict):
            return False
        for path, recorded in outputs.items():
            try:
                if file_state(path) != {k: recorded.get(k) for k in ("bytes", "mtime_ns")}:
                    return False
            except OSError:
                return False
        return all(self._same_input(path, recorded) for path, recorded in inputs.items())

    def find_done(self, job: Job) -> dict | None:
        """The manifest entry that shows ``job`` done and its outputs current, else None."""
        folders = dict.fromkeys(p.parent.absolute() for p in named_paths(job.args, job.base))
        for folder in folders:
            entry = self._folder(folder).get(job.key)
            if isinstance(entry, dict) and self.is_current(entry):
                return entry
        return None

    def record(self, job: Job, result: dict) -> Path | None:
        """Write ``job``'s entry (from a ``done`` :func:`~hairtool.farm.runner.run_job` result) into
        the manifest beside its first output; None when the job wrote nothing."""
        paths = self.record_many([(job, result)])
        return paths[0] if paths else None

    def record_many(self, done: list[tuple[Job, dict]]) -> list[Path]:
        """:meth:`record` for several jobs, one write per manifest; the manifests written."""
        by_folder: dict[Path, dict[str, dict]] = {}
        for job, result in done:
            if result.get("outputs"):
                folder = Path(next(iter(result["outputs"]))).parent
                by_folder.setdefault(folder, {})[job.key] = self._entry(job, result)
        return [self._write(folder, new) for folder, new in by_folder.items()]

    @staticmethod
    def _entry(job: Job, result: dict) -> dict:
        return {
            "command": job.command,
            "args": list(job.args),
            "base": job.base,
            "inputs": result["inputs"],
            "outputs": result["outputs"],
            "seconds": result["seconds"],
            "fields": result.get("fields", {}),
            "finished": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
            "hairtool": __version__,
        }

    def _write(self, folder: Path, new: dict[str, dict]) -> Path:
        path = folder / MANIFEST_NAME
        # Keep what another batch wrote since this one last read or wrote the file: read it again
        # unless it is still the very file written here (an atomic write by anyone makes a new
        # file, so the same inode, size and time mean nobody else has written).
        entries = self._written.get(folder)
        if entries is None or _identity(path) != self._identity.get(folder):
            entries = self._read(folder)
        entries = {**entries, **new}
        try:
            with atomic_open(path, "w", encoding="utf-8") as f:
                f.write(manifest_text(entries, self._lines.setdefault(folder, {})))
        except OSError as e:
            raise FormatError(path, f"cannot write the batch manifest: {e.strerror or e}") from None
        self._entries[folder] = self._written[folder] = entries
        self._identity[folder] = _identity(path)
        return path


def manifest_text(entries: dict[str, dict], encoded: dict[str, tuple[dict, str]] | None = None) -> str:
    """The manifest file's JSON: one job per line, each compact.

    The client rewrites a folder's manifest after every job that finishes there, so a batch of n
    jobs writes n(n + 1)/2 entries in all. ``encoded`` (key → (entry, its line)) keeps each
    entry's line from the last rewrite, reused while the entry is the same object, so that each
    entry is encoded once and a rewrite only joins lines: recording 1,000 jobs one by one into
    one folder took 6.1 s when every rewrite encoded every entry, and takes 1.5 s, most of it
    writing and syncing the file."""
    if encoded is None:
        encoded = {}

    def line(key: str, entry: dict) -> str:
        cached = encoded.get(key)
        if cached is None or cached[0] is not entry:
            text = json.dumps({key: entry}, ensure_ascii=False, separators=(",", ":"))[1:-1]
            encoded[key] = cached = (entry, text)
        return cached[1]

    head = json.dumps({"format": FORMAT, "version": VERSION}, ensure_ascii=False)[:-1]
    jobs = ",\n".join(line(key, entry) for key, entry in entries.items())
    return f'{head}, "jobs": {{\n{jobs}\n}}}}\n'


def _identity(path: Path) -> tuple[int, int, int, int] | None:
    try:
        st = os.stat(path)
    except OSError:
        return None
    return st.st_dev, st.st_ino, st.st_size, st.st_mtime_ns
