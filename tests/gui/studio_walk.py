"""The every-action walk: every QAction of the studio's menus and toolbars, found at run time, in
each of a few states, with every dialog answered by its defaults and real paths.

Run by ``test_studio_every_action.py`` in a subprocess (a fatal error then fails that test
instead of killing pytest): ``python tests/gui/studio_walk.py OUT_DIR [--states STATE …]`` walks
the states in the order given (a state named twice is walked twice, in the same process).
It prints one JSON report as its last line: the problems it met (error dialogs, Python
exceptions, Qt warnings, dialogs that refused their defaults, exported files that do not read
back, disabled actions that do not say why), what it triggered and the files it read back,
and the wall and CPU seconds of each action and of building each state (how often).

How it answers: ``QDialog.exec`` presses the dialog's own OK button (its checks run; a dialog
still open afterwards refused its defaults); file dialogs return the state's own file (a copy in
OUT_DIR, so nothing of the repository is written) or the suggested name in OUT_DIR; Save /
Discard / Cancel questions are answered Discard, other questions No; a critical or warning
message box is an error dialog. Each action runs in its state: when an action replaced the groom
or the animation (New from sample, Open, Close animation …), the state is rebuilt before the next
one, so in the capture state every File ▸ New from sample entry is followed by reopening the
capture (the sequence that once aborted the process in a ``paintEvent``). Long jobs are given
:data:`JOB_S` seconds, then cancelled as a user would, and must leave no partial file (a video
export, which the test reads back, runs to its end). File ▸ Quit
comes last, as Ctrl+Q over an edit answered Discard: the process must then end cleanly.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import shutil
import sys
import time
import traceback
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
DATA = ROOT / "tests" / "data"
STATES = ("sample", "bear", "bvh", "simulation")
JOB_S = 1.5  # seconds a job may run before the walk cancels it …
JOB_MORE_S = 60.0  # … or more, while it moves, once a tenth of it is done (short videos, small solves)
JOB_STALL_S = 5.0  # … and cancelled when its bar has not moved for this long
JOB_FIRST_S = 3.0  # … waiting this long at most for that tenth (a video's first frame, on a
# loaded CI core beside the other test worker, came after 1.5 s and the export was cancelled)
JOB_VIDEO_S = 240.0  # a video export (8 frames, read back by the test) runs to its end: a loaded
# CI core once drew no frame for 5 s, and the walk cancelled the file the test reads back
SIMULATION = {"frames": 8, "substeps": 2}  # the simulated state: a short simulation of the sample
SELF_EXPLAINED = ("Edit ▸ Undo", "Edit ▸ Redo")  # Qt greys these itself; their text says why


def label(text: str) -> str:
    return text.replace("&&", "\0").replace("&", "").replace("\0", "&").split("\t")[0]


class Walk:
    def __init__(self, out: Path) -> None:
        from PySide6.QtCore import QSettings
        from PySide6.QtWidgets import QApplication

        self.out = out
        self.problems: list[dict] = []
        self.triggered: dict[str, list[list[str]]] = {}  # state: the actions of each walk
        self.disabled: dict[str, list[str]] = {}
        self.read_back: list[str] = []
        self.timings: dict[str, float] = {}  # wall seconds of each action and of entering each state
        self.cpu: dict[str, float] = {}  # … and the process's CPU seconds there (all its threads):
        # where wall runs far past CPU, the walk waited (a helper process, another test worker)
        self.entered: dict[str, int] = {}  # how often each state was built
        self._read_ok: set[str] = set()  # digests of the files that read back
        self.where = ("start", "")
        self.app = QApplication.instance()
        data = out / "data"
        data.mkdir(parents=True, exist_ok=True)
        self.files = {}
        for name, source in (
            ("bear", DATA / "grooms" / "bear.tfx"),
            ("bvh", DATA / "motion" / "pymo_walk.bvh"),
            ("head", DATA / "grooms" / "sintel_head.obj"),
        ):
            self.files[name] = data / source.name
            shutil.copyfile(source, self.files[name])
        self.exports = out / "exports"
        self.exports.mkdir(exist_ok=True)
        settings = QSettings(str(out / "studio.ini"), QSettings.Format.IniFormat)
        settings.setValue("last_dir", str(self.exports / "x"))
        self._patch_dialogs()
        from app.ui.window import MainWindow

        self.window = MainWindow(None, settings=settings)
        self.window.resize(760, 520)
        self.window.show()
        self.pump()
        self._simulated = None
        self.state = None
        self.print_state = None

    # -- problems ------------------------------------------------------------------------
    def problem(self, kind: str, text: str) -> None:
        state, action = self.where
        self.problems.append({"state": state, "action": action, "kind": kind, "text": text})

    def install_hooks(self) -> None:
        from PySide6.QtCore import QtMsgType, qInstallMessageHandler

        def excepthook(kind, value, tb) -> None:
            self.problem("exception", "".join(traceback.format_exception(kind, value, tb)))

        def messages(mode, context, message) -> None:
            if mode in (QtMsgType.QtWarningMsg, QtMsgType.QtCriticalMsg, QtMsgType.QtFatalMsg):
                self.problem("qt-warning", message)

        sys.excepthook = excepthook
        self._handler = messages
        qInstallMessageHandler(messages)

    # -- dialogs answered with their defaults ----------------------------------------------------
    def _patch_dialogs(self) -> None:
        from PySide6.QtWidgets import QDialog, QDialogButtonBox, QFileDialog, QInputDialog, QMessageBox

        walk = self
        B = QDialogButtonBox.StandardButton

        def dialog_exec(dialog) -> int:
            ok = None
            for box in dialog.findChildren(QDialogButtonBox):
                for which in (B.Ok, B.Save, B.Open, B.Yes):
                    ok = ok or box.button(which)
            if ok is not None:
                ok.click()  # the dialog's own checks run, as when the user presses OK
            else:
                dialog.accept()
            walk.pump()
            if dialog.result() != QDialog.DialogCode.Accepted:
                walk.problem("dialog-refused", f"{dialog.windowTitle()} refused its defaults")
            dialog.deleteLater()
            return dialog.result()

        M = QMessageBox.StandardButton

        def question(parent, title, text, buttons=M.Yes | M.No, default=M.NoButton):
            if buttons & M.Discard:
                return M.Discard
            return M.No if buttons & M.No else default

        def error_box(kind):
            def show(parent, title, text, *args, **kwargs):
                walk.problem("error-dialog", f"{kind} {title}: {text}")
                return M.Ok

            return staticmethod(show)

        def box_exec(box) -> int:
            icon = box.icon()
            if icon in (QMessageBox.Icon.Critical, QMessageBox.Icon.Warning):
                walk.problem("error-dialog", f"{box.windowTitle()}: {box.text()}")
            buttons = box.standardButtons()
            for which in (M.Discard, M.No, M.Ok):
                if buttons & which:
                    return int(which.value)
            return int(M.Ok.value)

        def open_name(parent, title="", start="", filters="", *args, **kwargs):
            return walk.open_answer(title, filters), ""

        def save_name(parent, title="", start="", filters="", *args, **kwargs):
            name = Path(start).name if start and Path(start).suffix else "untitled"
            return str(self.exports / name), ""

        QDialog.exec = dialog_exec
        QMessageBox.exec = box_exec
        QMessageBox.question = staticmethod(question)
        QMessageBox.critical = error_box("critical")
        QMessageBox.warning = error_box("warning")
        QMessageBox.information = staticmethod(lambda *a, **k: M.Ok)
        QFileDialog.getOpenFileName = staticmethod(open_name)
        QFileDialog.getSaveFileName = staticmethod(save_name)
        QInputDialog.getText = staticmethod(lambda parent, title, label, *a, **k: (k.get("text", ""), True))

    def open_answer(self, title: str, filters: str) -> str:
        """The file an Open dialog picks: the thing it asks for, written earlier or shipped."""
        if ".hairproj" in filters:
            found = sorted(self.exports.glob("*.hairproj"))
            return str(found[0]) if found else ""
        if "*.obj" in filters and "*.tfx" not in filters:
            return str(self.files["head"])
        if "Stroke" in filters:
            found = sorted(self.exports.glob("*strokes*.json"))
            return str(found[0]) if found else ""
        return str(self.state_file())

    def state_file(self) -> Path:
        return self.files["bvh"] if self.state == "bvh" else self.files["bear"]

    # -- states ------------------------------------------------------------------------------
    def pump(self, rounds: int = 3) -> None:
        for _ in range(rounds):
            self.app.processEvents()

    def settle(self) -> None:
        """Let jobs finish (cancel those still running after JOB_S), then draw."""
        jobs = self.window.jobs
        if any(j.title.endswith((".mp4", ".gif")) for j in jobs.active()):
            jobs.wait(JOB_VIDEO_S)
        if not jobs.wait(JOB_S):

            def tenth() -> bool:
                return all((j.fraction or 0.0) >= 0.1 for j in jobs.active())

            waited = 0.0
            while not tenth() and waited < JOB_FIRST_S:
                if jobs.wait(0.1):
                    break
                waited += 0.1
            if tenth():  # as an artist waits while the bar moves
                last, spent = -1.0, 0.0
                while spent < JOB_MORE_S and not jobs.wait(JOB_STALL_S):
                    now = min((j.fraction or 0.0) for j in jobs.active()) if jobs.active() else 1.0
                    if now <= last:
                        break
                    last, spent = now, spent + JOB_STALL_S
            jobs.cancel()  # as the artist presses Cancel: it must leave no partial file
            self.window.writes.wait()  # a file being saved has no Cancel: it ends whole (or fails)
            jobs.wait(30.0)
        self.pump()

    def fingerprint(self) -> tuple:
        w = self.window
        return (id(w.scene.rest), id(w.animation.animation), w.scene.binding is not None)

    def enter(self, state: str) -> None:
        t0, c0 = time.perf_counter(), time.process_time()
        try:
            self._enter(state)
        finally:
            self._spent(f"enter {state}", t0, c0)
            self.entered[state] = self.entered.get(state, 0) + 1

    def _spent(self, key: str, t0: float, c0: float) -> None:
        self.timings[key] = round(self.timings.get(key, 0.0) + time.perf_counter() - t0, 2)
        self.cpu[key] = round(self.cpu.get(key, 0.0) + time.process_time() - c0, 2)

    def _enter(self, state: str) -> None:
        from app.ui.simulate_dialog import SOURCE
        from hairtool.simulate.options import SimulateOptions

        self.state = state
        w = self.window
        w.undo_stack.setClean()
        w.settings.setValue("recent", [])  # File ▸ Open Recent: this state's own file
        if state in ("sample", "simulation"):
            w.open_bundled_sample()
        else:
            w.open_path(self.files[state])
        self.settle()
        if state == "simulation":
            if self._simulated is None:
                options = SimulateOptions(**SIMULATION).fitted_to(w.scene.result)
                job = w.sources.start_simulation(options)
                w.jobs.wait(120.0)
                self._simulated = w.animation.animation if job.state == "done" else None
                if self._simulated is None:
                    self.problem("state", "the sample's simulation did not finish")
            else:
                w.animation.load_animation(self._simulated, SOURCE)
            self.settle()
        w.viewport.frame_all()
        self.print_state = self.fingerprint()

    def ensure(self, state: str) -> None:
        if self.fingerprint() != self.print_state or self.window.isHidden():
            self.enter(state)

    # -- actions -----------------------------------------------------------------------------
    def actions(self) -> list[tuple[str, object]]:
        """(name, QAction) of every menu (submenus included) and toolbar, each action once."""
        from PySide6.QtWidgets import QToolBar

        found: list[tuple[str, object]] = []
        seen: set[int] = set()

        def visit(menu, path: str) -> None:
            menu.aboutToShow.emit()  # menus that fill themselves when shown (Open Recent)
            for a in menu.actions():
                if a.isSeparator():
                    continue
                name = f"{path} ▸ {label(a.text())}"
                if a.menu() is not None:
                    visit(a.menu(), name)
                elif id(a) not in seen:
                    seen.add(id(a))
                    found.append((name, a))

        for top in self.window.menuBar().actions():
            visit(top.menu(), label(top.text()))
        for bar in self.window.findChildren(QToolBar):
            for a in bar.actions():
                if not a.isSeparator() and id(a) not in seen and a.menu() is None:
                    seen.add(id(a))
                    found.append((f"{bar.windowTitle()} toolbar ▸ {label(a.text())}", a))
        return found

    @staticmethod
    def is_quit(action) -> bool:
        from PySide6.QtGui import QKeySequence

        return action.shortcut() == QKeySequence(QKeySequence.StandardKey.Quit)

    def walk_state(self, state: str) -> None:
        self.where = (state, "")
        self.enter(state)
        names = []
        for name, action in self.actions():
            if self.is_quit(action):
                continue
            recent = "Open Recent ▸" in name
            key = f"File ▸ Open Recent ▸ {Path(name.split('▸')[-1].strip()).name}" if recent else name
            self.ensure(state)
            self.where = (state, key)
            if not action.isEnabled():
                self.disabled.setdefault(state, []).append(key)
                explained = any(key.startswith(s) for s in SELF_EXPLAINED)
                if not explained and action.toolTip() == label(action.text()):
                    self.problem("disabled-silently", "greyed out without a tooltip saying why")
                continue
            before = {p: p.stat().st_mtime_ns for p in self.exports.rglob("*") if p.is_file()}
            t0, c0 = time.perf_counter(), time.process_time()
            action.trigger()
            self.settle()
            if action.isCheckable() and action.actionGroup() is None and action.isEnabled():
                action.trigger()  # a toggle: back as it was
                self.settle()
            self.check_exports(before)
            names.append(key)
            self._spent(f"{state}: {key}", t0, c0)
        self.triggered.setdefault(state, []).append(names)
        self.where = (state, "")

    # -- exported files ------------------------------------------------------------------------
    def check_exports(self, before: dict) -> None:
        for path in sorted(self.exports.rglob("*")):
            if not path.is_file() or before.get(path) == path.stat().st_mtime_ns:
                continue
            if ".tmp" in path.name or path.name.startswith("."):
                self.problem("partial-file", f"{path.name} left behind")
                continue
            digest = hashlib.sha1(path.read_bytes()).hexdigest()
            if digest not in self._read_ok:  # the same bytes (Save, then Save As) read once
                try:
                    self.read_file(path)
                except Exception as e:  # any failure to read back is the export's problem
                    self.problem("read-back", f"{path.name}: {type(e).__name__}: {e}")
                    continue
                self._read_ok.add(digest)
            self.read_back.append(f"{self.where[0]}: {path.name}")

    def read_file(self, path: Path) -> None:
        suffix = path.suffix.lower()
        if suffix == ".png":
            import imageio.v3 as iio

            image = iio.imread(path)
            assert image.ndim == 3 and image.shape[0] > 8 and image.shape[1] > 8, image.shape
            assert np.ptp(image[..., :3]) > 0, "a blank image"
        elif suffix in (".mp4", ".gif"):
            import imageio.v3 as iio

            frames = iio.imread(path, index=None)
            assert len(frames) >= 2, f"{len(frames)} frames"
        elif suffix == ".hairproj":
            from hairtool import project

            project.load(path)
        elif suffix == ".json" and "strokes" in path.name:
            from hairtool.frozen.strokes import read_strokes

            read_strokes(path)
        elif suffix == ".json":
            from hairtool.keys.export import read_keys_json, record_keys

            assert len(record_keys(read_keys_json(path))) >= 2
        elif suffix == ".csv":
            import csv

            with open(path, newline="") as f:
                rows = list(csv.reader(f))
            assert len(rows) >= 2, "no key rows"
        elif suffix == ".svg":
            import xml.etree.ElementTree as ET

            ET.parse(path)
        else:  # grooms, animations and caches: the studio's own reader
            from app.ui.animation_io import read_any

            read_any(path)

    # -- the end ---------------------------------------------------------------------------------
    def quit_over_an_edit(self) -> None:
        """Ctrl+Q with unsaved work, answered Discard: the window closes, the process ends."""
        from PySide6.QtCore import Qt
        from PySide6.QtTest import QTest

        self.where = ("quit", "File ▸ Quit (Ctrl+Q, Discard)")
        w = self.window
        if w.isHidden():
            self.enter("sample")
        name = "length_scale" if hasattr(w.scene.params, "length_scale") else None
        if name is not None:
            w._on_param_edited(name, getattr(w.scene.params, name) * 1.01, None)
        w.activateWindow()
        self.pump()
        QTest.keyClick(w, Qt.Key.Key_Q, Qt.KeyboardModifier.ControlModifier)
        self.pump()
        if w.isVisible():  # the shortcut did not reach the window (no focus under Xvfb)
            quit_action = next(a for _, a in self.actions() if self.is_quit(a))
            quit_action.trigger()
            self.pump()
        if w.isVisible():
            self.problem("quit", "the window stayed open")

    def report(self, seconds: float) -> dict:
        return {
            "problems": self.problems,
            "triggered": self.triggered,
            "disabled": self.disabled,
            "read_back": self.read_back,
            "seconds": round(seconds, 1),
            "slowest": sorted(self.timings.items(), key=lambda kv: -kv[1]),
            "cpu": self.cpu,
            "entered": self.entered,
        }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("out", type=Path)
    parser.add_argument("--states", nargs="*", default=list(STATES), help="walked in this order")
    args = parser.parse_args(argv)
    from app.surface import configure_gl

    configure_gl()
    from PySide6.QtWidgets import QApplication

    app = QApplication(sys.argv[:1])
    t0 = time.perf_counter()
    walk = Walk(args.out)
    walk.install_hooks()
    seconds = []
    for state in args.states:
        t = time.perf_counter()
        walk.walk_state(state)
        seconds.append((state, round(time.perf_counter() - t, 1)))
    walk.quit_over_an_edit()
    app.processEvents()
    report = walk.report(time.perf_counter() - t0)
    report["state_seconds"] = seconds
    print(json.dumps(report), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
