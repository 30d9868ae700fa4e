"""Timeline responsiveness: scrubbing, key-count changes, solving and key edits on a large animation.

``python -m app.bench_timeline [--json]``. A swaying scalp (default 2,000 strands × 24 vertices,
240 frames) is loaded into a real window. Scrub rows time a left-drag across the timeline
ruler: per mouse move, the event (the model sets the frame, the viewport is given its points)
plus a synchronous paintGL with glFinish, so the frame is on the GPU when the clock stops
(Qt's compositing onto the screen is not included); medians and 90th percentiles over the moves,
in each view mode. The other rows time the model's work directly, on the GUI thread.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time

import numpy as np

HELP = "time scrubbing, key solves and key edits on a large animation in the studio"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--strands", type=int, default=2000)
    parser.add_argument("--vertices", type=int, default=24)
    parser.add_argument("--frames", type=int, default=240)
    parser.add_argument("--moves", type=int, default=60, help="mouse moves per scrub (default 60)")
    parser.add_argument("--size", type=int, nargs=2, default=(1280, 900), metavar=("W", "H"))
    parser.add_argument("--json", action="store_true")


def _timed(fn) -> float:
    t0 = time.perf_counter()
    fn()
    return (time.perf_counter() - t0) * 1e3


def run(args: argparse.Namespace) -> list[dict]:
    from app.bench import in_studio_app

    return in_studio_app(lambda app, settings: _measure(app, args, settings))


def _stall(app, window, m) -> dict:
    """Solve keys through the window's job runner while a 10 ms timer ticks on the GUI thread:
    the longest gap between ticks is how long the window could not answer."""
    from PySide6.QtCore import QTimer

    m.runner, m.inline_values = window.jobs, 0
    ticks: list[float] = []
    timer = QTimer()
    timer.timeout.connect(lambda: ticks.append(time.perf_counter()))
    timer.start(10)
    t0 = time.perf_counter()
    m.set_settings(interp="hermite" if m.settings.interp == "linear" else "linear")
    window.jobs.wait(600)
    total = (time.perf_counter() - t0) * 1e3
    timer.stop()
    m.runner = None
    gaps = np.diff(ticks) * 1e3 if len(ticks) > 1 else np.array([total])
    return {"ms": total, "max_gap_ms": float(gaps.max()), "p90_ms": float(np.percentile(gaps, 90))}


def _measure(app, args: argparse.Namespace, settings) -> list[dict]:
    from PySide6.QtCore import Qt

    from app.ui.qt_utils import send_mouse
    from app.ui.window import MainWindow
    from hairtool import samples
    from hairtool.keys import session as ks
    from hairtool.simulate.sway import sway_animation

    groom = samples.scalp(args.strands, args.vertices)
    anim = sway_animation(groom, args.frames, 24.0, flick_frame=int(args.frames * 0.6))
    label = f"{args.strands}x{args.vertices}, {args.frames} frames"
    rows: list[dict] = []
    window = MainWindow(groom=groom, settings=settings)
    window.ask_save_changes = lambda: "discard"  # the benchmark's animation is not work to keep
    window.resize(*args.size)
    window.show()
    for _ in range(20):
        app.processEvents()
    m, v, view = window.animation, window.viewport, window.timeline.view
    m.runner = None  # time the work itself, on this thread
    rows.append(
        {"what": "load + solve + errors", "animation": label, "ms": _timed(lambda: m.load_animation(anim))}
    )
    s = m.settings
    rows.append(
        {"what": "solve (features, table, DP)", "animation": label, "ms": _timed(lambda: ks.solve(anim, s))}
    )
    rows.append(
        {
            "what": "key count change (trace)",
            "animation": label,
            "ms": _timed(lambda: m.key_solve.keys_for_count(min(30, m.key_solve.kmax))),
        }
    )
    rows.append(
        {"what": "errors of DP + uniform keys, speed", "animation": label,
         "ms": _timed(lambda: ks.analyse(anim, m.dp_keys, "linear"))}
    )  # fmt: skip
    key = int(m.dp_keys[len(m.dp_keys) // 2])
    pose = anim.frames[key] + np.float32(0.01)
    rows.append(
        {"what": "key edit (ranged residual edit)", "animation": label,
         "ms": _timed(lambda: ks.key_edit_block(anim.frames, m.dp_keys, "linear", key, pose))}
    )  # fmt: skip
    start, block = ks.key_edit_block(anim.frames, m.dp_keys, "linear", key, pose)
    rows.append(
        {"what": "key edit applied (new frames, key poses, errors)", "animation": label,
         "ms": _timed(lambda: m.replace_frames(start, block))}
    )  # fmt: skip

    rows.append({"what": "GUI stall during a background solve", "animation": label, **_stall(app, window, m)})
    rows.append({"what": "timeline redraw (keys or curves changed)", "animation": label,
                 "ms": _timed(lambda: (view.invalidate(), view.repaint()))})  # fmt: skip
    rows.append({"what": "timeline repaint (frame changed)", "animation": label,
                 "ms": _timed(lambda: (m.set_frame(m.frame + 1), view.repaint()))})  # fmt: skip

    v.finish_frames = True
    left = Qt.MouseButton.LeftButton
    y = view.row_rect("curves").center().y()

    for mode in ("original", "reconstruction", "ghost", "error"):
        m.set_view_mode(mode)
        xs = np.linspace(view.frame_to_x(0), view.frame_to_x(args.frames - 1), args.moves + 1)
        send_mouse(view, "press", (xs[0], y), left, left)
        v.draw_now()
        totals, events, upload, draw = [], [], [], []
        for x in xs[1:]:
            t0 = time.perf_counter()
            send_mouse(view, "move", (x, y), None, left)
            t1 = time.perf_counter()
            v.draw_now()
            totals.append((time.perf_counter() - t0) * 1e3)
            events.append((t1 - t0) * 1e3)
            upload.append(v.last_upload_ms)
            draw.append(v.last_draw_ms)
        send_mouse(view, "release", (xs[-1], y), left)
        assert v.shown_frame == m.frame == args.frames - 1
        rows.append(
            {
                "what": f"scrub step, view {mode}",
                "animation": label,
                "ms": statistics.median(totals),
                "p90_ms": float(np.percentile(totals, 90)),
                "event_ms": statistics.median(events),
                "upload_ms": statistics.median(upload),
                "draw_ms": statistics.median(draw),
            }
        )
    window.close()
    window.deleteLater()
    app.processEvents()
    return rows


def main(argv: list[str] | None = None) -> int:
    from hairtool.bench import format_table

    parser = argparse.ArgumentParser(prog="python -m app.bench_timeline", description=HELP)
    add_arguments(parser)
    args = parser.parse_args(argv)
    if args.frames < 2 or args.moves < 2 or args.strands < 1 or not 2 <= args.vertices <= 1024:
        print(
            "app.bench_timeline: --frames, --moves >= 2, --strands >= 1, --vertices in [2, 1024]",
            file=sys.stderr,
        )
        return 2
    rows = run(args)
    print(json.dumps(rows, indent=2) if args.json else format_table(rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
