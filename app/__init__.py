"""Hairtool Studio: the Qt desktop view over the ``hairtool`` library.

Importing it first keeps None, True and False alive against the PySide6 bindings that drop
references to them on Python 3.11 (:mod:`app.singletons`), before any Qt call can.

It also gives numpy's OpenBLAS one thread (unless OPENBLAS_NUM_THREADS says otherwise), before
numpy loads it: OpenBLAS's worker threads spin for a while after every call, and the studio's
calls are small (a dense groom's projection at a press, a 4 × 4 matrix on n points), so the
spinning only held a core the engine's numba threads then waited for. The first brush move
after a press on the bear took 65 ms against 35 (2-core VM).

And numba's OpenMP threads wait passively (OMP_WAIT_POLICY=PASSIVE, unless set), before any
kernel loads libgomp: by default an idle thread spins after each of the dozens of parallel
kernels a brush move runs, holding a core the next kernel, the draw or another program needs.
A bear comb drag alternating with and without it on a shared 2-core host (at 0.05-0.4 of its
speed): a median 0.89× the time (p90 0.96×) over 16 pairs with the host as it was, 0.76× (p90
0.55×) over 7 with one more core kept busy; a short spin (GOMP_SPINCOUNT=10000) lost to both.
"""

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

from app import singletons  # (after the environment numpy reads)

singletons.protect()
