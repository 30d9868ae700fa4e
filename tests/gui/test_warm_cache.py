"""``./dev``'s warm-up from a terminal: the lanes run side by side and one line says how far."""

from __future__ import annotations

import io
import sys

import pytest

from app.ui import kernel_warmup, warm_cache

pytestmark = pytest.mark.gui  # the studio's warm-up (app/ lanes), with the studio's tests


def _fake_lanes(monkeypatch, code: int = 0) -> None:
    """Each lane replaced by a process that reports its steps as the warm-up numbers them."""
    index = {label: i for i, (label, _) in enumerate(kernel_warmup.STEPS)}
    total = len(kernel_warmup.STEPS)

    def command(lane: int) -> list[str]:
        labels = kernel_warmup.lane_labels(lane, quick=False)
        lines = [f"step {index[label] + 1} {total} {label}" for label in labels]
        script = f"import sys\nfor line in {lines!r}:\n    print(line, flush=True)\nsys.exit({code})"
        return [sys.executable, "-c", script]

    monkeypatch.setattr(warm_cache, "lane_command", command)


def test_the_progress_line_counts_both_lanes_steps(monkeypatch):
    _fake_lanes(monkeypatch)
    out = io.StringIO()
    assert warm_cache.warm(out=out) == 0
    lines = out.getvalue().splitlines()
    total = len(kernel_warmup.lane_labels(None, quick=False))
    counts = [line.split("] ")[1].split()[0] for line in lines[:-1]]
    assert counts == [f"{i}/{total}" for i in range(1, total + 1)]
    assert lines[-1].startswith("The studio's kernels are cached")


def test_a_failed_lane_says_the_studio_compiles_the_rest(monkeypatch):
    _fake_lanes(monkeypatch, code=3)
    out = io.StringIO()
    assert warm_cache.warm(out=out) == 3
    assert "the studio compiles the rest" in out.getvalue()


def test_if_needed_does_nothing_when_cached(monkeypatch):
    monkeypatch.setattr(kernel_warmup, "kernels_cached", lambda: True)
    monkeypatch.setattr(warm_cache, "lane_command", lambda lane: pytest.fail("a lane started"))
    out = io.StringIO()
    assert warm_cache.warm(if_needed=True, out=out) == 0 and out.getvalue() == ""


def test_the_terminal_warm_up_caches_the_parallel_kernels_only():
    """A start after ``./dev``'s warm-up finds every kernel cached and runs parallel: the serial
    twins of a first start are not compiled for it."""
    for lane in range(1, len(kernel_warmup.LANES) + 1):
        assert "--no-quick" in warm_cache.lane_command(lane)
        labels = kernel_warmup.lane_labels(lane, quick=False)
        assert labels and not set(labels) & set(kernel_warmup.QUICK_STEPS)
    assert set(kernel_warmup.PARALLEL_STEPS) <= set(kernel_warmup.lane_labels(None, quick=False))
