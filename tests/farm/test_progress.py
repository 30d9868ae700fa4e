"""The progress line: counts, a bar and an ETA on a terminal; nothing in a pipe."""

from __future__ import annotations

import io

from hairtool.farm.progress import Progress, format_seconds


class Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_the_line_counts_jobs_and_estimates_the_time_left():
    stream = Terminal()
    p = Progress(stream)
    assert p.enabled
    p.start(total=5, skipped=1)
    assert p.eta() is None and p.line().endswith("ETA ?")
    p.update(done=1, running=2)
    p.update(failed=1, running=1)
    line = p.line()
    assert line.startswith("[")
    assert "3/5 · 1 done · 1 running · 1 failed · 1 skipped · ETA " in line
    assert 0 <= p.eta() < 60
    p.finish()
    text = stream.getvalue()
    assert text.startswith("\r[") and text.endswith("\n") and text.count("\n") == 1


def test_nothing_is_drawn_when_the_stream_is_not_a_terminal():
    stream = io.StringIO()
    p = Progress(stream)
    p.start(total=2, skipped=0)
    p.update(done=2, running=0)
    p.finish()
    assert stream.getvalue() == ""


def test_times_read_as_seconds_minutes_or_hours():
    assert [format_seconds(s) for s in (0.4, 59, 61, 3599, 3600, 7322)] == [
        "0s",
        "59s",
        "1m01s",
        "59m59s",
        "1h00m",
        "2h02m",
    ]
