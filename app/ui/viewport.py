"""The GL viewport: moderngl in a native GL window (:mod:`app.ui.gl_surface`), camera navigation
and the brushes.

Navigation follows Blender/Maya: middle-drag or Alt+left-drag orbits (pans in 2-D), Shift with
either pans, the wheel zooms, Ctrl+wheel resizes the brush. A plain left-drag is the current
brush (Ctrl+left-drag inverts it, as in Blender: shrink for grow, erase for paint; with the Select
brush a plain drag starts a new selection and Shift+left-drag adds to it instead of panning): the cursor is
unprojected onto a plane facing the camera, through the hair under the mouse at the press (the
vertex nearest to it on screen within the brush circle, of a front-facing strand with "front
faces only"; the groom's centre when the circle holds none), so that a brush reaches the hair the
artist sees in a 3-D view, not the middle of the head; the mouse's motion
between two moves on that plane is the brush's direction (comb), the camera's ray through the
cursor its view (front faces only), and every move runs the frozen-hair pipeline, in the
engine's worker thread (:mod:`app.ui.engine_thread`). The view is told what changed by the
scene's signals and uploads it at the next paint (positions only while dragging); a paint for
the overlays alone (the circle, the sizing ring, the box) copies the last image instead of
drawing the strands again (:mod:`app.render.last_image`), so the cursor keeps the input's rate.

A pen (tablet events) does what the mouse does, with its pressure (:attr:`Viewport.pressure`,
1 for a mouse) given to the brush. F / Shift+F (:attr:`Viewport.sizing`,
:mod:`app.ui.brush_sizing`) size the brush or its strength with the mouse until a click or Enter
keeps the value, Esc or a right click cancels.

Box select (:meth:`Viewport.arm_box`, the B key): the next left-drag draws a rectangle and its
release emits the selection step (:attr:`Viewport.box_finished`): the strands with a point
inside it are added to the selection, or with Ctrl held taken from it; Esc or a right-click
cancels.

With an animation loaded the window shows one of its frames instead of the scene's groom
(:meth:`Viewport.show_frame`: positions, optional per-vertex colours and a ghost, all for the
groom's strands), and a ``brush_target`` may take over the left-drag (editing a key pose).
"""

from __future__ import annotations

import contextlib
import time
from collections.abc import Iterator
from typing import Protocol

import moderngl
import numpy as np
from PySide6.QtCore import QCoreApplication, QEvent, QEventLoop, QPointF, Qt, Signal
from PySide6.QtGui import QImage, QKeyEvent, QMouseEvent, QPainter, QTabletEvent, QWheelEvent
from PySide6.QtWidgets import QWidget

from app.render.camera import Camera
from app.render.drawn import Drawn
from app.render.last_image import LastImage
from app.render.offscreen import Overlays
from app.render.painted_layer import PaintedLayer
from app.render.screen_pick import nearest_in_sight, nearest_on_screen
from app.render.strands import StrandRenderer, default_strand_raster
from app.ui.brush_sizing import CanvasSizing, pen_pressure
from app.ui.drawn import drawn
from app.ui.gl_surface import GLSurface, hold_surface
from app.ui.scene import Scene
from hairtool import sorted_ids
from hairtool.frozen.brushes import NEED_SURFACE, facing_away
from hairtool.frozen.brushes.sight import hidden_points
from hairtool.frozen.sample_schema import SELECTION
from hairtool.frozen.selection import SelectionSample

BRUSH_STEP = 1.1  # radius factor per wheel notch or [ / ] press
# The reconstruction behind the original: one flat cyan no ramp uses, opaque enough to read on the
# dark background wherever it parts from the original (where they agree, the original covers it).
GHOST_RGBA = (0.2, 0.9, 1.0, 0.75)


class BrushTarget(Protocol):
    """Takes over the align drag (e.g. editing an animation's key pose instead of the groom).

    A target may also pick in screen space: ``press(pos, modifiers) -> bool`` is asked first on
    a left press (True takes the drag, Alt included), then ``drag(pos)`` on each move."""

    def begin(self, cursor: np.ndarray) -> bool:
        """A left press at ``cursor`` (on the interaction plane); False leaves the drag unused."""

    def move(self, cursor: np.ndarray) -> None: ...

    def end(self) -> None: ...


class Viewport(QWidget):
    """Draws the scene's current groom; emits a finished stroke as the document's groom states
    (before, after) once it is a step."""

    stroke_finished = Signal(object, object)
    stroke_started = Signal()  # a left-drag on the scene's groom begins (before its first align)
    cursor_moved = Signal(object)  # (3,) float array on the interaction plane, or None
    frame_drawn = Signal()
    engine_wait = Signal()  # a stroke began before the engine is ready: nothing was done
    box_finished = Signal(object)  # a box select's SelectionSample, when its drag ends

    def __init__(self, scene: Scene, parent=None) -> None:
        super().__init__(parent)
        self.scene = scene
        self.surface = GLSurface(self)  # draws; this widget takes the input (see gl_surface)
        hold_surface(self, self.surface)
        self.camera = self._fresh_camera()
        self.ctx: moderngl.Context | None = None
        self.renderer: StrandRenderer | None = None
        # a first start draws GL's lines until the CPU rasterizer's kernels are cached: when the
        # engine starts, or when a running warm-up says so (``wait_for_raster``; set_raster_ready)
        self.raster_ready = scene.engine_ready
        self.wait_for_raster = False
        self.finish_frames = False  # glFinish after upload and draw, so timings are real (benchmark)
        # Samples per pixel of Qt's framebuffer: the requested format's (format() reports the
        # context's, 0, once GL is up), since moderngl cannot tell for a framebuffer it did not make.
        self.samples = max(self.surface.format().samples(), 0)
        self.last_upload_ms = 0.0
        self.last_draw_ms = 0.0
        self._dirty = {"groom", "colors", "display", "mesh"}
        self._moved: np.ndarray | None = None  # with "points" dirty: the only strands moved (None: any)
        self.last_image: LastImage | None = None  # the scene drawn last, without its overlays
        # painted with QPainter over the view at each paint (the joint handles): ``shown()`` and
        # ``paint(painter)``; the GL window would cover a widget placed over it
        self.painted_over: list = []
        self.painted_layer: PaintedLayer | None = None
        self._scene_stale = True  # something other than an overlay changed since the last paint
        self.scene_draws = 0  # paints that drew the scene (the others copied the last image)
        self._drag: str | None = None  # "align" | "orbit" | "pan" while a button is held
        self._drag_button = Qt.MouseButton.NoButton
        self._last_pos = QPointF()
        self._stroke_before: object | None = None
        self._stroke_cursor: np.ndarray | None = None  # the last move's cursor (for the direction)
        self._stroke_depth: np.ndarray | None = None  # the stroke's cursor plane passes through it
        self._stroke_invert = False  # Ctrl held at the press
        self._stroke_add = False  # Shift held at the press (select adds to the selection)
        self.stroke_touched = False  # the brush reached a strand during the current / last stroke
        self._hover: QPointF | None = None
        self._auto_frame = True  # follow the widget's size with frame-all until the user navigates
        # an animation frame shown instead of the scene's groom (see show_frame)
        self.frame_points: np.ndarray | None = None
        self.frame_colors: np.ndarray | None = None
        self.ghost_points: np.ndarray | None = None
        self.frame_children: np.ndarray | None = None  # its drawn children, built off the GUI thread
        self.shown_frame: int | None = None  # the frame number uploaded at the last paint
        self._pending_frame: int | None = None
        self.brush_target: BrushTarget | None = None
        self._drag_target: BrushTarget | None = None  # the target that took the current drag
        self.box_armed = False  # the next left-drag is a box select (B)
        self._box: list[QPointF] | None = None  # its corners while it drags
        self._box_mode = "add"
        self.pressure = 1.0  # the pen's at the last event (a mouse's: 1), for the brush
        self._pen_down = False  # a pen touches: the mouse events a platform makes of it are dropped
        self.sizing = CanvasSizing(self)  # F / Shift+F: the brush sized on the canvas
        scene.groom_loaded.connect(self.sizing.cancel)
        self.setMouseTracking(True)
        self.setTabletTracking(True)  # a pen hovering moves the circle, as the mouse does
        self.setFocusPolicy(Qt.FocusPolicy.StrongFocus)
        self.setMinimumSize(200, 150)
        scene.groom_loaded.connect(self._on_groom_loaded)
        scene.points_changed.connect(self._on_points_changed)
        scene.params_changed.connect(lambda _p: self._mark("colors"))
        scene.display_changed.connect(lambda: self._mark("display", "colors"))
        scene.mesh_changed.connect(lambda: self._mark("mesh"))
        scene.drawn_changed.connect(lambda: self._mark("groom", "colors"))
        scene.tool_changed.connect(self.update_overlays)  # the brush's circle, the symmetry plane
        scene.mask_changed.connect(lambda: self._mark("colors"))
        scene.selection_changed.connect(self._on_selection_changed)
        scene.engine_started.connect(self._on_engine_started)
        scene.up_axis_changed.connect(self._on_up_axis_changed)

    # -- scene → view ----------------------------------------------------------------------
    def update(self, *args) -> None:
        """Repaint, drawing the scene again (QWidget.update's arguments: the whole view is drawn)."""
        self._scene_stale = True
        self.surface.update()

    def update_overlays(self) -> None:
        """Repaint the overlays only (the circle, the sizing ring, the box): over the last image,
        at the input's rate, unless something else asked for the scene meanwhile."""
        self.surface.update()

    def _mark(self, *what: str) -> None:
        if "points" in what:
            self._moved = None
        self._dirty.update(what)
        self.update()

    def _aspect(self) -> float:
        return max(self.width(), 1) / max(self.height(), 1)

    def _fresh_camera(self) -> Camera:
        """Front orthographic view for planar grooms (2-D), a three-quarter perspective otherwise."""
        lo, hi = self.scene.result.bounds
        s = self.scene
        return Camera.for_bounds(lo, hi, ortho=s.is_planar, aspect=self._aspect(), up_axis=s.up_axis)

    def _on_up_axis_changed(self) -> None:
        """The document's up axis changed: the same kind of view, with that axis up, framed."""
        ortho = self.camera.ortho
        self.camera = Camera.for_bounds(
            *self.scene.result.bounds, ortho=ortho, aspect=self._aspect(), up_axis=self.scene.up_axis
        )
        self.frame_all()

    def _on_selection_changed(self, hidden: bool) -> None:
        """Unselected strands dim; hidden ones leave the drawn strands (a new upload)."""
        if hidden:
            self._mark("groom", "colors")
        else:
            self._mark("colors")

    def _on_groom_loaded(self) -> None:
        self.camera = self._fresh_camera()
        self.frame_all()  # the groom and its own head (set with it)
        self._mark("groom", "colors")

    def _on_points_changed(self) -> None:
        if self.frame_points is not None:
            return  # an animation frame is on screen; the groom's edits show when it goes
        known = self.scene.moved
        if known is None:
            self._moved = None
        elif "points" not in self._dirty:
            self._moved = known
        elif self._moved is not None:
            self._moved = sorted_ids.union(self._moved, known)
        self._dirty.add("points")
        if self.scene.colour_mode in ("displacement", "clump"):
            self._dirty.add("colors")
        self.update()

    def show_frame(
        self,
        points: np.ndarray,
        colors: np.ndarray | None = None,
        ghost: np.ndarray | None = None,
        frame: int | None = None,
        children: np.ndarray | None = None,
    ) -> None:
        """Draw ``points`` ``(V, 3)`` (the groom's strands) instead of the scene's groom, with
        optional per-vertex ``colors`` (None: the scene's colouring) and a ``ghost`` drawn under
        them; uploaded at the next paint, so calls faster than the screen refreshes cost nothing.
        ``children``: with render hair, the drawn points already built for ``points``
        (:mod:`app.ui.frame_children`), drawn while they fit the drawn strands."""
        had_colors, had_ghost = self.frame_colors is not None, self.ghost_points is not None
        self.frame_points, self.frame_colors, self.ghost_points = points, colors, ghost
        self.frame_children = children
        self._pending_frame = frame
        self._dirty.add("points")
        self._moved = None
        if colors is not None or had_colors:
            self._dirty.add("colors")
        if ghost is not None or had_ghost:
            self._dirty.add("ghost")
        self.update()

    def clear_frame(self) -> None:
        """Back to drawing the scene's groom."""
        if self.frame_points is None and self.ghost_points is None:
            return
        self.frame_points = self.frame_colors = self.ghost_points = self.frame_children = None
        self._pending_frame = None
        self._mark("points", "colors", "ghost")

    def frame_all(self) -> None:
        """Fit the groom (and the head mesh) in view; planar grooms get the 2-D orthographic camera."""
        lo, hi = self.scene.result.bounds
        if self.scene.mesh is not None:
            v = np.asarray(self.scene.mesh.vertices, dtype=np.float32)
            if v.size:
                lo, hi = np.minimum(lo, v.min(axis=0)), np.maximum(hi, v.max(axis=0))
        self.camera.frame(lo, hi, aspect=self._aspect())
        self._auto_frame = True
        self.update()

    def set_camera(self, camera: Camera) -> None:
        """Look through ``camera`` (a project's saved view): kept as it is, not framed again."""
        self.camera = camera
        self._auto_frame = False
        self.update()

    def set_ortho(self, on: bool) -> None:
        """2-D (orthographic, front view) or 3-D (perspective) view, framed again."""
        if self.camera.ortho != on:
            if on:
                self.camera.ortho = True
            else:
                lo, hi = self.scene.result.bounds
                self.camera = Camera.for_bounds(lo, hi, aspect=self._aspect(), up_axis=self.scene.up_axis)
            self.frame_all()

    # -- GL ----------------------------------------------------------------------------------
    def initializeGL(self) -> None:
        self.ctx = moderngl.create_context()
        self.renderer = StrandRenderer(self.ctx)
        self.last_image = LastImage(self.ctx)
        self.painted_layer = PaintedLayer(self.ctx)
        if not self.raster_ready:  # the CPU rasterizer's kernels are still compiling
            self.renderer.strand_raster = "gl"
        self._dirty = {"groom", "colors", "display", "mesh"}

    def set_raster_ready(self) -> None:
        """The CPU strand rasterizer's kernels are cached now (a first start's warm-up said so, or
        it ended): draw strands as the renderer chooses again, instead of GL's lines."""
        self.raster_ready = True
        if self.renderer is not None:
            self.renderer.strand_raster = default_strand_raster()
        self.update()

    def _on_engine_started(self) -> None:
        if not self.wait_for_raster:  # no warm-up to wait for: the engine's start compiled what it needs
            self.set_raster_ready()
        self._mark("groom", "colors", "display")

    def drawn(self, mask: bool = True) -> Drawn:
        """What this view draws now: the scene's groom, or the animation frame it shows (with the
        render hair following it), as stills and videos draw it too (``mask``: the mask's tint)."""
        children = self.frame_children
        return drawn(self.scene, self.frame_points, self.frame_colors, mask=mask, children=children)

    def _upload(self) -> None:
        r, s, dirty = self.renderer, self.scene, self._dirty
        shown = self.frame_points is not None and len(self.frame_points) == s.result.vertex_count
        children = s.has_children  # frames and ghosts are of the guides: their children are drawn
        d = self.drawn() if dirty & {"groom", "points", "display", "colors"} else None
        if "groom" in dirty:  # render hair: its points as they are, no groom made of millions of them
            r.set_strands(d.points, d.topology)
            dirty.discard("points")
            dirty.update(("ghost",) if shown or self.ghost_points is not None else ())
        if "points" in dirty:
            # the engine's region, where the drawn strands are the groom's own
            mine = self._moved is not None and d.topology.strand_count == s.result.strand_count
            r.update_points(d.points, self._moved if mine else None)
        if "groom" in dirty or "points" in dirty:
            self.shown_frame = self._pending_frame if shown else None
        if "display" in dirty:
            r.set_look(d)
        if "colors" in dirty:
            r.set_vertex_colors(d.colors)
        if "ghost" in dirty:
            if shown and self.ghost_points is not None:
                ghost = s.drawn_for(self.ghost_points) if children else self.ghost_points
                r.set_ghost_points(ghost, GHOST_RGBA)
            else:
                r.set_ghost_points(None)
        if "mesh" in dirty:
            r.set_mesh(s.mesh)
        dirty.clear()

    def mirror_outline(self, w: float, h: float) -> np.ndarray | None:
        """``(4, 2)`` pixels (of a ``w`` × ``h`` view) of the X-symmetry plane's rectangle across
        the groom's box, or None (symmetry off, or a corner behind the camera)."""
        s = self.scene
        if not s.tool.symmetry:
            return None
        lo, hi = s.result.bounds
        pad = 0.05 * float(np.max(hi - lo))
        y0, y1, z0, z1 = lo[1] - pad, hi[1] + pad, lo[2] - pad, hi[2] + pad
        x = s.mirror_plane_x()
        corners = np.array([[x, y0, z0], [x, y1, z0], [x, y1, z1], [x, y0, z1]], np.float64)
        if not self.camera.ortho and np.any(self.camera.depth(corners) <= 1e-6):
            return None
        return self.camera.project(corners, w, h)

    def overlays(self, size: tuple[int, int]) -> Overlays:
        """The working overlays shown now (brush circle, symmetry plane) for an image of ``size``
        pixels of this view's camera (a still or video that includes them)."""
        w, h = size
        circle = None
        if self._hover is not None and self._drag in (None, "align") and self.width() > 0:
            depth = self._stroke_depth if self._stroke_depth is not None and self._drag else self.scene.centre
            cursor = self.cursor_on_plane(self._hover, depth)
            centre = self.camera.project(cursor, w, h)[0]
            radius_px = self.scene.radius * self.camera.pixels_per_unit_at(depth, h)
            circle = ((float(centre[0]), float(centre[1])), radius_px)
        return Overlays(circle, self.mirror_outline(w, h))

    def _overlay(self, w: int, h: int) -> None:
        box = self.box_outline(self.devicePixelRatioF())
        self.renderer.set_overlay_outline(self.mirror_outline(w, h) if box is None else box, (w, h))
        dpr = self.devicePixelRatioF()
        if self.sizing.active:  # the circle being sized, round its centre
            c, r = self.sizing.centre, self.sizing.circle_px()
            self.renderer.set_overlay_circle((c.x() * dpr, c.y() * dpr), r * dpr, (w, h))
            return
        if self._hover is None or self._drag not in (None, "align") or self.box_armed:
            self.renderer.set_overlay_circle(None, 0.0, (w, h))
            return
        depth = self.scene.centre if self._stroke_depth is None or self._drag is None else self._stroke_depth
        radius = self.scene.tool.radius_at(self.pressure if self._drag else 1.0)  # a pen's, while it presses
        radius_px = radius * self.camera.pixels_per_unit_at(depth, h)
        centre = (self._hover.x() * dpr, self._hover.y() * dpr)
        self.renderer.set_overlay_circle(centre, radius_px, (w, h))

    def resizeGL(self, w: int, h: int) -> None:
        if self._auto_frame and w > 1 and h > 1:
            self.frame_all()

    def paintGL(self) -> None:
        if self.renderer is None:
            return
        t0 = time.perf_counter()
        dpr = self.devicePixelRatioF()
        w, h = max(1, round(self.width() * dpr)), max(1, round(self.height() * dpr))
        cam = self.camera
        key = (w, h, cam.view_matrix().tobytes(), cam.projection_matrix(w / h).tobytes())
        redraw = self._scene_stale or bool(self._dirty) or not self.last_image.holds(key)
        self._scene_stale = False
        if redraw:
            self._upload()
        if self.finish_frames:
            self.ctx.finish()
        t1 = time.perf_counter()
        self._overlay(w, h)
        # Qt's framebuffer id changes on every resize: look it up each time, never draw to 0.
        fbo = self.ctx.detect_framebuffer(self.defaultFramebufferObject())
        if redraw:
            self.renderer.render(fbo, cam, (w, h), samples=self.samples, overlays=False)
            self.last_image.keep(fbo, (w, h), self.samples, key)
            self.scene_draws += 1
        else:
            self.last_image.put(fbo)
        self.renderer.render_overlays(fbo, (w, h))
        self._paint_over(fbo, (w, h))
        if self.finish_frames:
            self.ctx.finish()
        t2 = time.perf_counter()
        self.last_upload_ms = (t1 - t0) * 1e3
        self.last_draw_ms = (t2 - t1) * 1e3
        self.frame_drawn.emit()

    def _paint_over(self, fbo: moderngl.Framebuffer, size: tuple[int, int]) -> None:
        """What the painters show, painted into an image of the frame's ``size`` and drawn over it."""
        shown = [p for p in self.painted_over if p.shown()]
        if not shown:
            return
        w, h = size
        image = QImage(w, h, QImage.Format.Format_RGBA8888_Premultiplied)
        image.fill(0)
        image.setDevicePixelRatio(self.devicePixelRatioF())
        painter = QPainter(image)
        for p in shown:
            p.paint(painter)
        painter.end()
        line = image.bytesPerLine()
        rgba = np.frombuffer(image.constBits(), np.uint8, count=line * h).reshape(h, line)[:, : w * 4]
        self.painted_layer.draw(fbo, rgba.reshape(h, w, 4))

    def makeCurrent(self) -> None:
        """The surface's GL context current, its framebuffer bound (as QOpenGLWidget's)."""
        self.surface.makeCurrent()

    def doneCurrent(self) -> None:
        self.surface.doneCurrent()

    def defaultFramebufferObject(self) -> int:
        return self.surface.defaultFramebufferObject()

    def gl_ready(self) -> bool:
        """Whether GL is up. Qt starts it at the surface's first paint, once the window system
        shows it, a moment after the window: a view shown but not yet painted waits for that
        (a second at most), as a GL widget would start its GL on demand."""
        if self.renderer is None and self.isVisible():
            deadline = time.perf_counter() + 1.0
            while self.renderer is None and time.perf_counter() < deadline:
                QCoreApplication.processEvents(QEventLoop.ProcessEventsFlag.ExcludeUserInputEvents, 10)
        return self.renderer is not None

    def grabFramebuffer(self) -> QImage:
        """The view drawn now, as an image (as QOpenGLWidget's: painted afresh, then read; a
        multisampled framebuffer resolved first, since GL reads none)."""
        if not self.gl_ready():
            return QImage()
        self.makeCurrent()
        try:
            self.paintGL()
            fbo = self.ctx.detect_framebuffer(self.defaultFramebufferObject())
            w, h = fbo.size
            if self.samples > 0:
                plain = self.ctx.simple_framebuffer((w, h))
                self.ctx.copy_framebuffer(plain, fbo)
                data = plain.read(components=4)
                plain.release()
            else:
                data = fbo.read(components=4)
        finally:
            self.doneCurrent()
        # GL's rows run bottom-up; flipped() makes the image its own copy of the bytes
        return QImage(data, w, h, 4 * w, QImage.Format.Format_RGBA8888).flipped(Qt.Orientation.Vertical)

    def draw_now(self) -> None:
        """Paint synchronously into the widget's framebuffer (Qt's own repaint may be deferred),
        so a benchmark's frame is complete when this returns (with ``finish_frames`` set)."""
        self.makeCurrent()
        self.paintGL()
        self.doneCurrent()

    @contextlib.contextmanager
    def current_context(self) -> Iterator[moderngl.Context | None]:
        """This widget's context made current (None before the first paint), for offscreen draws:
        the studio keeps to one GL context, since a second (EGL) one beside Qt's is unreliable."""
        if not self.gl_ready():
            yield None
            return
        self.makeCurrent()
        try:
            yield self.ctx
        finally:
            self.doneCurrent()

    def release_gl(self) -> None:
        """Free the GL objects while the context still exists (called when the window closes)."""
        if self.renderer is not None and self.ctx is not None:
            self.makeCurrent()
            self.renderer.release()
            self.renderer = None
            self.last_image.release()
            self.painted_layer.release()
            self.doneCurrent()

    # -- box select ----------------------------------------------------------------------------
    def arm_box(self, on: bool = True) -> None:
        """The next left-drag draws a box select (off: cancelled)."""
        self.box_armed = bool(on)
        if not on and self._drag == "box":
            self._drag, self._box = None, None
        if on:
            self.setCursor(Qt.CursorShape.CrossCursor)
        else:
            self.unsetCursor()
        self.update()

    def box_outline(self, scale: float = 1.0) -> np.ndarray | None:
        """``(4, 2)`` pixels (times ``scale``) of the box being dragged, or None."""
        if self._box is None:
            return None
        a, b = self._box
        x0, y0, x1, y1 = a.x() * scale, a.y() * scale, b.x() * scale, b.y() * scale
        return np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]], np.float64)

    def box_sample(self, a: QPointF, b: QPointF, mode: str = "add") -> SelectionSample:
        """The selection step of a box from ``a`` to ``b`` (widget pixels) in this view."""
        w, h = max(self.width(), 1), max(self.height(), 1)
        cam = self.camera
        vp = cam.view_matrix().astype(np.float64) @ cam.projection_matrix(w / h).astype(np.float64)
        rect = (2.0 * a.x() / w - 1.0, 1.0 - 2.0 * a.y() / h, 2.0 * b.x() / w - 1.0, 1.0 - 2.0 * b.y() / h)
        view = tuple(float(v) for v in cam.forward()) if self.scene.tool.front_only else None
        # by sight under perspective, each point's ray goes to the eye (a wide box's corners
        # are seen along their own lines of sight)
        to_eye = view is not None and not cam.ortho
        return SELECTION.make(
            op="box", matrix=tuple(vp.T.ravel().tolist()), rect=rect, mode=mode, view=view, to_eye=to_eye
        )

    def keyPressEvent(self, event: QKeyEvent) -> None:
        if self.sizing.active and self.sizing.key_press(event):
            event.accept()
            return
        if event.key() == Qt.Key.Key_Escape and self.box_armed:
            self.arm_box(False)
            event.accept()
            return
        super().keyPressEvent(event)

    # -- picking -------------------------------------------------------------------------------
    def cursor_on_plane(self, pos: QPointF, through: np.ndarray | None = None) -> np.ndarray:
        """The 3-D point under ``pos`` (widget pixels) on the plane facing the camera through
        ``through`` (default: the groom's centre)."""
        q = self.scene.centre if through is None else through
        return np.asarray(
            self.camera.unproject_to_plane(pos.x(), pos.y(), self.width(), self.height(), q), dtype=np.float64
        )

    def project(self, points: np.ndarray) -> np.ndarray:
        """``(n, 2)`` widget pixel positions of 3-D points (tests check pixels there)."""
        return np.asarray(self.camera.project(np.asarray(points), self.width(), self.height()))

    # -- input -----------------------------------------------------------------------------------
    def _navigation(self, event: QMouseEvent) -> str | None:
        button, mods = event.button(), event.modifiers()
        shift = bool(mods & Qt.KeyboardModifier.ShiftModifier)
        alt = bool(mods & Qt.KeyboardModifier.AltModifier)
        if button == Qt.MouseButton.MiddleButton or (button == Qt.MouseButton.LeftButton and alt):
            return "pan" if shift or self.camera.ortho else "orbit"
        if button == Qt.MouseButton.LeftButton and shift and not self._shift_adds():
            return "pan"
        if button == Qt.MouseButton.LeftButton:
            return "align"
        return None

    def _shift_adds(self) -> bool:
        """Shift+left-drag is the brush's "add" (select), not a pan: no target edits a pose."""
        return self.brush_target is None and self.scene.tool.shift_adds()

    def is_dragging(self) -> bool:
        """A button is held for a stroke, a box or navigation."""
        return self._drag is not None

    def hover_pos(self) -> QPointF | None:
        """The mouse over the view (widget pixels), None while it is outside."""
        return self._hover

    def tabletEvent(self, event: QTabletEvent) -> None:
        """A pen: its press, moves and release do what the mouse's would, with its pressure
        (accepted, so Qt sends no mouse event after it)."""
        handler = {
            QEvent.Type.TabletPress: self.mousePressEvent,
            QEvent.Type.TabletMove: self.mouseMoveEvent,
            QEvent.Type.TabletRelease: self.mouseReleaseEvent,
        }.get(event.type())
        if handler is None:
            super().tabletEvent(event)
            return
        self._pen_down = event.type() != QEvent.Type.TabletRelease
        handler(event)
        event.accept()

    def _from_pen(self, event) -> bool:
        """A mouse event while a pen touches (X11 also sends the pen as the core pointer): the
        pen's own events drive the brush, with their pressure, so this one is dropped."""
        if self._pen_down and not isinstance(event, QTabletEvent):
            event.accept()
            return True
        return False

    def mousePressEvent(self, event: QMouseEvent) -> None:
        if self._from_pen(event):
            return
        self.pressure = pen_pressure(event)
        if self.sizing.active:
            self.sizing.mouse_press(event)
            event.accept()
            return
        if self._drag is not None:
            return
        if self.box_armed and event.button() == Qt.MouseButton.RightButton:
            self.arm_box(False)
            event.accept()
            return
        alt = bool(event.modifiers() & Qt.KeyboardModifier.AltModifier)
        if self.box_armed and event.button() == Qt.MouseButton.LeftButton and not alt:
            self._drag, self._drag_button = "box", event.button()
            self._box = [event.position(), event.position()]
            ctrl = bool(event.modifiers() & Qt.KeyboardModifier.ControlModifier)
            self._box_mode = "subtract" if ctrl else "add"
            event.accept()
            return
        target = self.brush_target
        if event.button() == Qt.MouseButton.LeftButton and hasattr(target, "press"):
            # a target that picks in screen space (a capture's joint handles) takes Alt there too
            if target.press(event.position(), event.modifiers()):
                self._drag, self._drag_button, self._drag_target = "align", event.button(), target
                self._last_pos = event.position()
                event.accept()
                return
        self._drag = self._navigation(event)
        self._drag_button = event.button()
        self._last_pos = event.position()
        self._drag_target = self.brush_target if self._drag == "align" else None
        if self._drag_target is not None:
            if not self._drag_target.begin(self._cursor_at(event.position())):
                self._drag, self._drag_target = None, None
            event.accept()
            return
        if self._drag == "align" and not self.scene.engine_ready:
            self._drag = None
            self.engine_wait.emit()
        elif self._drag == "align" and (why := self.scene.stroke_refusal()) is not None:
            self._drag = None
            self.scene.refused.emit(why)
        elif self._drag == "align":
            self._stroke_before = self.scene.snapshot()
            self._stroke_cursor = None
            self._stroke_depth = self.hair_under(event.position())
            self._stroke_invert = bool(event.modifiers() & Qt.KeyboardModifier.ControlModifier)
            self._stroke_add = bool(event.modifiers() & Qt.KeyboardModifier.ShiftModifier)
            self.stroke_touched = False
            self.scene.moves.begin()
            self.stroke_started.emit()
            self.scene.set_dragging(True)  # children at the drag display percentage
            self._brush_at(event.position())
        event.accept()

    def mouseMoveEvent(self, event: QMouseEvent) -> None:
        if self._from_pen(event):
            return
        pos = event.position()
        self._hover = pos
        self.pressure = pen_pressure(event)
        if self.sizing.active:
            self.sizing.move(pos)
            self.update_overlays()
            return
        dx, dy = pos.x() - self._last_pos.x(), pos.y() - self._last_pos.y()
        self._last_pos = pos
        if self._drag == "align" and self._drag_target is not None and hasattr(self._drag_target, "drag"):
            self._drag_target.drag(pos)
        elif self._drag == "align" and self._drag_target is not None:
            self._drag_target.move(self._cursor_at(pos))
        elif self._drag == "align":
            self._brush_at(pos)  # the strands follow when the engine's result lands
        elif self._drag == "box" and self._box is not None:
            self._box[1] = pos
        elif self._drag == "orbit":
            self._auto_frame = False
            self.camera.orbit(dx, dy)
        elif self._drag == "pan":
            self._auto_frame = False
            self.camera.pan(dx, dy, self.height())
        else:
            self.cursor_moved.emit(self.cursor_on_plane(pos))
        if self._drag in ("orbit", "pan") or self._drag_target is not None:
            self.update()
        else:  # the circle or the box moved: drawn over the last image
            self.update_overlays()

    def _cursor_at(self, pos: QPointF, through: np.ndarray | None = None) -> np.ndarray:
        cursor = self.cursor_on_plane(pos, through)
        self.cursor_moved.emit(cursor)
        return cursor

    def view_at(self, pos: QPointF) -> np.ndarray:
        """The camera's viewing direction through ``pos`` (from the eye into the scene)."""
        return self.camera.ray(pos.x(), pos.y(), self.width(), self.height())[1]

    def eye(self) -> np.ndarray | None:
        """A perspective camera's eye, which the brushes' lines of sight go to; None for the
        orthographic 2-D view, whose lines of sight all run along the view."""
        return None if self.camera.ortho else self.camera.eye().astype(np.float64)

    def hair_under(self, pos: QPointF) -> np.ndarray:
        """The point a stroke starting at ``pos`` keeps its cursor level with (module docstring);
        for the brushes that work on the head's surface (slide, add, density), the head mesh
        under the mouse where it is there."""
        s = self.scene
        surface = None if s.pipeline is None else s.pipeline.surface
        if s.tool.brush in NEED_SURFACE and surface is not None and hasattr(surface, "ray_hit"):
            eye, ray = self.camera.ray(pos.x(), pos.y(), self.width(), self.height())
            hit = surface.ray_hit(eye, ray)
            if hit is not None:
                return hit
        pts = s.result.points
        r_px = s.radius * self.camera.pixels_per_unit_at(s.centre, self.height())
        size, mouse = (self.width(), self.height()), (pos.x(), pos.y())
        strand = s.result.topology.strand_index
        vp = self.camera.view_projection(*size)
        grid = getattr(surface, "face_grid", None)
        if s.tool.front_only and grid is not None:  # by sight, as the stroke's samples judge
            view = self.view_at(pos)
            eye = self.eye()
            hides = lambda p: bool(hidden_points(p[None], view, grid, eye)[0])  # noqa: E731
            i = nearest_in_sight(pts, vp, size, mouse, r_px, strand, hides)
        else:
            away = None
            if s.tool.front_only and s.pipeline is not None:
                away = facing_away(s.pipeline.strand_normals, self.view_at(pos))
            i = nearest_on_screen(pts, vp, size, mouse, r_px, strand, away)
        if i < 0:
            return np.asarray(s.centre, np.float64)
        return pts[i].astype(np.float64)

    def _brush_at(self, pos: QPointF) -> None:
        cursor = self._cursor_at(pos, self._stroke_depth)
        last, self._stroke_cursor = self._stroke_cursor, cursor
        direction = np.zeros(3) if last is None else cursor - last
        view = self.view_at(pos)
        # the engine runs it off this thread (app.ui.engine_thread): the circle moves on now
        self.scene.moves.move(
            cursor, direction, view, self._stroke_invert, last is None, self.pressure, self._stroke_add,
            self.eye(),
        )  # fmt: skip

    def mouseReleaseEvent(self, event: QMouseEvent) -> None:
        if self._from_pen(event):
            return
        if self._drag is None or event.button() != self._drag_button:
            return
        drag, self._drag = self._drag, None
        if drag == "box" and self._box is not None:
            (a, _), b = self._box, event.position()
            self._box = None
            self.arm_box(False)
            self.box_finished.emit(self.box_sample(a, b, self._box_mode))
        elif drag == "align" and self._drag_target is not None:
            target, self._drag_target = self._drag_target, None
            target.end()
        elif drag == "align" and self._stroke_before is not None:
            before, self._stroke_before = self._stroke_before, None
            self.scene.moves.drain()  # every move of the stroke has run
            self.stroke_touched = self.scene.moves.touched
            # one document step, its moves settled first; then the full-density render hair is
            # built (and clumped) once, from the settled guides
            after = self.scene.end_stroke(before)
            self.scene.set_dragging(False)  # full density again
            self.stroke_finished.emit(before, after)
        self.update()

    def wheelEvent(self, event: QWheelEvent) -> None:
        steps = event.angleDelta().y() / 120.0
        if steps == 0:
            return
        if event.modifiers() & Qt.KeyboardModifier.ControlModifier:
            self.scale_brush(BRUSH_STEP**steps)
            self.update_overlays()
        else:
            self._auto_frame = False
            self.camera.zoom(steps)
            self.update()
        event.accept()

    def scale_brush(self, factor: float) -> None:
        self.scene.set_radius(self.scene.radius * factor)

    def leaveEvent(self, event) -> None:
        if self._drag is None:
            self._pen_down = False  # (a pen lifted where its release never reached the view)
        self._hover = None
        self.cursor_moved.emit(None)
        self.update_overlays()
