"""The numbers a report row carries beyond status and time, per command, read from what the
command printed with ``--json`` (nothing is solved again); :func:`report_options` are the
options a job gets so that it prints them.

``keys``: ``key_count`` and ``frames``; ``total_error`` and ``uniform_total_error``, the
solve's error E summed over frames for the DP keys and for uniform keys of the same count
(``hairtool keys``' ``cost``, under ``--objective total``; None under ``worst``);
``worst_error`` and ``uniform_worst_error``, the largest point distance of either
reconstruction over all frames, and ``mean_error``/``uniform_mean_error`` the mean one, in
scene units (animations and BVH captures; None for raw features); ``storage_ratio``, on every
keys job of an animation whatever its ``--export``: the bytes of a real file holding only the
key poses, written in the input's own format (``.usdc`` for a ``.usdc``) to the system's temp
dir and deleted (``hairtool keys --storage``, :mod:`hairtool.keys.storage`), over the bytes
of the input (None for BVH captures, raw features and ``--per-channel``). Every command:
``summary``, the plain numbers and strings of its ``--json`` object.
"""

from __future__ import annotations

from collections.abc import Callable

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


#: Options a command's job gets beyond ``--json``, for the report's numbers.
_OPTIONS = {"keys": ("--storage",)}


def report_options(command: str) -> list[str]:
    """``--json`` where the command takes it, then what :data:`_OPTIONS` adds."""
    from hairtool.cli import command_parser

    takes = command_parser(command)._option_string_actions
    return [o for o in ("--json", *_OPTIONS.get(command, ())) if o in takes]


def _keys(summary: dict) -> dict:
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
    storage = summary.get("storage") if isinstance(summary.get("storage"), dict) else {}
    fields["storage_ratio"] = _number(storage.get("ratio"))
    return fields


_BY_COMMAND: dict[str, Callable[[dict], dict]] = {"keys": _keys}


def report_fields(job: Job, summary: dict | None) -> dict:
    """The command's numbers for the report (empty when it printed no JSON object)."""
    if not isinstance(summary, dict):
        return {}
    plain = {k: v for k, v in summary.items() if isinstance(v, (int, float, str)) and not isinstance(v, bool)}
    special = _BY_COMMAND.get(job.command)
    return {**(special(summary) if special else {}), "summary": plain}
