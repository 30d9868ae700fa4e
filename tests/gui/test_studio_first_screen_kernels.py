"""The warm-up's first steps compile every kernel the first screen uses: after them, Sintel with
her render hair, shaded, drawn and combed with the align brush loads every kernel from numba's
cache and compiles none on the GUI thread (which would freeze the window on a first start). So
do the parallel steps for a start on the parallel kernels (every start after the first)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.gui

#: ``startup MODE``: run the warm-up's first-screen steps (MODE ``serial``: the first start's,
#: on the serial twins; ``parallel``: the parallel kernels' steps); ``screen MODE``: the studio's
#: first screen (window, engine, render hair, a frame, an align drag) on those kernels. Either
#: prints the numba dispatchers' signatures in the process afterwards, the kernels it compiled
#: (cache misses) and the parallel kernels it ran.
SCRIPT = r"""
import gc, json, sys
from numba.core import event
from numba.core.dispatcher import Dispatcher

compiled = []
class Compiles(event.Listener):
    def on_start(self, e):
        d = e.data["dispatcher"]
        compiled.append(f"{d.py_func.__module__}:{d.py_func.__qualname__} {e.data['args']}")
    def on_end(self, e):
        pass
event.register("numba:compile", Compiles())

from app.ui import kernel_warmup
if sys.argv[1] == "startup":
    labels = kernel_warmup.FIRST_SCREEN
    if sys.argv[2] == "parallel":
        labels = (*kernel_warmup.PARALLEL_STEPS, kernel_warmup.RASTER_STEP)
    for label, step in kernel_warmup.STEPS:
        if label in labels:
            step()
else:
    import tempfile
    import numpy as np
    from app.surface import configure_gl
    configure_gl()
    from PySide6.QtCore import QSettings
    from PySide6.QtWidgets import QApplication
    from app.main import open_window
    from app.ui.qt_utils import send_mouse
    from PySide6.QtCore import Qt
    app = QApplication([])
    settings = QSettings(tempfile.mkdtemp() + "/studio.ini", QSettings.Format.IniFormat)
    w = open_window(None, engine_ready=False, settings=settings)
    w.ask_save_changes = lambda: "discard"
    w.resize(640, 480)
    w.show()
    app.processEvents()
    del compiled[:]  # what compiled before the window showed is not the first start's concern
    kernel_warmup.use_parallel(sys.argv[2] == "parallel")  # as the studio's start sets it
    w.scene.start_engine()  # what the warm-up's startup steps let the studio do
    w._bind_pending_render_hair()  # and its render hair step
    w.viewport.set_raster_ready()  # and its strand drawing step
    v = w.viewport
    v.draw_now()
    s = w.scene
    assert s.binding is not None and s.engine_ready
    centre = v.project(s.centre[None])[0]
    left = Qt.MouseButton.LeftButton
    send_mouse(v, "press", centre, left, left, None)
    for f in np.linspace(0.0, 1.0, 6)[1:]:
        send_mouse(v, "move", centre + f * np.array([40.0, 10.0]), None, left, None)
        v.draw_now()
    send_mouse(v, "release", centre + np.array([40.0, 10.0]), left, None, None)
    v.draw_now()
    assert w.undo_stack.count() == 1
    w.close()

sigs = sorted(
    f"{d.py_func.__module__}:{d.py_func.__qualname__} {s}"
    for d in gc.get_objects() if isinstance(d, Dispatcher) for s in d.signatures
)
parallel = sorted(
    f"{d.py_func.__module__}:{d.py_func.__qualname__}"
    for d in gc.get_objects() if isinstance(d, Dispatcher) and d.signatures
    and d.targetoptions.get("parallel")
)
print(json.dumps({"signatures": sigs, "compiled": compiled, "parallel": parallel}))
"""


def _run(what: str, mode: str, env: dict) -> dict:
    command = [sys.executable, "-c", SCRIPT, what, mode]
    out = subprocess.run(command, env=env, capture_output=True, text=True, timeout=900, check=False)
    assert out.returncode == 0, out.stderr[-3000:]
    return json.loads(out.stdout.strip().splitlines()[-1])


@pytest.mark.slow(seconds=12)
@pytest.mark.parametrize("mode", ["serial", "parallel"])
def test_the_first_screen_compiles_nothing_after_the_startup_steps(mode):
    """Both processes use the same cache (the worktree's, usually warm: then both load, and the
    first screen's signatures must be among those the startup steps loaded or compiled; from
    an empty cache the startup steps compile them and the first screen must compile nothing).
    On the serial twins, the only parallel kernels are the strand rasterizer's (not twinned: the
    viewport draws with GL until they are cached)."""
    env = dict(os.environ)
    startup = _run("startup", mode, env)
    screen = _run("screen", mode, env)
    missing = sorted(set(screen["signatures"]) - set(startup["signatures"]))
    needed = "the first screen needs kernels the startup steps do not compile:\n"
    assert not missing, needed + "\n".join(missing)
    assert not screen["compiled"], "compiled on the GUI thread:\n" + "\n".join(screen["compiled"])
    if mode == "serial":
        ran = [name for name in screen["parallel"] if not name.startswith("app.render.soft_raster:")]
        assert not ran, "parallel kernels on the serial start:\n" + "\n".join(ran)
    else:
        assert {"hairtool.frozen.freeze:_freeze_kernel", "hairtool.frozen.align:_align_kernel"} <= set(
            screen["parallel"]
        )


def test_the_engine_step_ends_with_a_full_run_on_an_updated_list(monkeypatch):
    """The warm-up's engine step ends with a full run whose neighbour list is updated, not built
    (neighbour_update's cost model could make it build): so the update's kernels are among
    those it compiles, for the first full run after a stroke (an undo, a parameter) on any groom."""
    from app.ui import kernel_warmup
    from hairtool.frozen.pipeline import FrozenPipeline

    updated = []
    update = FrozenPipeline.update

    def spy(self):
        out = update(self)
        updated.append(self.neighbour_updates)
        return out

    monkeypatch.setattr(FrozenPipeline, "update", spy)
    kernel_warmup._engine_step()
    assert updated and updated[-1] >= 1


#: The warm-up's parallel engine step, then the bear (a dense real groom) opened with the studio's
#: engine parameters and dragged with a brush whose moves' regions reach the parallel kernels:
#: prints the moves' region sizes and the kernel signatures the moves added to the process.
#: What both scripts below start with: ``sigs()``, the kernel signatures loaded in the process.
SIGNATURES = r"""
import gc
from numba.core.dispatcher import Dispatcher

def sigs():
    return {
        f"{d.py_func.__module__}:{d.py_func.__qualname__} {s}"
        for d in gc.get_objects() if isinstance(d, Dispatcher) for s in d.signatures
    }
"""

DENSE = (
    SIGNATURES
    + r"""
import json, sys
import numpy as np
from app.ui import kernel_warmup
from hairtool import io
from hairtool.frozen import local
from hairtool.frozen.pipeline import FrozenParams, FrozenPipeline


for label, step in kernel_warmup.STEPS:
    if label == kernel_warmup.PARALLEL_ENGINE_STEP:
        step()
g = io.read_groom(sys.argv[1])
pipe = FrozenPipeline(g, FrozenParams(**kernel_warmup.STUDIO_PARAMS))
pipe.update()
before = sigs()
lo, hi = g.bounds
extent = float(np.max(hi - lo))
tips = g.tips.astype(np.float64)
tip = tips[np.argmin(np.linalg.norm(tips - (lo + hi) / 2.0, axis=1))]
regions = []
for i in range(2):
    pipe.align(tip + np.array([0.01 * i * extent, 0.0, 0.0]), 0.08 * extent, 0.8)
    regions.append(pipe.clump_redone * g.vertex_count)
print(json.dumps({"regions": regions, "serial_below": local.SERIAL_BELOW, "new": sorted(sigs() - before)}))
"""
)


def _report(script: str, *args) -> dict:
    """The JSON line ``script`` prints last, run in a fresh process (no kernel loaded before)."""
    command = [sys.executable, "-c", script, *map(str, args)]
    out = subprocess.run(command, capture_output=True, text=True, timeout=900, check=False)
    assert out.returncode == 0, out.stderr[-3000:]
    return json.loads(out.stdout.strip().splitlines()[-1])


@pytest.mark.slow(seconds=10)
def test_a_dense_grooms_first_strokes_need_no_kernel_the_warm_up_left_out():
    """The bear's brush-local moves (regions of 4,000-5,000 vertices) run the parallel kernels
    that Sintel's small regions never reach; the warm-up's parallel engine step compiles them,
    so the first stroke on such a groom loads them instead of compiling (13 s on a quiet host)."""
    report = _report(DENSE, Path(__file__).parents[1] / "data" / "grooms" / "bear.tfx")
    assert all(r >= report["serial_below"] for r in report["regions"]), report["regions"]
    assert not report["new"], "kernels the warm-up does not compile:\n" + "\n".join(report["new"])


#: The warm-up's brushes step, then a Delete stroke with the studio's default rule (any segment
#: under the brush, Blender's): prints the strands before and after and the signatures it added.
DELETE = (
    SIGNATURES
    + r"""
import json
import numpy as np
from app.ui import kernel_warmup
from app.ui.brush_tool import BrushTool
from hairtool import samples
from hairtool.frozen.brushes import falloff_lut
from hairtool.frozen.pipeline import FrozenPipeline
from hairtool.frozen.sample_schema import BRUSH


kernel_warmup._brushes_step()
before = sigs()
groom = samples.scalp(strands=40, vertices=8)
pipe = FrozenPipeline(groom)
lo, hi = groom.bounds
tool = BrushTool()
sample = BRUSH.make(
    brush="delete", cursor=tuple(float(v) for v in groom.points[groom.offsets[5] + 4]),
    direction=(1.0, 0.0, 0.0), radius=0.05 * float(np.max(hi - lo)), strength=0.5,
    lut=tuple(falloff_lut("smooth").tolist()), view=None, start=True, any_segment=tool.delete_any_segment,
)
pipe.brush(sample)
print(json.dumps({"strands": [groom.strand_count, pipe.result.strand_count], "new": sorted(sigs() - before)}))
"""
)


def test_the_studios_default_delete_needs_no_kernel_the_warm_up_left_out():
    """The studio's Delete removes every strand with a segment under the brush (its default, a
    kernel of its own); the brushes step's samples take the schema's default (the root rule of
    older logs), so the step deletes once more by the studio's rule."""
    report = _report(DELETE)
    before, after = report["strands"]
    assert after < before  # the stroke deleted strands
    assert not report["new"], "kernels the warm-up does not compile:\n" + "\n".join(report["new"])
