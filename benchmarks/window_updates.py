"""What one update costs the studio's window, Qt's composition included: a status label's
``repaint()``, and the viewport's overlay-only and whole-scene updates from the request until
the frame is on screen (the event loop running), on the default scene.

    PYTHONPATH=. xvfb-run -a python benchmarks/window_updates.py [--size 1280 900] [--updates 30]

``python -m app.bench`` times ``paintGL`` directly and leaves Qt's composition out; this is the
share of every frame an artist waits for on top of it (a window that composes its widgets
through GL paid 37-110 ms per update under llvmpipe, whatever changed).
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time


def _summary(name: str, ms: list[float]) -> str:
    p90 = sorted(ms)[int(0.9 * (len(ms) - 1))]
    return f"{name:36s} median {statistics.median(ms):7.1f} ms   p90 {p90:7.1f} ms"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, nargs=2, default=(1280, 900), metavar=("W", "H"))
    parser.add_argument("--updates", type=int, default=30)
    args = parser.parse_args(argv)

    from app.surface import configure_gl

    configure_gl()
    from PySide6.QtCore import QSettings
    from PySide6.QtWidgets import QApplication, QLabel

    from app.ui.window import MainWindow

    app = QApplication.instance() or QApplication(sys.argv[:1])
    with tempfile.TemporaryDirectory() as tmp:
        window = MainWindow(None, settings=QSettings(f"{tmp}/studio.ini", QSettings.Format.IniFormat))
        window.ask_save_changes = lambda: "discard"
        window.resize(*args.size)
        window.show()
        settle = time.perf_counter() + 3.0
        while time.perf_counter() < settle:
            app.processEvents()
            time.sleep(0.005)
        view = window.viewport
        label = QLabel("frame", window.statusBar())
        window.statusBar().addWidget(label)
        app.processEvents()
        repaints = []
        for i in range(args.updates):
            label.setText(f"frame {i}")
            t0 = time.perf_counter()
            label.repaint()
            repaints.append((time.perf_counter() - t0) * 1e3)
            app.processEvents()
        drawn: list[int] = []
        view.frame_drawn.connect(lambda: drawn.append(1))

        def until_shown(update) -> list[float]:
            ms = []
            for _ in range(args.updates):
                drawn.clear()
                t0 = time.perf_counter()
                update()
                while not drawn:
                    app.processEvents()
                app.processEvents()  # the composition or the swap after the paint
                ms.append((time.perf_counter() - t0) * 1e3)
            return ms

        overlay, scene = until_shown(view.update_overlays), until_shown(view.update)
        print(f"window {args.size[0]} x {args.size[1]}, {window.scene.result.strand_count} strands")
        print(_summary("status label repaint", repaints))
        print(_summary("view overlay update until shown", overlay))
        print(_summary("view scene update until shown", scene))
        window.close()
        app.processEvents()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
