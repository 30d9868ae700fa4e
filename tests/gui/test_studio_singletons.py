"""None, True and False outlive PySide6 bindings that drop references to them (app.singletons):
a studio process survives more such calls than the objects had references."""

from __future__ import annotations

import json
import subprocess
import sys

SCRIPT = r"""
import json, sys
from PySide6.QtCore import QObject, Signal
from PySide6.QtGui import QColor

class Emitter(QObject):
    changed = Signal()

colour, emitter = QColor(1, 2, 3), Emitter()

def dropped(call, obj):  # references to obj lost per call (1: the binding forgot one)
    call()
    before = sys.getrefcount(obj)
    for _ in range(100):
        call()
    return (before - sys.getrefcount(obj)) / 100

out = {
    "void": dropped(lambda: colour.setAlpha(3), None),  # a void C++ function's None
    "emit": dropped(emitter.changed.emit, True),  # Signal.emit's True
}
counts = {obj: sys.getrefcount(obj) + 1000 for obj in (None, True)}  # more than they have
import app  # noqa: E402  (what every studio process imports first)
for obj, call in ((None, lambda: colour.setAlpha(3)), (True, emitter.changed.emit)):
    for _ in range(counts[obj]):
        call()
out["survived"] = True
print(json.dumps(out))
"""


def test_singletons_survive_the_bindings_reference_slips(tmp_path):
    run = subprocess.run(
        [sys.executable, "-c", SCRIPT], capture_output=True, text=True, timeout=60, cwd=tmp_path
    )
    assert run.returncode == 0, run.stderr[-2000:]
    out = json.loads(run.stdout.strip().splitlines()[-1])
    assert out["survived"]
    assert out["void"] in (0.0, 1.0) and out["emit"] in (0.0, 1.0), out  # a slip, or none at all


def test_protect_is_a_no_op_where_the_singletons_are_immortal():
    from app import singletons

    assert singletons.protect() is False  # already done on importing app, or not needed
    if singletons.needed():
        assert sys.getrefcount(None) > singletons.EXTRA
