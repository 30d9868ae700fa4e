"""What File ▸ Save and Export groom write: the groom, and in a USD file the head mesh beside it,
renamed into place as one file.

Both go into one temporary file first, so no reader (and no save still queued behind this one)
ever finds the groom on disk without its head. Plain functions of immutable values: the studio
hands a snapshot taken on the GUI thread to :func:`write_groom_apart`, which writes it in a
helper process. usd-core's writer holds the GIL all along (the bundled Sintel with her 30,000
children: about 2 s writing the curves, 1.5 s at a time while adding the head), so in a thread
of the studio's own process it would stall the window as surely as on the GUI thread.
"""

from __future__ import annotations

import multiprocessing
import os
import threading
from concurrent.futures import ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool
from pathlib import Path

from hairtool import io
from hairtool.errors import FormatError, HairtoolError
from hairtool.groom import Groom
from hairtool.io.atomic import atomic_path
from hairtool.io.obj import Mesh

USD_SUFFIXES = (".usda", ".usdc", ".usd")


def write_groom(path: str | os.PathLike[str], groom: Groom, mesh: Mesh | None = None) -> None:
    """Write ``groom`` to ``path`` (its extension picks the format); a USD file also gets
    ``mesh`` (the head, or None) as a Mesh prim.

    Raises
    ------
    FormatError
        The file cannot be written; the message names ``path``, never the temporary file.
    """
    if mesh is None or Path(path).suffix.lower() not in USD_SUFFIXES:
        io.write(path, groom)
        return
    from hairtool.io.usd_mesh import add_mesh

    tmp: Path | None = None
    try:
        with atomic_path(path) as tmp:
            io.write(tmp, groom)
            add_mesh(tmp, mesh)  # the head goes with the groom (a Mesh prim beside)
    except HairtoolError as e:
        reason = e.reason if isinstance(e, FormatError) else str(e)
        raise FormatError(path, reason if tmp is None else reason.replace(str(tmp), str(path))) from None
    except OSError as e:
        raise FormatError(path, f"cannot write: {e}") from None


_pool: ProcessPoolExecutor | None = None
_pool_lock = threading.Lock()


def _writer() -> ProcessPoolExecutor:
    """The helper process (started at the first call: spawned, never forked from a process
    running Qt's threads), kept for the next writes."""
    global _pool
    with _pool_lock:
        if _pool is None:
            _pool = ProcessPoolExecutor(1, mp_context=multiprocessing.get_context("spawn"))
        return _pool


def _write_reporting(path: str, groom: Groom, mesh: Mesh | None) -> str | None:
    """In the helper: :func:`write_groom`; a failure comes back as its reason (a FormatError
    itself would not survive the trip back: its constructor takes two arguments)."""
    try:
        write_groom(path, groom, mesh)
    except FormatError as e:
        return e.reason
    except HairtoolError as e:
        return str(e)
    return None


def write_groom_apart(path: str | os.PathLike[str], groom: Groom, mesh: Mesh | None = None) -> None:
    """:func:`write_groom` in the helper process; blocks the calling (worker) thread, not the GIL.

    Raises
    ------
    FormatError
        The file cannot be written, or the helper process ended; the message names ``path``.
    """
    global _pool
    pool = _writer()
    try:
        reason = pool.submit(_write_reporting, os.fspath(path), groom, mesh).result()
    except BrokenProcessPool as e:
        with _pool_lock:
            if _pool is pool:
                _pool = None  # the next save starts a new helper
        raise FormatError(path, f"the writing process ended before the file was written ({e})") from None
    if reason is not None:
        raise FormatError(path, reason)
