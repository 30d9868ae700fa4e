"""Compiling the studio's numba kernels in separate processes, so a first start shows the window
at once (no Qt here: :mod:`app.ui.engine_start` runs this and shows its progress).

``python -m app.ui.kernel_warmup`` runs the engine and the strand rasterizer once on a small
groom, in the order the studio needs them, which compiles every kernel they call into numba's
on-disk cache; each finished step prints ``step I N LABEL`` (I: the step's place in
:data:`STEPS`). The studio then loads the kernels from the cache (a fraction of a second)
instead of compiling them on its GUI thread (a minute on two cores, with the window frozen).
Other processes, not threads: numba compiles holding the GIL, so a compiling thread would stall
the window as surely as compiling in it.

Compiling is single-threaded, so the studio runs one process per :data:`LANES` entry
(``--lane K``): on two cores the engine's kernels and the render hair's compile side by side.
The first screen's steps compile serial twins of its parallel kernels first (half numba's
compile time, :mod:`hairtool.serial_twins`), the studio runs on those, and switches to the
parallel kernels when their steps are done. ``--no-quick`` leaves the twins out: a warm-up
ahead of a start (:mod:`app.ui.warm_cache`) caches every kernel, and that start runs parallel.
:mod:`app.ui.warm_cache` (what ``./dev`` runs after installing) runs the lanes from a terminal
with one progress line.

:func:`kernels_cached` tells a start whether that is needed: the warm-up records the kernels it
compiled (one record per lane), and they are cached when numba's index for each still matches
its source and the records cover every step.

Started by the studio (``--with-parent``), the warm-up ends quietly as soon as the studio does,
however it ends (Quit, a crash, a kill): its standard input is the studio's pipe, and a thread
that waits on it ends the process at end-of-file. A closed output pipe or Ctrl+C in the terminal
ends it quietly too, never with a traceback; what it compiled so far stays cached (numba writes
each cache file whole, by renaming).
"""

from __future__ import annotations

import importlib
import json
import os
import pkgutil
import sys
from collections.abc import Callable
from pathlib import Path

import numpy as np

from app.ui import action_warmup, startup_trace

#: Packages and modules whose kernels the warm-up's steps compile (searched for numba dispatchers).
KERNEL_PACKAGES = (
    "hairtool.character",
    "hairtool.frozen",
    "hairtool.frozen.brushes",
    "hairtool.guides",
    "hairtool.keys",
    "hairtool.anime",
    "hairtool.simulate",
)
KERNEL_MODULES = (
    "hairtool.bounds",
    "app.render.ramps",
    "app.render.soft_raster",
    "app.render.hair_shading",
    "app.render.screen_pick",
)


def record_path(lane: int | None = None) -> Path:
    """Where the warm-up records the kernels it compiled (the user's cache folder): one file for
    a warm-up of every step, one per lane (1, 2, …) for the studio's lanes."""
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    name = "studio-kernels.json" if lane is None else f"studio-kernels-lane{lane}.json"
    return Path(base) / "hairtool" / name


def _dispatchers() -> dict[str, object]:
    """``module:function`` → numba dispatcher, for every cached kernel of :data:`KERNEL_PACKAGES`'
    modules and of :data:`KERNEL_MODULES` (a twinned kernel twice: ``module:function`` the
    parallel one, ``module:function_serial`` its serial twin, whichever the module names now)."""
    from numba.core.dispatcher import Dispatcher

    from hairtool import serial_twins

    names = list(KERNEL_MODULES)
    for package in KERNEL_PACKAGES:
        path = importlib.import_module(package).__path__
        names += [f"{package}.{m.name}" for m in pkgutil.iter_modules(path)]
    found = {}
    for name in names:
        try:
            module = importlib.import_module(name)
        except ImportError:  # a module the engine no longer has
            continue
        for attr, value in vars(module).items():
            if not isinstance(value, Dispatcher) or getattr(value, "_cache", None) is None:
                continue
            if serial_twins.is_twinned(value):
                value = serial_twins.parallel_of(value)
                found[f"{name}:{attr}{serial_twins.SERIAL_SUFFIX}"] = serial_twins.serial(value)
            found[f"{name}:{attr}"] = value
    return found


def use_parallel(parallel: bool) -> None:
    """Run the engine's and the render hair's kernels parallel (True) or on their quicker-to-
    compile serial twins (:mod:`hairtool.serial_twins`), in this process from now on: every
    kernel module is imported first, so each one's names are pointed at the chosen kernels."""
    from hairtool import serial_twins

    _dispatchers()
    serial_twins.use_parallel(parallel)


def _has_cache(dispatcher: object) -> bool:
    """True when numba's on-disk index for ``dispatcher`` exists and matches its source."""
    from hairtool.kernel_loading import cache_index

    return bool(cache_index(dispatcher))


def _read_record(path: Path) -> tuple[set[str], set[str]]:
    """(steps, kernels) of one record; empty sets when it is missing or unreadable."""
    try:
        record = json.loads(path.read_text())
        return set(map(str, record["steps"])), set(map(str, record["kernels"]))
    except (OSError, ValueError, KeyError, TypeError):
        return set(), set()


def kernels_cached() -> bool:
    """True when the warm-up's records cover every step (the :data:`QUICK_STEPS` aside: a
    start with all cached runs parallel) and every kernel they name is still in numba's cache;
    False on a first start, after the caches were cleared, after a kernel's source changed, or
    when a warm-up was stopped before its end."""
    needed = set(lane_labels(None, quick=False))
    steps, names = _read_record(record_path())
    if not needed <= steps:  # no whole warm-up: the lanes' records together
        steps, names = set(), set()
        for lane in range(1, len(LANES) + 1):
            lane_steps, lane_names = _read_record(record_path(lane))
            steps, names = steps | lane_steps, names | lane_names
    if not names or not needed <= steps:
        return False
    found = _dispatchers()
    return all(n in found and _has_cache(found[n]) for n in names)


#: The studio's engine parameters for a new scene (``app.ui.scene.Scene``'s default; that module
#: is Qt): the first screen's kernels are compiled for exactly these.
STUDIO_PARAMS = {"keep_lengths": True}


def _sintel():
    """The first screen's groom and head: the bundled Sintel (228 guides), read as the studio
    reads her, so every kernel is compiled for the very types (float32 points) it will meet."""
    from app import resources
    from hairtool import io
    from hairtool.io.obj import read_mesh

    return io.read_groom(resources.path(resources.SINTEL_HAIR)), read_mesh(
        resources.path(resources.SINTEL_HEAD)
    )


def _engine_step() -> None:
    """Sintel's engine on her head and a short align drag as the viewport makes it (front faces
    only, kept out of the head)."""
    from app.ui.brush_tool import BrushTool
    from hairtool.frozen.brushes import scalp_centre
    from hairtool.frozen.pipeline import FrozenParams, FrozenPipeline
    from hairtool.guides.planting import HeadSurface

    groom, head = _sintel()
    # on her head, as the studio runs it: the strokes keep out of it (surface collision)
    pipe = FrozenPipeline(groom, FrozenParams(**STUDIO_PARAMS), HeadSurface(head))
    lo, hi = groom.bounds
    centre = (lo.astype(np.float64) + hi) * 0.5
    extent = float(np.max(hi - lo))
    tool = BrushTool()
    tool.reset_radius(0.3 * extent)
    plane = float(scalp_centre(groom)[0])
    for i in range(3):  # the first sample and the incremental ones after it
        cursor = centre + np.array([0.05 * i * extent, 0.0, 0.0])
        pipe.apply_samples(tool.samples(cursor, (1.0, 0.0, 0.0), (0.0, 0.0, -1.0), plane))
        tool.touches(pipe.aligned.points, cursor, plane)
    pipe.update()  # a full run after the drag (an undo's)
    # and one after a short drag on the front hair, whose list is brought up to date, not built
    # (the drag above reaches strands all round the head by sight: the cost model builds it)
    front = np.array([centre[0], centre[1], float(hi[2]) - 0.1 * extent])
    pipe.apply_samples(tool.samples(front, (1.0, 0.0, 0.0), (0.0, 0.0, -1.0), plane))
    pipe.update()
    _press_step(pipe)


def _press_step(pipe) -> None:
    """What a press asks before a stroke: the vertex nearest the mouse on screen, front faces
    only (by root normal, or by sight on a head) or not (the viewport's hair_under, without a
    viewport)."""
    from app.render.camera import Camera
    from app.render.screen_pick import nearest_on_screen
    from hairtool.frozen.brushes import facing_away
    from hairtool.frozen.brushes.sight import hidden_points

    result = pipe.result
    view = Camera().view_projection(640, 480)
    away = facing_away(pipe.strand_normals, (0.0, 0.0, -1.0))
    for skip in (None, away):
        nearest_on_screen(
            result.points, view, (640, 480), (320.0, 240.0), 40.0, result.topology.strand_index, skip
        )
    grid = getattr(pipe.surface, "face_grid", None)
    if grid is not None:  # the press's vertex; a box selection's, Add's and Density's float64 points
        hidden_points(result.points[:1], (0.0, 0.0, -1.0), grid)
        hidden_points(result.points[:1].astype(np.float64), (0.0, 0.0, -1.0), grid)


def _head_step() -> None:
    """Sintel's head as the engine's strokes meet it (closest points, inside test, first hit), compiled
    apart from the engine's step so that the other process can do it first: the largest of
    the drag's kernels, and one whose types do not depend on the groom's (float64 always)."""
    from hairtool.guides.planting import HeadSurface

    groom, head = _sintel()
    surface = HeadSurface(head)
    points = groom.points.astype(np.float64)
    few = np.concatenate([points[:: max(len(points) // 64, 1)], points[:1] + 1e3])  # one far away
    for ask in (points, few):  # a whole groom on every thread, a stroke's few on this one
        surface.project(ask)
        surface.signed_distance(ask)
    # the head under the mouse: a press's and a perspective Add or Density sample's aim
    surface.ray_hit(points[0] + 1e3, -1e3 * np.ones(3))


def _scalp_engine_step() -> None:
    """The engine with the engine's own defaults (keep lengths off) on a procedural groom."""
    from hairtool import samples
    from hairtool.frozen.pipeline import FrozenParams, FrozenPipeline

    groom = samples.scalp(strands=60, vertices=12)
    pipe = FrozenPipeline(groom, FrozenParams())
    lo, hi = groom.bounds
    centre = (lo.astype(np.float64) + hi) * 0.5
    extent = float(np.max(hi - lo))
    for i in range(3):
        pipe.align(centre + np.array([0.05 * i * extent, 0.0, 0.0]), 0.3 * extent, 0.8, "paper")


def _more_engine_step() -> None:
    from dataclasses import replace

    from hairtool import samples
    from hairtool.frozen.pipeline import FrozenParams, FrozenPipeline

    groom = samples.portrait(strands=30, vertices=10)
    params = replace(FrozenParams(), keep_lengths=True, gap_mode="text", strand_variation=0.5)
    pipe = FrozenPipeline(groom, params)
    lo, hi = groom.bounds
    pipe.align((lo.astype(np.float64) + hi) * 0.5, float(np.max(hi - lo)), 0.5, "preserve-length")


def _raster_step() -> list[int]:
    """Draw, redraw the changed tiles, and redraw told what moved: the tiles it redrew each
    time (a tile redraw needs few changed tiles: short strands on an image of many tiles)."""
    from app.render.ramps import ramp_texture, sample_linear
    from app.render.soft_raster import StrandRaster
    from app.render.strands import RAMP_TEXELS

    sample_linear(ramp_texture("root-tip", RAMP_TEXELS), np.linspace(0.0, 1.0, 8))  # the strands' colours
    rng = np.random.default_rng(0)
    strands, per = 24, 4
    roots = rng.uniform(-0.8, 0.8, (strands, 3))
    rise = np.linspace(0.0, 0.06, per)[None, :, None] * np.array([0.0, 1.0, 0.0])
    points = (roots[:, None, :] + rise).reshape(-1, 3).astype(np.float32)
    starts = (np.arange(strands)[:, None] * per + np.arange(per - 1)).reshape(-1).astype(np.int64)
    colors = rng.uniform(0.0, 1.0, (points.shape[0], 3)).astype(np.float32)
    mvp = np.eye(4)
    redrawn = []
    for width in (2.0, 1.0):
        raster = StrandRaster()
        raster.draw(points, starts, colors, mvp, (256, 192), width)
        moved = points.copy()
        moved[1] += 0.01
        raster.draw(moved, starts, colors, mvp, (256, 192), width)  # the tiles-only redraw
        redrawn.append(raster.tiles_redrawn)
        moved[per + 1] += 0.01
        raster.draw(moved, starts, colors, mvp, (256, 192), width, changed=[[per, 2 * per]])  # told
        redrawn.append(raster.tiles_redrawn)
    return redrawn


def _brushes_step() -> None:
    from hairtool import samples
    from hairtool.frozen.brushes import falloff_lut, registry
    from hairtool.frozen.pipeline import FrozenPipeline
    from hairtool.frozen.sample_schema import BRUSH

    class Flat:  # a surface for slide: the plane through each point, facing up
        def project(self, points):
            return np.asarray(points, np.float64), np.tile([0.0, 1.0, 0.0], (len(points), 1))

    groom = samples.scalp(strands=40, vertices=8)
    pipe = FrozenPipeline(groom, surface=Flat())
    lo, hi = groom.bounds
    centre = tuple(float(v) for v in (lo.astype(np.float64) + hi) * 0.5)
    lut = tuple(falloff_lut("smooth").tolist())
    for spec in registry.specs()[1:]:  # align has its own step
        if spec.needs_surface and spec.changes_strands:  # they plant with render hair's binding (warmed)
            continue
        strength = -0.5 if spec.signed else 0.5
        radius = float(np.max(hi - lo)) * (0.05 if spec.changes_strands else 1.0)  # not every strand
        pipe.brush(  # (a stroke's first sample: a snake hook hooks there)
            BRUSH.make(brush=spec.name, cursor=centre, direction=(1.0, 0.0, 0.0), radius=radius,
                       strength=strength, lut=lut, view=None, start=True)
        )  # fmt: skip
    # Delete's studio default, Blender's rule (any segment under the brush: its own kernel); the
    # samples above take the schema's default, the root rule of older logs
    radius = 0.05 * float(np.max(hi - lo))
    pipe.brush(
        BRUSH.make(brush="delete", cursor=centre, direction=(1.0, 0.0, 0.0), radius=radius, strength=0.5,
                   lut=lut, view=None, start=True, any_segment=True)
    )  # fmt: skip

    from hairtool.frozen.brushes.add import append_strands
    from hairtool.frozen.density import accept, thin
    from hairtool.frozen.root_grid import nearest_root

    pts = groom.roots.astype(np.float64)
    accept(pts[:8], pts[8:], 0.1)  # density's own kernels
    thin(pts, np.zeros(len(pts), bool), 0.1)
    # Add and Density on a groom without render hair: new strands take their nearest old root's
    # look, a root search in the groom's own precision (float32 here), and Add plants on the head
    # with one in float64 (the render hair's too)
    append_strands(groom, samples.scalp(strands=4, vertices=8, seed=3))
    nearest_root(pts, pts[:4])


def _render_hair_step() -> None:
    """Sintel's render hair as the studio makes it (bound on her scalp, built in place from the
    moved guides, shaded), with fewer children: the same kernels, the same types."""
    from app import resources
    from app.render.hair_shading import light_and_eye, shade
    from hairtool.bounds import box
    from hairtool.guides.binding import bind_scalp
    from hairtool.guides.children import build_points, moved_guides

    guides, mesh = _sintel()
    binding = bind_scalp(guides, mesh, 300, seed=resources.SINTEL_CHILD_SEED)
    drawn = np.empty((binding.vertex_count, 3), np.float32)
    source = np.full((guides.vertex_count, 3), np.nan, np.float32)
    build_points(binding, guides, out=drawn, moved=moved_guides(guides, source))
    # as the renderer takes them: its box, and shading from its read-only points and topology
    # (numba compiles read-only arrays apart from writable ones)
    box(drawn)
    points, offsets = drawn.copy(), binding.offsets.copy()
    for a in (points, offsets):
        a.setflags(write=False)
    light, eye = light_and_eye(np.array([1.0, 0, 0]), np.array([0, 1.0, 0]), np.array([0, 0, -1.0]))
    base = np.ones((len(drawn), 3), np.float32)
    shade(points, offsets, base, light, eye, out=np.empty((len(drawn), 3), np.float32))
    # and a move's changed strands, gathered into writable arrays of their own
    shade(drawn.copy(), binding.offsets.copy(), base, light, eye, out=np.empty((len(drawn), 3), np.float32))


def _clumped_hair_step() -> None:
    """Render hair bound to given roots (what Grow render hair… reaches), and clumped as the
    studio's Clump children clumps it (its engine's passes, gaps and length rule)."""
    from app.render.hair_shading import light_and_eye, shade
    from hairtool import samples
    from hairtool.frozen.pipeline import FrozenParams
    from hairtool.guides.binding import bind_roots
    from hairtool.guides.children import moved_guides
    from hairtool.guides.render import ChildClump, RenderHair

    guides = samples.scalp(strands=12, vertices=8)
    roots = guides.points[guides.topology.offsets[:-1]].astype(np.float64)
    rng = np.random.default_rng(0)
    roots = roots[rng.integers(0, len(roots), 60)] + rng.normal(0.0, 1e-3, (60, 3))
    binding = bind_roots(guides, roots, k=3, seed=0)
    children = RenderHair(binding).update(guides)
    moved_guides(guides, np.array(guides.points))
    clumped = RenderHair(binding, ChildClump.following(FrozenParams(**STUDIO_PARAMS)))
    clumped.update_points(guides)
    bent = guides.points.copy()
    bent[guides.topology.tip_indices[::2]] += np.float32([0.0, 0.0, 1e-3])
    clumped.update_points(guides.with_points(bent))  # a release after a stroke: the moved guides' clumps
    light, eye = light_and_eye(np.array([1.0, 0, 0]), np.array([0, 1.0, 0]), np.array([0, 0, -1.0]))
    base = np.ones((len(children.points), 3), np.float32)
    shade(children.points, children.topology.offsets, base, light, eye)


def _animation_step() -> None:
    from hairtool import samples
    from hairtool.anime.settings import AnimeSettings, cycle_for_groom
    from hairtool.keys import session as ks
    from hairtool.simulate.options import SimulateOptions, run_simulation

    groom = samples.scalp(strands=20, vertices=8)
    anim = run_simulation(groom, SimulateOptions(frames=12, substeps=2), lambda *a: None, lambda: False)
    cycle_for_groom(groom, AnimeSettings())
    solves = (("total", "linear"), ("total", "hermite"), ("total", "hermite-fit"), ("worst", "linear"))
    for objective, interp in solves:
        session = ks.solve(anim, ks.KeySettings(objective=objective, interp=interp))
        keys = session.keys_for_count(4)
        ks.analyse(anim, keys, interp)
    # a price per key (the timeline's tau mode, a capture's per-channel keys): a DP of its own
    ks.solve(anim, ks.KeySettings()).keys_for_tau(0.05)


#: The step after which the bundled sample's render hair can be bound and shaded without compiling.
RENDER_HAIR_STEP = "render hair"
#: The step after which the engine can start: Sintel's pipeline on her head and an align drag.
ENGINE_STEP = "hair engine"
#: The step after which the viewport can draw with the CPU strand rasterizer (on software GL).
RASTER_STEP = "strand drawing"
#: The step after which Clump children clumps the render hair without compiling (on a first
#: start the render hair shows unclumped until then, and until the studio runs parallel).
CLUMPED_HAIR_STEP = "clumped render hair"
#: Part of the align drag's kernels (the head's closest points), apart so the lanes share them.
HEAD_STEP = "head surface"

#: The steps after which the first screen (Sintel, her render hair shaded and drawn, an align
#: drag) compiles nothing: tests/gui/test_studio_first_screen_kernels.py checks it.
FIRST_SCREEN = (HEAD_STEP, ENGINE_STEP, RENDER_HAIR_STEP, RASTER_STEP)

#: The first screen's steps that compile the serial twins of its parallel kernels
#: (:mod:`hairtool.serial_twins`: half the compile time), on which a first start runs until
#: the :data:`PARALLEL_STEPS` are done. A start with every kernel cached needs none of them.
QUICK_STEPS = (HEAD_STEP, ENGINE_STEP, RENDER_HAIR_STEP)
#: The engine's (with the head's) and the render hair's parallel kernels.
PARALLEL_ENGINE_STEP = "hair engine, parallel"
PARALLEL_RENDER_HAIR_STEP = "render hair, parallel"
#: The steps after which the studio switches from the serial twins to the parallel kernels.
PARALLEL_STEPS = (PARALLEL_ENGINE_STEP, PARALLEL_RENDER_HAIR_STEP)
#: Studio actions past the first screen with kernels of their own (:mod:`app.ui.action_warmup`).
CHARACTER_STEP = "character spring bones"
CLUMP_COLOURS_STEP = "colour by clump"
PICKED_GUIDES_STEP = "picked guides"


def _serially(step: Callable[[], None]) -> Callable[[], None]:
    """``step`` run on the serial twins (and the process back on the parallel kernels after)."""

    def run() -> None:
        use_parallel(False)
        try:
            step()
        finally:
            use_parallel(True)

    run.__name__ = run.__qualname__ = step.__name__
    return run


def _parallel_engine_step() -> None:
    """The first screen's engine on the parallel kernels, then its drags again with every
    brush-local move on them too: a dense groom's regions (the bear's: 4,000-9,000 vertices a
    comb move) take the parallel kernels that Sintel's small regions never reach, and without
    this the first stroke on such a groom compiled them (about 13 s on a quiet 2-core host)."""
    from hairtool.frozen import local

    _head_step()
    _engine_step()
    with local.parallel_from(0):
        _engine_step()


#: (label, step) in the order a single process runs them: the engine for the first groom, the
#: render hair (the bundled sample's children wait for it), the rasterizer for software GL, the
#: same engine and render hair on the parallel kernels, then what other brush modes and settings
#: reach, the other brushes, what opening an animation needs (simulation, anime waves, keys),
#: and the studio actions with kernels of their own (a character's spring bones, colours by
#: clump, picked guides): without these, the first use of each compiled it inside the studio,
#: on a job or the GUI thread.
_STEPS: tuple[tuple[str, Callable[[], None]], ...] = (
    (HEAD_STEP, _serially(_head_step)),
    (ENGINE_STEP, _serially(_engine_step)),
    (RENDER_HAIR_STEP, _serially(_render_hair_step)),
    (RASTER_STEP, _raster_step),
    (PARALLEL_ENGINE_STEP, _parallel_engine_step),
    (PARALLEL_RENDER_HAIR_STEP, _render_hair_step),
    ("brush modes and settings", _more_engine_step),
    ("engine defaults", _scalp_engine_step),
    (CLUMPED_HAIR_STEP, _clumped_hair_step),
    ("grooming brushes", _brushes_step),
    ("animation and keys", _animation_step),
    (CHARACTER_STEP, action_warmup.character_step),
    (CLUMP_COLOURS_STEP, action_warmup.clump_colours_step),
    (PICKED_GUIDES_STEP, action_warmup.picked_guides_step),
)

#: The studio's warm-up processes, one per core of the two-core reference machine, each a list
#: of step labels: the engine in one, the head surface (part of the engine's align drag) and
#: the render hair in the other, so the first screen's compiles run side by side, then the
#: parallel kernels and the rest (CPU seconds on a quiet two-core host, empty cache: engine 12.5
#: serial, 25.6 parallel; head 2.9 / 4.4; render hair 5.8 / 11.6; strand drawing 10.7). The
#: studio actions' steps close the render hair's lane, the one that ended first (CPU seconds on a
#: loaded host: character spring bones 12.9, colour by clump 2.7, picked guides 1.1); in the
#: quietest run of ``python -m app.ui.warm_cache`` the lanes ended 8 s apart, at 116 and 108 s.
LANES: tuple[tuple[str, ...], ...] = (
    (ENGINE_STEP, PARALLEL_ENGINE_STEP, "brush modes and settings", "engine defaults", "grooming brushes"),
    (HEAD_STEP, RENDER_HAIR_STEP, RASTER_STEP, PARALLEL_RENDER_HAIR_STEP, CLUMPED_HAIR_STEP,
     PICKED_GUIDES_STEP, "animation and keys", CHARACTER_STEP, CLUMP_COLOURS_STEP),
)  # fmt: skip


def _traced(i: int, label: str, step: Callable[[], None]) -> Callable[[], None]:
    """``step``, then its moment for ``python -m app.bench --cold-start`` (HAIRTOOL_STARTUP_TRACE)."""

    def run() -> None:
        step()
        startup_trace.mark("warmup-step", f"{i + 1}/{len(_STEPS)} {label}")

    run.__name__ = run.__qualname__ = step.__name__
    return run


STEPS = tuple((label, _traced(i, label, step)) for i, (label, step) in enumerate(_STEPS))


def lane_labels(lane: int | None, quick: bool = True) -> list[str]:
    """The step labels of lane ``lane`` (1-based) or of every step; ``quick=False``: without the
    :data:`QUICK_STEPS` (a warm-up ahead of the studio's start, as ``./dev`` runs)."""
    labels = [label for label, _ in STEPS] if lane is None else list(LANES[lane - 1])
    return [label for label in labels if quick or label not in QUICK_STEPS]


def lane_steps(lane: int | None, quick: bool = True) -> list[tuple[int, str, Callable[[], None]]]:
    """(index in :data:`STEPS`, label, step) of :func:`lane_labels`."""
    index = {label: i for i, (label, _) in enumerate(STEPS)}
    return [(index[label], label, STEPS[index[label]][1]) for label in lane_labels(lane, quick)]


def _end_with_parent() -> None:
    """End the process when its standard input (the studio's pipe) reaches end-of-file."""
    import threading

    def wait() -> None:
        try:
            while sys.stdin.buffer.read(4096):
                pass
        except (OSError, ValueError):
            pass
        os._exit(0)  # the studio is gone: nobody reads the progress any more

    threading.Thread(target=wait, name="warm-up-parent", daemon=True).start()


def _quietly_gone() -> int:
    """Standard output has no reader any more: stop without Python's flush error at exit."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except OSError:
        pass
    return 0


def _lane(argv: list[str]) -> int | None:
    if "--lane" not in argv:
        return None
    try:
        lane = int(argv[argv.index("--lane") + 1])
    except (IndexError, ValueError):
        lane = 0
    if not 1 <= lane <= len(LANES):
        raise SystemExit(f"kernel_warmup: --lane takes 1 to {len(LANES)}")
    return lane


def _record(lane: int | None, steps: list[str]) -> None:
    compiled = sorted(n for n, d in _dispatchers().items() if d.signatures)
    path = record_path(lane)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_suffix(f".tmp{os.getpid()}")
        tmp.write_text(json.dumps({"steps": steps, "kernels": compiled}, indent=1))
        tmp.replace(path)  # a lane's record whole or not at all
    except OSError:  # a read-only home: the next start warms up again, no worse than now
        pass


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    lane = _lane(argv)
    if "--with-parent" in argv:
        _end_with_parent()
    done: list[str] = []
    try:
        for i, label, step in lane_steps(lane, quick="--no-quick" not in argv):
            step()
            done.append(label)
            print(f"step {i + 1} {len(STEPS)} {label}", flush=True)
    except BrokenPipeError:
        return _quietly_gone()
    except KeyboardInterrupt:
        return 130
    _record(lane, done)
    return 0


def entry(argv: list[str] | None = None) -> None:
    """``python -m app.ui.kernel_warmup``: :func:`main`, then the exit. Started by the studio
    (``--with-parent``), the process leaves by ``os._exit`` once its output is flushed: the thread
    that waits on standard input holds that stream's lock, and Python's own shutdown aborted on it
    ("could not acquire lock for <stdin>", exit 134) at the end of every lane that went well."""
    argv = sys.argv[1:] if argv is None else argv
    code = main(argv)
    if "--with-parent" in argv:
        for stream in (sys.stdout, sys.stderr):
            try:
                stream.flush()
            except (OSError, ValueError):  # nobody reads it any more
                pass
        os._exit(code)
    sys.exit(code)


if __name__ == "__main__":
    entry()
