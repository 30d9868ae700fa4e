"""Timeline responsiveness: scrubbing, key-count changes, solving and key edits on a large animation.

``python -m app.bench_timeline [--json]``. A swaying scalp (default 2,000 strands × 24 vertices,
240 frames) is loaded into a real window. Scrub rows time a left-drag across the timeline
ruler: per mouse move, the event (the model sets the frame, the viewport is given its points)
plus a synchronous paintGL with glFinish, so the frame is on the GPU when the clock stops
(Qt's compositing onto the screen is not included); medians and 90th percentiles over the moves,
in each view mode. The other rows time the model's work directly, on the GUI thread.

``--sintel`` times Sintel with her render hair instead (the bundled scene: 228 guides, 30,000
children, shaded as hair, Clump children on) under a generated sway of ``--sintel-frames``
frames (default 22), beside ``hairtool bench host``'s speed (the first row):

- ``scrub``: a left-drag on the ruler, one mouse move every 1/60 s with the event loop
  running between them, as a hand drags, back and forth across the frames at ``--scrub-rate``
  frames a second (default 48, twice the target: a drag that crossed the 22 frames once in a
  second could show at most 21 a second, whatever the view's speed); ``mouse_fps`` is the
  distinct frames under the mouse per second, the most the view could show, and ``fps`` the
  distinct frames the view drew per second of the drag (target 24), ``behind_frames`` how far
  the frame on screen was behind the
  frame under the mouse at each move (median), ``settle_ms`` from the last move until the view
  shows that frame, ``paint_ms`` a paint of a scrubbed frame (upload and draw, median);
  ``release_full_ms`` from the release until every child is on screen (target 500),
  ``release_clumped_ms`` until they are clumped, as the groom's are; ``gui_max_gap_ms``: the
  longest the GUI thread was away from its event loop meanwhile. The drag starts once the
  studio has loaded its cached kernels (:mod:`app.ui.kernel_preload`), as ``app.bench``'s does;
  ``--drag-percent`` sets the share of the children drawn while dragging (default the studio's).
- ``GIF at viewport size``: File ▸ Export animation to a GIF of every frame, the children
  clumped on each (``s``: until the file is written; the issue measured 22.6 s);
  ``view_paints``: the viewport's repaints meanwhile (``--no-gif`` leaves the export out).
"""

from __future__ import annotations

import argparse
import itertools
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
    parser.add_argument("--sintel", action="store_true", help="scrub and export Sintel's render hair")
    parser.add_argument("--sintel-frames", type=int, default=22, help="--sintel: frames of the sway")
    parser.add_argument(
        "--scrub-rate", type=float, default=48.0, help="--sintel: frames the drag crosses per second"
    )
    parser.add_argument(
        "--drag-percent", type=float, help="--sintel: the children drawn while dragging, in %% (default 10)"
    )
    parser.add_argument("--no-gif", action="store_true", help="--sintel: time the scrub only")
    parser.add_argument("--json", action="store_true")


def _timed(fn) -> float:
    t0 = time.perf_counter()
    fn()
    return (time.perf_counter() - t0) * 1e3


def run(args: argparse.Namespace) -> list[dict]:
    from app.bench import _host_speed, in_studio_app

    if not args.sintel:
        return in_studio_app(lambda app, settings: _measure(app, args, settings))
    host = {"what": "hairtool bench host", "speed": _host_speed()}
    return [host, *in_studio_app(lambda app, settings: _measure_sintel(app, args, settings))]


def _until(app, done, timeout_s: float = 120.0) -> float:
    """Run the event loop until ``done()``; the milliseconds it took."""
    t0 = time.perf_counter()
    while not done():
        if time.perf_counter() - t0 > timeout_s:
            raise TimeoutError("the studio did not get there in time")
        app.processEvents()
        time.sleep(0.001)
    return (time.perf_counter() - t0) * 1e3


def _measure_sintel(app, args: argparse.Namespace, settings) -> list[dict]:
    import tempfile
    from pathlib import Path

    from PySide6.QtCore import Qt, QTimer

    from app.bench import PRELOAD_WAIT_S, close_window
    from app.ui.qt_utils import send_mouse
    from app.ui.window import MainWindow
    from hairtool.simulate.sway import sway_animation

    window = MainWindow(settings=settings)
    window.ask_save_changes = lambda: "discard"
    window.resize(*args.size)
    window.show()
    window.open_bundled_sample()
    for _ in range(20):
        app.processEvents()
    s, v, m, view = window.scene, window.viewport, window.animation, window.timeline.view
    if args.drag_percent is not None:
        s.set_display_percent(drag=args.drag_percent)
    n = args.sintel_frames
    anim = sway_animation(s.result, n, 24.0, flick_frame=int(n * 0.6))
    m.load_animation(anim, "sway")
    window.jobs.wait(600)
    label = f"Sintel, {s.binding.child_count:,} children ({s.drag_percent:g} % dragged), {n} frames"
    full = s.drawn_topology.strand_count
    _until(app, lambda: not s.frames_live and v.shown_frame == m.frame)
    deadline = time.perf_counter() + PRELOAD_WAIT_S  # (an artist's drag comes later than that)
    while not window.kernel_preload.done and time.perf_counter() < deadline:
        app.processEvents()
    # each paint: when, frame, clumped, strands, and its upload + draw milliseconds
    drawn: list[tuple[float, int | None, bool, int, float]] = []

    def on_paint() -> None:
        strands = s.drawn_topology.strand_count
        ms = v.last_upload_ms + v.last_draw_ms
        drawn.append((time.perf_counter(), v.shown_frame, not s.frames_live, strands, ms))

    v.frame_drawn.connect(on_paint)
    ticks: list[float] = []
    timer = QTimer()
    timer.timeout.connect(lambda: ticks.append(time.perf_counter()))
    timer.start(5)
    left = Qt.MouseButton.LeftButton
    y = view.height() - 4  # the ruler
    xs = [view.frame_to_x(f) for f in scrub_path(n, args.moves, args.scrub_rate / 60.0)]
    send_mouse(view, "press", (xs[0], y), left, left)
    behind, under = [], [m.frame]
    t_start = time.perf_counter()
    for i, x in enumerate(xs[1:], 1):
        send_mouse(view, "move", (x, y), None, left)
        under.append(m.frame)
        behind.append(abs(m.frame - (v.shown_frame if v.shown_frame is not None else 0)))
        due = t_start + i / 60.0
        while time.perf_counter() < due:
            app.processEvents()
            time.sleep(0.001)
    t_end = time.perf_counter()
    settle = _until(app, lambda: v.shown_frame == m.frame)
    paint_ms = [d[4] for d in drawn if t_start <= d[0] and d[3] != full]  # the drag's paints
    during = [d[1] for d in drawn if t_start <= d[0] <= t_end]
    changes = sum(1 for a, b in itertools.pairwise(during) if a != b)
    t0 = time.perf_counter()
    send_mouse(view, "release", (xs[-1], y), left)
    _until(app, lambda: drawn[-1][0] > t0 and drawn[-1][2] and drawn[-1][3] == full)
    after = [d for d in drawn if d[0] > t0]
    release_full = (next(d[0] for d in after if d[3] == full) - t0) * 1e3
    release_clumped = (next(d[0] for d in after if d[2] and d[3] == full) - t0) * 1e3
    timer.stop()
    gaps = np.diff([t for t in ticks if t >= t_start]) * 1e3
    rows = [
        {
            "what": "scrub, render hair", "animation": label, "fps": changes / (t_end - t_start),
            "mouse_fps": sum(1 for a, b in itertools.pairwise(under) if a != b) / (t_end - t_start),
            "behind_frames": statistics.median(behind), "settle_ms": settle,
            "release_full_ms": release_full, "release_clumped_ms": release_clumped,
            "gui_max_gap_ms": float(gaps.max()) if gaps.size else 0.0,
            "paint_ms": statistics.median(paint_ms) if paint_ms else None,
        }
    ]  # fmt: skip
    if args.no_gif:
        close_window(app, window)
        return rows
    paints = len(drawn)
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        job = window.exporter.export_animation(Path(tmp) / "shot.gif")
        window.jobs.wait(900)
        seconds = time.perf_counter() - t0
    rows.append(
        {"what": "GIF at viewport size", "animation": label, "s": seconds, "state": job.state,
         "size": "x".join(str(c) for c in window.viewport_pixel_size()), "view_paints": len(drawn) - paints}
    )  # fmt: skip
    close_window(app, window)
    return rows


def scrub_path(frames: int, moves: int, per_move: float) -> list[int]:
    """The frames under the mouse at each of ``moves`` moves of a drag that crosses ``per_move``
    frames a move, from the first frame to the last and back, again and again."""
    period = 2 * (frames - 1)
    path = [round(i * per_move) % period for i in range(moves)]
    return [f if f < frames else period - f for f in path]


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

    from app.bench import close_window
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
        {"what": "key edit applied (a document step: new frames, key poses, errors)", "animation": label,
         "ms": _timed(lambda: m.edit_frames(start, block, f"Edit key {key}"))}
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
    close_window(app, window)
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
    drag = args.drag_percent
    if not (np.isfinite(args.scrub_rate) and args.scrub_rate > 0) or args.sintel_frames < 2:
        print("app.bench_timeline: --scrub-rate > 0 and --sintel-frames >= 2", file=sys.stderr)
        return 2
    if drag is not None and not (np.isfinite(drag) and 0 < drag <= 100):
        print(f"app.bench_timeline: --drag-percent must be in (0, 100], got {drag}", file=sys.stderr)
        return 2
    rows = run(args)
    print(json.dumps(rows, indent=2) if args.json else format_table(rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
