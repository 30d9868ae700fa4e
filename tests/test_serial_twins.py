"""Serial twins of the first screen's parallel kernels: the same bytes as the parallel kernels,
cached under names of their own, called by each other, and chosen for every module's names."""

from __future__ import annotations

import importlib
import pkgutil
import sys

import numpy as np
import pytest
from numba.core.dispatcher import Dispatcher

from hairtool import samples, serial_twins
from hairtool.frozen.pipeline import FrozenParams, FrozenPipeline

#: Where the twinned kernels live (and every jitted function that could call one).
PACKAGES = ("hairtool.frozen", "hairtool.guides")


def _modules():
    names = []
    for package in PACKAGES:
        path = importlib.import_module(package).__path__
        names += [f"{package}.{m.name}" for m in pkgutil.iter_modules(path)]
    return [importlib.import_module(n) for n in names] + [importlib.import_module("hairtool.bounds")]


@pytest.fixture
def serial_mode():
    _modules()
    serial_twins.use_parallel(False)
    yield
    serial_twins.use_parallel(True)


def _drag(groom):
    pipe = FrozenPipeline(groom, FrozenParams(keep_lengths=True))
    lo, hi = groom.bounds
    extent = float(np.max(hi - lo))
    tip = groom.tips[40].astype(np.float64)
    for k in range(4):  # brush-local moves and the clump kernels behind them
        pipe.align(tip + 0.04 * extent * np.array([np.cos(k), np.sin(k), 0.0]), 0.12 * extent, 0.8)
    pipe.align(tip, 2.0 * extent, 0.5)  # and a move over the whole groom
    return pipe.result.points.copy(), pipe.clump_redone


def test_the_engine_on_the_serial_twins_gives_the_parallel_engines_bytes():
    groom = samples.scalp(strands=300, vertices=10, seed=4)
    parallel, _ = _drag(groom)
    _modules()
    serial_twins.use_parallel(False)
    try:
        assert not serial_twins.parallel_in_use()
        serial, redone = _drag(groom)
    finally:
        serial_twins.use_parallel(True)
    assert redone == 1.0  # the last move ran in full
    assert serial.tobytes() == parallel.tobytes()


def test_render_hair_on_the_serial_twins_gives_the_same_bytes(serial_mode):
    from app.render.hair_shading import light_and_eye, shade
    from hairtool.guides.binding import bind_roots
    from hairtool.guides.render import RenderHair

    guides = samples.scalp(strands=20, vertices=8)
    roots = guides.points[guides.topology.offsets[:-1]].astype(np.float64)
    roots = roots[np.random.default_rng(0).integers(0, len(roots), 80)] + 1e-3
    light, eye = light_and_eye(np.array([1.0, 0, 0]), np.array([0, 1.0, 0]), np.array([0, 0, -1.0]))

    def render():
        children = RenderHair(bind_roots(guides, roots, k=3, seed=0)).update(guides)
        base = np.ones((len(children.points), 3), np.float32)
        return children.points.copy(), shade(children.points, children.topology.offsets, base, light, eye)

    serial = render()
    serial_twins.use_parallel(True)
    parallel = render()
    for a, b in zip(serial, parallel, strict=True):
        assert a.tobytes() == b.tobytes()


def test_a_twin_is_cached_apart_and_calls_serial_twins():
    from hairtool.frozen import spatial

    clump = sys.modules["hairtool.frozen.clump"]
    twin = serial_twins.serial(clump._clump_run)
    assert twin.py_func.__qualname__ == "_clump_run" + serial_twins.SERIAL_SUFFIX
    assert twin._cache._cache_file._index_name != clump._clump_run._cache._cache_file._index_name
    assert not twin.targetoptions.get("parallel") and clump._half_force_kernel.targetoptions["parallel"]
    # its callees are the serial twins; the parallel kernel's are the parallel kernels
    assert twin.py_func.__globals__["_half_force_kernel"] is serial_twins.serial(clump._half_force_kernel)
    assert clump._clump_run.py_func.__globals__["_half_force_kernel"] is clump._half_force_kernel
    assert serial_twins.serial(twin) is twin and serial_twins.parallel_of(twin) is clump._clump_run
    assert serial_twins.serial(spatial._row_sort).py_func.__globals__["_row_keys"] is serial_twins.serial(
        spatial._row_keys
    )
    with pytest.raises(TypeError, match="not a twin_njit kernel"):
        serial_twins.serial(spatial._scan_row)


def test_use_parallel_points_every_modules_names_and_leaves_jitted_callees_alone(monkeypatch):
    import types

    _modules()
    clump = sys.modules["hairtool.frozen.clump"]
    freeze = sys.modules["hairtool.frozen.freeze"]
    importer = types.ModuleType("hairtool._imports_keep_still")  # ``from ...clump import keep_still``
    importer.keep_still = clump.keep_still
    monkeypatch.setitem(sys.modules, importer.__name__, importer)
    serial_twins.use_parallel(False)
    try:
        assert freeze._freeze_kernel is serial_twins.serial(serial_twins.parallel_of(freeze._freeze_kernel))
        assert clump.keep_still.py_func.__qualname__.endswith(serial_twins.SERIAL_SUFFIX)
        assert importer.keep_still is clump.keep_still
        assert clump._half_force_kernel.targetoptions["parallel"]  # only _clump_run calls it: left parallel
    finally:
        serial_twins.use_parallel(True)
    assert clump.keep_still is serial_twins.parallel_of(clump.keep_still) is importer.keep_still


def test_no_plain_jitted_function_calls_a_twinned_kernel():
    """A jitted function that calls a twinned kernel must be twinned itself: otherwise it would
    compile the parallel kernel into itself on the serial start (the slow compile again)."""
    offenders = []
    for module in _modules():
        for name, value in vars(module).items():
            if not isinstance(value, Dispatcher) or serial_twins.is_twinned(value):
                continue
            scope = value.py_func.__globals__
            called = [n for n in value.py_func.__code__.co_names if serial_twins.is_twinned(scope.get(n))]
            if called:
                offenders.append(f"{module.__name__}.{name} calls {called}")
    assert not offenders, offenders
