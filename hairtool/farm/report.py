"""The batch report: every row as JSON, and a CSV beside it for spreadsheets (same name, ``.csv``).

JSON: ``{"summary": {...}, "jobs": [{"index", "command", "args", "input", "status", "error",
"seconds", "outputs", "worker", ...}]}`` with each command's numbers (:mod:`hairtool.farm.fields`).
The CSV has one row per job and the columns of :data:`CSV_COLUMNS`; lists are joined with
spaces (args) or semicolons (outputs). Both are written atomically.
"""

from __future__ import annotations

import csv
import json
import os
import shlex
from pathlib import Path

from hairtool.errors import FormatError, ParameterError
from hairtool.farm.fields import KEYS_FIELDS
from hairtool.io.atomic import atomic_open

CSV_COLUMNS = ("index", "command", "input", "status", "seconds", "error", *KEYS_FIELDS, "outputs", "args")


def check_report_path(path: str | os.PathLike[str]) -> Path:
    """``path`` if it names a ``.json`` file (checked before a batch runs); its folder, like any
    output's, is made when the report is written."""
    p = Path(path)
    if p.suffix.lower() != ".json":
        raise ParameterError("report", str(path), "a .json file (the .csv is written beside it)")
    return p


def csv_path(path: str | os.PathLike[str]) -> Path:
    return Path(path).with_suffix(".csv")


def _cell(name: str, value: object) -> object:
    if value is None:
        return ""
    if name == "args":
        return shlex.join(value)  # type: ignore[arg-type]
    if name == "outputs":
        return ";".join(value)  # type: ignore[arg-type]
    return value


def write_report(path: str | os.PathLike[str], rows: list[dict], summary: dict) -> tuple[Path, Path]:
    """Write the JSON report at ``path`` and its CSV beside it; both paths."""
    p, c = Path(path), csv_path(path)
    writing = p
    try:
        with atomic_open(p, "w", encoding="utf-8") as f:
            json.dump({"summary": summary, "jobs": rows}, f, indent=1)
            f.write("\n")
        writing = c
        with atomic_open(c, "w", encoding="utf-8", newline="") as f:
            w = csv.writer(f)
            w.writerow(CSV_COLUMNS)
            for r in rows:
                w.writerow([_cell(k, r.get(k)) for k in CSV_COLUMNS])
    except OSError as e:
        raise FormatError(writing, f"cannot write the report: {e}") from None
    return p, c
