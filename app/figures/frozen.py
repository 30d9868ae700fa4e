"""The frozen-hair paper's three experiments (Kim 2026, Figs. 1–3) on the 2-D portrait sample.

``python -m app.figures.frozen OUTDIR`` writes each panel as its own PNG and each figure as a
labelled row of panels:

- ``frozen_fig1_intensity.png``: one mouse stroke (drawn in grey) aligns the right-hand hair at
  intensity (a) 0.8 and (b) 0.2; red roots, blue tips as in the paper. 0.8 turns whole strands,
  0.2 mostly their ends, so the curves are gentler.
- ``frozen_fig2_stiffness.png``: (a) the rest groom, (b) frozen with stiffness 7 (stretch and
  bend), (c) with stiffness 3: lower stiffness gives more uneven lengths and kinks.
- ``frozen_fig3_clumping.png``: (a) the rest groom; both sides combed together by strokes and
  frozen, (b) without clumping, then clumped (c) within a small and (d) within a larger radius:
  neighbouring strands gather into bunches with gaps between them.

All randomness comes from the pipeline's seed, so the pictures are the same on every run.
"""

from __future__ import annotations

import dataclasses
import math
import sys
from collections.abc import Sequence

import numpy as np

from app.figures.sheet import grid, label, main_guard, out_dir, write
from app.render.camera import Camera
from app.render.offscreen import render_image
from app.render.ramps import ramp_colors
from hairtool import samples
from hairtool.groom import Groom

BACKGROUND = (1.0, 1.0, 1.0, 1.0)
STROKE_GREY = (0.55, 0.55, 0.55)
ALIGN_RADIUS = 0.9
SEED = 7
FIG3_CLUMP_RADII = (0.06, 0.12)  # groom units (head radius 1)


def stroke(start: Sequence[float], end: Sequence[float], samples_: int = 14) -> np.ndarray:
    """``(n, 3)`` cursor positions of a straight mouse drag (z = 0)."""
    t = np.linspace(0.0, 1.0, samples_)[:, None]
    a, b = np.asarray(start, dtype=np.float64), np.asarray(end, dtype=np.float64)
    return np.column_stack([a + t * (b - a), np.zeros(samples_)])


def tip_centre(groom: Groom, side: float) -> np.ndarray:
    """Mean tip position of the strands on one side (side = +1 right, −1 left), in the xy plane."""
    tips = groom.tips[:, :2].astype(np.float64)
    return tips[np.sign(tips[:, 0]) == side].mean(axis=0)


def fig1_stroke(rest: Groom) -> np.ndarray:
    """Grab the right-hand tips and sweep them out and up."""
    start = tip_centre(rest, 1.0)
    return stroke(start, start + np.array([1.5, 1.4]))


def fig3_strokes(rest: Groom) -> tuple[np.ndarray, ...]:
    """Grab each side's tips and comb them in and down, so neighbouring strands line up."""
    out = []
    for side in (1.0, -1.0):
        start = tip_centre(rest, side)
        out.append(stroke(start, start + np.array([-0.9 * side, -0.7])))
    return tuple(out)


def drag(pipeline, cursors: np.ndarray, intensity: float, mode: str = "paper") -> Groom:
    """Feed a stroke to the pipeline one mouse move at a time, as the studio does."""
    result = pipeline.result
    for c in cursors:
        result = pipeline.align(c, ALIGN_RADIUS, intensity, mode)
    return result


def with_strokes(groom: Groom, strokes: Sequence[np.ndarray], ramp: str) -> tuple[Groom, np.ndarray]:
    """The groom plus each stroke as a grey polyline; ``(V', 3)`` colours for both."""
    hair = ramp_colors(groom.vertex_param, ramp)
    if not strokes:
        return groom, hair
    points = np.concatenate([groom.points, *strokes])
    counts = np.concatenate([groom.counts, [len(s) for s in strokes]])
    grey = np.tile(np.float32(STROKE_GREY), (sum(len(s) for s in strokes), 1))
    return Groom(points, counts), np.concatenate([hair, grey])


def camera_for(grooms: Sequence[Groom], extra: Sequence[np.ndarray] = ()) -> Camera:
    """One orthographic camera for every panel of a figure, so they compare 1:1."""
    pts = np.concatenate([g.points for g in grooms] + [np.asarray(e, np.float32) for e in extra])
    return Camera.for_bounds(pts.min(axis=0), pts.max(axis=0), ortho=True)


def panels(
    grooms: Sequence[Groom],
    captions: Sequence[str],
    size: int,
    *,
    ramp: str = "root-tip",
    strokes: Sequence[Sequence[np.ndarray]] | None = None,
) -> list[np.ndarray]:
    strokes = strokes or [()] * len(grooms)
    cam = camera_for(grooms, [p for group in strokes for p in group])
    out = []
    for g, caption, st in zip(grooms, captions, strokes, strict=True):
        shown, colors = with_strokes(g, st, ramp)
        img = render_image(
            shown, size=(size, size), camera=cam, colors=colors, line_width=2.0, background=BACKGROUND
        )
        out.append((img, caption))
    return out


def save_figure(outdir, name: str, stem: str, rendered: list[tuple[np.ndarray, str]]) -> None:
    for i, (img, caption) in enumerate(rendered):
        slug = caption.split(") ", 1)[-1].replace(" ", "_").replace("=", "").replace(",", "")
        write(outdir / f"{stem}{chr(ord('a') + i)}_{slug}.png", img)
    write(outdir / name, grid([label(img, caption) for img, caption in rendered]))


def make(argv: list[str] | None = None) -> None:
    outdir, args = out_dir(__doc__.splitlines()[0], argv)
    from hairtool.frozen.pipeline import FrozenParams, FrozenPipeline

    rest = samples.portrait(strands=160, vertices=20, seed=0)
    size = args.size

    # Fig. 1: the same stroke at intensity 0.8 and 0.2 (no freezing, so only alignment shows).
    plain = FrozenParams(seed=SEED, freeze=False, clump=False)
    fig1_path = fig1_stroke(rest)
    fig1 = [drag(FrozenPipeline(rest, plain), fig1_path, x) for x in (0.8, 0.2)]
    save_figure(
        outdir,
        "frozen_fig1_intensity.png",
        "frozen_fig1",
        panels(
            fig1,
            ["(a) intensity 0.8", "(b) intensity 0.2"],
            size,
            ramp="red-blue",
            strokes=[[fig1_path]] * 2,
        ),
    )

    # Fig. 2: freezing at stiffness 7 and 3 (stretch and bend alike).
    def frozen_at(k: float) -> Groom:
        params = FrozenParams(
            stretch_stiffness=k, bend_stiffness=k, max_bend_angle=math.radians(60.0), seed=SEED, clump=False
        )
        return FrozenPipeline(rest, params).result

    save_figure(
        outdir,
        "frozen_fig2_stiffness.png",
        "frozen_fig2",
        panels(
            [rest, frozen_at(7.0), frozen_at(3.0)],
            ["(a) original", "(b) stiffness 7", "(c) stiffness 3"],
            size,
        ),
    )

    # Fig. 3: comb both sides together and freeze; then clump within a small and a larger radius.
    # Fewer strands than Figs. 1–2, so the gaps between clumps stay visible in 2-D. Panel (b),
    # the same strokes without clumping, is not in the paper: it shows what clumping changes.
    sparse = samples.portrait(strands=100, vertices=20, seed=0)
    strokes3 = fig3_strokes(sparse)
    base = FrozenParams(
        stretch_stiffness=7.0,
        bend_stiffness=7.0,
        max_bend_angle=math.radians(60.0),
        seed=SEED,
        clump=False,
        clump_iterations=10,
    )
    pipe = FrozenPipeline(sparse, base)
    for st in strokes3:
        drag(pipe, st, 0.8)
    fig3 = [pipe.result]
    for radius in FIG3_CLUMP_RADII:
        fig3.append(pipe.set_params(dataclasses.replace(base, clump=True, clump_radius=radius)))
    save_figure(
        outdir,
        "frozen_fig3_clumping.png",
        "frozen_fig3",
        panels(
            [sparse, *fig3],
            [
                "(a) original",
                "(b) aligned and frozen, no clumping",
                *(f"({chr(ord('c') + i)}) clump radius {h:g}" for i, h in enumerate(FIG3_CLUMP_RADII)),
            ],
            size,
            strokes=[(), *([strokes3] * 3)],
        ),
    )


if __name__ == "__main__":
    sys.exit(main_guard(make))
