"""The kernel cache folder chosen in Edit ▸ Preferences, put to work at a start: numba reads
NUMBA_CACHE_DIR once, when it is imported, so this module imports nothing of the engine and
runs before anything does."""

from __future__ import annotations

import os

KEY = "preferences/cache_folder"


def use_preferred_cache_folder(settings) -> str | None:
    """Set NUMBA_CACHE_DIR to the preferred folder (a ``QSettings``'s) and return it; None, with
    nothing changed, when none is preferred or the environment already names one."""
    if os.environ.get("NUMBA_CACHE_DIR"):
        return None
    folder = str(settings.value(KEY, "") or "").strip()
    if not folder:
        return None
    os.environ["NUMBA_CACHE_DIR"] = folder
    return folder
