"""One picture per brush for the manual: the 2-D portrait sample before and after one stroke.

``python -m app.figures.brushes OUTDIR`` writes ``figure-brush-NAME.png`` for every brush of
:data:`hairtool.frozen.brushes.BRUSHES`: (a) the groom before, (b) after the stroke, its path
drawn in grey. Each stroke is written as a stroke log entry (the form File ▸ Export Strokes
writes) and applied one mouse move at a time, as the studio does. The brushes that work on the
head's surface (slide, add, density) get the portrait's head as a mesh: a short cylinder around
its outline, so roots slide, and strands grow, along the outline the picture shows. Masked
strands are drawn slate blue, unselected ones grey, planted ones green. Everything is seeded:
the same pictures on every run.
"""

from __future__ import annotations

import math
import sys

import numpy as np

from app.figures.frozen import camera_for, stroke, tip_centre, with_strokes
from app.figures.sheet import grid, label, main_guard, out_dir, write
from app.render.offscreen import render_image
from hairtool import samples
from hairtool.groom import Groom, vertex_ids_of

BACKGROUND = (1.0, 1.0, 1.0, 1.0)
SLATE = (0.42, 0.48, 0.8)  # the studio's mask tint
UNSELECTED = (0.78, 0.78, 0.78)
PLANTED = (0.2, 0.62, 0.3)  # strands the stroke planted (add, density)
SEED = 7
HEAD_SIDES = 96  # the cylinder that stands for the portrait's head
#: The engine's settings of every picture, and where a brush needs its effect to show, its own:
#: smooth takes out kinks, so its groom has more; clump erases clumping, so its groom has more.
BASE = dict(
    stretch_stiffness=5.0, bend_stiffness=5.0, max_bend_angle=math.radians(40.0), seed=SEED,
    clump_radius=0.1, clump_iterations=6, keep_lengths=True,
)  # fmt: skip
LOOKS = {
    "smooth": dict(stretch_stiffness=2.5, bend_stiffness=2.5, max_bend_angle=math.radians(80.0)),
    "clump": dict(clump_radius=0.16, clump_iterations=12),
}


def head_mesh(radius: float = samples.HEAD_RADIUS, depth: float = 0.5):
    """The portrait's head outline as a mesh: a cylinder about z, normals pointing out."""
    from hairtool.io.obj import Mesh

    a = np.linspace(0.0, 2.0 * math.pi, HEAD_SIDES, endpoint=False)
    ring = np.column_stack([np.cos(a), np.sin(a), np.zeros(HEAD_SIDES)])
    vertices = np.concatenate([ring * radius + [0, 0, -depth], ring * radius + [0, 0, depth]])
    i = np.arange(HEAD_SIDES)
    j = (i + 1) % HEAD_SIDES
    faces = np.concatenate(
        [np.column_stack([i, j, j + HEAD_SIDES]), np.column_stack([i, j + HEAD_SIDES, i + HEAD_SIDES])]
    )
    return Mesh(
        vertices.astype(np.float32), faces.astype(np.int32), np.concatenate([ring, ring]).astype(np.float32)
    )


def samples_along(path: np.ndarray, radius: float, strength: float, **extra) -> list[dict]:
    """Stroke-log samples of a drag along ``path``: each move's cursor and its direction."""
    moves = np.diff(path, axis=0, prepend=path[:1])
    return [
        {"cursor": c.tolist(), "direction": d.tolist(), "radius": radius, "strength": strength, **extra}
        for c, d in zip(path, moves, strict=True)
    ]


def on_head(
    degrees_from: float, degrees_to: float, radius: float = samples.HEAD_RADIUS, n: int = 10
) -> np.ndarray:
    """``(n, 3)`` cursor positions along the head outline, angles counted from +x."""
    a = np.radians(np.linspace(degrees_from, degrees_to, n))
    return np.column_stack([radius * np.cos(a), radius * np.sin(a), np.zeros(n)])


def strokes_for(rest: Groom) -> dict[str, tuple[list[dict], str]]:
    """Each brush's stroke log entries and the caption of its picture's second panel."""
    right = tip_centre(rest, 1.0)
    mid_right = np.array([1.35, 0.2])
    sweep = stroke(right, right + np.array([1.2, 1.3]))
    comb = stroke(np.array([1.0, -0.6]), np.array([2.3, -0.2]))
    across = stroke(mid_right + np.array([0.0, 0.9]), mid_right + np.array([0.0, -1.2]))
    back_and_forth = np.concatenate([across, across[::-1], across])
    still = stroke(mid_right, mid_right, 8)
    hook = np.concatenate(
        [
            stroke(right, right + np.array([0.9, 0.2]), 8),
            stroke(right + np.array([0.9, 0.2]), right + np.array([1.2, 1.4]), 8),
        ]
    )
    top = on_head(80.0, 40.0)

    def brush(name: str, moves: list[dict], **fields) -> dict:
        return {"brush": name, "falloff": "smooth", "samples": moves, **fields}

    return {
        "align": ([brush("align", samples_along(sweep, 0.9, 0.8), params={"mode": "paper"})], "after Align"),
        "comb": ([brush("comb", samples_along(comb, 0.8, 1.0))], "after Comb"),
        "smooth": ([brush("smooth", samples_along(back_and_forth, 0.9, 1.0))], "after Smooth"),
        "length": ([brush("length", samples_along(across, 0.8, 0.05))], "after Length"),
        "puff": ([brush("puff", samples_along(across, 1.0, 0.6))], "after Puff"),
        "clump": ([brush("clump", samples_along(across, 0.8, -1.0))], "after Clump, Ctrl (erase)"),
        "mask": (
            [
                brush("mask", samples_along(stroke([1.0, 0.7], [1.0, 0.7], 2), 0.3, 1.0)),
                brush("comb", samples_along(comb, 0.8, 1.0)),
            ],
            "after Mask, then Comb",
        ),
        "pinch": ([brush("pinch", samples_along(still, 0.7, 0.4))], "after Pinch"),
        "snake_hook": ([brush("snake_hook", samples_along(hook, 0.35, 1.0))], "after Snake Hook"),
        "delete": ([brush("delete", samples_along(top, 0.18, 1.0))], "after Delete"),
        "slide": ([brush("slide", samples_along(on_head(70.0, 45.0), 0.3, 1.0))], "after Slide"),
        "add": (
            [
                brush(
                    "add",
                    samples_along(on_head(70.0, 110.0, n=8), 0.25, 1.0),
                    params={"count": 3, "seed": SEED},
                )
            ],
            "after Add",
        ),
        "density": (
            [
                brush(
                    "density",
                    samples_along(on_head(95.0, 60.0, n=4), 0.35, 1.0),
                    params={"spacing": 0.12, "seed": SEED},
                )
            ],
            "after Density",
        ),
        "select": (
            [brush("select", samples_along(across, 0.6, -1.0))],
            "after Select, Ctrl",
        ),
        "cut": ([brush("cut", samples_along(across, 0.35, 1.0))], "after Cut"),
    }


def default_stroke(name: str) -> tuple[list[dict], str]:
    """A brush without its own stroke here: one drag down through the strands on the right, at
    full strength, so a new brush has its picture before anyone tunes one."""
    path = stroke(np.array([1.35, 1.1]), np.array([1.35, -1.0]))
    return [{"brush": name, "falloff": "smooth", "samples": samples_along(path, 0.6, 1.0)}], f"after {name}"


def colours(pipe, groom: Groom) -> np.ndarray:
    """The ramp; masked strands slate blue and unselected ones grey, as the studio tints them,
    planted ones green."""
    from app.render.ramps import ramp_colors

    rgb = ramp_colors(groom.vertex_param, "root-tip").copy()
    for state, tint in ((~pipe.selected, UNSELECTED), (pipe.locked, SLATE), (pipe.origin < 0, PLANTED)):
        ids = np.flatnonzero(state)
        if ids.size:
            rgb[vertex_ids_of(groom.topology, ids)] = tint
    return rgb


def picture(name: str, entries: list[dict], caption: str, rest: Groom, size: int) -> np.ndarray:
    """(a) before and (b) after the stroke log ``entries``, side by side under one camera."""
    from hairtool.frozen.brushes import NEED_SURFACE
    from hairtool.frozen.pipeline import FrozenParams, FrozenPipeline
    from hairtool.frozen.strokes import stroke_from_dict
    from hairtool.guides.planting import HeadSurface

    params = FrozenParams(**{**BASE, **LOOKS.get(name, {})})
    surface = HeadSurface(head_mesh()) if name in NEED_SURFACE else None
    pipe = FrozenPipeline(rest, params, surface)
    before, before_rgb = pipe.result, colours(pipe, pipe.result)
    for entry in entries:
        for sample in stroke_from_dict(entry).pipeline_samples(float(pipe.scalp_centre[0])):
            pipe.apply_samples([sample])
    after = pipe.settle()
    after_rgb = colours(pipe, after)
    paths = [np.array([s["cursor"] for s in e["samples"]], np.float32) for e in entries]
    cam = camera_for([before, after], paths)
    shown = []
    for groom, rgb, path_list, text in (
        (before, before_rgb, [], "(a) before"),
        (after, after_rgb, paths, f"(b) {caption}"),
    ):
        drawn, _ = with_strokes(groom, path_list, "root-tip")
        grey = drawn.points.shape[0] - groom.points.shape[0]
        rgb = np.concatenate([rgb, np.tile(np.float32([0.55, 0.55, 0.55]), (grey, 1))])
        img = render_image(
            drawn, size=(size, size), camera=cam, colors=rgb, line_width=1.5, background=BACKGROUND
        )
        shown.append(label(img, text))
    return grid(shown)


def make(argv: list[str] | None = None) -> None:
    outdir, args = out_dir(__doc__.splitlines()[0], argv)
    from hairtool.frozen.brushes import BRUSHES

    rest = samples.portrait(strands=90, vertices=20, seed=0)
    strokes = strokes_for(rest)
    for name in BRUSHES:
        entries, caption = strokes.get(name) or default_stroke(name)
        write(outdir / f"figure-brush-{name}.png", picture(name, entries, caption, rest, args.size))


if __name__ == "__main__":
    sys.exit(main_guard(make))
