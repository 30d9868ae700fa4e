"""The numbers a report row carries beyond status and time, per command, read from what the
command printed with ``--json`` (nothing is solved again).

``keys``: ``key_count`` and ``frames``; ``total_error`` and ``uniform_total_error``, the
solve's error E summed over frames for the DP keys and for uniform keys of the same count
(``hairtool keys``' ``cost``, under ``--objective total``; None under ``worst``);
``worst_error`` and ``uniform_worst_error``, the largest point distance of either
reconstruction over all frames, and ``mean_error``/``uniform_mean_error`` the mean one, in
scene units (animations and BVH captures; None for raw features); ``storage_ratio``, the
bytes of the ``--export`` keys-only file over the bytes of the full animation read (None
without ``--export``). Every command: ``summary``, the plain numbers and strings of its
``--json`` object.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from hairtool.farm.jobs import Job

KEYS_FIELDS = (
    "frames",
    "key_count",
    "total_error",
    "uniform_total_error",
    "worst_error",
    "uniform_worst_error",
    "mean_error",
    "uniform_mean_error",
    "storage_ratio",
)


def _number(value: object) -> float | None:
    return float(value) if isinstance(value, (int, float)) and not isinstance(value, bool) else None


def _keys(job: Job, summary: dict, inputs: dict, outputs: dict) -> dict:
    from hairtool.cli import command_parser

    keys = summary.get("keys", summary.get("union")) or []
    uniform = summary.get("uniform") if isinstance(summary.get("uniform"), dict) else {}
    errors = summary.get("position_errors") if isinstance(summary.get("position_errors"), dict) else {}
    total = summary.get("objective", "total") == "total"
    fields = {
        "frames": summary.get("frames"),
        "key_count": len(keys),
        "total_error": _number(summary.get("cost")) if total else None,
        "uniform_total_error": _number(uniform.get("cost")) if total else None,
    }
    for prefix, name in (("", "keys"), ("uniform_", "uniform")):
        e = errors.get(name) if isinstance(errors.get(name), dict) else {}
        fields[f"{prefix}worst_error"] = _number(e.get("max"))
        fields[f"{prefix}mean_error"] = _number(e.get("mean"))
    args = command_parser("keys").parse_known_args(list(job.args))[0]
    ratio = None
    if args.export is not None:
        exported = outputs.get(str(Path(job.base, args.export).resolve()))
        read = inputs.get(str(Path(job.base, args.input).resolve()))
        if exported and read and read["bytes"] > 0:
            ratio = exported["bytes"] / read["bytes"]
    fields["storage_ratio"] = ratio
    return fields


_BY_COMMAND: dict[str, Callable[[Job, dict, dict, dict], dict]] = {"keys": _keys}


def report_fields(job: Job, summary: dict | None, inputs: dict, outputs: dict) -> dict:
    """The command's numbers for the report (empty when it printed no JSON object)."""
    if not isinstance(summary, dict):
        return {}
    plain = {k: v for k, v in summary.items() if isinstance(v, (int, float, str)) and not isinstance(v, bool)}
    special = _BY_COMMAND.get(job.command)
    return {**(special(job, summary, inputs, outputs) if special else {}), "summary": plain}
