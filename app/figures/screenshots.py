"""The manual's pictures of the studio, made by driving the real window as an artist would.

``python -m app.figures.screenshots OUTDIR`` (needs a display: Xvfb works) writes

- ``screenshot-studio.png``: Sintel's hair on her head, frozen and clumped, groomed with the
  brushes as an artist would: the fringe combed aside with X symmetry (the mirror plane drawn),
  the ends smoothed and puffed, one align stroke: the 228 guides (orange) with their 30,000
  interpolated render strands following, shaded as hair;
- ``screenshot-timeline.png``: an anime cycle on that groom in the timeline — the DP keys against
  uniform keys of the same count, the error and speed curves, the error-versus-key-count plot —
  with the anime wave dock beside it and the viewport in ghost mode at a frame between keys.

The strokes are mouse events sent to the viewport, so the pictures show what a user gets.
Settings go to a temporary file, never to the user's.
"""

from __future__ import annotations

import sys
import tempfile
from collections.abc import Sequence
from pathlib import Path

import numpy as np

WINDOW_SIZE = (1366, 768)  # a laptop screen: the studio must fit one


def stroke(window, start: Sequence[float], end: Sequence[float], steps: int = 24) -> None:
    """A left-drag across the viewport in fractions of its size (0..1 from the top left)."""
    from PySide6.QtCore import Qt
    from PySide6.QtWidgets import QApplication

    from app.ui.qt_utils import send_mouse

    left = Qt.MouseButton.LeftButton
    v = window.viewport
    size = np.array([v.width(), v.height()], dtype=np.float64)
    a, b = np.asarray(start) * size, np.asarray(end) * size
    send_mouse(v, "press", a, left, left)
    for f in np.linspace(0.0, 1.0, steps + 1)[1:]:
        send_mouse(v, "move", (1.0 - f) * a + f * b, None, left)
        QApplication.processEvents()
    send_mouse(v, "release", b, left)
    QApplication.processEvents()


def settle(app, rounds: int = 30) -> None:
    for _ in range(rounds):
        app.processEvents()


def save(window, path: Path) -> None:
    from app.ui.gl_surface import grab_with_view

    window.statusBar().clearMessage()  # a stroke's passing remark is no part of the picture
    if not grab_with_view(window, window.viewport).save(str(path)):
        raise OSError(f"could not write {path}")
    print(f"wrote {path}")


def main(argv: Sequence[str] | None = None) -> int:
    import argparse

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("outdir", type=Path, help="folder for the PNGs (made if missing)")
    args = parser.parse_args(argv)
    args.outdir.mkdir(parents=True, exist_ok=True)

    from app.surface import configure_gl

    configure_gl()
    from PySide6.QtCore import QSettings
    from PySide6.QtWidgets import QApplication

    from app.ui.window import MainWindow

    app = QApplication.instance() or QApplication(sys.argv[:1])
    with tempfile.TemporaryDirectory() as tmp:
        settings = QSettings(str(Path(tmp) / "studio.ini"), QSettings.Format.IniFormat)
        window = MainWindow(settings=settings)
        window.ask_save_changes = lambda: "discard"
        window.resize(*WINDOW_SIZE)
        window.show()
        settle(app)
        if not window.open_bundled_sample():
            return 1
        window.timeline.hide()
        settle(app)
        # Comb the fringe aside with X symmetry, smooth and puff the ends, then sweep one side
        # out with the paper's align brush; the comb stays selected, its mirror plane drawn.
        scene = window.scene
        scene.set_symmetry(True)
        window.brush_actions["comb"].trigger()
        scene.set_intensity(1.0)
        stroke(window, (0.47, 0.30), (0.56, 0.40))
        window.brush_actions["smooth"].trigger()
        stroke(window, (0.40, 0.62), (0.44, 0.66))
        window.brush_actions["puff"].trigger()
        stroke(window, (0.60, 0.58), (0.61, 0.58), steps=4)
        window.brush_actions["align"].trigger()
        scene.set_symmetry(False)
        stroke(window, (0.62, 0.62), (0.70, 0.56))
        window.brush_actions["comb"].trigger()
        scene.set_symmetry(True)
        window.viewport.leaveEvent(None)
        settle(app)
        save(window, args.outdir / "screenshot-studio.png")

        scene.set_symmetry(False)  # the timeline's picture is about the animation
        window.timeline.show()
        window.sources.dock.raise_()
        window.sources.apply_anime()
        model = window.animation
        settle(app)
        model.set_key_count(max(3, model.n_frames // 3))
        keys = model.dp_keys
        gaps = np.diff(keys)
        between = int(keys[np.argmax(gaps)] + gaps.max() // 2)  # mid-way through the longest gap
        model.set_view_mode("ghost")
        model.set_frame(between)
        settle(app, 60)
        save(window, args.outdir / "screenshot-timeline.png")
        window.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
