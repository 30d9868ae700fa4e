"""``hairtool-studio [FILE]``: start the desktop application (``--bench``: the responsiveness benchmark)."""

from __future__ import annotations

import argparse
import sys

STUDIO_PACKAGES = ("PySide6", "moderngl", "pyrr", "imageio", "PIL")


def missing_studio_packages() -> list[str]:
    """The studio's packages this environment lacks (``pip install hairtool`` has none of them)."""
    import importlib.util

    return [name for name in STUDIO_PACKAGES if importlib.util.find_spec(name) is None]


def show_splash(app):
    """A splash screen for the second or two until the window is up (on a first start the
    kernels compile after it appears, in the background: see :mod:`app.ui.engine_start`)."""
    from PySide6.QtCore import Qt
    from PySide6.QtGui import QColor, QPixmap
    from PySide6.QtWidgets import QSplashScreen

    pixmap = QPixmap(560, 140)
    pixmap.fill(QColor(41, 43, 48))
    splash = QSplashScreen(pixmap)
    splash.showMessage(
        "Hairtool Studio\n\nStarting…",
        Qt.AlignmentFlag.AlignCenter,
        QColor(225, 228, 232),
    )
    splash.show()
    app.processEvents()
    return splash


def parse_args(argv: list[str]) -> tuple[argparse.Namespace, list[str]]:
    parser = argparse.ArgumentParser(
        prog="hairtool-studio",
        description="Shape hair grooms interactively with the frozen-hair tools.",
    )
    parser.add_argument(
        "file",
        nargs="?",
        help="a groom, animation or project (.hairproj) to open; default: Sintel's hair and head",
    )
    parser.add_argument(
        "--bench",
        action="store_true",
        help="run the responsiveness benchmark (options as python -m app.bench)",
    )
    return parser.parse_known_args(argv)


def open_window(file: str | None, *, engine_ready: bool = True, settings=None):
    """The studio's window on ``file`` (a groom, animation or ``.hairproj`` project); with no
    file, or one that cannot be opened (its error shown), on the bundled Sintel scene."""
    from app.ui.window import MainWindow

    window = MainWindow(None, engine_ready=engine_ready, settings=settings)
    if file is None or not window.open_path(file):
        window.open_bundled_sample()
    return window


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    if "--bench" in argv:  # everything else belongs to the benchmark's own parser
        from app import bench

        argv.remove("--bench")
        return bench.main(argv)
    args, rest = parse_args(argv)
    if rest:
        print(f"hairtool-studio: unrecognised arguments: {' '.join(rest)}", file=sys.stderr)
        return 2
    missing = missing_studio_packages()
    if missing:
        print(
            f"hairtool-studio: the studio needs {', '.join(missing)}, which this install lacks: "
            'pip install "hairtool[studio]"',
            file=sys.stderr,
        )
        return 2
    from PySide6.QtCore import QSettings

    from app.ui.cache_folder import use_preferred_cache_folder

    use_preferred_cache_folder(QSettings("hairtool", "Hairtool Studio"))  # before numba is imported
    from app.surface import configure_gl

    configure_gl()
    from PySide6.QtWidgets import QApplication

    from app.ui.kernel_warmup import kernels_cached

    app = QApplication(sys.argv[:1])
    app.setOrganizationName("hairtool")
    app.setApplicationName("Hairtool Studio")
    splash = show_splash(app)
    cached = kernels_cached()
    window = open_window(args.file, engine_ready=cached)
    window.show()
    splash.finish(window)
    trace_start(window)
    if not cached:
        window.start_warmup()
    return app.exec()


def trace_start(window) -> None:
    """The start's moments on standard error when HAIRTOOL_STARTUP_TRACE is set (see
    :mod:`app.ui.startup_trace`; ``python -m app.bench --cold-start`` reads them)."""
    from app.ui import startup_trace

    if not startup_trace.enabled():
        return
    startup_trace.mark("window-shown")
    scene, viewport = window.scene, window.viewport
    if scene.engine_ready:
        startup_trace.mark("engine-ready")
    else:
        scene.engine_started.connect(lambda: startup_trace.mark("engine-ready"))
    shown = []

    def on_frame() -> None:  # the first frame drawn with the render hair bound
        if not shown and scene.binding is not None:
            shown.append(True)
            startup_trace.mark("render-hair")

    viewport.frame_drawn.connect(on_frame)


def entry() -> None:
    sys.exit(main())
