"""What File ▸ Save and Export groom write: the groom, and in a USD file the head mesh beside it,
renamed into place as one file.

Both go into one temporary file first, so no reader (and no save still queued behind this one)
ever finds the groom on disk without its head. Plain functions of immutable values: the studio
calls :func:`write_groom` in a worker thread with a snapshot taken on the GUI thread.
"""

from __future__ import annotations

import os
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
