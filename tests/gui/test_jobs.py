"""The job runner: results on the GUI thread, progress, cancel drops the result, errors become
one message, a newer job of a group supersedes the older (no window, no GL)."""

from __future__ import annotations

import threading

from PySide6.QtCore import QThread

from app.ui.jobs import JobRunner, JobStatus
from hairtool.errors import Cancelled, ParameterError


def test_result_arrives_on_the_gui_thread_with_progress(qapp):
    errors = []
    runner = JobRunner(lambda t, m: errors.append((t, m)))
    seen, progress_seen = [], []
    runner.progress_changed.connect(lambda job: progress_seen.append(job.fraction))

    def work(progress, cancelled):
        assert QThread.currentThread() is not qapp.thread()
        progress(1.0, "done")
        return 42

    job = runner.run("Answer", work, lambda r: seen.append((r, QThread.currentThread() is qapp.thread())))
    assert runner.busy
    assert runner.wait(10)
    assert seen == [(42, True)] and job.state == "done" and not errors
    assert progress_seen == [1.0]
    assert not runner.busy


def test_cancel_drops_the_result_and_calls_on_cancelled(qapp):
    runner = JobRunner()
    go = threading.Event()
    seen, cancelled_calls = [], []

    def work(progress, cancelled):
        go.wait(5)
        return "late"

    job = runner.run("Slow", work, seen.append, on_cancelled=lambda: cancelled_calls.append(1))
    status = JobStatus(runner)
    status._refresh()
    assert not status.isHidden()
    status.cancel_button.click()  # the user's Cancel: the bar goes away at once
    assert status.isHidden() and job.cancelled
    go.set()
    assert runner.wait(10)
    assert seen == [] and cancelled_calls == [1] and job.state == "cancelled"


def test_errors_become_one_message_and_job_cancelled_is_a_cancel(qapp):
    errors = []
    runner = JobRunner(lambda t, m: errors.append((t, m)))

    def bad(progress, cancelled):
        raise ParameterError("tau", -1, "a number >= 0")

    def stop(progress, cancelled):
        raise Cancelled

    runner.run("Solve", bad)
    stopped = runner.run("Stop", stop, lambda r: errors.append("should not run"))
    assert runner.wait(10)
    assert errors == [("Solve", "tau=-1 is invalid: expected a number >= 0")]
    assert stopped.state == "cancelled"


def test_a_newer_job_of_the_same_group_supersedes_the_older(qapp):
    runner = JobRunner()
    seen = []
    gate = threading.Event()

    def first(progress, cancelled):
        gate.wait(5)
        return "first"

    a = runner.run("A", first, seen.append, group="keys")
    b = runner.run("B", lambda p, c: "second", seen.append, group="keys")
    other = runner.run("C", lambda p, c: "other", seen.append, group="video")
    assert a.cancelled and not b.cancelled and not other.cancelled
    gate.set()
    assert runner.wait(10)
    assert sorted(seen) == ["other", "second"]
