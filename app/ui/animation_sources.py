"""Making animations in the studio: the anime dock's "Apply to groom" and Animation → Simulate….

Both hand their result to the animation model with ``window.animation.load_animation``. The
cycle is posed at once (numba, milliseconds for thousands of strands); the simulation runs as a
job in ``window.jobs`` with per-frame progress, and a cancel leaves the previous animation.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from PySide6.QtCore import QObject, Qt

from app.ui.anime_dock import SOURCE as ANIME_SOURCE
from app.ui.anime_dock import AnimeDock
from app.ui.jobs import Job
from app.ui.simulate_dialog import SOURCE as SIMULATE_SOURCE
from hairtool.anime.settings import AnimeSettings, cycle_for_groom
from hairtool.errors import HairtoolError
from hairtool.simulate.options import SimulateOptions, run_simulation

if TYPE_CHECKING:
    from app.ui.host import StudioHost


class AnimationSources(QObject):
    """Owned by the window (``window.sources``): the anime dock and the simulation job."""

    def __init__(self, window: StudioHost) -> None:
        super().__init__(window)
        self.window = window
        self.simulate_options = SimulateOptions()
        self.simulation: Job | None = None
        self.dock = AnimeDock(window)
        window.addDockWidget(Qt.DockWidgetArea.RightDockWidgetArea, self.dock)
        window.tabifyDockWidget(window.dock, self.dock)
        window.dock.raise_()
        self.dock.apply_requested.connect(self.apply_anime)
        window.animation.frame_changed.connect(self._follow_frame)
        window.animation.animation_changed.connect(self._follow_frame)

    # -- anime -------------------------------------------------------------------------------
    def selected_strands(self) -> np.ndarray | None:
        """The scene's strand selection, if the studio has one (None: every strand)."""
        sel = getattr(self.window.scene, "selection", None)
        if sel is None:
            return None
        ids = np.asarray(sel, dtype=np.int64).reshape(-1)
        return ids if ids.size else None

    def apply_anime(self, settings: AnimeSettings | None = None) -> bool:
        """The cycle on the edited groom (or the selected strands) into the timeline."""
        s = self.dock.settings() if settings is None else settings
        character = getattr(self.window, "character", None)
        if character is not None and character.doc is not None:  # the cycle on its hair chains
            return character.apply(s)
        if not self.may_replace():
            return False
        try:
            anim = cycle_for_groom(self.window.scene.result, s, self.selected_strands())
        except HairtoolError as e:
            self.window.show_error("Cannot make the anime cycle", str(e))
            return False
        self.window.animation.load_animation(anim, ANIME_SOURCE)
        return True

    def may_replace(self) -> bool:
        """Before a new animation replaces the one on the timeline: unsaved work asks Save /
        Discard / Cancel, as Open does. True to go on."""
        if self.window.animation.animation is None:
            return True
        return self.window.project.confirm_discard()

    def _follow_frame(self, *_: object) -> None:
        model = self.window.animation
        on = model.animation is not None and model.source == ANIME_SOURCE
        self.dock.set_current_frame(model.frame if on else None)

    # -- simulation -----------------------------------------------------------------------------
    def simulate_dialog(self) -> Job | None:
        """Ask for the options and start; until the user has chosen some, the dialog opens with
        the head fitted to the groom on screen, so a real groom of any scale simulates sensibly."""
        if not self.may_replace():
            return None
        options = self.simulate_options
        if options == SimulateOptions():
            try:
                options = options.fitted_to(self.window.scene.result)
            except HairtoolError:
                pass  # keep the sample head
        options = self.window.ask_simulate_options(options)
        if options is None:
            return None
        return self.start_simulation(options)

    def start_simulation(self, options: SimulateOptions) -> Job:
        """Simulate the edited groom in a worker thread; the result goes to the timeline."""
        self.simulate_options = options
        groom = self.window.scene.result

        def work(progress, cancelled):
            return run_simulation(groom, options, progress, cancelled)

        def done(anim) -> None:
            if anim is not None:
                self.window.animation.load_animation(anim, SIMULATE_SOURCE)

        self.simulation = self.window.jobs.run(
            f"Simulating {options.frames} frames", work, done, group="simulate"
        )
        return self.simulation

    # -- project settings -------------------------------------------------------------------------
    def to_settings(self) -> dict:
        return {"anime": self.dock.settings().to_dict(), "simulate": self.simulate_options.to_dict()}

    def apply_settings(self, settings: dict) -> None:
        """Restore the dock and dialog values saved in a project (bad ones are reported)."""
        problems = []
        if "anime" in settings:
            try:
                self.dock.set_settings(AnimeSettings.from_dict(settings["anime"]))
            except (HairtoolError, TypeError, ValueError) as e:
                problems.append(f"anime: {e}")
        if "simulate" in settings:
            try:
                upm = self.window.scene.result.metadata.units_per_meter
                self.simulate_options = SimulateOptions.from_dict(settings["simulate"], upm)
            except (HairtoolError, TypeError, ValueError) as e:
                problems.append(f"simulate: {e}")
        if problems:
            self.window.show_error("Some project settings were not applied", "\n".join(problems))
