"""The layers a stage brings in (sublayers, references, payloads), checked before usd-core
follows them: each must be a regular file.

usd-core opens a sublayer or a reference by its path as it composes the stage; a FIFO there
blocks inside usd-core forever, and a device (``/dev/zero``) reads without end. So the layer
the user named, and every layer it brings in, are walked first (without recursion), each asset
path resolved against the layer that names it and stat'ed, and only regular files are opened
to look for theirs. A path that names no file is left to usd-core, which reports it as today.
"""

from __future__ import annotations

import os
import stat
from pathlib import Path

from hairtool.errors import FormatError, quoted

#: More layers than this in one stage (each opened here once) is refused: no groom has them.
MAX_LAYERS = 4096


def _dependencies(layer) -> list[str]:
    """The asset paths ``layer`` names: sublayers, references and payloads."""
    found = layer.GetCompositionAssetDependencies()
    return [str(p) for p in found if str(p)]


def check_dependencies(path: Path, layer) -> None:
    """Refuse (:class:`FormatError` naming ``path`` and the layer) a stage whose layers bring
    in anything that is not a regular file.

    Parameters
    ----------
    path : Path
        The stage, named in a refusal.
    layer : Sdf.Layer
        Its root layer.
    """
    from pxr import Sdf

    seen = {os.path.realpath(layer.realPath)} if layer.realPath else set()
    stack = [layer]
    while stack:
        here = stack.pop()
        for asset in _dependencies(here):
            target = here.ComputeAbsolutePath(asset) if here.realPath else asset
            try:
                mode = os.stat(target).st_mode
            except (OSError, ValueError):
                continue  # missing: usd-core says so
            if not stat.S_ISREG(mode):
                raise FormatError(
                    path, f"the layer {quoted(asset)} it brings in is not a regular file (a FIFO, a device?)"
                )
            real = os.path.realpath(target)
            if real in seen:
                continue
            seen.add(real)
            if len(seen) > MAX_LAYERS:
                raise FormatError(path, f"it brings in more than {MAX_LAYERS} layers")
            sub = Sdf.Layer.FindOrOpen(target)
            if sub is not None:
                stack.append(sub)
