"""The render hair of animation frames, built off the GUI thread while the timeline is scrubbed.

Dragging the timeline's frame asks for one frame per mouse move; with render hair each frame's
children must be interpolated from its guides (and, once the mouse is let go, clumped: about
2 s for Sintel's 30,000 on a loaded 2-core host). One worker thread builds them: while it works,
newer asks replace the waiting one (coalesced: the view never works through a queue of stale
frames), and each result comes back to the GUI thread by a queued signal, which the view takes
with its guides at once (:meth:`app.ui.viewport.Viewport.show_frame`'s ``children``).

What a frame's children are is decided on the GUI thread when it is asked for (the drawn share
of the children, Clump children, the guides drawn after them: :class:`FrameAsk`); the worker
reads nothing of the scene, so the scene may change meanwhile (a landing that no longer fits the
drawn strands is dropped by whoever takes it).

A drag goes back and forth over the same frames: the interpolated frames built are kept (up to
:data:`KEPT_BYTES`, the least recently shown going first), and an ask for one of them (the same
frame, guides bit for bit, drawn children and guides) lands at once, in the ask's own call, with
the points built for it before; the build under way then lands for nobody (it is older).
"""

from __future__ import annotations

import time
from collections import OrderedDict
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field

import numpy as np
from PySide6.QtCore import QObject, Qt, Signal, Slot

from hairtool.groom import Groom, Topology
from hairtool.guides.binding import ChildBinding
from hairtool.guides.children import build_points
from hairtool.guides.render import ChildClump, RenderHair
from hairtool.guides.root_motion import following

KEPT_BYTES = 64 << 20  # built frames kept for a drag's return (Sintel's 10 % share: 1.2 MB a frame)


@dataclass(eq=False)
class FrameAsk:
    """One frame to show: its guides' points ``(V, 3)`` (of ``topology``), the view's colours and
    ghost passed through, and what its drawn children are: ``binding`` (the drawn share),
    ``clump`` (None: interpolated only) and ``with_guides`` (the guides drawn after them).
    ``number`` orders the asks; ``points`` (the drawn children, then the guides) is the result."""

    frame: int
    guides: np.ndarray
    topology: Topology
    binding: ChildBinding
    clump: ChildClump | None = None
    with_guides: bool = True
    colors: np.ndarray | None = None
    ghost: np.ndarray | None = None
    number: int = 0
    points: np.ndarray | None = field(default=None, repr=False)
    error: BaseException | None = field(default=None, repr=False)
    ms: float = 0.0

    @property
    def vertex_count(self) -> int:
        """The drawn vertices this ask gives (children, then the guides when drawn)."""
        return self.binding.vertex_count + (self.topology.vertex_count if self.with_guides else 0)


def frame_points(ask: FrameAsk, clumper: RenderHair | None = None) -> np.ndarray:
    """The drawn points of ``ask``'s frame, as :meth:`app.ui.scene.Scene.drawn_for` makes them:
    the children (clumped by ``clumper``, a :class:`RenderHair` of the ask's binding and clump,
    when it has a clump), then the guides when drawn; the children's roots carried by their
    guides' (:mod:`hairtool.guides.root_motion`), as the exported frames' are. A new array each call."""
    g = Groom(ask.guides, ask.topology)
    if ask.clump is not None:
        children = (clumper or RenderHair(ask.binding, ask.clump, follow_roots=True)).update_points(g)
    else:
        children = build_points(following(ask.binding, g), g)
    if ask.with_guides:
        return np.concatenate([children, g.points])
    return children.copy() if ask.clump is not None else children


class FrameChildren(QObject):
    """One worker thread building the asked frames' drawn points, the latest ask first (module
    docstring). ``delay_s``: seconds each build waits first, an injected slow build (tests)."""

    landed = Signal(object)  # a FrameAsk with its points (GUI thread)
    _finished = Signal(object)  # from the worker, queued to the GUI thread

    def __init__(self, parent: QObject | None = None) -> None:
        super().__init__(parent)
        self.delay_s = 0.0
        self.built = 0  # builds finished (fewer than the asks when asks were coalesced)
        self._pending: FrameAsk | None = None
        self._running: FrameAsk | None = None
        self._clumper: tuple[tuple, RenderHair] | None = None  # the worker's own (never the scene's)
        self._closed = False  # shut down: a build that lands later is dropped
        self._kept: OrderedDict[int, FrameAsk] = OrderedDict()  # frame -> its last interpolated build
        self._kept_bytes = 0
        self._overtaken: FrameAsk | None = None  # the build under way when a kept frame landed
        self.reused = 0  # asks answered with a kept frame
        self._worker = ThreadPoolExecutor(max_workers=1, thread_name_prefix="hairtool-frames")
        self._finished.connect(self._on_finished, Qt.ConnectionType.QueuedConnection)

    @property
    def busy(self) -> bool:
        """A build is under way or an ask waits for one."""
        return self._running is not None or self._pending is not None

    def ask(self, ask: FrameAsk) -> None:
        """Build ``ask`` when the worker is free; an ask still waiting is dropped for it. A frame
        built before for the same guides and drawn strands lands at once instead."""
        if self._closed:
            return
        kept = self._kept_for(ask)
        if kept is not None:
            self._pending, self._overtaken = None, self._running
            ask.points, ask.ms = kept.points, 0.0
            self.reused += 1
            self.landed.emit(ask)
            return
        self._pending = ask
        if self._running is None:
            self._launch()

    def _kept_for(self, ask: FrameAsk) -> FrameAsk | None:
        """The kept build of ``ask``'s frame when it is ``ask``'s (module docstring), else None."""
        kept = self._kept.get(ask.frame)
        if kept is None or ask.clump is not None or kept.binding is not ask.binding:
            return None
        if kept.topology is not ask.topology or kept.with_guides != ask.with_guides:
            return None
        if kept.guides.shape != ask.guides.shape or not np.array_equal(kept.guides, ask.guides):
            return None
        self._kept.move_to_end(ask.frame)
        return kept

    def _keep(self, ask: FrameAsk) -> None:
        """Keep an interpolated build (its guides copied: the caller's may change in place)."""
        if ask.clump is not None or ask.points is None or ask.points.nbytes > KEPT_BYTES:
            return
        if self._kept and next(iter(self._kept.values())).binding is not ask.binding:
            self._kept.clear()  # other drawn children: the kept frames are no one's now
            self._kept_bytes = 0
        old = self._kept.pop(ask.frame, None)
        if old is not None:
            self._kept_bytes -= old.points.nbytes
        guides = np.array(ask.guides, copy=True)
        self._kept[ask.frame] = FrameAsk(
            ask.frame, guides, ask.topology, ask.binding, None, ask.with_guides, points=ask.points
        )
        self._kept_bytes += ask.points.nbytes
        while self._kept_bytes > KEPT_BYTES:
            _, first = self._kept.popitem(last=False)
            self._kept_bytes -= first.points.nbytes

    def cancel(self) -> None:
        """Drop the waiting ask (the one being built still lands; its taker may drop it)."""
        self._pending = None

    def _launch(self) -> None:
        ask, self._pending = self._pending, None
        self._running = ask
        self._worker.submit(self._run, ask)

    def _clumper_for(self, ask: FrameAsk) -> RenderHair:
        key = (id(ask.binding), ask.clump)
        if self._clumper is None or self._clumper[0] != key:
            # frame after frame, it redoes the clumps of the guides that moved between them
            self._clumper = (key, RenderHair(ask.binding, ask.clump, follow_roots=True))
        return self._clumper[1]

    def _run(self, ask: FrameAsk) -> None:
        """In the worker thread."""
        try:
            t0 = time.perf_counter()
            if self.delay_s > 0:
                time.sleep(self.delay_s)
            clumper = self._clumper_for(ask) if ask.clump is not None else None
            ask.points = frame_points(ask, clumper)
            ask.ms = (time.perf_counter() - t0) * 1e3
        except BaseException as e:  # handed to the GUI thread, raised there
            ask.error = e
        try:
            self._finished.emit(ask)
        except RuntimeError:  # the window closed meanwhile, and this object with it
            pass

    @Slot(object)  # (a receiver of a signal from another thread is a declared slot: PYSIDE-3124)
    def _on_finished(self, ask: FrameAsk) -> None:
        if self._closed:  # the window closed meanwhile: its view has no GL to draw it with
            return
        self._running = None
        self.built += 1
        overtaken, self._overtaken = self._overtaken is ask, None
        if ask.error is None:
            self._keep(ask)
        waiting, kept = self._pending, None
        if waiting is not None:
            kept = self._kept_for(waiting)  # (this build may be the waiting ask's too)
            if kept is None:
                self._launch()
            else:
                self._pending = None
        if ask.error is not None:
            raise ask.error
        if not overtaken:
            self.landed.emit(ask)
        if kept is not None:
            waiting.points, waiting.ms = kept.points, 0.0
            self.reused += 1
            self.landed.emit(waiting)

    def shutdown(self) -> None:
        """No more asks; the worker ends after the build under way, which is dropped (the window
        closes)."""
        self._closed = True
        self._pending = None
        self._kept.clear()
        self._worker.shutdown(wait=True)
