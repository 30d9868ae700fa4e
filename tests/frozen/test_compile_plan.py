"""The kernels a cold ``hairtool freeze`` compiles in a second process are the ones the serial
pipeline then calls, with the same argument types (a drifted type would compile twice), and a
small groom runs the serial twins while a large one keeps the parallel kernels."""

from __future__ import annotations

from hairtool import samples, serial_twins
from hairtool.frozen.compile_plan import serial_plan
from hairtool.frozen.pipeline import FrozenParams, FrozenPipeline


def test_the_serial_pipeline_calls_each_planned_kernel_with_the_planned_types():
    groom = samples.scalp(strands=40, vertices=8, seed=2)
    with serial_twins.for_size(groom.vertex_count, ("hairtool.frozen",)) as parallel:
        assert not parallel and not serial_twins.parallel_in_use()
        pipeline = FrozenPipeline(groom, FrozenParams(keep_lengths=True, redraw_noise=True))
        pipeline.settle()
        pipeline.update()  # new noise: the neighbour list brought up to date (_moved_mask)
        plan = serial_plan()
    assert serial_twins.parallel_in_use()
    for kernel, sig in plan:
        assert not kernel.targetoptions.get("parallel"), kernel
        assert sig in kernel.overloads, (kernel, sorted(map(str, kernel.overloads)))


def test_a_groom_past_the_threshold_keeps_the_parallel_kernels():
    import sys

    freeze = sys.modules["hairtool.frozen.freeze"]
    kernel = freeze._freeze_kernel
    with serial_twins.for_size(serial_twins.PARALLEL_FROM_VERTICES, ("hairtool.frozen",)) as parallel:
        assert parallel and freeze._freeze_kernel is kernel
    with serial_twins.for_size(serial_twins.PARALLEL_FROM_VERTICES - 1, ("hairtool.frozen",)) as parallel:
        assert not parallel and freeze._freeze_kernel is serial_twins.serial(kernel)
    assert freeze._freeze_kernel is kernel


def test_the_plan_is_compiled_ahead_only_for_serial_kernels_in_a_process_of_one_thread(monkeypatch):
    import threading

    from hairtool import compile_ahead
    from hairtool.frozen.compile_plan import pipeline_kernels

    plans = []
    monkeypatch.setattr(compile_ahead, "start", lambda plan: plans.append(plan))
    for threads, vertices, forks in ((1, 100, 1), (2, 100, 0), (1, serial_twins.PARALLEL_FROM_VERTICES, 0)):
        monkeypatch.setattr(threading, "active_count", lambda threads=threads: threads)
        plans.clear()
        with pipeline_kernels(vertices) as parallel:
            assert parallel == (vertices >= serial_twins.PARALLEL_FROM_VERTICES)
        assert len(plans) == forks, (threads, vertices)
    assert serial_twins.parallel_in_use()
