"""The studio's model: the rest groom, the frozen-hair pipeline over it, and the display settings.

The scene knows nothing of widgets. Setters emit a signal only when the value really changes, so
a widget that writes a value and listens for it cannot loop; the viewport and the dock listen.

On a first start the engine's kernels compile in another process (:mod:`app.ui.engine_start`):
until :meth:`Scene.start_engine`, a scene made with ``engine_ready=False`` shows its groom as it
is, keeps parameter edits for later, and has no pipeline (``pipeline`` None, no strokes).
"""

from __future__ import annotations

import dataclasses
import time
from pathlib import Path

import numpy as np
from PySide6.QtCore import QObject, Signal

from app.render.ramps import DEFAULT_RAMP
from hairtool.errors import ParameterError
from hairtool.frozen.pipeline import FrozenParams, FrozenPipeline
from hairtool.groom import Groom

ALIGN_MODES = ("paper", "preserve-length")
COLOUR_MODES = {
    "root-to-tip": "Root to tip",
    "strand": "Per-strand random",
    "clump": "Clump membership",
    "displacement": "Displacement from rest",
}


class Scene(QObject):
    """One groom being edited: rest strands, pipeline, brush settings and display settings."""

    groom_loaded = Signal()  # new strands: topology may have changed, re-upload everything
    points_changed = Signal()  # same strands at new positions: re-upload positions only
    params_changed = Signal(object)  # FrozenParams
    tool_changed = Signal()  # brush radius, intensity or align mode
    display_changed = Signal()  # colour mode, ramp or line width
    mesh_changed = Signal()
    path_changed = Signal()
    engine_starting = Signal()  # the pipeline is about to be built (may compile: show a wait)
    engine_started = Signal()

    def __init__(
        self,
        groom: Groom,
        params: FrozenParams | None = None,
        parent: QObject | None = None,
        *,
        engine_ready: bool = True,
    ):
        super().__init__(parent)
        self.engine_ready = engine_ready
        self._params = params if params is not None else FrozenParams()
        self.colour_mode = "root-to-tip"
        self.ramp = DEFAULT_RAMP
        self.line_width = 2.0
        self.mesh = None
        self.path: Path | None = None
        self.radius = 1.0
        self.intensity = 0.8
        self.align_mode = "paper"
        self.last_update_ms = 0.0
        self._set_groom(groom)

    # -- strands -----------------------------------------------------------------------
    def _set_groom(self, groom: Groom) -> None:
        if self.engine_ready:
            self.pipeline: FrozenPipeline | None = FrozenPipeline(groom, self._params)
            self.result: Groom = self.pipeline.result
        else:
            self._params.validate()
            self.pipeline, self.result = None, groom
        self.rest = groom
        lo, hi = groom.bounds
        self.centre = ((lo.astype(np.float64) + hi) * 0.5).astype(np.float32)
        extent = float(np.max(hi - lo))
        self.radius = 0.25 * extent if extent > 0 else 1.0

    def load(self, groom: Groom, path: str | Path | None = None, params: FrozenParams | None = None) -> None:
        """Replace the groom being edited (strokes are dropped; the parameters stay unless
        ``params`` gives new ones, e.g. a project's, which may only fit the new strands)."""
        old_params = self._params
        if params is not None:
            self._params = params
        try:
            self._set_groom(groom)
        except BaseException:
            self._params = old_params
            raise
        self.path = None if path is None else Path(path)
        self.groom_loaded.emit()
        self.tool_changed.emit()
        self.path_changed.emit()
        if params is not None and params != old_params:
            self.params_changed.emit(params)

    def set_path(self, path: str | Path | None) -> None:
        p = None if path is None else Path(path)
        if p != self.path:
            self.path = p
            self.path_changed.emit()

    def start_engine(self) -> None:
        """Build the pipeline of a scene made with ``engine_ready=False`` (nothing when ready):
        the groom takes the frozen look with the parameters edited meanwhile."""
        if self.engine_ready:
            return
        self.engine_starting.emit()
        t0 = time.perf_counter()
        self.pipeline = FrozenPipeline(self.rest, self._params)
        self.result = self.pipeline.result
        self.engine_ready = True
        self.last_update_ms = (time.perf_counter() - t0) * 1e3
        self.params_changed.emit(self._params)
        self.points_changed.emit()
        self.engine_started.emit()

    @property
    def is_planar(self) -> bool:
        return self.rest.is_planar

    def align(self, cursor: np.ndarray) -> Groom:
        """One mouse move of the align tool: align → freeze → clump, timed in ms."""
        self.start_engine()
        t0 = time.perf_counter()
        self.result = self.pipeline.align(
            np.asarray(cursor, dtype=np.float64), self.radius, self.intensity, self.align_mode
        )
        self.last_update_ms = (time.perf_counter() - t0) * 1e3
        self.points_changed.emit()
        return self.result

    def snapshot(self) -> object:
        """The pipeline's stroke state (for one undo step); strokes need the engine running."""
        self.start_engine()
        return self.pipeline.snapshot()

    def restore(self, snap: object) -> None:
        self.start_engine()
        t0 = time.perf_counter()
        self.result = self.pipeline.restore(snap)
        self.last_update_ms = (time.perf_counter() - t0) * 1e3
        self.points_changed.emit()

    # -- engine parameters ---------------------------------------------------------------
    @property
    def params(self) -> FrozenParams:
        return self._params

    def set_params(self, params: FrozenParams) -> None:
        if params == self._params:
            return
        if not self.engine_ready:  # kept for the engine when it starts
            self._params = params.validate()
            self.params_changed.emit(params)
            return
        t0 = time.perf_counter()
        self.result = self.pipeline.set_params(params)
        self.last_update_ms = (time.perf_counter() - t0) * 1e3
        self._params = params
        self.params_changed.emit(params)
        self.points_changed.emit()

    def with_param(self, name: str, value: object) -> FrozenParams:
        """The current parameters with one field changed; ParameterError names a bad value."""
        return dataclasses.replace(self._params, **{name: value}).validate()

    # -- brush ---------------------------------------------------------------------------
    def set_radius(self, radius: float) -> None:
        if not np.isfinite(radius) or radius <= 0:
            raise ParameterError("radius", radius, "a positive number")
        if radius != self.radius:
            self.radius = float(radius)
            self.tool_changed.emit()

    def set_intensity(self, intensity: float) -> None:
        if not np.isfinite(intensity) or not 0.0 <= intensity <= 1.0:
            raise ParameterError("intensity", intensity, "a number in [0, 1]")
        if intensity != self.intensity:
            self.intensity = float(intensity)
            self.tool_changed.emit()

    def set_align_mode(self, mode: str) -> None:
        if mode not in ALIGN_MODES:
            raise ParameterError("mode", mode, f"one of {', '.join(ALIGN_MODES)}")
        if mode != self.align_mode:
            self.align_mode = mode
            self.tool_changed.emit()

    # -- display -------------------------------------------------------------------------
    def set_colour_mode(self, mode: str) -> None:
        if mode not in COLOUR_MODES:
            raise ParameterError("colour mode", mode, f"one of {', '.join(COLOUR_MODES)}")
        if mode != self.colour_mode:
            self.colour_mode = mode
            self.display_changed.emit()

    def set_ramp(self, name: str) -> None:
        if name != self.ramp:
            self.ramp = name
            self.display_changed.emit()

    def set_line_width(self, width: float) -> None:
        if not np.isfinite(width) or not 0.1 <= width <= 20.0:
            raise ParameterError("line width", width, "a number of pixels in [0.1, 20]")
        if width != self.line_width:
            self.line_width = float(width)
            self.display_changed.emit()

    def set_mesh(self, mesh: object | None) -> None:
        self.mesh = mesh
        self.mesh_changed.emit()

    def displacement(self) -> np.ndarray:
        """``(V,)`` float64 distance of each vertex from its rest position (scene units)."""
        d = self.result.points.astype(np.float64) - self.rest.points
        return np.sqrt(np.einsum("ij,ij->i", d, d))
