"""Writes that never leave a half file: write beside the target, then rename over it.

The renamed file gets the permissions a plain ``open(path, "w")`` would give it: the mode of the
file it replaces, or 0o666 less the process umask for a new file (a ``mkstemp`` file is 0o600,
which would leave the user's groom unreadable to the rest of the studio).

Two helpers serve ``hairtool batch``, which runs any command and must learn what it wrote:
:func:`recording_writes` collects the paths renamed into place, whatever the writer, and
:func:`stale_temporaries` finds the temporary files a killed process left behind.
"""

from __future__ import annotations

import contextlib
import contextvars
import os
import re
import secrets
import stat
from collections.abc import Iterator
from pathlib import Path

_CREATE_FLAGS = (
    os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_CLOEXEC", 0) | getattr(os, "O_NOFOLLOW", 0)
)


def _create_temp(target: Path) -> tuple[Path, int]:
    """A new empty file beside ``target`` and the mode a new file gets here (umask applied).

    The file is created with mode 0o666 and the system takes the umask (and any default ACL)
    off, as for any new file; reading that mode back avoids ``os.umask``, whose set-and-restore
    would briefly change the umask of every thread in the process.
    """
    folder = target.parent if str(target.parent) else Path(".")
    for _ in range(100):
        tmp = folder / f".{target.name}.{secrets.token_hex(4)}.tmp{target.suffix}"
        try:
            fd = os.open(tmp, _CREATE_FLAGS, 0o666)
        except FileExistsError:
            continue
        try:
            mode = stat.S_IMODE(os.fstat(fd).st_mode)
        finally:
            os.close(fd)
        return tmp, mode
    raise FileExistsError(f"no free temporary name beside {target}")


def _temp_name_pattern(target: Path) -> re.Pattern[str]:
    """The names :func:`_create_temp` gives temporary files for ``target``."""
    return re.compile(rf"\.{re.escape(target.name)}\.[0-9a-f]{{8}}\.tmp{re.escape(target.suffix)}")


def stale_temporaries(path: str | os.PathLike[str]) -> list[Path]:
    """Temporary files beside ``path`` from writes that never finished (a killed process cannot
    remove its own); only call this when no other writer of ``path`` is running."""
    target = Path(path)
    folder = target.parent if str(target.parent) else Path(".")
    pattern = _temp_name_pattern(target)
    try:
        names = os.listdir(folder)
    except OSError:
        return []
    return sorted(folder / n for n in names if pattern.fullmatch(n))


#: Lists that :func:`recording_writes` blocks in this context (thread or task) are filling.
_recorders: contextvars.ContextVar[tuple[list[Path], ...]] = contextvars.ContextVar(
    "hairtool_atomic_recorders", default=()
)


@contextlib.contextmanager
def recording_writes() -> Iterator[list[Path]]:
    """Collect the absolute path of every file an atomic write renames into place inside the block
    (in this thread or task), in order; a path written twice appears twice."""
    written: list[Path] = []
    token = _recorders.set((*_recorders.get(), written))
    try:
        yield written
    finally:
        _recorders.reset(token)


def _final_mode(target: Path, new_file_mode: int) -> int:
    """The mode of the file being replaced (permission bits only), else that of a new file."""
    try:
        st = os.stat(target)
    except OSError:
        return new_file_mode
    return stat.S_IMODE(st.st_mode) & 0o777 if stat.S_ISREG(st.st_mode) else new_file_mode


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike[str]) -> Iterator[Path]:
    """Yield a temporary path in the target's folder (same suffix); rename it over ``path`` on success.

    For writers that need a file name (usd-core, imageio). On any exception the temporary file
    is removed and the previous ``path``, if any, is untouched. The result keeps the mode of the
    file it replaces; a new file gets 0o666 less the umask.
    """
    target = Path(path)
    tmp_path, new_file_mode = _create_temp(target)
    try:
        yield tmp_path
        # After the writer: some (usd-core) replace the file at tmp_path with their own.
        os.chmod(tmp_path, _final_mode(target, new_file_mode))
        os.replace(tmp_path, target)
    except BaseException:
        with contextlib.suppress(OSError):
            tmp_path.unlink()
        raise
    for written in _recorders.get():
        written.append(target.absolute())


@contextlib.contextmanager
def atomic_open(path: str | os.PathLike[str], mode: str = "wb", **kwargs) -> Iterator:
    """Open a temporary file for writing; it replaces ``path`` only if the block finishes."""
    with atomic_path(path) as tmp:
        with open(tmp, mode, **kwargs) as f:
            yield f
            f.flush()
            os.fsync(f.fileno())
