"""The bundled character's hair: the anime cycle's drawings beside its spring bones.

``python -m app.figures.character OUTDIR`` writes ``character_cycle_vs_springs.png``: the top row
shows the six drawings of one cycle (the paper's Fig. 2 timing, T = 0.45 s on twos), the bottom
row the spring bones at the same frames while the head shakes ±30° once a second; each panel
draws the 14 hair chains, seen from the character's left.
"""

from __future__ import annotations

import sys

import numpy as np

from app.figures.sheet import grid, label, main_guard, out_dir, write
from app.render.camera import Camera
from app.render.offscreen import render_image
from app.resources import path as resource
from hairtool.character import load_character
from hairtool.character.cycle import chain_points, character_cycle
from hairtool.character.springs import head_shake, simulate
from hairtool.groom import Groom

BACKGROUND = (1.0, 1.0, 1.0, 1.0)


def _chains(character, rotations) -> Groom:
    """The chains as strands, turned so the view along +x (the character's left) shows them."""
    world = character.nodes.world(rotations)
    strands = [chain_points(character, ch, world) for ch in character.chains]
    return Groom.from_strands([s[:, [2, 1, 0]] * np.array([-1.0, 1.0, 1.0]) for s in strands])


def make(argv: list[str] | None = None) -> None:
    outdir, args = out_dir(__doc__.splitlines()[0], argv)
    size = (args.size, args.size)
    c = load_character(resource("bunches.vrm"))
    cyc = character_cycle(c)
    frames = cyc.frames()
    starts = np.concatenate([[0], np.cumsum(cyc.schedule.holds)[:-1]])
    springs = simulate(c, head_shake(c, len(frames), cyc.schedule.fps), cyc.schedule.fps)
    cycle_grooms = [_chains(c, cyc.pictures[i]) for i in range(cyc.schedule.n_pictures)]
    spring_grooms = [_chains(c, springs[f]) for f in starts]
    everything = cycle_grooms + spring_grooms
    lo = np.min([g.bounds[0] for g in everything], axis=0)
    hi = np.max([g.bounds[1] for g in everything], axis=0)
    cam = Camera.for_bounds(lo, hi, ortho=True)
    panels = []
    for i, g in enumerate(cycle_grooms):
        img = render_image(g, size=size, camera=cam, line_width=2.0, background=BACKGROUND)
        panels.append(label(img, f"drawing {i}, frame {starts[i]}"))
    for f, g in zip(starts, spring_grooms, strict=True):
        img = render_image(g, size=size, camera=cam, line_width=2.0, background=BACKGROUND)
        panels.append(label(img, f"springs, frame {f}"))
    write(outdir / "character_cycle_vs_springs.png", grid(panels, columns=len(cycle_grooms)))


if __name__ == "__main__":
    sys.exit(main_guard(make))
