"""What keying saves on disk: the bytes of the key poses alone, in the source's own format.

A real file is written and measured, not estimated: the key poses
(:func:`~hairtool.keys.export.key_poses_only`, what ``--export KEYS.usdc`` writes) go in the
input's format into a fresh folder of the system's temp dir, deleted at once, so nothing is
left behind.
Compression (``.npz``, ``.usdc``) makes the ratio differ from keys / frames.
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Sequence
from pathlib import Path

from hairtool.groom import Animation


def keys_only_bytes(animation: Animation, keys: Sequence[int], suffix: str) -> int | None:
    """Bytes of the key poses written as a ``suffix`` file (``.usdc``, ``.npz``, …); None for a
    format that cannot hold an animation.

    Parameters
    ----------
    animation : Animation
        The animation.
    keys : sequence of int
        Its key frames.
    suffix : str
        The format's suffix.

    Returns
    -------
    int or None
        Bytes.
    """
    from hairtool.io import format_for, write
    from hairtool.keys.export import key_poses_only

    fmt = format_for(f"keys{suffix}", writing=True)
    if not fmt.animated:
        return None
    poses = key_poses_only(animation, keys)
    with tempfile.TemporaryDirectory(prefix="hairtool-keys-only-") as folder:
        path = Path(folder, f"keys{suffix}")
        write(path, poses)
        return path.stat().st_size


def storage(animation: Animation, keys: Sequence[int], source: str | os.PathLike[str]) -> dict | None:
    """``{"format", "keys_only_bytes", "input_bytes", "ratio"}``: the key poses in ``source``'s
    format against ``source`` itself; None when that format holds no animation.

    Parameters
    ----------
    animation : Animation
        The animation.
    keys : sequence of int
        Its key frames.
    source : str or os.PathLike
        The file it was read from.

    Returns
    -------
    dict or None
        The comparison.
    """
    suffix = Path(source).suffix.lower()
    keys_only = keys_only_bytes(animation, keys, suffix)
    full = os.path.getsize(source)
    if keys_only is None or full == 0:
        return None
    return {"format": suffix, "keys_only_bytes": keys_only, "input_bytes": full, "ratio": keys_only / full}
