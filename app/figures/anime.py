"""The anime hair cycle (Furukawa & Nakata 2018, Fig. 2 parameters) on the 2-D portrait.

``python -m app.figures.anime OUTDIR`` writes one PNG per picture of the cycle
(``anime_picture_NN.png``), a labelled contact sheet of them (``anime_contact_sheet.png``) and
``anime_envelope.png``: every picture of two strands (one each side) overlaid, coloured from the first picture
(dark) to the last (light), so the swing growing from root to tip shows in one image.
Parameters: s = 1.2, k = 1.0, a = 0.8, T = 0.45 s, p = 1, 24 fps on twos; bunches in lock step
(no per-strand amplitude or phase spread) so the travelling wave reads clearly.
"""

from __future__ import annotations

import sys

import numpy as np

from app.figures.sheet import grid, label, main_guard, out_dir, write
from app.render.camera import Camera
from app.render.offscreen import render_image
from app.render.ramps import ramp_colors
from hairtool import samples
from hairtool.anime.wave import WaveParams, cycle_pictures
from hairtool.groom import Groom

FIG2 = WaveParams(amplitude=0.8, wavelength=1.0, gravity=1.2, profile=1.0, period=0.45)
BACKGROUND = (1.0, 1.0, 1.0, 1.0)


def _camera_for(grooms: list[Groom]) -> Camera:
    lo = np.min([g.bounds[0] for g in grooms], axis=0)
    hi = np.max([g.bounds[1] for g in grooms], axis=0)
    return Camera.for_bounds(lo, hi, ortho=True)


def make(argv: list[str] | None = None) -> None:
    outdir, args = out_dir(__doc__.splitlines()[0], argv)
    size = (args.size, args.size)
    rest = samples.portrait(strands=120, vertices=24, seed=0)
    sched, pictures = cycle_pictures(rest, FIG2, fps=24.0, hold=2, amplitude_spread=0.0, phase_spread=0.0)
    cam = _camera_for([rest, *pictures])
    panels = []
    for i, (pose, t) in enumerate(zip(pictures, sched.picture_times, strict=True)):
        img = render_image(pose, size=size, camera=cam, line_width=2.0, background=BACKGROUND)
        write(outdir / f"anime_picture_{i:02d}.png", img)
        panels.append(label(img, f"picture {i}  t = {t:.3f} s"))
    write(outdir / "anime_contact_sheet.png", grid(panels, columns=min(4, len(panels))))

    # Envelope: one strand on each side in every picture, coloured by picture time.
    picked = np.array([20, 100])
    stack = [p.subset(picked) for p in pictures]
    envelope = Groom(np.concatenate([g.points for g in stack]), np.tile(stack[0].counts, len(stack)))
    shade = ramp_colors(np.linspace(0.0, 1.0, len(stack)), "viridis")
    colors = np.repeat(shade, stack[0].vertex_count, axis=0)
    img = render_image(envelope, size=size, camera=cam, colors=colors, line_width=2.0, background=BACKGROUND)
    write(outdir / "anime_envelope.png", label(img, f"{len(stack)} pictures of one cycle, dark to light"))


if __name__ == "__main__":
    sys.exit(main_guard(make))
