"""None, True and False kept alive for PySide6 builds that drop references to them.

PySide6 6.12 returns the result of every binding of a ``void`` C++ function (``QPainter.drawLine``,
``QLabel.setText``, ``QAction.trigger``, ``QWidget.update`` …) as ``None`` without taking a
reference to it, and ``Signal.emit`` returns ``True`` the same way. From Python 3.12 on these
objects are immortal (PEP 683) and nothing happens; on Python 3.11 each such call takes one
reference from them that nobody gave, until one count reaches zero and the interpreter aborts with
``Fatal Python error: none_dealloc`` (or ``bool_dealloc``) wherever the last call happens to be:
in a ``paintEvent`` that draws thousands of lines (the dope sheet of a long capture), or at Quit.

:func:`protect` gives the three objects what 3.12 gives them: a reference count no slip of this
kind can exhaust (2**40 extra references, which at a billion lost references a second last
nine days). They are never freed before the interpreter ends anyway, so the extra references
change nothing else. :func:`dropped_references` measures the slip (the tests use it).
"""

from __future__ import annotations

import ctypes
import sys

EXTRA = 1 << 40
SINGLETONS = (None, True, False)
_protected = False


def needed() -> bool:
    """True on CPython before 3.12, where None, True and False are still reference counted."""
    return sys.implementation.name == "cpython" and sys.version_info < (3, 12)


def protect() -> bool:
    """Add :data:`EXTRA` references to None, True and False (once; nothing where they are
    immortal). Returns whether it added them now."""
    global _protected
    if _protected or not needed():
        return False
    for obj in SINGLETONS:
        # CPython's object header starts with its reference count (Py_ssize_t), at id(obj)
        ctypes.c_ssize_t.from_address(id(obj)).value += EXTRA
    _protected = True
    return True


def dropped_references(call, obj: object = None, times: int = 100) -> float:
    """References to ``obj`` (None, True or False) lost per ``call()``: 0 for a correct
    binding, 1 for one that returns ``obj`` without a reference. Meaningful only where
    :func:`needed`; the caller's frame keeps no reference to the results."""
    call()
    before = sys.getrefcount(obj)
    for _ in range(times):
        call()
    return (before - sys.getrefcount(obj)) / times
