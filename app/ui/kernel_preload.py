"""The engine's cached kernels loaded in the studio's idle time, so that no stroke waits for them.

numba loads a cached kernel at its first call (:mod:`hairtool.kernel_loading`): without this, an
artist's first comb move on the bear waited 110-130 ms for a dozen of them. Once the engine runs
on cached kernels, :class:`KernelPreload` loads one overload per turn of the event loop (a few
milliseconds each), the brush-local engine's first, and waits while a button is held in the
viewport, so a stroke, an orbit or a box is never slowed by it. It only ever loads what the
cache holds; a kernel the cache lacks compiles at its first call, as before.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable

from PySide6.QtCore import QObject, QTimer, Signal

from hairtool import serial_twins
from hairtool.kernel_loading import cached_signatures, load_cached

#: Modules whose kernels load first: a brush move's (the brush-local engine, the brushes, the
#: strand rasterizer's redraw), then the full run's on release, then shading.
FIRST_MODULES = (
    "hairtool.frozen.vertex_grid",
    "hairtool.frozen.local",
    "hairtool.frozen.brushes",
    "hairtool.frozen.align",
    "hairtool.frozen.lengths",
    "hairtool.frozen.collide",
    "hairtool.bounds",
    "app.render.soft_raster",
    "hairtool.frozen.clump",
    "hairtool.frozen.spatial",
    "hairtool.frozen.freeze",
    "app.render.hair_shading",
)
#: Modules whose serial twins a parallel process calls too: the brush-local engine runs them on
#: regions below :data:`hairtool.frozen.local.SERIAL_BELOW` (the bear's comb, for one).
SERIAL_TOO = ("hairtool.frozen.local", "hairtool.frozen.vertex_grid", "hairtool.frozen.lengths")
BUSY_RETRY_MS = 100  # a button is held: look again after this long
INDEXES_PER_TURN = 8  # cache indexes read in one turn at most, looking for something to load


def kernels_in_use() -> list:
    """The kernels the studio's Python calls now, :data:`FIRST_MODULES`' first: the parallel
    kernels (and the serial twins of :data:`SERIAL_TOO`), or the serial twins while the process
    runs on them (a first start)."""
    from app.ui.kernel_warmup import _dispatchers

    parallel = serial_twins.parallel_in_use()
    rank = {m: i for i, m in enumerate(FIRST_MODULES)}
    picked = []
    for name, kernel in _dispatchers().items():
        module = name.split(":")[0]
        twin = name.endswith(serial_twins.SERIAL_SUFFIX)
        if serial_twins.is_twinned(kernel) and twin == parallel and not (twin and module in SERIAL_TOO):
            continue  # the twin not in use
        package = module.rpartition(".")[0]  # (a brush module ranks as its package)
        picked.append((rank.get(module, rank.get(package, len(rank))), name, kernel))
    picked.sort(key=lambda t: t[:2])
    return [kernel for _, _, kernel in picked]


class KernelPreload(QObject):
    """Loads :func:`kernels_in_use` from numba's cache, one overload per idle turn; ``busy()``
    True (a button held) puts it off. ``finished`` once every kernel is loaded."""

    finished = Signal()

    def __init__(self, busy: Callable[[], bool], parent: QObject | None = None) -> None:
        super().__init__(parent)
        self._busy = busy
        self._kernels: deque | None = None
        self._pending: deque = deque()  # (kernel, signature) of the kernel being loaded
        self.loaded = 0  # overloads loaded so far
        self.done = False
        self._timer = QTimer(self)
        self._timer.setSingleShot(True)
        self._timer.timeout.connect(self._step)

    def start(self) -> None:
        if not self.done and not self._timer.isActive():
            self._timer.start(0)

    def _step(self) -> None:
        if self._busy():
            self._timer.start(BUSY_RETRY_MS)
            return
        if self._kernels is None:
            self._kernels = deque(kernels_in_use())
        for _ in range(INDEXES_PER_TURN):  # reading an index is quick: find work
            if self._pending or not self._kernels:
                break
            kernel = self._kernels.popleft()
            self._pending.extend((kernel, sig) for sig in cached_signatures(kernel))
        if not self._pending:
            if self._kernels:
                self._timer.start(0)
                return
            self.done = True
            self.finished.emit()
            return
        kernel, sig = self._pending.popleft()
        if sig not in kernel.overloads:  # a call may have loaded it meanwhile
            load_cached(kernel, sig)
            self.loaded += 1
        self._timer.start(0)
