"""Which kernels a command runs the frozen pipeline on, and the ones a cold run compiles in a
second process (:mod:`hairtool.compile_ahead`), with the argument types the pipeline gives them.

On a small groom the pipeline runs the serial twins (:func:`hairtool.serial_twins.for_size`).
A cold ``freeze`` of Sintel's guides then spends about 4.7 of its 10.3 CPU seconds of compiling
on ClumpWithGaps' iterations (``_clump_run`` and its callees) and the brush grid's kernels,
which the pipeline needs only after FreezeDeform and the neighbour lists (the other 5.6): those
are the plan, so both halves compile at once.
``tests/frozen/test_compile_plan.py`` checks that a pipeline run calls each kernel with exactly
these types.
"""

from __future__ import annotations

import contextlib
import threading
from collections.abc import Iterator

from numba.core import types

from hairtool import compile_ahead, serial_twins
from hairtool.compile_ahead import Entry


def _array(dtype, ndim: int = 1, readonly: bool = False) -> types.Array:
    return types.Array(dtype, ndim, "C", readonly=readonly)


#: A groom's points as the pipeline holds them: float32, read-only.
_POINTS = _array(types.float32, 2, readonly=True)
_I32, _I64, _F64 = _array(types.int32), _array(types.int64), _array(types.float64)


def serial_plan() -> list[Entry]:
    """(serial kernel, argument types) for the serial pipeline, the longest compile first. (The
    kernels are imported here, not named by this module: the studio's warm-up lists every
    kernel its modules name.)"""
    from hairtool.frozen.clump import _clump_run
    from hairtool.frozen.neighbour_update import _moved_mask
    from hairtool.frozen.vertex_grid import _build, _count_blocks

    f64_2d = _array(types.float64, 2)
    lists = types.Tuple((_I32, _I64, _I64, _I32, _I64, _I64, f64_2d))  # pair lists, clump.py
    bufs = types.Tuple((f64_2d, f64_2d, f64_2d, _I64, _I64, _F64, _array(types.uint64), _F64))
    f64_3d = _array(types.float64, 3)
    record = types.Tuple((f64_3d, f64_3d, _array(types.int64, 2), _I64, _F64))  # iterates, forces, nearest
    run = (
        _POINTS, _F64, _I64, lists, _array(types.boolean), types.float64, types.int64, types.float64,
        types.int64, types.uint64, bufs, _array(types.float32, 2), record,
    )  # fmt: skip
    return [
        (serial_twins.serial(_clump_run), run),
        (_build, (_POINTS, types.float64, types.uint64, _I64, _I64, _I64, _I64)),
        (_count_blocks, (_I64, _I64, _I64, types.int64, _array(types.int32))),
        (
            serial_twins.serial(_moved_mask),
            (_POINTS, _POINTS, _array(types.boolean)),
        ),
    ]


@contextlib.contextmanager
def pipeline_kernels(vertices: int) -> Iterator[bool]:
    """Within the block, the pipeline's kernels for a groom of ``vertices`` (yields whether they
    run parallel): the serial twins on a small groom, with :func:`serial_plan` compiled in a
    second process where the cache lacks it (and that process stopped at the block's end). Not
    in a process that runs other threads (a farm's worker, which warms its cache at its start):
    a fork copies the calling thread alone, and a lock another one held would stay taken."""
    with serial_twins.for_size(vertices, ("hairtool.frozen",)) as parallel:
        alone = threading.active_count() == 1
        ahead = compile_ahead.start(serial_plan()) if alone and not parallel else None
        try:
            yield parallel
        finally:
            if ahead is not None:
                ahead.close()
