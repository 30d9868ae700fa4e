"""``hairtool-studio [FILE]``: start the desktop application (``--bench``: the responsiveness benchmark)."""

from __future__ import annotations

import argparse
import os
import sys

MSAA_ENV = "HAIRTOOL_MSAA"  # samples per pixel of the viewport; 0 (default) keeps llvmpipe interactive


def configure_gl() -> None:
    """A 3.3 core default surface with depth; must run before the QApplication exists.

    Multisampling is off unless ``HAIRTOOL_MSAA`` asks for it: on Mesa's llvmpipe 4× MSAA
    makes every viewport frame about 3–4× slower (stills are always rendered with 4×).
    """
    from PySide6.QtGui import QSurfaceFormat

    fmt = QSurfaceFormat()
    fmt.setVersion(3, 3)
    fmt.setProfile(QSurfaceFormat.OpenGLContextProfile.CoreProfile)
    fmt.setDepthBufferSize(24)
    try:
        samples = int(os.environ.get(MSAA_ENV, "0"))
    except ValueError:
        samples = 0
    fmt.setSamples(min(max(samples, 0), 16))
    QSurfaceFormat.setDefaultFormat(fmt)


def show_splash(app):
    """A splash screen until the window is up: on a fresh install numba compiles the engine's
    and the rasterizer's kernels first (about half a minute on two cores, then cached), and a
    window that takes that long to appear with no sign of life looks hung."""
    from PySide6.QtCore import Qt
    from PySide6.QtGui import QColor, QPixmap
    from PySide6.QtWidgets import QSplashScreen

    pixmap = QPixmap(560, 140)
    pixmap.fill(QColor(41, 43, 48))
    splash = QSplashScreen(pixmap)
    splash.showMessage(
        "Hairtool Studio\n\nPreparing the engine…\n"
        "(the first start compiles its kernels: about half a minute)",
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
        help="a groom or animation to open (any readable format); default: Sintel's hair and head",
    )
    parser.add_argument(
        "--bench",
        action="store_true",
        help="run the responsiveness benchmark (options as python -m app.bench)",
    )
    return parser.parse_known_args(argv)


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
    configure_gl()
    from PySide6.QtWidgets import QApplication

    from app.ui.window import MainWindow

    app = QApplication(sys.argv[:1])
    app.setOrganizationName("hairtool")
    app.setApplicationName("Hairtool Studio")
    splash = show_splash(app)
    window = MainWindow(args.file)
    if args.file is None:
        window.open_bundled_sample()
    window.show()
    splash.finish(window)
    return app.exec()


def entry() -> None:
    sys.exit(main())
