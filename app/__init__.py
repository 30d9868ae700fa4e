"""Hairtool Studio: the Qt desktop view over the ``hairtool`` library.

Importing it first keeps None, True and False alive against the PySide6 bindings that drop
references to them on Python 3.11 (:mod:`app.singletons`), before any Qt call can.

It also gives numpy's OpenBLAS one thread (unless OPENBLAS_NUM_THREADS says otherwise), before
numpy loads it: OpenBLAS's worker threads spin for a while after every call, and the studio's
calls are small (a dense groom's projection at a press, a 4 × 4 matrix on n points), so the
spinning only held a core the engine's numba threads then waited for. The first brush move
after a press on the bear took 65 ms against 35 (2-core VM).
"""

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

from app import singletons  # (after the environment numpy reads)

singletons.protect()
