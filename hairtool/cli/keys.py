"""Find globally optimal keyframes of an animation, a BVH capture or a feature array.

IN is an animation file (.usd/.usda/.usdc/.npz cache), a .bvh, or an .npz holding an array
``X`` of shape (frames, dims) used as raw features. Exactly one mode: --keys K (default: a
tenth of the frames), --penalty TAU, --budget E (total error) or --max-error E (worst frame).
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

HELP = "find globally optimal keyframes (exact DP) and compare with uniform keys"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("input", metavar="IN", help="animation file, .bvh, or .npz with an array X")
    mode = parser.add_mutually_exclusive_group()
    mode.add_argument("--keys", "-k", type=int, metavar="K", help="exactly K keys")
    mode.add_argument("--penalty", type=float, metavar="TAU", help="price per key (seed 003)")
    mode.add_argument("--budget", type=float, metavar="E", help="fewest keys with total error <= E")
    mode.add_argument("--max-error", type=float, metavar="E", help="fewest keys with worst frame <= E")
    parser.add_argument("--objective", choices=("total", "worst"), default="total")
    parser.add_argument("--interp", choices=("linear", "hermite"), default="linear")
    parser.add_argument("--curvature", type=float, default=0.0, metavar="LAMBDA", help="curvature weight")
    parser.add_argument(
        "--per-channel", action="store_true", help="keys per degree of freedom (needs --penalty)"
    )
    parser.add_argument("--curve-keys", type=int, default=100, metavar="N", help="curve up to N keys")
    feat = parser.add_argument_group("hair features (seed 000)")
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
        choices=("positions", "rotations", "quaternion"),
        default="positions",
        help="BVH: joint positions, quaternion features, or seed 003's quaternion-distance table",
    )
    parser.add_argument("--json", action="store_true", help="print the result as JSON")
    parser.add_argument("--out", type=Path, metavar="KEYS.json", help="write keys, times and parameters")
    parser.add_argument("--export", type=Path, metavar="OUT.usd", help="write the key poses as time samples")


def _load(args: argparse.Namespace):
    """``(kind, data, fps)``: kind "raw" (X), "animation" (Animation) or "bvh" (Motion)."""
    from hairtool.errors import FormatError, GroomError
    from hairtool.groom import Animation

    path = Path(args.input)
    if not path.is_file():
        raise FormatError(path, "no such file" if not path.exists() else "not a regular file")
    suffix = path.suffix.lower()
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


def _mode(args: argparse.Namespace, n: int) -> dict:
    if args.penalty is not None:
        return {"penalty": args.penalty}
    if args.budget is not None:
        return {"budget": args.budget}
    if args.max_error is not None:
        return {"max_error": args.max_error}
    return {"keys": args.keys if args.keys is not None else max(2, round(n / 10))}


def run(args: argparse.Namespace) -> int:
    import numpy as np

    from hairtool.errors import ParameterError
    from hairtool.keys.costs import cost_table
    from hairtool.keys.dp import select_keys
    from hairtool.keys.features import FeatureOptions, frame_features, raw_features

    kind, data, fps = _load(args)
    options = FeatureOptions(
        samples=None if args.no_resample else args.samples,
        center=not args.no_center,
        relative=not args.no_relative,
        weighting=not args.no_weighting,
        root_weight=args.root_weight,
        tip_weight=args.tip_weight,
        exponent=args.weight_exponent,
    )
    if kind == "bvh":
        from hairtool.mocap.costs import motion_features

        x = motion_features(data, "positions" if args.bvh_features == "positions" else "rotations")
    elif kind == "animation":
        x = frame_features(data, options)
    else:
        x = raw_features(data)
    n = x.shape[0]

    if args.per_channel:
        from hairtool.keys.session import per_channel_keys

        if args.penalty is None:
            raise ParameterError("per-channel", True, "a --penalty TAU (seed 003 prices keys per channel)")
        result = {
            "frames": n,
            "fps": fps,
            **per_channel_keys(x, args.penalty, interp=args.interp, curvature=args.curvature).to_dict(),
        }
        return _emit(args, result, f"{len(result['union'])} frames key at least one of {x.shape[1]} channels")

    mode = _mode(args, n)
    objective = "worst" if args.max_error is not None else args.objective
    if kind == "bvh" and args.bvh_features == "quaternion":
        from hairtool.mocap.costs import rotation_cost_table

        if args.interp != "linear" or args.curvature or objective != "total":
            raise ParameterError("bvh-features", "quaternion", "the linear (slerp) total objective only")
        table = rotation_cost_table(data)
    else:
        table = cost_table(x, args.interp, args.curvature, objective)
    sel = select_keys(table, objective=objective, curve_keys=args.curve_keys, **mode)
    result = {"frames": n, "fps": fps, **sel.to_dict()}
    result["params"].update(interp=args.interp, curvature=args.curvature)
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
    if args.export is not None:
        if kind != "animation":
            raise ParameterError("export", str(args.export), "an animation input (hair strands)")
        from hairtool.keys.export import write_key_poses

        write_key_poses(args.export, data, sel.keys)
    line = (
        f"{sel.n_keys} keys of {n} frames, {sel.objective} error {sel.cost:.6g} "
        f"(uniform {sel.uniform_cost:.6g}): {' '.join(map(str, sel.keys.tolist()))}"
    )
    return _emit(args, result, line)


def _emit(args: argparse.Namespace, result: dict, line: str) -> int:
    if args.out is not None:
        from hairtool.keys.export import keys_record, write_keys_json

        write_keys_json(args.out, keys_record(result, args.input))
    print(json.dumps(result) if args.json else line)
    return 0
