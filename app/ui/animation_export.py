"""Exporting the animation (USD, ``.npz``, MP4, GIF, a PNG sequence) and its keys (JSON, CSV, USD).

Video frames are drawn like the viewport draws them, off screen at the size chosen in the
export dialog, in the viewport's own GL context (the studio keeps to one context; a second,
headless one beside Qt's is unreliable) but never into the window: the export's worker thread
makes each frame's strands (render hair built and clumped there:
:mod:`app.ui.video_frames`), rasterizes them where strands are drawn on the CPU (software GL),
and encodes, while the GUI thread only draws each frame into an offscreen framebuffer on
request (uploading the worker's strand images, when it made them), one frame a turn of its
event loop, with one renderer kept for the whole export (:class:`GuiFrameSource`); the window
keeps answering, its viewport is not repainted for the export, and Cancel works between
frames. Every file is written beside its target and renamed at the end: a cancelled or failed
export leaves no partial file (a PNG sequence appears all at once, from a temporary folder).

With render hair (a groom with children) an animation of the guides is written as render hair
by default: every child following the guides frame by frame, in USD with the guides as a second
prim of purpose "guide" (frames streamed to the file), in ``.npz`` with the guides beside
(``shot.guides.npz``); the Export Animation dialog asks first (:class:`RenderHairDialog`).

API for the window: :class:`AnimationExporter` (``export_animation(path)``,
``export_keys(path)``, the two ``*_dialog`` methods); the functions below work without Qt
widgets and are what the tests drive.
"""

from __future__ import annotations

import dataclasses
import os
import queue
import shutil
import tempfile
from collections.abc import Callable, Iterable, Iterator
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray
from PySide6.QtCore import QObject, Qt, QThread, Signal, Slot
from PySide6.QtGui import QAction
from PySide6.QtWidgets import QCheckBox, QDialog, QDialogButtonBox, QLabel, QVBoxLayout, QWidget

from app.render.camera import Camera
from app.render.drawn import Drawn
from app.render.offscreen import Overlays, render_drawn
from app.render.raster_layer import RasterJob
from app.render.soft_raster import StrandRaster
from app.render.strands import StrandRenderer
from app.ui.drawn import drawn
from app.ui.jobs import Job
from app.ui.qt_utils import set_available
from app.ui.video_frames import render_hair_frames
from hairtool import io
from hairtool.errors import Cancelled, FormatError, HairtoolError, ParameterError
from hairtool.groom import Animation, Groom
from hairtool.guides.animate import RenderHairAnimation
from hairtool.guides.files import write_animation
from hairtool.guides.render import ChildClump
from hairtool.io.atomic import atomic_path
from hairtool.keys.export import export_keys as write_keys
from hairtool.keys.export import keys_record

if TYPE_CHECKING:
    from app.ui.host import StudioHost
    from hairtool.guides.binding import ChildBinding

DATA_SUFFIXES = (".usd", ".usda", ".usdc", ".npz")
VIDEO_SUFFIXES = (".mp4", ".gif")
SEQUENCE_SUFFIXES = (".png",)
KEY_SUFFIXES = (".json", ".csv", ".usda", ".usdc", ".usd")
ANIMATION_FILTERS = ";;".join(
    [
        "USD animation (*.usda *.usdc *.usd)",
        "hairtool cache (*.npz)",
        "MP4 video (*.mp4)",
        "GIF animation (*.gif)",
        "PNG sequence (*.png)",
    ]
)
NO_ANIMATION = "No animation to export: open one, record drags, simulate or apply the anime cycle"
NO_KEYS = "No keys to export: open or make an animation first (the timeline solves its keys)"
KEYS_SOLVING = "No keys to export yet: the timeline is still solving them"
ANIMATION_TIP = "Write the animation: USD, a .npz cache, MP4, GIF or a PNG sequence"
KEYS_TIP = "Write the timeline's DP keys: a JSON record, a CSV key sheet or USD key poses"
CAPTURE_FILTER = "BVH motion capture, edited (*.bvh)"
KEY_FILTERS = "Keys record (*.json);;Key sheet (*.csv);;USD key poses (*.usda *.usdc *.usd)"
MP4_QUALITY = 8  # imageio-ffmpeg's 0..10 scale: visually clean thin hair lines, small files

Progress = Callable[..., None]
CancelCheck = Callable[[], bool]


def _never() -> bool:
    return False


def _ignore(*_: object) -> None:
    return None


def even_size(size: tuple[int, int]) -> tuple[int, int]:
    """The size rounded down to even numbers (H.264 in yuv420p needs them), at least 2×2."""
    w, h = (int(v) for v in size)
    return max(2, w - w % 2), max(2, h - h % 2)


def _rgb(image: NDArray) -> NDArray[np.uint8]:
    img = np.asarray(image)
    if img.dtype != np.uint8 or img.ndim != 3 or img.shape[2] not in (3, 4):
        raise ParameterError("frame", f"{img.dtype} {img.shape}", "(H, W, 3 or 4) uint8")
    return np.ascontiguousarray(img[..., :3])


def _frames_checked(
    frames: Iterable[NDArray], n_frames: int, progress: Progress, cancelled: CancelCheck
) -> Iterator[NDArray[np.uint8]]:
    """RGB frames with progress after each and a cancel check before each."""
    count = 0
    for count, image in enumerate(frames, 1):
        if cancelled():
            raise Cancelled
        yield _rgb(image)
        progress(count / max(n_frames, 1), f"frame {count}/{n_frames}")
    if cancelled():
        raise Cancelled
    if count != n_frames:
        raise ParameterError("frames", count, f"{n_frames} frames")


def write_video(
    path: str | os.PathLike[str],
    frames: Iterable[NDArray],
    n_frames: int,
    fps: float,
    *,
    progress: Progress = _ignore,
    cancelled: CancelCheck = _never,
) -> None:
    """Encode ``n_frames`` RGB(A) uint8 frames as MP4 (H.264) or GIF, atomically.

    :class:`Cancelled` (raised when ``cancelled()`` turns True) leaves no file behind. GIF:
    Pillow merges identical consecutive frames into one longer frame (pictures held on twos
    play the same, in fewer GIF frames); delays are whole centiseconds, as GIF stores them.
    """
    suffix = Path(path).suffix.lower()
    if suffix not in VIDEO_SUFFIXES:
        raise FormatError(path, f"videos are written as {' or '.join(VIDEO_SUFFIXES)}, not '{suffix}'")
    if not (np.isfinite(fps) and 0 < fps <= 1000):
        raise ParameterError("fps", fps, "a frame rate in (0, 1000]")
    checked = _frames_checked(frames, n_frames, progress, cancelled)
    try:
        with atomic_path(path) as tmp:
            if suffix == ".mp4":
                _write_mp4(tmp, checked, fps)
            else:
                _write_gif(tmp, checked, fps)
    except OSError as e:
        raise FormatError(path, f"cannot write: {e}") from None


def _write_mp4(tmp: Path, frames: Iterator[NDArray[np.uint8]], fps: float) -> None:
    import imageio.v2 as imageio

    writer = imageio.get_writer(
        tmp,
        format="FFMPEG",
        mode="I",
        fps=fps,
        codec="libx264",
        quality=MP4_QUALITY,
        pixelformat="yuv420p",
        macro_block_size=1,
        ffmpeg_log_level="error",
    )
    try:
        for image in frames:
            h, w = image.shape[:2]
            writer.append_data(image[: h - h % 2, : w - w % 2])
    finally:
        writer.close()


def _write_gif(tmp: Path, frames: Iterator[NDArray[np.uint8]], fps: float) -> None:
    from PIL import Image

    images = (Image.fromarray(image) for image in frames)
    first = next(images, None)
    if first is None:
        raise ParameterError("frames", 0, "at least one frame")
    first.save(tmp, format="GIF", save_all=True, append_images=images, duration=1000.0 / fps, loop=0)


def sequence_paths(path: str | os.PathLike[str], n_frames: int) -> list[Path]:
    """``shot.png`` → ``shot_0000.png`` … (at least 4 digits, more for long shots)."""
    p = Path(path)
    digits = max(4, len(str(max(n_frames - 1, 0))))
    return [p.with_name(f"{p.stem}_{i:0{digits}d}{p.suffix}") for i in range(n_frames)]


def write_png_sequence(
    path: str | os.PathLike[str],
    frames: Iterable[NDArray],
    n_frames: int,
    *,
    progress: Progress = _ignore,
    cancelled: CancelCheck = _never,
) -> list[Path]:
    """Write ``shot_0000.png`` … beside ``path``: into a temporary folder first, moved into
    place only when every frame is written, so a cancel leaves nothing behind."""
    import imageio.v3 as iio

    if Path(path).suffix.lower() not in SEQUENCE_SUFFIXES:
        raise FormatError(path, "a PNG sequence is named like shot.png (frames become shot_0000.png …)")
    targets = sequence_paths(path, n_frames)
    folder = targets[0].parent if targets else Path(path).parent
    try:
        tmp = Path(tempfile.mkdtemp(prefix=f".{Path(path).stem}.", suffix=".tmp", dir=folder))
    except OSError as e:
        raise FormatError(path, f"cannot write: {e}") from None
    try:
        for target, image in zip(
            targets, _frames_checked(frames, n_frames, progress, cancelled), strict=False
        ):
            iio.imwrite(tmp / target.name, image, extension=".png")
        for target in targets:
            os.replace(tmp / target.name, target)
    except OSError as e:
        raise FormatError(path, f"cannot write: {e}") from None
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return targets


def write_animation_data(path: str | os.PathLike[str], animation: Animation) -> None:
    """USD time samples or the ``.npz`` cache (atomic, through :mod:`hairtool.io`)."""
    if Path(path).suffix.lower() not in DATA_SUFFIXES:
        raise FormatError(path, f"animations are written as {', '.join(DATA_SUFFIXES)}")
    io.write(path, animation)


def write_render_hair_data(
    path: str | os.PathLike[str],
    animation: Animation,
    binding: ChildBinding,
    *,
    clump: ChildClump | None = None,
    progress: Progress = _ignore,
    cancelled: CancelCheck = _never,
) -> dict[str, str]:
    """The render hair of ``binding`` following ``animation`` (of its guides), clumped on every
    frame with ``clump`` (the scene's Clump children), with the guides: USD one file (guide
    prim), ``.npz`` the guides beside (:func:`hairtool.guides.files.write_animation`).
    :class:`Cancelled` between frames leaves no file."""
    if Path(path).suffix.lower() not in DATA_SUFFIXES:
        raise FormatError(path, f"animations are written as {', '.join(DATA_SUFFIXES)}")
    hair = RenderHairAnimation(binding, animation, clump)

    def step(done: int, total: int) -> None:
        if cancelled():
            raise Cancelled
        progress(done / total, f"frame {done}/{total}")

    return write_animation(path, hair, progress=step)


class RenderHairDialog(QDialog):
    """Export Animation's first question when the groom has children: write the render hair
    (on by default) or the guides alone."""

    def __init__(self, children: int, guides: int, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setWindowTitle("Export animation")
        layout = QVBoxLayout(self)
        self.render_hair = QCheckBox(f"Render hair: {children:,} strands following the {guides:,} guides")
        self.render_hair.setChecked(True)
        self.render_hair.setToolTip(
            "USD: the render strands and the guides (a second prim of purpose 'guide', which DCCs "
            "do not render) in one file; .npz: the render strands, the guides beside in NAME.guides.npz. "
            "Videos draw the children as the view does. Off: the guides alone, as the engine animates them."
        )
        layout.addWidget(self.render_hair)
        layout.addWidget(QLabel("Then choose the file (USD, .npz, MP4, GIF, PNG sequence)."))
        buttons = QDialogButtonBox(
            QDialogButtonBox.StandardButton.Ok | QDialogButtonBox.StandardButton.Cancel
        )
        buttons.accepted.connect(self.accept)
        buttons.rejected.connect(self.reject)
        layout.addWidget(buttons)


class FrameRenderer:
    """Draws an animation's frames as the viewport draws the groom: camera, look and head mesh
    fixed when the export starts; ``frame_drawn(f)``: the :class:`~app.render.drawn.Drawn` of
    frame f (default the animation's frame in the ramp: render hair draws the children of its
    guides); ``overlays``: the working overlays drawn over every frame (None: none)."""

    def __init__(
        self,
        animation: Animation,
        camera: Camera,
        size: tuple[int, int],
        *,
        mesh: object | None = None,
        frame_drawn: Callable[[int], Drawn] | None = None,
        overlays: Overlays | None = None,
    ) -> None:
        self.animation, self.size = animation, even_size(size)
        self.frame_drawn = frame_drawn or (lambda f: Drawn.of_groom(animation.frame(f)))
        self.camera = camera.copy()
        lo, hi = animation.bounds
        self.camera.set_scene(lo, hi)  # near and far planes enclose the whole motion
        self.mesh, self.overlays = mesh, overlays

    def frame_groom(self, frame: int) -> Groom:
        """The strands drawn on ``frame``, as a groom."""
        return self.frame_drawn(frame).groom()

    def render(self, frame: int, ctx: object | None = None) -> NDArray[np.uint8]:
        """``(H, W, 4)`` uint8 of one frame (``ctx``: a current moderngl context; None: headless)."""
        return self.render_drawn(self.frame_drawn(frame), ctx)

    def render_drawn(
        self, d: Drawn, ctx: object | None = None, renderer: StrandRenderer | None = None
    ) -> NDArray[np.uint8]:
        """``(H, W, 4)`` uint8 of ``d`` (a frame's :meth:`frame_drawn`, made in any thread) with
        this export's camera, size, mesh and overlays; ``renderer``: one of ``ctx`` kept across
        the frames (:func:`~app.render.offscreen.render_drawn`)."""
        return render_drawn(
            d, size=self.size, camera=self.camera, mesh=self.mesh, ctx=ctx, overlays=self.overlays,
            renderer=renderer,
        )  # fmt: skip


class GuiFrameSource(QObject):
    """Frames drawn on the GUI thread for a worker thread that makes what they draw.

    Create it on the GUI thread with ``render(drawn, images) → image or job``. :meth:`frames`
    (in the worker) makes frame i + 1's :class:`Drawn` while the GUI thread draws frame i, so
    each side does its part at once; the GUI thread draws one frame per request, between its
    other events. Where the strands are rasterized on the CPU, ``render(drawn, None)`` answers
    the frame's :class:`~app.render.raster_layer.RasterJob` instead of an image: the worker
    rasters it and asks again with ``images`` (the job, its colour and depth images), and the GUI
    thread only composites them, so the frame's raster never holds up the window. ``close``
    runs on the GUI thread when the frames end (however they end): it frees what ``render`` kept.
    Called on the GUI thread itself, everything runs there directly (synchronous use, tests).

    ``parent`` (a QObject of the GUI thread, the exporter) owns the source, which deletes itself
    there once its frames have ended (one run of frames a source). The worker holds the last
    Python reference to a source: owned by Python, it was deleted in the worker as the job
    ended, while the GUI thread could still be delivering its last request or ``close`` to it
    (a segfault inside the GUI thread's event processing).
    """

    _requested = Signal(int, object, object)
    _closing = Signal()

    def __init__(
        self,
        render: Callable[[Drawn, tuple | None], NDArray | RasterJob],
        close: Callable[[], None] = _ignore,
        *,
        parent: QObject,
    ) -> None:
        super().__init__(parent)
        self._render, self._close = render, close
        self._answers: queue.Queue = queue.Queue()
        self._requested.connect(self._on_request, Qt.ConnectionType.QueuedConnection)
        self._closing.connect(self._on_close, Qt.ConnectionType.QueuedConnection)

    def _here(self) -> bool:
        return QThread.currentThread() == self.thread()

    @Slot(int, object, object)
    def _on_request(self, frame: int, d: Drawn, images: tuple | None) -> None:
        try:
            self._answers.put((frame, self._render(d, images), None))
        except BaseException as e:  # handed to the worker, which raises it
            self._answers.put((frame, None, e))

    @Slot()
    def _on_close(self) -> None:
        try:
            self._close()
        finally:
            self.deleteLater()  # here, once this event is delivered; never by the worker

    def _post(self, index: int, d: Drawn, images: tuple | None = None) -> None:
        if self._here():
            self._on_request(index, d, images)
        else:
            self._requested.emit(index, d, images)

    def _take(self, index: int, cancelled: CancelCheck) -> NDArray:
        while True:
            try:
                frame, image, error = self._answers.get(timeout=0.05)
            except queue.Empty:
                if cancelled():
                    raise Cancelled from None
                continue
            if frame != index:  # a late answer to an earlier, abandoned request
                continue
            if error is not None:
                raise error
            return image

    def frames(
        self, n_frames: int, make: Callable[[int], Drawn], cancelled: CancelCheck = _never
    ) -> Iterator[NDArray]:
        """The ``n_frames`` images, frame ``i`` drawn from ``make(i)`` (called in this thread),
        its CPU raster too where it has one. The first comes as soon as it can (the progress
        shows); from the second on, frame i + 1 is made while the GUI thread draws frame i."""
        raster = StrandRaster()  # this thread's: the frames' strands rasterized here
        made: dict[int, Drawn] = {}
        try:
            for i in range(n_frames):
                d = made.pop(i) if i in made else make(i)
                self._post(i, d)
                if i > 0 and i + 1 < n_frames and not cancelled():
                    made[i + 1] = make(i + 1)  # while the GUI thread draws frame i
                answer = self._take(i, cancelled)
                if isinstance(answer, RasterJob):  # rasterized here, composited there
                    self._post(i, d, (answer, *answer.draw(raster)))
                    answer = self._take(i, cancelled)
                yield answer
        finally:
            if self._here():
                self._on_close()
            else:
                try:
                    self._closing.emit()
                except RuntimeError:  # the window (and this object) went meanwhile
                    pass


def keys_result(model: object) -> dict:
    """The keys on the timeline as a ``hairtool keys`` result: frames, fps, DP keys and their
    cost, the uniform keys of the same count and theirs, the key settings and, when measured,
    the mean/tip/max position errors of both reconstructions."""
    from hairtool.keys.dp import keys_cost, uniform_constraints

    anim, solve, keys = model.animation, model.key_solve, model.dp_keys
    if anim is None or keys is None or solve is None:
        raise HairtoolError(
            "no keys to export: make or open an animation first (the timeline solves its keys)"
        )
    uni = model.uniform_keys
    objective = solve.objective
    result = {
        "frames": anim.n_frames,
        "fps": anim.fps,
        "keys": np.asarray(keys).tolist(),
        "cost": keys_cost(solve.table, keys, objective),
        "objective": objective,
        "mode": model.settings.mode,
        "uniform": {"keys": np.asarray(uni).tolist(), "cost": keys_cost(solve.table, uni, objective)}
        | uniform_constraints(model.settings.pins, model.settings.excludes),
        # the keys chosen, whatever mode chose them (the settings' count is 0 for "the knee")
        "params": dataclasses.asdict(model.settings) | {"count": int(np.size(keys))},
    }
    if model.analysis is not None:
        result["position_errors"] = {
            "keys": model.analysis.dp.summary(),
            "uniform": model.analysis.uniform.summary(),
        }
    return result


class AnimationExporter(QObject):
    """File → Export Animation / Export Keys for the window (errors go to ``window.show_error``)."""

    exported = Signal(str)  # the path, once a file (or sequence) is complete

    def __init__(self, window: StudioHost) -> None:
        super().__init__(window)
        self.window = window
        self.job: Job | None = None

    def render_hair_binding(self, animation: Animation | None = None) -> ChildBinding | None:
        """The children an animation can be written as: the groom's, when the animation is of
        its guides (simulations, cycles and recordings are; an opened file may not be)."""
        anim = self.window.animation.animation if animation is None else animation
        binding = self.window.scene.children_binding()  # (of the guides as they are now)
        if anim is None or binding is None or anim.topology != binding.rest_guides.topology:
            return None
        return binding

    def ask_render_hair(self, binding: ChildBinding) -> bool | None:
        """The dialog's answer: render hair (True), the guides alone (False), or None (cancel)."""
        dialog = RenderHairDialog(binding.child_count, binding.rest_guides.strand_count, self.window)
        if dialog.exec() != QDialog.DialogCode.Accepted:
            return None
        return dialog.render_hair.isChecked()

    def bind_actions(self, animation_action: QAction, keys_action: QAction) -> None:
        """File ▸ Export Animation… and Export Keys…, greyed out (their tooltips say why) while
        there is no animation or no keys to write."""
        self._actions = (animation_action, keys_action)
        model = self.window.animation
        for signal in (model.animation_changed, model.keys_changed):
            signal.connect(self._sync_actions)
        self._sync_actions()

    def _sync_actions(self, *_: object) -> None:
        model = self.window.animation
        animation_action, keys_action = self._actions
        has_animation = model.animation is not None
        has_keys = has_animation and model.key_solve is not None and model.dp_keys is not None
        set_available(animation_action, has_animation, NO_ANIMATION, ANIMATION_TIP)
        set_available(keys_action, has_keys, NO_KEYS if not has_animation else KEYS_SOLVING, KEYS_TIP)

    def export_animation_dialog(self) -> bool:
        if self.window.animation.animation is None:
            self.window.show_error("Cannot export animation", "No animation: make or open one first")
            return False
        binding = self.render_hair_binding()
        render_hair = False
        if binding is not None:
            answer = self.ask_render_hair(binding)
            if answer is None:
                return False
            render_hair = answer
        capture = getattr(self.window, "capture", None)
        if capture is not None and capture.attached:  # a capture: its edited BVH first
            filters, suggested = f"{CAPTURE_FILTER};;{ANIMATION_FILTERS}", "animation.bvh"
        else:
            filters, suggested = ANIMATION_FILTERS, "animation.mp4"
        path = self.window.ask_save_path("Export animation", filters, suggested)
        if not path:
            return False
        size, overlays = None, False
        if Path(path).suffix.lower() in VIDEO_SUFFIXES + SEQUENCE_SUFFIXES:  # pictures: their size
            picture = self.window.ask_picture_options()
            if picture is None:
                return False
            size, overlays = picture.size, picture.overlays
        return self.export_animation(path, size, render_hair=render_hair, overlays=overlays) is not False

    def export_keys_dialog(self) -> bool:
        path = self.window.ask_save_path("Export keys", KEY_FILTERS, "keys.json")
        return bool(path) and self.export_keys(path)

    def export_keys(self, path: str | os.PathLike[str]) -> bool:
        """JSON record, CSV sheet or USD key poses of the timeline's DP keys."""
        model = self.window.animation
        try:
            result = keys_result(model)  # a clear error when there are no keys
            codes = model.animation.time_codes  # keys at the source's time codes
            record = keys_record(result, model.source or None, time_codes=codes)
            write_keys(path, record, model.animation)
        except HairtoolError as e:
            self.window.show_error("Cannot export keys", str(e))
            return False
        self._done(path)
        return True

    def renderer(
        self,
        animation: Animation,
        size: tuple[int, int] | None = None,
        *,
        render_hair: bool = False,
        overlays: bool = False,
    ) -> FrameRenderer:
        """Frames drawn as the viewport draws them; ``render_hair``: the children drawn now (the
        release share of them) following each frame's guides, the guides over them if shown;
        ``overlays``: the brush circle, mirror plane and mask tint as the view shows them."""
        w, scene = self.window, self.window.scene
        size = even_size(size or w.viewport_pixel_size())
        binding = self.render_hair_binding(animation) if render_hair else None
        if binding is not None:  # made in the export's worker thread (the children cost)
            frame_drawn = render_hair_frames(scene, animation, mask=overlays)
        else:  # the animation's own strands (the guides alone, or another groom's)
            look = drawn(scene, mask=overlays)
            same = animation.topology == scene.result.topology and not scene.has_children
            # the view's colours hang on the strands (ramp, per strand, clumps, mask), not the pose,
            # so they hold on every frame; the distances from rest are the edit's, not the frame's
            colors = look.colors if same and scene.colour_mode != "displacement" else None

            def frame_drawn(f: int) -> Drawn:
                return dataclasses.replace(
                    look, points=animation.frames[f], topology=animation.topology, guides=0,
                    make_colors=lambda: colors,
                )  # fmt: skip

        return FrameRenderer(
            animation,
            w.viewport.camera,
            size,
            mesh=scene.mesh,
            frame_drawn=frame_drawn,
            overlays=w.viewport.overlays(size) if overlays else None,
        )

    def export_animation(
        self,
        path: str | os.PathLike[str],
        size: tuple[int, int] | None = None,
        *,
        render_hair: bool | None = None,
        overlays: bool = False,
    ) -> bool | Job:
        """Data formats are written at once (True/False), or as render hair in a job;
        video and PNG sequences start a job in ``window.jobs`` and return it (False when
        refused before starting). ``render_hair``: write the children following the guides
        (default: whenever the animation is of the guides of a groom with children). Pictures:
        ``size`` (default the viewport's), ``overlays`` the working overlays drawn too."""
        w = self.window
        anim = w.animation.animation
        suffix = Path(path).suffix.lower()
        if suffix == ".bvh" and getattr(w, "capture", None) is not None:
            return w.capture.export_bvh(path)  # the edited capture at every frame
        try:
            if anim is None:
                raise HairtoolError("no animation: make or open one first")
            binding = self.render_hair_binding(anim)
            if render_hair and binding is None:
                raise HairtoolError("no render hair for this animation: it is not of the groom's guides")
            if suffix in DATA_SUFFIXES and binding is not None and render_hair is not False:
                return self._export_render_hair(path, anim, binding)
            if suffix in DATA_SUFFIXES:
                write_animation_data(path, anim)
                self._done(path)
                return True
            if suffix not in VIDEO_SUFFIXES + SEQUENCE_SUFFIXES:
                raise FormatError(
                    path, "animations are written as .usda/.usdc/.usd, .npz, .mp4, .gif or .png"
                )
            hair = binding is not None and render_hair is not False
            renderer = self.renderer(anim, size, render_hair=hair, overlays=overlays)
        except HairtoolError as e:
            w.show_error("Cannot export animation", str(e))
            return False

        kept: list[StrandRenderer] = []  # one renderer for every frame, made at the first

        def render(d: Drawn, images: tuple | None) -> NDArray | RasterJob:
            """Frame ``d``; where its strands are rasterized on the CPU and ``images`` is None,
            the raster's job instead (the worker makes the images: :class:`GuiFrameSource`)."""
            with w.viewport.current_context() as ctx:
                if ctx is None:
                    return renderer.render_drawn(d, ctx)
                if not kept:
                    kept.append(StrandRenderer(ctx))
                layer = kept[0].cpu_raster_layer()
                layer.defer, layer.given, layer.job = images is None, images, None
                try:
                    image = renderer.render_drawn(d, ctx, kept[0])
                    job = layer.job
                finally:
                    layer.defer, layer.given, layer.job = False, None, None
                return job if images is None and job is not None else image

        def close() -> None:
            if kept and w.viewport.ctx is not None:
                with w.viewport.current_context():
                    kept.pop().release()

        source = GuiFrameSource(render, close, parent=self)
        n = anim.n_frames

        def work(progress: Progress, cancelled: CancelCheck) -> str:
            frames = source.frames(n, renderer.frame_drawn, cancelled)
            if suffix in VIDEO_SUFFIXES:
                write_video(path, frames, n, anim.fps, progress=progress, cancelled=cancelled)
            else:
                write_png_sequence(path, frames, n, progress=progress, cancelled=cancelled)
            return str(path)

        self.job = w.jobs.run(f"Exporting {Path(path).name}", work, on_done=lambda p: self._done(p))
        return self.job

    def _export_render_hair(
        self, path: str | os.PathLike[str], anim: Animation, binding: ChildBinding
    ) -> Job:
        """Every child on every frame is a long write (30,000 children × 32 vertices are 11.5 MB a
        frame): a job with progress and Cancel."""

        clump = self.window.scene.children_clump()

        def work(progress: Progress, cancelled: CancelCheck) -> str:
            write_render_hair_data(path, anim, binding, clump=clump, progress=progress, cancelled=cancelled)
            return str(path)

        self.job = self.window.jobs.run(
            f"Exporting render hair to {Path(path).name}", work, on_done=lambda p: self._done(p)
        )
        return self.job

    def _done(self, path: str | os.PathLike[str]) -> None:
        self.window.remember_dir(path)
        self.window.statusBar().showMessage(f"wrote {path}", 5000)
        self.exported.emit(str(path))
