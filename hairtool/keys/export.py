"""Keys leave hairtool in three forms: a JSON record, a CSV key sheet, and USD key poses.

- JSON (``write_keys_json``/``read_keys_json``): frame numbers and times of the keys, the solve's
  parameters and costs, for pipelines and for reopening a solve.
- CSV (``write_key_sheet``): one row per frame, like an animator's exposure sheet: whether the
  frame is a key (and on key rows whether the animator pinned it), which keys it lies between
  and its interpolation weight, so a reader can rebuild every in-between without hairtool. A
  record with Hermite curves (``record["tangents"]``, written by ``hairtool keys --interp
  hermite|hermite-fit`` for a BVH or a feature array) adds three columns per channel, filled on
  key rows: ``NAME`` (the value at the key), ``NAME:in`` and ``NAME:out`` (the tangents arriving
  at and leaving the key, per frame): see :func:`sheet_rows` for the curve they give.
- USD (``write_key_poses``): only the key poses as time samples at their time codes; USD
  readers interpolate linearly between samples, so the file plays back as the linear
  reconstruction in any USD viewer. Keys of a Hermite curve are refused there: what would
  play is not their curve (bake every frame instead, ``hairtool keys --bake``).

Keys are frame indices 0…F−1 of the animation; the JSON record, the CSV sheet (its
``time_code`` column) and the USD poses also give each frame's time code in the source (an
animation sampled at time codes 1…48 keys its first frame at 1, not 0), so what is written lands
where the source's frames are. All three give ``time`` in seconds as time code / fps.

The CLI (``hairtool keys --out/--export``) and the studio both write through this module.
"""

from __future__ import annotations

import csv
import json
import math
import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from hairtool.errors import FormatError, ParameterError
from hairtool.groom import Animation
from hairtool.io import user_text
from hairtool.io.atomic import atomic_open

FORMAT = "hairtool keys"
FORMAT_VERSION = 1
JSON_SUFFIXES = (".json",)
CSV_SUFFIXES = (".csv",)
USD_SUFFIXES = (".usd", ".usda", ".usdc")
F64 = NDArray[np.float64]
#: Records nest a few levels (keys, params, uniform); a deeper one read back would make writing
#: it again (``_plain``, ``json.dump``) recurse past Python's limit.
MAX_NESTING = 32
# Results that are large or only useful on screen; the record keeps everything else.
_NOT_RECORDED = ("keys", "frames", "fps", "curve", "time_codes", "storage")


def _check_keys(keys: ArrayLike, n_frames: int) -> NDArray[np.int64]:
    k = np.asarray(keys)
    if k.ndim != 1 or k.size == 0:
        raise ParameterError("keys", k.tolist() if k.size < 8 else f"{k.size} values", "a 1-D list of frames")
    if k.dtype.kind not in "iuf":  # e.g. Python ints beyond int64 make an object array
        raise ParameterError("keys", k.tolist()[:8], f"whole frame numbers in [0, {n_frames})")
    if not np.issubdtype(k.dtype, np.integer):
        if not np.all(np.isfinite(k)) or np.any(k != np.round(k)):
            raise ParameterError("keys", k.tolist()[:8], "whole frame numbers")
    k = k.astype(np.int64)
    if np.any(np.diff(k) <= 0) or k[0] < 0 or k[-1] >= n_frames:
        raise ParameterError("keys", k.tolist()[:8], f"strictly increasing frames in [0, {n_frames})")
    return k


def _plain(value: Any) -> Any:
    """JSON-ready copy: numpy scalars and arrays become Python numbers and lists."""
    if isinstance(value, Mapping):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if isinstance(value, np.ndarray):
        return _plain(value.tolist())
    if isinstance(value, np.generic):
        return value.item()
    return value


def _check_time_codes(time_codes: ArrayLike | None, n_frames: int) -> NDArray[np.float64]:
    if time_codes is None:
        return np.arange(n_frames, dtype=np.float64)
    try:
        t = np.asarray(time_codes, dtype=np.float64).reshape(-1)
    except (TypeError, ValueError):
        raise ParameterError("time_codes", "not numbers", f"{n_frames} increasing numbers") from None
    if t.size != n_frames or not np.all(np.isfinite(t)) or np.any(np.diff(t) <= 0):
        shown = t.tolist()[:8]
        raise ParameterError("time_codes", shown, f"{n_frames} finite, strictly increasing numbers")
    return t


def keys_record(
    result: Mapping[str, Any],
    source: str | os.PathLike[str] | None = None,
    time_codes: ArrayLike | None = None,
) -> dict:
    """The JSON record of one solve.

    ``result``: ``{"frames": n, "fps": fps, **Selection.to_dict(), ...}`` as ``hairtool keys
    --json`` prints it (per-channel results carry ``union`` instead of ``keys``). The record
    keeps everything but the cost curve, and lists each key as ``{"frame", "time_code",
    "time"}``: its frame index, its time code in the source (``time_codes``, the animation's
    :attr:`~hairtool.groom.Animation.time_codes`, or ``result["time_codes"]``; default the frame
    index) and that time code in seconds on the source's clock (time code / fps).

    Parameters
    ----------
    result : mapping
        One solve as ``hairtool keys --json`` prints it.
    source : str or os.PathLike, optional
        The animation the keys are of, kept in the record.
    time_codes : array_like, optional
        The source's time code of every frame.

    Returns
    -------
    dict
        The record :func:`write_keys_json` writes.
    """
    try:
        n, fps = int(result["frames"]), float(result["fps"])
    except (KeyError, TypeError, ValueError):
        raise ParameterError("result", sorted(result), "a mapping with frames and fps") from None
    if not (math.isfinite(fps) and fps > 0):
        raise ParameterError("fps", fps, "a positive frame rate")
    keys = _check_keys(result.get("keys", result.get("union", [])), n)
    codes = _check_time_codes(time_codes if time_codes is not None else result.get("time_codes"), n)
    return {
        "format": FORMAT,
        "version": FORMAT_VERSION,
        "input": None if source is None else str(source),
        "frames": n,
        "fps": fps,
        "keys": [
            {"frame": int(k), "time_code": float(codes[k]), "time": float(codes[k]) / fps} for k in keys
        ],
        **{k: _plain(v) for k, v in result.items() if k not in _NOT_RECORDED},
    }


def _nesting(value: Any) -> int:
    """How deeply lists and objects nest in a JSON value (counted without recursion)."""
    deepest, stack = 0, [(value, 1)]
    while stack:
        v, depth = stack.pop()
        if isinstance(v, dict | list):
            deepest = max(deepest, depth)
            stack.extend((c, depth + 1) for c in (v.values() if isinstance(v, dict) else v))
    return deepest


def record_keys(record: Mapping[str, Any]) -> NDArray[np.int64]:
    """The key frame numbers of a record, as int64.

    Parameters
    ----------
    record : mapping
        A keys record.

    Returns
    -------
    ndarray
        The key frames, int64.
    """
    return np.array([k["frame"] for k in record["keys"]], dtype=np.int64)


def write_keys_json(path: str | os.PathLike[str], record: Mapping[str, Any]) -> None:
    """Write a record from :func:`keys_record`, atomically.

    Parameters
    ----------
    path : str or os.PathLike
        The ``.json`` file.
    record : mapping
        A record from :func:`keys_record`.
    """
    try:
        with atomic_open(path, "w", encoding="utf-8") as f:
            json.dump(_plain(record), f, indent=1, allow_nan=False)
            f.write("\n")
    except ValueError as e:  # a NaN or infinity in the costs
        raise FormatError(path, f"cannot write the keys: {e}") from None
    except OSError as e:
        raise FormatError(path, f"cannot write: {e}") from None


def read_keys_json(path: str | os.PathLike[str]) -> dict:
    """Read and check a keys record; :class:`FormatError` names the file on any bad input.

    Records written before the format field existed (``hairtool keys --out`` of version 0.1)
    are accepted when their keys, frames and fps are valid.

    Parameters
    ----------
    path : str or os.PathLike
        A keys record.

    Returns
    -------
    dict
        The checked record.
    """
    record = user_text.read(path, "a keys record", "json", max_depth=MAX_NESTING)  # all text limits
    if not isinstance(record, dict):
        raise FormatError(path, "a keys record is a JSON object")
    if _nesting(record) > MAX_NESTING:
        raise FormatError(path, f"not a keys record: its JSON nests deeper than {MAX_NESTING} levels")
    if record.get("format", FORMAT) != FORMAT:
        raise FormatError(path, f"format is {record.get('format')!r}, not {FORMAT!r}")
    version = record.get("version", FORMAT_VERSION)
    if version != FORMAT_VERSION:
        raise FormatError(path, f"keys format version {version!r}; this hairtool reads {FORMAT_VERSION}")
    n, fps, keys = record.get("frames"), record.get("fps"), record.get("keys")
    if not isinstance(n, int) or isinstance(n, bool) or n < 1:
        raise FormatError(path, f"'frames' is {n!r}; expected a whole number ≥ 1")
    if not isinstance(fps, (int, float)) or isinstance(fps, bool) or not (math.isfinite(fps) and fps > 0):
        raise FormatError(path, f"'fps' is {fps!r}; expected a positive number")
    if not isinstance(keys, list) or not all(
        isinstance(k, dict) and isinstance(k.get("frame"), int) and not isinstance(k.get("frame"), bool)
        for k in keys
    ):
        raise FormatError(path, '\'keys\' must be a list of {"frame": int, "time": seconds}')
    try:
        _check_keys([k["frame"] for k in keys], n)
    except ParameterError as e:
        raise FormatError(path, str(e)) from None
    return record


def _check_curves(curves: Mapping[str, Any], n_keys: int) -> tuple[list[str], F64, F64, F64]:
    """Channel names and the ``(K, C)`` values, leaving and arriving tangents of a record's curves."""
    try:
        names = [str(c) for c in curves["channels"]]
        arrays = [np.asarray(curves[f], dtype=np.float64) for f in ("values", "out", "in")]
    except (KeyError, TypeError, ValueError):
        raise ParameterError(
            "tangents", sorted(curves) if isinstance(curves, Mapping) else type(curves).__name__,
            "channels, values, out and in of every key",
        ) from None
    shape = (n_keys, len(names))
    if any(a.shape != shape or not np.all(np.isfinite(a)) for a in arrays):
        raise ParameterError("tangents", [a.shape for a in arrays], f"finite values of shape {shape}")
    return names, *arrays


def sheet_rows(
    n_frames: int,
    fps: float,
    keys: ArrayLike,
    uniform_keys: ArrayLike | None = None,
    curves: Mapping[str, Any] | None = None,
    pins: Sequence[int] = (),
    time_codes: ArrayLike | None = None,
) -> list[list[Any]]:
    """Rows of the key sheet (header first): frame (0-based), time_code (the source's, from
    ``time_codes``; default the frame), time (time code / fps, in seconds), key, key number,
    previous and next key, interpolation weight s (frame = (1 − s)·previous + s·next), pinned
    (1 on the key rows of ``pins``, the frames the animator pinned, 0 on other key rows, blank
    between keys), the uniform key column when ``uniform_keys`` is given, and with ``curves`` (``{"channels",
    "values", "out", "in"}``, one row of C numbers per key) three columns per channel, filled on
    key rows: NAME, NAME:in, NAME:out.

    They give the Hermite curve without hairtool: between keys a < b (L = b − a frames) the
    channel at a frame of weight s is h00·v_a + h10·L·out_a + h01·v_b + h11·L·in_b, with
    h00 = 2s³ − 3s² + 1, h10 = s³ − 2s² + s, h01 = −2s³ + 3s², h11 = s³ − s². Tangents are per
    frame; seed 003's data tangents have in = out, fitted handles may break at a key. Numbers
    are written with all their digits (Python's repr), so they read back to the same float64.

    Parameters
    ----------
    n_frames : int
        Frames of the source.
    fps : float
        Its frames per second.
    keys : array_like
        The key frames.
    uniform_keys : array_like, optional
        Uniform keys of the same count, marked beside them.
    curves : mapping, optional
        The keys' channel values and Hermite slopes (``channels``, ``values``, ``out``,
        ``in``), three columns per channel.
    pins : sequence of int, default ()
        Frames pinned as keys.
    time_codes : array_like, optional
        The source's time code of every frame (None: the frame).

    Returns
    -------
    list of list
        The rows, header first.
    """
    k = _check_keys(keys, n_frames)
    codes = _check_time_codes(time_codes, n_frames)
    header = ["frame", "time_code", "time", "key", "key_number", "previous_key", "next_key", "weight"]
    header.append("pinned")
    pinned = {int(p) for p in pins}
    uni = None
    if uniform_keys is not None:
        uni = set(_check_keys(uniform_keys, n_frames).tolist())
        header.append("uniform_key")
    per_key: list[list[str]] = []
    if curves is not None:
        names, values, out_t, in_t = _check_curves(curves, k.size)
        for name in names:
            header += [name, f"{name}:in", f"{name}:out"]
        stacked = np.stack([values, in_t, out_t], axis=2).reshape(k.size, -1)
        per_key = [[repr(float(v)) for v in row] for row in stacked]
        blank = [""] * (3 * len(names))
    rows: list[list[Any]] = [header]
    frames = np.arange(n_frames)
    right = np.clip(np.searchsorted(k, frames, side="left"), 0, k.size - 1)
    for f in frames.tolist():
        j = int(right[f])
        is_key = k[j] == f
        if is_key:
            prev = nxt = f
            weight = 0.0
        elif f < k[0] or f > k[-1]:  # outside the keyed range: held at the nearest key
            prev = nxt = int(k[0] if f < k[0] else k[-1])
            weight = 0.0
        else:
            prev, nxt = int(k[j - 1]), int(k[j])
            weight = (f - prev) / (nxt - prev)
        code = float(codes[f])
        row = [f, repr(code), repr(round(code / fps, 9)), int(is_key), j + 1 if is_key else "", prev, nxt]
        row += [repr(round(weight, 9)), int(f in pinned) if is_key else ""]
        if uni is not None:
            row.append(int(f in uni))
        if per_key:
            row += per_key[j] if is_key else blank
        rows.append(row)
    return rows


def _pins(record: Mapping[str, Any]) -> list[int]:
    """The pinned frames a record's params list (the CLI's ``--pin``, the studio's dope sheet)."""
    params = record.get("params")
    pins = params.get("pins", []) if isinstance(params, Mapping) else []
    if not isinstance(pins, (list, tuple)):
        raise ParameterError("pins", type(pins).__name__, "a list of frame numbers")
    if not all(isinstance(p, int) and not isinstance(p, bool) for p in pins):
        raise ParameterError("pins", list(pins)[:8], "whole frame numbers")
    return list(pins)


def sheet_time_codes(record: Mapping[str, Any], time_codes: ArrayLike | None = None) -> F64:
    """Every frame's time code for the sheet of ``record``: ``time_codes`` (the source's, checked
    against the record's keys), or without them the record's own, where its keys carry time
    codes one offset from their frames (a source at 1…48); the frame index for a record
    without time codes.

    Parameters
    ----------
    record : mapping
        A keys record.
    time_codes : array_like, optional
        The source's time codes.

    Returns
    -------
    ndarray
        ``(n_frames,)`` float64 time codes.
    """
    n = int(record["frames"])
    keyed = [(int(k["frame"]), k["time_code"]) for k in record["keys"] if "time_code" in k]
    if not all(isinstance(c, int | float) and not isinstance(c, bool) and math.isfinite(c) for _, c in keyed):
        raise ParameterError("time_code", [c for _, c in keyed][:8], "a finite number on every key")
    if time_codes is not None:
        codes = _check_time_codes(time_codes, n)
        wrong = [(f, c) for f, c in keyed if float(codes[f]) != c]
        if wrong:
            f, c = wrong[0]
            raise ParameterError("time_codes", float(codes[f]), f"frame {f}'s time code in the keys, {c!r}")
        return codes
    offsets = {float(c) - f for f, c in keyed}
    if len(offsets) > 1:
        why = "the source's time code of every frame: the record's keys are not one offset from their frames"
        raise ParameterError("time_codes", None, why)
    return np.arange(n, dtype=np.float64) + (offsets.pop() if offsets else 0.0)


def write_key_sheet(
    path: str | os.PathLike[str], record: Mapping[str, Any], time_codes: ArrayLike | None = None
) -> None:
    """Write the CSV key sheet of a record (one row per frame), atomically; ``time_codes``: the
    source's time code of every frame (:func:`sheet_time_codes`).

    Parameters
    ----------
    path : str or os.PathLike
        The ``.csv`` file.
    record : mapping
        A keys record.
    time_codes : array_like, optional
        The source's time code of every frame.
    """
    uniform = record.get("uniform", {}).get("keys") if isinstance(record.get("uniform"), dict) else None
    curves = record.get("tangents")
    keys = record_keys(record)
    codes = sheet_time_codes(record, time_codes)
    n, fps = int(record["frames"]), float(record["fps"])
    rows = sheet_rows(n, fps, keys, uniform, curves, _pins(record), time_codes=codes)
    try:
        with atomic_open(path, "w", newline="", encoding="utf-8") as f:
            csv.writer(f).writerows(rows)
    except OSError as e:
        raise FormatError(path, f"cannot write: {e}") from None


def key_poses_only(animation: Animation, keys: Sequence[int] | ArrayLike) -> Animation:
    """The animation with only its key poses, each at its time code in the source; the poses
    keep the animation's metadata (up axis, unit, curve prims), so they land where the source's
    frames are.

    Parameters
    ----------
    animation : Animation
        The source.
    keys : sequence of int or array_like
        The key frames.

    Returns
    -------
    Animation
        One frame per key.
    """
    k = _check_keys(keys, animation.n_frames)
    return animation.with_frames(animation.frames[k], time_codes=animation.time_codes[k])


def linear_playback(path: str | os.PathLike[str], interp: str) -> None:
    """Refuse key poses whose curve is not what USD plays: readers interpolate time samples
    linearly, so Hermite keys written as poses would play as straight lines between them.

    Parameters
    ----------
    path : str or os.PathLike
        The USD file asked for, named in a refusal.
    interp : str
        The keys' interpolation.

    Raises
    ------
    FormatError
        For an interpolation other than linear, naming the file.
    """
    if interp != "linear":
        why = (
            f"USD plays key poses back linearly, not as their {interp} curve; "
            "bake every frame of the curve instead (--bake)"
        )
        raise FormatError(path, why)


def write_key_poses(
    path: str | os.PathLike[str],
    animation: Animation,
    keys: Sequence[int] | ArrayLike,
    interp: str = "linear",
) -> None:
    """Write USD with only the key poses (:func:`key_poses_only`), atomically; ``interp``, the
    keys' interpolation, must be linear (:func:`linear_playback`).

    Parameters
    ----------
    path : str or os.PathLike
        The USD file.
    animation : Animation
        The source.
    keys : sequence of int or array_like
        The key frames.
    interp : str, default "linear"
        The keys' interpolation (linear only).
    """
    from hairtool.io import usd

    if Path(path).suffix.lower() not in USD_SUFFIXES:
        raise FormatError(path, f"key poses are written as USD ({', '.join(USD_SUFFIXES)})")
    linear_playback(path, interp)
    poses = key_poses_only(animation, keys)
    try:
        usd.write(Path(path), poses)
    except OSError as e:
        raise FormatError(path, f"cannot write: {e}") from None


def export_keys(
    path: str | os.PathLike[str],
    record: Mapping[str, Any],
    animation: Animation | None = None,
    time_codes: ArrayLike | None = None,
) -> None:
    """Write keys in the format the suffix names: .json record, .csv sheet, .usd/.usda/.usdc poses
    (linear keys only). The sheet's time codes are ``time_codes``, else the animation's, else
    the record's (:func:`sheet_time_codes`).

    Parameters
    ----------
    path : str or os.PathLike
        ``.json``, ``.csv``, ``.usd``, ``.usda`` or ``.usdc``.
    record : mapping
        A keys record.
    animation : Animation, optional
        The source, for key poses and time codes.
    time_codes : array_like, optional
        The source's time code of every frame.
    """
    suffix = Path(path).suffix.lower()
    if suffix in JSON_SUFFIXES:
        write_keys_json(path, record)
    elif suffix in CSV_SUFFIXES:
        if time_codes is None and animation is not None and animation.n_frames == int(record["frames"]):
            time_codes = animation.time_codes
        write_key_sheet(path, record, time_codes)
    elif suffix in USD_SUFFIXES:
        if animation is None:
            raise FormatError(path, "key poses need the animation the keys were chosen from")
        if animation.n_frames != int(record["frames"]):
            raise FormatError(
                path, f"the keys are for {record['frames']} frames but the animation has {animation.n_frames}"
            )
        params = record.get("params")
        interp = params.get("interp", "linear") if isinstance(params, Mapping) else "linear"
        write_key_poses(path, animation, record_keys(record), str(interp))
    else:
        usd = ", ".join(USD_SUFFIXES)
        raise FormatError(path, f"keys are written as .json, .csv or {usd}, not '{suffix}'")
