"""Studio responsiveness: time from a mouse-move event to the finished frame, while dragging hair.

``python -m app.bench [--json]`` (or ``hairtool-studio --bench``). Each row is one groom: the
sample grooms and a 5,000 strands × 20 vertices scalp. A real window with a real GL viewport
receives a left-drag of QMouseEvents; per move we time the event plus a synchronous paintGL
with glFinish after upload and after draw (``cursor_ms``: the frame with the brush circle where
the mouse is, while the frozen-hair pipeline runs in its worker thread, :mod:`app.ui.engine_thread`),
then until the move's result has landed and is drawn (``total_ms``), so the
draw time is the GPU's (llvmpipe's) real time; Qt's compositing of the widget onto the screen
is not included. Numbers are medians over the moves; ``p90_total_ms`` the 90th percentile,
``first_move_ms`` the first move after the press (with ``--json``, ``move_ms`` lists every move).
The stroke starts once the studio has loaded its cached kernels (:mod:`app.ui.kernel_preload`,
what it does in the idle second after an open, before an artist's first stroke).
Target: total under 33 ms (30 frames/s) for the 5,000-strand groom.
The guides case (``--only guides``): 1,000 guides × 32 vertices with 100,000 interpolated children
shaded as hair, drawn at 10 % while dragging (target: median under 33 ms), and the full-density
frame after the release (``release_ms``, target under 250 ms); ``children_ms`` is the rebuild of
the drawn children on each move. ``cpu_ms`` and ``release_cpu_ms``: the CPU time the process
spent (all its threads) on a move and on the release; on a machine shared with other work
they show what the work costs where the wall-clock times show how long it waited for a core.
The viewport draws without
MSAA unless HAIRTOOL_MSAA is set (the ``msaa`` column says which ran); the ``lines`` column says
how strands were drawn (a GL line method, or rasterized on the CPU: ``--strand-raster``).
``--brush`` drags another brush than align (``--symmetry``: mirrored, two samples per move).
``--groom PATH`` times that groom file instead (any readable one, e.g. the bear; with
``--only guides`` it is the guides of the children case); ``--clump-children`` and
``--no-clump-children`` turn Clump children on or off (ClumpWithGaps among the render-hair
children once the mouse is released; by default on, as for any grown children). Every row reports
the release (``release_ms``, ``release_cpu_ms``): the frame after the mouse is let go.

``--cold-start``: a first start instead. The studio starts in a subprocess on an empty kernel
cache (NUMBA_CACHE_DIR, XDG_CACHE_HOME and XDG_CONFIG_HOME in a temporary folder, on the display
or a private Xvfb) with HAIRTOOL_STARTUP_TRACE set, and the rows are its moments
(:mod:`app.ui.startup_trace`): the window shown, the engine ready, the first frame with Sintel's
render hair (target: both under 20 s on the 2-core reference machine), then each warm-up step.
``wall_s``: seconds since the launch; ``cpu_s``: the CPU seconds the studio and the warm-up had
spent by then (each process's as of its last line), ``step_cpu_s`` a warm-up step's own. The
first row is ``hairtool bench host``'s speed, to read the wall-clock times by.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

HELP = "time from mouse move to finished frame in the studio (pipeline / upload / draw)"
TARGET_MS = 33.0
RELEASE_TARGET_MS = 250.0  # the guides case: the full-density frame after the release
PRELOAD_WAIT_S = 10.0  # at most, for the studio to load its cached kernels before the stroke


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--moves", type=int, default=30, help="mouse moves per groom (default 30)")
    parser.add_argument("--strands", type=int, default=5000, help="strands of the large groom (default 5000)")
    parser.add_argument("--vertices", type=int, default=20, help="vertices per strand of the large groom")
    parser.add_argument("--size", type=int, nargs=2, default=(1024, 768), metavar=("W", "H"), help="window")
    parser.add_argument(
        "--only",
        choices=["samples", "large", "guides"],
        help="run only the samples, the large groom or the guides",
    )
    parser.add_argument("--guides", type=int, default=1000, help="guides of the guides case (default 1000)")
    parser.add_argument(
        "--children", type=int, default=100_000, help="children of the guides case (default 100000)"
    )
    parser.add_argument("--drag-percent", type=float, default=10.0, help="children drawn while dragging (%%)")
    parser.add_argument("--no-clump", action="store_true", help="ClumpWithGaps off (align, freeze only)")
    parser.add_argument("--line-width", type=float, help="strand width in pixels (default: the studio's)")
    parser.add_argument(
        "--fast-lines", action="store_true", help="the renderer's 1-px fast lines, whatever the width"
    )
    parser.add_argument(
        "--strand-raster",
        choices=["auto", "gl", "cpu"],
        help="draw strands with GL or rasterize them on the CPU (default: HAIRTOOL_STRAND_RASTER, else auto)",
    )
    parser.add_argument(
        "--brush",
        default="align",
        choices=["align", "comb", "smooth", "length", "puff", "clump", "mask"],
        help="the brush dragged (default align)",
    )
    parser.add_argument(
        "--radius",
        type=float,
        metavar="SHARE",
        help="brush radius as a share of the groom's largest side (default: the size a groom opens with)",
    )
    parser.add_argument("--symmetry", action="store_true", help="X symmetry on: each move and its mirror")
    parser.add_argument(
        "--groom", metavar="PATH", help="time this groom file (any readable one) instead of the samples"
    )
    parser.add_argument(
        "--clump-children",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="Clump children on or off (default: the studio's, on for grown children)",
    )
    parser.add_argument("--json", action="store_true", help="print the rows as JSON")
    parser.add_argument(
        "--cold-start",
        action="store_true",
        help="time a first start from an empty kernel cache (window, engine ready, render hair)",
    )
    parser.add_argument(
        "--timeout", type=float, default=900.0, help="--cold-start: give up after this many seconds"
    )


def _end_with_parent() -> None:
    """In the Xvfb child (Linux): SIGTERM when the benchmark's process ends. Qt tears its
    QApplication and the view's native GL window down only as the interpreter exits; a display
    ended before that broke their X connection (an abort in GLX after the table was printed)."""
    import ctypes
    import signal

    ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGTERM)  # PR_SET_PDEATHSIG


_ENDS_WITH_US = sys.platform.startswith("linux")


def _ensure_display() -> subprocess.Popen | None:
    """Start ``Xvfb -displayfd`` when no display is set (headless machines, CI); on Linux it
    ends with this process, elsewhere the caller ends it (:func:`_end_display`)."""
    if os.environ.get("DISPLAY") or shutil.which("Xvfb") is None:
        return None
    read_fd, write_fd = os.pipe()
    proc = subprocess.Popen(
        ["Xvfb", "-displayfd", str(write_fd), "-screen", "0", "1600x1000x24", "-nolisten", "tcp"],
        pass_fds=(write_fd,),
        preexec_fn=_end_with_parent if _ENDS_WITH_US else None,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    os.close(write_fd)
    with os.fdopen(read_fd) as f:
        os.environ["DISPLAY"] = f":{f.readline().strip()}"
    return proc


def _end_display(xvfb: subprocess.Popen | None) -> None:
    """Where the display does not end with this process by itself, end it now."""
    if xvfb is not None and not _ENDS_WITH_US:
        xvfb.terminate()
        xvfb.wait(timeout=10)


def _grooms(args: argparse.Namespace) -> list[tuple[str, object]]:
    from hairtool import samples

    out: list[tuple[str, object]] = []
    if getattr(args, "groom", None):
        from pathlib import Path

        from hairtool.io import read_groom

        groom = read_groom(args.groom)
        name = Path(args.groom).stem
        if args.only == "guides":
            return [(f"guides {name} + {args.children} children", groom)]
        return [(name, groom)]
    if args.only in (None, "samples"):
        out += [(name, samples.sample(name)) for name in samples.SAMPLES]
    if args.only in (None, "large"):
        out.append((f"scalp {args.strands}x{args.vertices}", samples.scalp(args.strands, args.vertices)))
    if args.only in (None, "guides"):
        out.append((f"guides {args.guides}x32 + {args.children} children", samples.scalp(args.guides, 32)))
    return out


def _bind_children(window, args: argparse.Namespace) -> None:
    """The guides case: children around the guide roots, drawn shaded as in the bundled sample."""
    from hairtool.guides.binding import bind_roots

    scene = window.scene
    scene.set_binding(bind_roots(scene.rest, count=args.children, seed=1))
    scene.set_display_percent(drag=args.drag_percent, release=100.0)
    scene.set_colour_mode("hair")


def _drag_path(window, moves: int) -> np.ndarray:
    """Widget positions: from the tip nearest the view's centre, a loop of ``moves`` steps around it."""
    v = window.viewport
    tips = v.project(window.scene.result.tips)
    centre = np.array([v.width() / 2.0, v.height() / 2.0])
    start = tips[np.argmin(np.linalg.norm(tips - centre, axis=1))]
    a = np.linspace(0.0, 2.0 * np.pi, moves + 1)
    radius = 0.12 * min(v.width(), v.height())
    return start + radius * np.column_stack([np.sin(a), 1.0 - np.cos(a)])


def _line_method(renderer) -> str:
    """The ``lines`` column: the renderer's line method; CPU raster as ``cpu/1px`` or ``cpu/quads``."""
    if renderer is None:
        return "-"
    method = renderer.line_method()
    if method == "cpu":
        return "cpu/1px" if renderer.gl_line_method() == "thin" else "cpu/quads"
    return method


def _time_groom(app, name: str, groom, args: argparse.Namespace, settings) -> dict:
    from PySide6.QtCore import Qt
    from PySide6.QtGui import QSurfaceFormat

    from app.ui.qt_utils import send_mouse
    from app.ui.window import MainWindow

    window = MainWindow(groom=groom, settings=settings)
    guides_case = name.startswith("guides")
    if guides_case:
        _bind_children(window, args)
    if args.no_clump:
        window.scene.set_params(window.scene.params.replace(clump=False))
    if getattr(args, "clump_children", None) is not None:
        window.scene.set_clump_children(bool(args.clump_children))
    window.scene.set_brush(getattr(args, "brush", "align"))
    window.scene.set_symmetry(bool(getattr(args, "symmetry", False)))
    if getattr(args, "radius", None) is not None:
        lo, hi = window.scene.rest.bounds
        window.scene.set_radius(float(args.radius) * float(np.max(hi - lo)))
    if args.line_width is not None:
        window.scene.set_line_width(args.line_width)
    window.resize(*args.size)
    window.show()
    for _ in range(20):
        app.processEvents()
    # the cached kernels load while the studio idles after an open (app.ui.kernel_preload): an
    # artist's first stroke comes later than that, so the timed one does too
    deadline = time.perf_counter() + PRELOAD_WAIT_S
    while not window.kernel_preload.done and time.perf_counter() < deadline:
        app.processEvents()
    v = window.viewport
    if args.fast_lines and v.renderer is not None:
        v.renderer.fast_lines = True
    if args.strand_raster and v.renderer is not None:
        v.renderer.strand_raster = args.strand_raster
    v.finish_frames = True
    left = Qt.MouseButton.LeftButton

    path = _drag_path(window, args.moves)
    send_mouse(v, "press", path[0], left, left)
    v.draw_now()  # the first update compiles kernels and allocates: not timed
    totals, pipeline, upload, draw, stages, children, cpu, redone = [], [], [], [], [], [], [], []
    cursor = []
    for p in path[1:]:
        t0, c0 = time.perf_counter(), time.process_time()
        send_mouse(v, "move", p, None, left)
        v.draw_now()  # the frame with the circle where the mouse is (the engine runs meanwhile)
        cursor.append((time.perf_counter() - t0) * 1e3)
        window.scene.moves.drain()
        v.draw_now()  # the frame with the move's result
        totals.append((time.perf_counter() - t0) * 1e3)
        cpu.append((time.process_time() - c0) * 1e3)
        pipeline.append(window.scene.last_update_ms)
        upload.append(v.last_upload_ms)
        draw.append(v.last_draw_ms)
        stages.append(window.scene.pipeline.timings)
        children.append(window.scene.last_children_ms)
        redone.append(window.scene.pipeline.clump_redone)
    drawn_strands = v.renderer.topology.strand_count if v.renderer is not None else 0
    children_ms = statistics.median(children) if children else 0.0
    t0, c0 = time.perf_counter(), time.process_time()
    send_mouse(v, "release", path[-1], left)
    v.draw_now()
    release_ms = (time.perf_counter() - t0) * 1e3
    release_cpu_ms = (time.process_time() - c0) * 1e3
    clump = window.scene.params.clump
    clump_children = bool(window.scene.clump_children)
    lines = _line_method(v.renderer)
    brush = window.scene.brush + (" x2" if window.scene.tool.symmetry else "")
    window.ask_save_changes = lambda: "discard"  # the benchmark's strokes are not work to keep
    close_window(app, window)
    row = {
        "groom": name,
        "brush": brush,
        "strands": groom.strand_count,
        "vertices": groom.vertex_count,
        "moves": len(totals),
        "clump": clump,
        "total_ms": statistics.median(totals),
        "cursor_ms": statistics.median(cursor),
        "p90_cursor_ms": float(np.percentile(cursor, 90)),
        "pipeline_ms": statistics.median(pipeline),
        "upload_ms": statistics.median(upload),
        "draw_ms": statistics.median(draw),
        "p90_total_ms": float(np.percentile(totals, 90)),
        "first_move_ms": totals[0],  # the stroke's first move (an open's first stroke: what is not ready yet)
        "move_ms": [round(t, 2) for t in totals],  # each move in order
        "cpu_ms": statistics.median(cpu),
    }
    for stage in ("freeze", "align", "clump"):
        row[f"{stage}_ms"] = statistics.median(float(t.get(stage, 0.0)) for t in stages)
    row["redone_share"] = statistics.median(redone)  # of the vertices a move's clumping redid
    row["release_ms"] = release_ms
    row["release_cpu_ms"] = release_cpu_ms
    row["clump_children"] = clump_children
    if guides_case:
        row["children_ms"] = children_ms
        row["drawn_strands"] = drawn_strands
        row["release_under_target"] = release_ms < RELEASE_TARGET_MS
    row["msaa"] = max(QSurfaceFormat.defaultFormat().samples(), 0)
    row["lines"] = lines
    row["under_target"] = row["total_ms"] < TARGET_MS
    return row


def close_window(app, window) -> None:
    """Close ``window`` and delete it now, on this thread: a ``deleteLater`` outside a running
    event loop waited for the interpreter's exit, where the view's native GL window was torn down
    after its display connection (a segfault after the table was printed)."""
    from PySide6.QtCore import QEvent

    window.close()
    window.deleteLater()
    app.sendPostedEvents(None, QEvent.Type.DeferredDelete)
    app.processEvents()


def in_studio_app(measure):
    """``measure(app, settings)`` with a QApplication on a display (Xvfb started when there is
    none) and throw-away studio settings, so a benchmark never touches the user's."""
    from app.surface import configure_gl

    xvfb = _ensure_display()
    try:
        configure_gl()
        from PySide6.QtCore import QSettings
        from PySide6.QtWidgets import QApplication

        app = QApplication.instance() or QApplication(sys.argv[:1])
        with tempfile.TemporaryDirectory() as tmp:
            settings = QSettings(os.path.join(tmp, "bench.ini"), QSettings.Format.IniFormat)
            return measure(app, settings)
    finally:
        _end_display(xvfb)


def run(args: argparse.Namespace) -> list[dict]:
    return in_studio_app(
        lambda app, settings: [_time_groom(app, name, g, args, settings) for name, g in _grooms(args)]
    )


COLD_START_TARGET_S = 20.0  # engine ready and render hair on screen, 2-core reference machine


def _host_speed() -> float | None:
    """``hairtool bench host``'s speed now (1.0: the reference machine at its best)."""
    out = subprocess.run(
        [sys.executable, "-m", "hairtool", "bench", "host", "--json", "--quick"],
        capture_output=True, text=True, check=False,
    )  # fmt: skip
    try:
        return float(next(r for r in json.loads(out.stdout) if r["probe"] == "host")["speed"])
    except (ValueError, StopIteration, KeyError, TypeError):
        return None


def _read_lines(stream, lines) -> None:
    for line in stream:
        lines.put(line)
    lines.put(None)


def cold_start(timeout: float) -> list[dict]:
    """Start the studio on an empty cache and collect its moments (see the module doc)."""
    import queue
    import signal
    import threading

    from app.ui import startup_trace

    speed = _host_speed()
    xvfb = _ensure_display()
    moments: list[tuple[str, float, float, int, str]] = []
    try:
        with tempfile.TemporaryDirectory(prefix="hairtool-cold-start-") as tmp:
            env = dict(os.environ, HAIRTOOL_STARTUP_TRACE="1")
            for var in ("NUMBA_CACHE_DIR", "XDG_CACHE_HOME", "XDG_CONFIG_HOME"):
                env[var] = os.path.join(tmp, var.lower())
            launched = time.time()
            proc = subprocess.Popen(
                [sys.executable, "-c", "from app.main import entry; entry()"],
                env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                start_new_session=True,  # the warm-up process too, ended with it below
            )  # fmt: skip
            lines: queue.Queue = queue.Queue()
            threading.Thread(target=_read_lines, args=(proc.stderr, lines), daemon=True).start()
            seen: set[str] = set()
            warmup_done = False
            while not ({"render-hair", "engine-ready"} <= seen and warmup_done):
                left = launched + timeout - time.time()
                try:
                    line = lines.get(timeout=max(0.1, left))
                except queue.Empty:
                    break
                if line is None:  # the studio ended
                    break
                parsed = startup_trace.parse(line)
                if parsed is None:
                    continue
                moments.append(parsed)
                seen.add(parsed[0])
                if parsed[0] == "warmup-step":
                    done, total = parsed[4].split(maxsplit=1)[0].split("/")
                    warmup_done = done == total
            try:
                os.killpg(proc.pid, signal.SIGTERM)
            except ProcessLookupError:
                pass
            proc.wait(timeout=30)
    finally:
        _end_display(xvfb)
    rows: list[dict] = [{"moment": "host speed", "label": "", "wall_s": None, "cpu_s": None,
                         "step_cpu_s": None, "speed": speed}]  # fmt: skip
    latest: dict[int, float] = {}  # CPU seconds of each process (studio, warm-ups) so far
    for moment, wall, cpu, pid, label in moments:
        step_cpu = cpu - latest.get(pid, 0.0) if moment.startswith("warmup") else None
        latest[pid] = cpu
        rows.append({
            "moment": moment, "label": label, "wall_s": wall - launched, "cpu_s": sum(latest.values()),
            "step_cpu_s": step_cpu, "speed": None,
        })  # fmt: skip
    for moment in ("window-shown", "engine-ready", "render-hair"):
        if moment not in {r["moment"] for r in rows}:
            rows.append({"moment": moment, "label": "not reached", "wall_s": None, "cpu_s": None,
                         "step_cpu_s": None, "speed": None})  # fmt: skip
    return rows


def main(argv: list[str] | None = None) -> int:
    from hairtool.bench import format_table

    parser = argparse.ArgumentParser(prog="python -m app.bench", description=HELP)
    add_arguments(parser)
    args = parser.parse_args(argv)
    if args.moves < 2 or args.strands < 1 or not 2 <= args.vertices <= 1024:
        print("app.bench: --moves >= 2, --strands >= 1 and --vertices in [2, 1024] please", file=sys.stderr)
        return 2
    rows = cold_start(args.timeout) if args.cold_start else run(args)
    if args.json:
        print(json.dumps(rows, indent=2))
    else:  # (each move's time, a list, in the JSON only)
        print(format_table([{k: v for k, v in r.items() if not isinstance(v, list)} for r in rows]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
