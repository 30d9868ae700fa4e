"""Find globally optimal keyframes of an animation, a BVH capture or a feature array.

IN is an animation file (.usd/.usda/.usdc/.npz cache), a .bvh, a character (.vrm/.glb/.gltf:
its last animation, keyed as the BVH of its hair chains), or an .npz holding an array
``X`` of shape (frames, dims) used as raw features. At most one mode: --keys K, --penalty TAU
(a price per key, as a share of the error of keying only the first and last frame, so it means
the same on any animation), --penalty-abs TAU (an absolute price, Fei et al.'s τ, in squared
feature units), --budget E (total error) or --max-error E (worst frame). Without one, the key count is
the knee of the error-vs-count curve: the count past which each key buys less than its share. The
knee is that of the animation without --pin/--exclude, and the count stays the same under them
(raised only when the pins need more keys), so pinning a frame that is already a key changes
nothing and moving a key (pin the new frame, exclude the old) keeps the count.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from hairtool.cli._progress import ProgressBar

HELP = "find globally optimal keyframes (exact DP) and compare with uniform keys"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "input",
        metavar="IN",
        help="animation file, .bvh, character (.vrm/.glb/.gltf), or .npz with an array X",
    )
    mode = parser.add_mutually_exclusive_group()
    mode.add_argument(
        "--keys",
        "-k",
        type=int,
        metavar="K",
        help="exactly K keys (default: the knee of the error-vs-count curve without --pin/--exclude, "
        "kept under them)",
    )
    mode.add_argument(
        "--penalty", type=float, metavar="TAU", help="price per key, a share of the two-key error (0.01: 1%%)"
    )
    mode.add_argument(
        "--penalty-abs",
        type=float,
        metavar="TAU",
        help="price per key in squared feature units (Fei et al.'s τ)",
    )
    mode.add_argument("--budget", type=float, metavar="E", help="fewest keys with total error <= E")
    mode.add_argument("--max-error", type=float, metavar="E", help="fewest keys with worst frame <= E")
    parser.add_argument("--objective", choices=("total", "worst"), default="total")
    parser.add_argument(
        "--interp",
        choices=("linear", "hermite", "hermite-fit"),
        default="linear",
        help="straight lines, smooth curves with tangents from the frames around each key, or smooth curves "
        "with each segment's handles fitted (cubic Hermite)",
    )
    parser.add_argument("--curvature", type=float, default=0.0, metavar="LAMBDA", help="curvature weight")
    parser.add_argument(
        "--per-channel", action="store_true", help="keys per degree of freedom (needs --penalty)"
    )
    parser.add_argument(
        "--per-chain",
        action="store_true",
        help="character input: keys per hair chain, each chain keyed on its own motion with the mode "
        "given (default: one key set shared by all chains); nodes outside the chains key at every "
        "frame a chain keys",
    )
    parser.add_argument("--curve-keys", type=int, default=100, metavar="N", help="curve up to N keys")
    steer = parser.add_argument_group("frames the animator steers (0-based; lists and ranges, e.g. 10,30-34)")
    steer.add_argument("--pin", metavar="FRAMES", help="frames that must be keys")
    steer.add_argument("--exclude", metavar="FRAMES", help="frames that must not be keys")
    feat = parser.add_argument_group("what counts as a change of the hair (Kim 2026's features)")
    feat.add_argument("--samples", type=int, default=16, metavar="M", help="points per strand (arc length)")
    feat.add_argument("--no-resample", action="store_true", help="use the original vertices")
    feat.add_argument("--tip-weight", type=float, default=2.0, metavar="W")
    feat.add_argument("--root-weight", type=float, default=1.0, metavar="W")
    feat.add_argument("--weight-exponent", type=float, default=1.0, metavar="P")
    feat.add_argument("--no-weighting", action="store_true")
    feat.add_argument("--no-center", action="store_true", help="keep the mean root translation")
    feat.add_argument("--no-relative", action="store_true", help="keep world positions, not root-relative")
    parser.add_argument(
        "--bvh-features",
        choices=("positions", "rotations", "quaternion", "channels"),
        default="positions",
        help="BVH: joint positions, joint rotations (quaternions), the rotation distance between frames, or "
        "the file's own channels (angles unwrapped; with --per-channel each channel keyed on its own, "
        "as a DCC keys them, and editable with --edit)",
    )
    parser.add_argument("--json", action="store_true", help="print the result as JSON")
    parser.add_argument("--out", type=Path, metavar="KEYS.json", help="write keys, times and parameters")
    parser.add_argument(
        "--export",
        type=Path,
        metavar="OUT",
        help="write the keys by suffix: .usd/.usda/.usdc key poses as time samples (animations; linear "
        "keys, as USD plays them: a Hermite curve needs --bake), .json record, .csv sheet (one row per "
        "frame with its time code in the source; with --interp hermite or hermite-fit, per channel the "
        "key values and tangents), .bvh (BVH input: the key curve at every frame, or with --edit the "
        "edited capture), .glb/.vrm/.gltf (character input: the character with keys on its bones, LINEAR, or "
        "CUBICSPLINE with --interp hermite or hermite-fit, their tangents the key curve's)",
    )
    parser.add_argument(
        "--bake", action="store_true", help="with --export: every frame of the key curve, not just the keys"
    )
    parser.add_argument(
        "--edit",
        type=Path,
        metavar="EDITS.json",
        help="BVH: the edits a studio project keeps, replayed: a list of edits of the pose keys, or a "
        'project\'s capture object {"edits": [...], "channel_edits": [...]}; each edit a pose by IK {frame '
        "(a key), joint, target [x, y, z], chain (how many joints above it turn)}, a key moved in time "
        "{frame, to}, a key's value {frame, joint, channel, value} or handle {frame, joint, channel, "
        "slope}, or (channel_edits) one channel's key moved {frame, joint, channel, to}; with --export "
        "OUT.bvh writes the edited capture, the captured detail kept",
    )
    parser.add_argument(
        "--channel-price",
        type=float,
        default=0.01,
        metavar="TAU",
        help="with --edit: the price per key (a share of each channel's two-key error) of the channels' "
        "own keys that channel_edits move, as the studio's price per key (default 0.01, the studio's)",
    )
    parser.add_argument(
        "--storage",
        action="store_true",
        help="measure what keying saves: write the key poses in IN's format to a temporary file (deleted) "
        "and report its bytes over IN's (animations; null for others)",
    )


def _load(args: argparse.Namespace):
    """``(kind, data, fps)``: kind "raw" (X), "animation" (Animation) or "bvh" (Motion)."""
    from hairtool.errors import FormatError, GroomError
    from hairtool.groom import Animation

    path = Path(args.input)
    if not path.is_file():
        raise FormatError(path, "no such file" if not path.exists() else "not a regular file")
    suffix = path.suffix.lower()
    if suffix in (".vrm", ".glb", ".gltf"):
        return "bvh", *_character_motion(path)
    if suffix == ".bvh":
        from hairtool.mocap.bvh import read_bvh

        motion = read_bvh(path)
        return "bvh", motion, motion.fps
    if suffix == ".npz":
        from hairtool.io.npz import holds_feature_array, read_feature_array

        if holds_feature_array(path):
            return "raw", read_feature_array(path), 1.0
    from hairtool.io import read

    obj = read(path)
    if not isinstance(obj, Animation):
        raise GroomError(f"{path} holds a static groom; keyframes need an animation of at least 2 frames")
    if obj.n_frames < 2:
        raise GroomError(f"{path} has {obj.n_frames} frame; keyframes need at least 2")
    return "animation", obj, obj.fps


def _character_motion(path: Path):
    """A character's last animation as the BVH motion of its hair chains, at its keys' rate."""
    from hairtool.character.bvh import chains_motion
    from hairtool.character.read import load_character
    from hairtool.errors import FormatError

    character = load_character(path)
    if not character.clips:
        raise FormatError(path, "has no animation to key")
    clip = character.clips[-1]
    fps = clip.frame_rate()
    rotations = clip.frames(character.nodes, fps)
    motion = chains_motion(character, rotations, fps)
    motion.character = (character, rotations)  # for --export OUT.glb/.vrm: the keys on the bones
    if motion.n_frames < 2:
        raise FormatError(path, f"its animation has {motion.n_frames} frame; keyframes need at least 2")
    return motion, motion.fps


def _mode(args: argparse.Namespace, session) -> dict:
    """The one mode asked for, with a relative tau made absolute; without one, the knee. Errors
    quote the value as typed (the engine sees the absolute price)."""
    from hairtool.errors import ParameterError

    worst = "the total-error objective, not worst: a price per key adds up over the keys"
    if args.penalty is not None:
        if not args.penalty >= 0 or args.penalty == float("inf"):
            raise ParameterError("penalty", args.penalty, "a finite share >= 0 of the two-key error")
        price = args.penalty * session.two_key_error
        if session.objective != "total":
            shown = f"{worst} (a share of {args.penalty:g} of the two-key error; absolute: {price:.6g})"
            raise ParameterError("penalty", args.penalty, shown)
        return {"penalty": price}
    if args.penalty_abs is not None:
        if session.objective != "total":
            raise ParameterError("penalty-abs", args.penalty_abs, worst)
        return {"penalty": args.penalty_abs}
    if args.budget is not None:
        return {"budget": args.budget}
    if args.max_error is not None:
        return {"max_error": args.max_error}
    return {"keys": args.keys if args.keys is not None else session.default_count()}


def run(args: argparse.Namespace) -> int:
    from hairtool.keys.constraints import KeyConstraints

    constraints = KeyConstraints.parse(args.pin, args.exclude)
    bar = ProgressBar(enabled=None if not args.json else False)
    try:
        done = _keys(args, constraints, bar)
    finally:
        bar.close()  # before anything is printed
    return done if isinstance(done, int) else _finish(args, *done)


def _keys(args: argparse.Namespace, constraints, bar: ProgressBar):
    """``run``'s work, moving the bar through reading and features, the cost table, the DP and
    the errors, the table and the DP by their shares of the work: ``(kind, data, n, selection,
    record)`` for :func:`_finish`, or the exit status of a per-channel run."""
    from hairtool.errors import ParameterError
    from hairtool.keys.features import FeatureOptions, frame_features, raw_features
    from hairtool.keys.session import KNEE_KEYS, KeySettings, solve, work_estimate

    bar(0.0, "reading")
    kind, data, fps = _load(args)
    args.edits = _read_edits(args, kind, data)
    bar(0.05, "features")
    options = FeatureOptions(
        samples=None if args.no_resample else args.samples,
        center=not args.no_center,
        relative=not args.no_relative,
        weighting=not args.no_weighting,
        root_weight=args.root_weight,
        tip_weight=args.tip_weight,
        exponent=args.weight_exponent,
    )
    if args.per_chain:
        return _per_chain(args, data, constraints)
    if kind == "bvh":
        x = _bvh_features(args, data)
    elif kind == "animation":
        x = frame_features(data, options)
    else:
        x = raw_features(data)
    n = x.shape[0]

    if args.per_channel:
        from hairtool.keys.channels import per_channel_keys

        if args.penalty is None and args.penalty_abs is None:
            raise ParameterError("per-channel", True, "a --penalty TAU (seed 003 prices keys per channel)")
        if constraints:
            raise ParameterError("pin", args.pin or args.exclude, "keys of the whole pose, not --per-channel")
        bvh_out = args.export is not None and args.export.suffix.lower() == ".bvh"
        if (args.edits is not None or bvh_out) and args.bvh_features != "channels":
            what = "edit" if args.edits is not None else "export"
            shown = str(args.edit if args.edits is not None else args.export)
            wanted = "--bvh-features channels with --per-channel (keys per BVH channel)"
            raise ParameterError(what, shown, wanted)
        relative = args.penalty is not None
        tau = args.penalty if relative else args.penalty_abs
        channels = per_channel_keys(x, tau, interp=args.interp, curvature=args.curvature, relative=relative)
        result = {"frames": n, "fps": fps, **channels.to_dict()}
        if args.storage:
            result["storage"] = None  # no one set of key poses
        if bvh_out:
            _export_channels_bvh(args, data, channels.keys, result)
        elif args.edits is not None:
            raise ParameterError("edit", str(args.edit), "an --export OUT.bvh to write the edited capture to")
        bar.close()
        line = f"{len(result['union'])} frames key at least one of {x.shape[1]} channels"
        line += _edit_lines(result)
        return _emit(args, result, line)

    objective = "worst" if args.max_error is not None else args.objective
    table = None
    if kind == "bvh" and args.bvh_features == "quaternion":
        from hairtool.mocap.costs import rotation_cost_table

        if args.interp != "linear" or args.curvature or objective != "total":
            raise ParameterError("bvh-features", "quaternion", "the linear (slerp) total objective only")
        bar(0.1, "cost table (quaternions)")  # the longest step: O(F³·J)
        table = rotation_cost_table(data, progress=lambda f: bar(0.1 + 0.7 * f, "cost table (quaternions)"))
    settings = KeySettings(objective=objective, interp=args.interp, curvature=args.curvature)
    # The table then the DP share the bar up to the errors, in proportion to their work.
    table_share, dp_share = work_estimate(x.shape, settings, max(args.curve_keys, args.keys or 0, KNEE_KEYS))
    start = 0.1 if table is None else 0.8  # a quaternion table is made already
    if table is not None:
        table_share = 0.0
    split = start + (0.85 - start) * table_share / max(table_share + dp_share, 1.0)
    bar(start, "cost table")
    session = solve(x, settings, table=table, layers=False, constraints=constraints, kmax=KNEE_KEYS)
    bar(split, "keys")
    mode = _mode(args, session)
    on_dp = lambda f: bar(split + (0.85 - split) * f, "keys")  # noqa: E731
    sel = session.select(curve_keys=args.curve_keys, **mode, progress=on_dp)
    bar(0.85, "errors")
    result = _report(args, kind, data, n, fps, sel, options, session)
    bar(1.0, "done")
    return kind, data, n, sel, result


def _bvh_features(args: argparse.Namespace, motion):
    """The ``(F, D)`` features ``--bvh-features`` asks for (quaternion: rotations, its table aside)."""
    if args.bvh_features == "channels":
        from hairtool.mocap.channel_edit import channel_features

        return channel_features(motion)
    from hairtool.mocap.costs import motion_features

    return motion_features(motion, "positions" if args.bvh_features == "positions" else "rotations")


def _per_chain(args: argparse.Namespace, data, constraints) -> int:
    """``--per-chain``: each hair chain of a character keyed on its own motion, in the mode given;
    ``--export OUT.glb`` writes each chain's bones on its own keys."""
    from hairtool.character.chain_keys import chain_motion, chain_weights, node_keys
    from hairtool.errors import ParameterError
    from hairtool.keys.session import KNEE_KEYS, KeySettings, solve
    from hairtool.mocap.costs import motion_features, rotation_cost_table

    if getattr(data, "character", None) is None:
        raise ParameterError("per-chain", True, "a character (.vrm/.glb/.gltf) as IN")
    if args.bvh_features == "channels":
        raise ParameterError(
            "bvh-features", "channels", "positions, rotations or quaternion with --per-chain"
        )
    refused = (
        ("per-channel", args.per_channel),
        ("edit", args.edit),
        ("storage", args.storage),
        ("out", args.out),
    )
    for flag, value in refused:
        if value:
            raise ParameterError(flag, str(value) if value is not True else True, "no value with --per-chain")
    suffix = args.export.suffix.lower() if args.export is not None else None
    if suffix is not None and suffix not in (".glb", ".vrm", ".gltf"):
        raise ParameterError("export", str(args.export), "a .glb, .vrm or .gltf with --per-chain")
    character, rotations = data.character
    objective = "worst" if args.max_error is not None else args.objective
    quaternion = args.bvh_features == "quaternion"
    if quaternion and (args.interp != "linear" or args.curvature or objective != "total"):
        raise ParameterError("bvh-features", "quaternion", "the linear (slerp) total objective only")
    settings = KeySettings(objective=objective, interp=args.interp, curvature=args.curvature)
    chains, keys = [], []
    for c, chain in enumerate(character.chains):
        motion = chain_motion(character, rotations, data.fps, c)
        weights = chain_weights(motion)
        table = rotation_cost_table(motion, weights) if quaternion else None
        x = motion_features(motion, "positions" if args.bvh_features == "positions" else "rotations", weights)
        session = solve(x, settings, table=table, layers=False, constraints=constraints, kmax=KNEE_KEYS)
        sel = session.select(curve_keys=args.curve_keys, **_mode(args, session))
        keys.append(sel.keys)
        chains.append(
            {"chain": chain.name, "n_keys": sel.n_keys, "keys": sel.keys.tolist(), "cost": sel.cost}
        )
    union = sorted(set().union(*(k.tolist() for k in keys)))
    result = {
        "frames": data.n_frames,
        "fps": data.fps,
        "objective": objective,
        "chains": chains,
        "union": union,
    }
    if args.export is not None:
        from hairtool.character.export import animated_nodes, write_animated

        nodes = animated_nodes(rotations, character.nodes.rotation)
        result["written"] = write_animated(
            args.input,
            args.export,
            rotations,
            character.nodes.rotation,
            data.fps,
            name="optimal keys per chain",
            step=False,
            key_frames=node_keys(character, nodes, keys),
            interp=args.interp,
        )
    line = "\n".join(f"{ch['chain']}: {ch['n_keys']} keys: {' '.join(map(str, ch['keys']))}" for ch in chains)
    line += f"\n{len(union)} frames key at least one of {len(chains)} chains"
    return _emit(args, result, line)


def _report(args: argparse.Namespace, kind: str, data, n: int, fps: float, sel, options, session) -> dict:
    """The result record of ``--json``: keys, costs, curve, params and the position errors."""
    import numpy as np

    result = {"frames": n, "fps": fps, **sel.to_dict()}
    if args.penalty is not None:
        result["params"]["penalty_share"] = args.penalty  # of the two-key error
    modes = (args.keys, args.penalty, args.penalty_abs, args.budget, args.max_error)
    note = session.explain(sel)
    if all(v is None for v in modes):
        result["params"].update(count_rule="knee", knee=session.knee)
        if sel.n_keys != session.knee:
            more = sel.n_keys > session.knee
            why = "the fewest these pins allow" if more else "the most these exclusions allow"
            note = f"{sel.n_keys} keys, not the knee's {session.knee}: {why}"
    if note:
        result["note"] = note
    if kind == "animation":
        from hairtool.keys.reconstruct import compare_with_uniform, key_distribution

        result["params"]["features"] = options.to_dict()
        result["position_errors"] = compare_with_uniform(data, sel.keys, args.interp)
        result["speed_at_keys"] = key_distribution(data.frames, sel.keys, fps)["speed_at_keys"]
    elif kind == "bvh":
        from hairtool.keys.dp import uniform_keys
        from hairtool.mocap.costs import joint_position_errors, reconstruct_motion

        errs = {}
        for name, k in (("keys", sel.keys), ("uniform", uniform_keys(n, sel.keys.size))):
            e = joint_position_errors(data, reconstruct_motion(data, k, args.interp))
            errs[name] = {"mean": float(np.mean(e)), "max": float(np.max(e))}
        result["position_errors"] = errs
    return result


def _finish(args: argparse.Namespace, kind: str, data, n: int, sel, result: dict) -> int:
    """The Hermite curves' values and tangents, exports, and the printed line (or JSON)."""
    from hairtool.errors import ParameterError
    from hairtool.keys.export import CSV_SUFFIXES, JSON_SUFFIXES

    if args.interp != "linear" and kind in ("raw", "bvh"):
        result["tangents"] = _curves(kind, data, sel.keys, args.interp)
    time_codes = data.time_codes if kind == "animation" else None
    if args.storage:
        from hairtool.keys.storage import storage

        result["storage"] = storage(data, sel.keys, args.input) if kind == "animation" else None
    if args.export is not None and args.export.suffix.lower() in (".glb", ".vrm", ".gltf"):
        if getattr(data, "character", None) is None:
            raise ParameterError("export", str(args.export), "a character (.vrm/.glb/.gltf) as IN")
        from hairtool.character.export import write_animated

        character, rotations = data.character
        result["written"] = write_animated(
            args.input,
            args.export,
            rotations,
            character.nodes.rotation,
            data.fps,
            name="optimal keys",
            step=False,
            key_frames=sel.keys,
            interp=args.interp,
        )
    elif args.export is not None and args.export.suffix.lower() == ".bvh":
        _export_bvh(args, kind, data, sel.keys, result)
    elif args.edits is not None:
        raise ParameterError("edit", str(args.edit), "an --export OUT.bvh to write the edited capture to")
    elif args.export is not None:
        suffix = args.export.suffix.lower()
        if (args.bake or suffix not in JSON_SUFFIXES + CSV_SUFFIXES) and kind != "animation":
            wanted = "a .json or .csv file, a .bvh for a BVH input, or an animation input"
            raise ParameterError("export", str(args.export), wanted)
        if args.bake:
            from hairtool.io import write
            from hairtool.keys.reconstruct import reconstruct

            write(args.export, reconstruct(data, sel.keys, args.interp))
        elif suffix in JSON_SUFFIXES + CSV_SUFFIXES:
            from hairtool.keys.export import export_keys, keys_record

            record = keys_record(result, args.input, time_codes=time_codes)
            export_keys(args.export, record, time_codes=time_codes)
        else:
            from hairtool.keys.export import write_key_poses

            write_key_poses(args.export, data, sel.keys, args.interp)  # linear keys only
        if suffix not in JSON_SUFFIXES + CSV_SUFFIXES:
            from hairtool.io.usd_carry import carry_between

            carry_between(args.input, args.export)  # USD to USD: the scene beside the hair
    elif args.bake:
        raise ParameterError("bake", True, "an --export path to write the key curve to")
    uniform = f"uniform {sel.uniform_cost:.6g}"
    if "note" in result["uniform"]:  # pins or exclusions the uniform keys ignore
        uniform += f"; {result['uniform']['note']}"
    line = (
        f"{sel.n_keys} keys of {n} frames, {sel.objective} error {sel.cost:.6g} "
        f"({uniform}): {' '.join(map(str, sel.keys.tolist()))}"
    )
    if "note" in result:
        line += f"\n{result['note']}"
    line += _edit_lines(result)
    if result.get("storage"):
        st = result["storage"]
        line += (
            f"\nkeys only: {st['keys_only_bytes']} bytes as {st['format']}, "
            f"{st['ratio']:.1%} of the input's {st['input_bytes']}"
        )
    return _emit(args, result, line, time_codes)


def _read_edits(args: argparse.Namespace, kind: str, data):
    """The checked edits of ``--edit`` (before the keys are solved, so a bad file fails fast), or None."""
    if args.edit is None:
        return None
    from hairtool.errors import ParameterError

    if kind != "bvh":
        raise ParameterError("edit", str(args.edit), "a .bvh input (edits move a skeleton's joints)")
    from hairtool.mocap.edit_file import read_capture_edits

    return read_capture_edits(args.edit, data)


def _export_bvh(args: argparse.Namespace, kind: str, data, keys, result: dict) -> None:
    """``--export OUT.bvh``: the capture with ``--edit``'s key poses (residuals kept), or the key
    curve itself (the reduced motion); the input's hierarchy, offsets, channels and frame time."""
    from hairtool.errors import ParameterError
    from hairtool.mocap.bvh import write_bvh

    if kind != "bvh":
        raise ParameterError("export", str(args.export), "a .bvh input to write a .bvh")
    if args.edits is None:
        from hairtool.mocap.costs import reconstruct_motion

        write_bvh(args.export, reconstruct_motion(data, keys, args.interp))
        return
    if args.bake:
        why = "no --edit: --bake writes the key curve, --edit the edited capture"
        raise ParameterError("bake", True, why)
    from hairtool.mocap.edit_file import replay

    price = args.channel_price
    if not (price >= 0 and price == price and price != float("inf")):
        raise ParameterError("channel-price", price, "a finite share >= 0")
    motion, reports = replay(data, keys, args.interp, args.edits, price=price, source=str(args.edit))
    result["edits"] = [r.to_dict() for r in reports]
    write_bvh(args.export, motion)


def _edit_lines(result: dict) -> str:
    """One line per edit of ``result["edits"]``: where the joint got to, what turned, what followed."""
    text = ""
    for i, r in enumerate(result.get("edits", []), 1):
        e = r["edit"]
        if "target" not in e:  # a key's value, handle or move: no effector to reach
            what = {"channel": "value", "handle": "handle", "retime": "move"}.get(r["method"], r["method"])
            where = f"{e['joint']} {e['channel']} " if "channel" in e else ""
            moved = f" to {e['to']}" if "to" in e else ""
            span = f"frames {r['first']}-{r['last']} follow"
            text += f"\nedit {i}: {where}key {what} at frame {e['frame']}{moved}; {span}"
            continue
        text += (
            f"\nedit {i}: {r['edit']['joint']} at frame {r['edit']['frame']} within {r['miss']:.3g} of its "
            f"target ({r['miss_share']:.2g} of the figure's height), turning {', '.join(r['turned'])} "
            f"({r['method']}); frames {r['first']}-{r['last']} follow"
        )
        if r["miss_share"] > r["tolerance_share"]:
            text += " (out of reach: as near as the chain allows)"
    return text


def _export_channels_bvh(args: argparse.Namespace, data, keys: list, result: dict) -> None:
    """``--per-channel --bvh-features channels --export OUT.bvh``: each channel its own key curve,
    or with ``--edit`` the capture with the edits' keys moved (residuals kept)."""
    from hairtool.errors import FormatError
    from hairtool.mocap.bvh import write_bvh
    from hairtool.mocap.channel_edit import ChannelEditor, channel_key_curve
    from hairtool.mocap.edit_file import apply_each

    if args.edits is None:
        write_bvh(args.export, channel_key_curve(data, keys, args.interp))
        return
    edits = args.edits
    if edits.project and edits.edits:
        why = 'the project\'s "edits" are of the pose keys: replay them without --per-channel'
        raise FormatError(args.edit, why)
    editor = ChannelEditor(data, keys, args.interp)
    todo, label = (edits.channel_edits, "channel edit") if edits.project else (edits.edits, "edit")
    result["edits"] = [r.to_dict() for r in apply_each(editor, todo, str(args.edit), label)]
    write_bvh(args.export, editor.motion())


def _curves(kind: str, data, keys, interp: str) -> dict:
    """Per channel the values at the keys and the Hermite tangents leaving ("out") and arriving
    at ("in") each key, per frame: fitted handles for hermite-fit, seed 003's data tangents
    (in = out) for hermite. A BVH's curves are its file channels, as a DCC keys them."""
    import numpy as np

    from hairtool.keys.reconstruct import key_poses

    if kind == "raw":
        values = np.asarray(data, dtype=np.float64)
        names = [f"x{c}" for c in range(values.shape[1])]
    else:
        values = np.asarray(data.values, dtype=np.float64)
        names = [f"{j}.{c}" for j, chans in zip(data.joint_names, data.channels, strict=True) for c in chans]
    kp = key_poses(values, keys, interp)
    arriving = kp.tangents if kp.tangents_in is None else kp.tangents_in
    return {
        "space": "X columns" if kind == "raw" else "BVH channels",
        "unit": "per frame",
        "channels": names,
        "values": kp.poses.tolist(),
        "out": kp.tangents.tolist(),
        "in": arriving.tolist(),
    }


def _emit(args: argparse.Namespace, result: dict, line: str, time_codes=None) -> int:
    """Write ``--out`` (keys at the source's time codes) and print the line or the JSON."""
    if args.out is not None:
        from hairtool.keys.export import keys_record, write_keys_json

        write_keys_json(args.out, keys_record(result, args.input, time_codes=time_codes))
    print(json.dumps(result) if args.json else line)
    return 0
