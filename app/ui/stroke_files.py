"""File → Export Strokes… and File → Import / Replay Strokes…: the session's stroke log as the
JSON that ``hairtool freeze --strokes`` replays (:mod:`hairtool.frozen.strokes`), and such a log
applied to the groom in the studio as one undo step."""

from __future__ import annotations

import os
from typing import TYPE_CHECKING

from hairtool.errors import HairtoolError
from hairtool.frozen.strokes import read_strokes, strokes_from_log, write_strokes

if TYPE_CHECKING:
    from app.ui.host import StudioHost

STROKE_FILTERS = "Stroke log (*.json)"


class StrokeFiles:
    """Owned by the window (``window.stroke_files``)."""

    def __init__(self, window: StudioHost) -> None:
        self.window = window

    def export_dialog(self) -> bool:
        w = self.window
        stem = w.scene.path.stem if w.scene.path is not None else "groom"
        path = w.ask_save_path("Export strokes", STROKE_FILTERS, f"{stem}_strokes.json")
        return bool(path) and self.export(path)

    def export(self, path: str | os.PathLike[str]) -> bool:
        """Write every stroke of the session (mirrored samples explicit), atomically."""
        w = self.window
        w.scene.start_engine()
        strokes = strokes_from_log(w.scene.pipeline.strokes)
        try:
            write_strokes(path, strokes)
        except HairtoolError as e:
            w.show_error("Cannot export strokes", str(e))
            return False
        w.remember_dir(path)
        w.statusBar().showMessage(f"wrote {len(strokes)} strokes to {path}", 5000)
        return True

    def replay_dialog(self) -> bool:
        path = self.window.ask_open_path("Import / replay strokes", STROKE_FILTERS)
        return bool(path) and self.replay(path)

    def replay(self, path: str | os.PathLike[str]) -> bool:
        """Apply a stroke log to the groom as one undo step; a bad log changes nothing."""
        w = self.window
        scene = w.scene
        try:
            strokes = read_strokes(path)
            scene.start_engine()
            plane = float(scene.pipeline.scalp_centre[0])
            samples = [s for stroke in strokes for s in stroke.pipeline_samples(plane)]
            before = scene.snapshot()
            scene.apply_samples(samples)
        except HairtoolError as e:
            w.show_error("Cannot replay strokes", str(e))
            return False
        scene.end_stroke(before, "Replayed strokes")
        w.remember_dir(path)
        w.statusBar().showMessage(f"replayed {len(strokes)} strokes ({len(samples)} moves) from {path}", 5000)
        return True
