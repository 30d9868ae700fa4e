"""hairtool's ClumpWithGaps against Blender 5's Clump Hair Curves node, in the same run.

Run it with hairtool's Python and point it at a Python that imports ``bpy`` (the Blender module,
``pip install bpy==5.0.1`` in a venv of its own)::

    .venv/bin/python benchmarks/blender_clump.py --bpy /work/bpyvenv/bin/python \
        [--sizes 500x20 5000x20 50000x20 tests/data/grooms/bear.tfx] [--repeat 7] [--rounds 3] \
        [--out clump.json]

Not part of the package or of CI. Each groom (scalp samples ``STRANDSxVERTICES`` or a groom
file) goes to Blender as a hair Curves object with the Essentials asset *Clump Hair Curves*
(``procedural_hair_node_assets.blend``) as a Geometry Nodes modifier: guides picked at least the
clump radius h apart (no existing guide map), every other curve pulled toward its nearest guide,
factor 1, shape 0.5. Its time is one evaluation of the object (``Depsgraph.update`` after a
change of the node's seed, so nothing is reused); ``passthrough_ms`` is the same evaluation with
an empty node group (Blender shares the unchanged geometry, so it is next to nothing: the clump
time is the node's own).

hairtool's side is ``hairtool.frozen.clump.clump`` at the same h (2× the median root spacing, as
``hairtool bench freeze`` uses), k = 3 iterations, gaps as printed: ``cold_ms`` with its
neighbour list built each time (what an evaluation that reuses nothing costs, as Blender's
does), ``kept_ms`` with the list of the last run (the studio's repeated runs on the same
points), ``stroke_ms`` the run after a comb stroke near the middle tip, its list that of the
points before the stroke brought up to date (the studio's release,
``hairtool.bench.freeze.release_times``; Blender evaluates its node anew after any edit).
``first_ms`` is the first run in a fresh process with an empty ``NUMBA_CACHE_DIR`` (compiling
every kernel it runs, then building the list and clumping; the interpreter's start and imports
aside), once per groom (``--no-first`` leaves it out), beside ``blender_first_ms``, the node's
first evaluation in its fresh process.
Both tools use every core. Each row is ``--rounds`` rounds of Blender then hairtool, each side's
median over them, and the median of the rounds' speedups: the 2-core VM's speed drifts by tens
of percent within minutes, and a round's two sides see about the same host. The rows come
between two runs of ``hairtool bench host`` (its ``speed`` and ``scaling``) and the load
average, printed first and last. ClumpWithGaps does more than Blender's node (three iterations
of an adhesion force over every pair within h, a gap correction, lengths kept), so the
comparison is of what an artist waits for, not of equal work.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

WORKER_FLAG = "--blender-worker"
FIRST_FLAG = "--first-worker"
ASSET = "assets/nodes/procedural_hair_node_assets.blend"
NODE_GROUP = "Clump Hair Curves"


# ---------------------------------------------------------------------------------------
# The Blender side (runs in the bpy Python; numpy and bpy only)
# ---------------------------------------------------------------------------------------
def _asset_path() -> str:
    import bpy

    base = os.path.dirname(bpy.__file__)  # bpy/<version>/scripts/modules/bpy
    version = os.path.normpath(os.path.join(base, "..", "..", ".."))
    return os.path.join(version, "datafiles", ASSET)


def _blender_times(points: np.ndarray, sizes: np.ndarray, h: float, repeat: int) -> dict:
    import bpy

    bpy.ops.wm.read_factory_settings(use_empty=True)
    with bpy.data.libraries.load(_asset_path()) as (src, dst):
        dst.node_groups = [n for n in src.node_groups if n == NODE_GROUP]
    clump = bpy.data.node_groups[NODE_GROUP]
    empty = bpy.data.node_groups.new("passthrough", "GeometryNodeTree")
    empty.interface.new_socket("Geometry", in_out="INPUT", socket_type="NodeSocketGeometry")
    empty.interface.new_socket("Geometry", in_out="OUTPUT", socket_type="NodeSocketGeometry")
    gin, gout = empty.nodes.new("NodeGroupInput"), empty.nodes.new("NodeGroupOutput")
    empty.links.new(gin.outputs[0], gout.inputs[0])

    curves = bpy.data.hair_curves.new("groom")
    curves.add_curves(sizes.tolist())
    curves.position_data.foreach_set("vector", points.astype(np.float32).ravel())
    obj = bpy.data.objects.new("groom", curves)
    bpy.context.scene.collection.objects.link(obj)
    mod = obj.modifiers.new("clump", "NODES")
    sockets = {i.name: i.identifier for i in clump.interface.items_tree if i.item_type == "SOCKET"}

    def evaluate(seed: int) -> float:
        if mod.node_group is clump:
            mod[sockets["Seed"]] = seed
        obj.update_tag()
        t0 = time.perf_counter()
        depsgraph = bpy.context.evaluated_depsgraph_get()
        depsgraph.update()
        evaluated = obj.evaluated_get(depsgraph)
        n = len(evaluated.data.points)
        took = time.perf_counter() - t0
        if n != len(points):
            raise RuntimeError(f"Blender's evaluated groom has {n} points, not {len(points)}")
        return took

    out = {}
    for name, group in (("passthrough", empty), ("clump", clump)):
        mod.node_group = group
        if group is clump:
            mod[sockets["Guide Distance"]] = float(h)
            mod[sockets["Existing Guide Map"]] = False
            mod[sockets["Factor"]] = 1.0
        first = evaluate(0)  # the first evaluation builds what later ones keep (the node tree's code)
        if group is clump:
            out["first_ms"] = 1e3 * first
        out[f"{name}_ms"] = 1e3 * float(np.median([evaluate(1 + i) for i in range(repeat)]))
    depsgraph = bpy.context.evaluated_depsgraph_get()
    moved = np.empty(len(points) * 3, np.float32)
    obj.evaluated_get(depsgraph).data.position_data.foreach_get("vector", moved)
    out["moved_share"] = float(np.mean(np.any(moved.reshape(-1, 3) != points.astype(np.float32), axis=1)))
    return out


def _worker(argv: list[str]) -> None:
    """``--blender-worker IN.npz OUT.json``: Blender's times for IN's groom."""
    src, dst = argv
    data = np.load(src)
    out = _blender_times(data["points"], data["sizes"], float(data["h"]), int(data["repeat"]))
    Path(dst).write_text(json.dumps(out))


# ---------------------------------------------------------------------------------------
# The hairtool side
# ---------------------------------------------------------------------------------------
def _first_worker(argv: list[str]) -> None:
    """``--first-worker GROOM.npz H``: the first ClumpWithGaps run of this process, in ms (the
    parent gives it an empty ``NUMBA_CACHE_DIR``)."""
    path, h = argv
    from hairtool.frozen.clump import clump
    from hairtool.io import read_groom

    groom = read_groom(path)
    t0 = time.perf_counter()
    clump(groom, float(h), 3, None, "printed", 0)
    print(json.dumps({"first_ms": 1e3 * (time.perf_counter() - t0)}))


def first_ms(size: str, groom, h: float) -> float:
    """:func:`_first_worker` in a child process with a new, empty numba cache."""
    from hairtool.io import write

    with tempfile.TemporaryDirectory(prefix="clump-first-") as tmp:
        path = os.path.join(tmp, "groom.npz")
        write(path, groom)
        env = dict(os.environ, NUMBA_CACHE_DIR=os.path.join(tmp, "numba"))
        done = subprocess.run(
            [sys.executable, os.path.abspath(__file__), FIRST_FLAG, path, repr(h)],
            capture_output=True, text=True, check=False, env=env,
        )  # fmt: skip
    if done.returncode != 0:
        raise SystemExit(f"the first run failed on {size}:\n{done.stderr[-3000:]}")
    return float(json.loads(done.stdout.strip().splitlines()[-1])["first_ms"])


def host() -> dict:
    """``hairtool bench host``'s speed and scaling, and the load average, now."""
    from types import SimpleNamespace

    from hairtool.bench import host as probe

    (*_, summary) = probe.run(SimpleNamespace(quick=False, repeat=5, threads=None))
    return {"host_speed": summary["speed"], "host_scaling": summary["scaling"], "load": os.getloadavg()[0]}


def _hairtool_times(groom, h: float, repeat: int) -> dict:
    from hairtool.bench import median_ms
    from hairtool.frozen.clump import ClumpWorkspace, clump

    ws = ClumpWorkspace()

    def cold():
        ws.invalidate()
        clump(groom, h, 3, None, "printed", 0, ws)

    from hairtool.bench.freeze import release_times

    return {
        "cold_ms": median_ms(cold, repeat),
        "kept_ms": median_ms(lambda: clump(groom, h, 3, None, "printed", 0, ws), repeat),
        "stroke_ms": release_times(groom, repeat, h)["release_ms"],
    }


def _blender(groom, h: float, bpy_python: str, repeat: int, size: str) -> dict:
    with tempfile.TemporaryDirectory(prefix="blender-clump-") as tmp:
        src, dst = os.path.join(tmp, "in.npz"), os.path.join(tmp, "out.json")
        sizes = np.diff(groom.offsets)
        np.savez(src, points=groom.points, sizes=sizes, h=h, repeat=repeat)
        done = subprocess.run(
            [bpy_python, os.path.abspath(__file__), WORKER_FLAG, src, dst],
            capture_output=True, text=True, check=False,
        )  # fmt: skip
        if done.returncode != 0:
            raise SystemExit(f"Blender failed on {size}:\n{done.stderr[-3000:]}")
        return {f"blender_{k}": v for k, v in json.loads(Path(dst).read_text()).items()}


def compare(size: str, groom, bpy_python: str, repeat: int, rounds: int = 1, first: bool = True) -> dict:
    """One row: each side's medians over ``rounds`` rounds of Blender then hairtool, and the
    median of the rounds' speedups (a host whose speed drifts moves both sides of a round)."""
    from hairtool.frozen.strand_clumps import auto_clump_radius

    h = float(auto_clump_radius(groom))
    row = {"groom": size, "strands": groom.strand_count, "vertices": groom.vertex_count, "h": h}
    runs = []
    for _ in range(rounds):
        run = _blender(groom, h, bpy_python, repeat, size)
        run.update(_hairtool_times(groom, h, repeat))
        for case in ("cold", "kept", "stroke"):
            run[f"speedup_{case}"] = run["blender_clump_ms"] / run[f"{case}_ms"]
        runs.append(run)
    row.update({k: float(np.median([r[k] for r in runs])) for k in runs[0]})
    if first:
        row["first_ms"] = first_ms(size, groom, h)
        row["speedup_first"] = row["blender_first_ms"] / row["first_ms"]
    row["rounds"] = rounds
    return row


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if argv[:1] == [WORKER_FLAG]:
        _worker(argv[1:])
        return 0
    if argv[:1] == [FIRST_FLAG]:
        _first_worker(argv[1:])
        return 0
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--bpy", required=True, help="a Python that imports bpy 5.0")
    parser.add_argument(
        "--sizes", nargs="+", default=["500x20", "5000x20", "50000x20"],
        help="STRANDSxVERTICES (scalp samples), 'real' (the checkout's real grooms) or groom files",
    )  # fmt: skip
    parser.add_argument("--repeat", type=int, default=7)
    parser.add_argument(
        "--rounds", type=int, default=3, help="rounds of Blender then hairtool; the median speedup of them"
    )
    parser.add_argument("--out", type=Path, default=None, help="also write the rows as JSON")
    parser.add_argument(
        "--no-first", action="store_true", help="leave out the first run in a fresh process (first_ms)"
    )
    args = parser.parse_args(argv)
    import numba

    from hairtool.bench import format_table

    rows = []
    from hairtool.bench.freeze import _grooms  # the sizes `hairtool bench freeze --sizes` takes

    before = host()
    print(json.dumps({"before": before}), flush=True)
    for size, groom in _grooms(args.sizes):
        rows.append(compare(size, groom, args.bpy, args.repeat, args.rounds, not args.no_first))
        rows[-1]["threads"] = numba.get_num_threads()
        print(json.dumps(rows[-1]), flush=True)
    after = host()
    print(json.dumps({"after": after}), flush=True)
    print(format_table(rows))
    print(f"host before: {before}\nhost after: {after}")
    if args.out is not None:
        args.out.write_text(json.dumps({"host_before": before, "host_after": after, "rows": rows}, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
