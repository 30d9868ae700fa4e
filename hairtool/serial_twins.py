"""Serial twins of the parallel kernels a first start needs: they compile in half the time.

numba's ``parallel=True`` about doubles a kernel's compile time (the parfor passes, and the
gufunc each parallel loop becomes): from an empty cache, the studio's first screen (the engine
and Sintel's render hair) waited ~50 CPU seconds for its parallel kernels against ~21 for the
same kernels compiled serially. A kernel declared with :func:`twin_njit` is numba's usual
dispatcher, and it has a serial twin, compiled on demand from the same code without
``parallel``. Where the kernel calls other twinned kernels, its serial twin calls their serial
twins. The kernels give the same bytes at any thread count, so which of the two runs changes
the time only.

:func:`use_parallel` says which one the library's Python code calls: it points every module
name of a twinned kernel at that kernel or its twin (names that jitted code reads stay on the
parallel kernel, whose compiled code already holds its callees). The library runs parallel
unless told otherwise; the studio's first start runs serial until the warm-up has the parallel
kernels cached (:mod:`app.ui.engine_start`). A command runs serial on a small groom
(:func:`for_size`): there the parallel kernels cost twice the compiling and save no time.

A serial twin is cached under its own name (``<name>_serial``): numba's cache index tells
signatures apart, not compile options, so a twin under the kernel's own name would overwrite
(or be read as) the parallel kernel.
"""

from __future__ import annotations

import contextlib
import importlib
import pkgutil
import sys
import types
from collections.abc import Callable, Iterator

from numba import njit
from numba.core.dispatcher import Dispatcher

#: Suffix of a serial twin's qualified name (its cache files' name).
SERIAL_SUFFIX = "_serial"
#: Vertices from which a command runs the parallel kernels (:func:`for_size`). Below it the
#: serial twins ran ``hairtool freeze`` as fast or faster on the 2-core VM (loaded, warm cache:
#: 7,296 vertices 28 ms against 304; 192,000: 166 against 338; 720,000: 755 against 918;
#: 2,400,000: 3,055 against 2,229), and they compile in half the time.
PARALLEL_FROM_VERTICES = 1_000_000


class _Twin:
    __slots__ = ("fn", "options", "parallel", "serial")

    def __init__(self, fn: Callable, options: dict, parallel: Dispatcher) -> None:
        self.fn, self.options, self.parallel = fn, options, parallel
        self.serial: Dispatcher | None = None


_TWINS: dict[int, _Twin] = {}  # id(parallel dispatcher) → its twin record
_SERIAL: dict[int, _Twin] = {}  # id(serial twin) → the same record
_parallel = True


def twin_njit(**options) -> Callable[[Callable], Dispatcher]:
    """``numba.njit(cache=True, **options)``, with a serial twin (see the module doc). For the
    parallel kernels of the first screen, and for jitted functions that call them."""

    def wrap(fn: Callable) -> Dispatcher:
        dispatcher = njit(cache=True, **options)(fn)
        _TWINS[id(dispatcher)] = _Twin(fn, options, dispatcher)
        return dispatcher

    return wrap


def is_twinned(kernel: object) -> bool:
    """True for a :func:`twin_njit` kernel (the parallel dispatcher) or its serial twin."""
    return id(kernel) in _TWINS or id(kernel) in _SERIAL


def serial(kernel: Dispatcher) -> Dispatcher:
    """The serial twin of ``kernel`` (a :func:`twin_njit` dispatcher), made on first asking:
    the kernel's own code, its globals as they are now, with every twinned kernel among them
    replaced by its serial twin (so a module is whole when a twin is first made)."""
    twin = _TWINS.get(id(kernel)) or _SERIAL.get(id(kernel))
    if twin is None:
        raise TypeError(f"{kernel!r} is not a twin_njit kernel")
    if twin.serial is None:
        fn = twin.fn
        scope = dict(fn.__globals__)
        twin.serial = njit(cache=True, **dict(twin.options, parallel=False))(
            _copy(fn, scope)
        )  # made before its callees' twins, so a kernel that calls itself finds its own
        _SERIAL[id(twin.serial)] = twin
        for name in fn.__code__.co_names:
            value = scope.get(name)
            if id(value) in _TWINS:
                scope[name] = serial(value)
    return twin.serial


def _copy(fn: Callable, scope: dict) -> Callable:
    copy = types.FunctionType(fn.__code__, scope, fn.__name__, fn.__defaults__, fn.__closure__)
    copy.__qualname__ = fn.__qualname__ + SERIAL_SUFFIX
    copy.__module__, copy.__doc__ = fn.__module__, fn.__doc__
    copy.__kwdefaults__ = fn.__kwdefaults__
    return copy


def parallel_in_use() -> bool:
    return _parallel


def use_parallel(parallel: bool, modules: tuple[str, ...] = ("hairtool", "app")) -> None:
    """Point the Python names of the twinned kernels, in every loaded module of ``modules``'
    packages, at the parallel kernels (True) or their serial twins (False)."""
    global _parallel
    _parallel = bool(parallel)
    read_by_jit = _read_by_jitted_code()
    for module in list(sys.modules.values()):
        name = getattr(module, "__name__", "") or ""
        if name.split(".")[0] not in modules:
            continue
        scope = vars(module)
        for attr, value in list(scope.items()):
            twin = _TWINS.get(id(value)) or _SERIAL.get(id(value))
            if twin is None or id(twin.parallel) in read_by_jit:
                continue
            scope[attr] = twin.parallel if parallel else serial(twin.parallel)


@contextlib.contextmanager
def for_size(vertices: int, packages: tuple[str, ...]) -> Iterator[bool]:
    """Within the block, the serial twins for a groom of fewer than
    :data:`PARALLEL_FROM_VERTICES` ``vertices`` (yields whether it runs parallel); the
    parallel kernels again after it. Every module of ``packages`` (the kernels' packages, such
    as ``"hairtool.frozen"``) is imported first, so that none loaded within the block names a
    parallel kernel: a cold command then compiles the serial twins alone."""
    if vertices >= PARALLEL_FROM_VERTICES or not _parallel:
        yield _parallel
        return
    for package in packages:
        for module in pkgutil.iter_modules(importlib.import_module(package).__path__):
            importlib.import_module(f"{package}.{module.name}")
    use_parallel(False)
    try:
        yield False
    finally:
        use_parallel(True)


def _read_by_jitted_code() -> set[int]:
    """ids of the twinned kernels that another twinned kernel calls (their module names must
    stay on the parallel kernel: it is what the parallel callers compile against)."""
    read = set()
    for twin in list(_TWINS.values()):
        for name in twin.fn.__code__.co_names:
            value = twin.fn.__globals__.get(name)
            if id(value) in _TWINS:
                read.add(id(value))
    return read


def parallel_of(kernel: Dispatcher) -> Dispatcher:
    """The parallel kernel of a twin (``kernel`` itself, or the kernel of a serial twin)."""
    twin = _TWINS.get(id(kernel)) or _SERIAL.get(id(kernel))
    if twin is None:
        raise TypeError(f"{kernel!r} is not a twin_njit kernel")
    return twin.parallel
