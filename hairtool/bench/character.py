"""Character speed: skinning a frame and stepping the spring bones, each against its numpy twin.

On the bundled character (or ``--character``): ``skin_ms``/``skin_numpy_ms`` pose every skinned
mesh once through the numba kernel and the numpy reference; ``springs_ms_per_frame`` and
``springs_numpy_ms_per_frame`` run the VRM spring bones on a head shake, one step a frame;
``cycle_ms`` makes the anime cycle's drawings (the paper's Fig. 2 timing).
"""

from __future__ import annotations

import argparse
from pathlib import Path

from hairtool.bench import DATA_DIR, add_common_arguments

HELP = "characters: skinning and spring bones per frame, numba against the numpy twins"

BUNDLED = DATA_DIR / "characters" / "bunches.vrm"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--character", type=Path, default=BUNDLED, help="a .vrm/.glb/.gltf (default the bundled one)"
    )
    parser.add_argument("--frames", type=int, default=48, help="spring frames to time (default 48)")
    add_common_arguments(parser, quick="6 spring frames, one run", repeat=3)


def run(args: argparse.Namespace) -> list[dict]:

    from hairtool.bench import median_ms, ratio, setup, threads
    from hairtool.character.cycle import character_cycle
    from hairtool.character.read import load_character
    from hairtool.character.skinning import skin
    from hairtool.character.springs import head_shake, simulate
    from hairtool.errors import ParameterError

    repeat = setup(args)
    frames = 6 if args.quick else args.frames
    if frames < 1:
        raise ParameterError("frames", frames, "a whole number ≥ 1")
    c = load_character(args.character)
    world = c.nodes.world(character_cycle(c).pictures[0])
    driver = head_shake(c, frames, 24.0)
    simulate(c, driver[:2], 24.0)  # compile or load the kernels
    for mesh in c.meshes:
        skin(mesh, world)
    rows = []
    for mesh in c.meshes:
        fast = median_ms(lambda m=mesh: skin(m, world), repeat)
        slow = median_ms(lambda m=mesh: skin(m, world, use_numba=False), repeat)
        rows.append(
            {
                "what": f"skin {mesh.name}",
                "vertices": len(mesh.positions),
                "skin_ms": fast,
                "skin_numpy_ms": slow,
                "numpy_over_numba": ratio(slow, fast),
                "threads": threads(),
            }
        )
    fast = median_ms(lambda: simulate(c, driver, 24.0), repeat) / frames
    slow = median_ms(lambda: simulate(c, driver, 24.0, use_numba=False), repeat) / frames
    joints = sum(len(ch.nodes) - (0 if ch.virtual_tail else 1) for ch in c.chains)
    cycle_ms = median_ms(lambda: character_cycle(c), repeat)
    rows.append(
        {
            "what": "springs",
            "joints": joints,
            "frames": frames,
            "springs_ms_per_frame": fast,
            "springs_numpy_ms_per_frame": slow,
            "numpy_over_numba": ratio(slow, fast),
            "cycle_ms": cycle_ms,
            "threads": threads(),
        }
    )
    return rows
