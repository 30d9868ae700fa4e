"""Writes that never leave a half file: write beside the target, then rename over it.

The renamed file gets the permissions a plain ``open(path, "w")`` would give it: the mode of the
file it replaces, or 0o666 less the process umask for a new file (a ``mkstemp`` file is 0o600,
which would leave the user's groom unreadable to the rest of the studio).

A writer killed outright (``kill -9``, a crash, a power cut) cannot remove its temporary file.
Temporaries are therefore named ``.<name>.<host>-<pid>.<random>.tmp<suffix>``: ``host`` is a
short tag of this machine and process namespace, ``pid`` the writer's process id. Every write
to a path first removes that path's temporaries whose writer is gone: made under this host tag
by a process id that no longer runs. A temporary of a live writer is never touched; a dead
writer's whose id has been reused by another live process waits for a later write; one made
on another machine sharing the folder is left alone, since its process id means nothing here.

The target's missing folders are created first, as a render ROP does (a batch template's
``out/{stem}/keys.json`` needs no set-up). A folder that cannot be made or written to is an
``OSError`` naming that folder, never the temporary file the user has not heard of.

Two helpers serve ``hairtool batch``, which runs any command and must learn what it wrote:
:func:`recording_writes` collects the paths renamed into place, whatever the writer, and
:func:`stale_temporaries` lists every temporary of a path, from any machine, for a batch that
knows no other writer of that path runs (a farm worker killed mid-job on another host).
"""

from __future__ import annotations

import contextlib
import contextvars
import errno
import functools
import hashlib
import os
import re
import secrets
import socket
import stat
from collections.abc import Iterator
from pathlib import Path

from hairtool import interrupts

_CREATE_FLAGS = (
    os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_CLOEXEC", 0) | getattr(os, "O_NOFOLLOW", 0)
)


@functools.cache
def host_tag() -> str:
    """Six hex digits naming this machine and its process-id namespace (process ids mean
    something only within one namespace: a container sharing the folder has its own)."""
    try:
        namespace = os.readlink("/proc/self/ns/pid")
    except OSError:
        namespace = ""
    return hashlib.sha1(f"{socket.gethostname()}|{namespace}".encode()).hexdigest()[:6]


def temp_name(target: Path, pid: int, token: str) -> str:
    """``.<name>.<host>-<pid>.<token>.tmp<suffix>``: hidden, beside the target, same suffix.

    Parameters
    ----------
    target : Path
        The file being written.
    pid : int
        The writer's process id.
    token : str
        A random part, so two writers of one process differ.

    Returns
    -------
    str
        The temporary's file name (no folder).
    """
    return f".{target.name}.{host_tag()}-{pid}.{token}.tmp{target.suffix}"


def _temp_pattern(target: Path) -> re.Pattern[str]:
    """Our temporaries of ``target``, and files a library made from their names: usd-core saves
    through its own ``<name without suffix>.XXXXXX`` beside the path it is given."""
    name = re.escape(target.name)
    return re.compile(rf"\.{name}\.{host_tag()}-(\d{{1,10}})\.[0-9a-f]{{8}}\.tmp(?:\.[^/]*)?")


def stale_temporaries(path: str | os.PathLike[str]) -> list[Path]:
    """Every temporary of ``path`` from any machine (``.<name>.<host>-<pid>.<random>.tmp…``);
    only call this when no other writer of ``path`` is running.

    Parameters
    ----------
    path : str or os.PathLike
        The target.

    Returns
    -------
    list of Path
        Its temporaries, sorted.
    """
    target = Path(path)
    folder = target.parent if str(target.parent) else Path(".")
    name = re.escape(target.name)
    pattern = re.compile(rf"\.{name}\.[0-9a-f]{{6}}-\d{{1,10}}\.[0-9a-f]{{8}}\.tmp(?:\.[^/]*)?")
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


def process_alive(pid: int) -> bool:
    """Whether process ``pid`` may still be writing; True whenever it cannot be ruled out.

    Parameters
    ----------
    pid : int
        A process id of this host.

    Returns
    -------
    bool
        False only where the process is known to be gone.
    """
    if pid == os.getpid():
        return True
    if os.name != "posix" or not 0 < pid < 2**31:
        return True  # on Windows os.kill would terminate it; beyond pid_t it is no process id
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:
        return True  # it exists but belongs to someone else
    try:  # a killed process not yet reaped by its parent is a zombie: it writes no more
        with open(f"/proc/{pid}/stat", "rb") as f:
            state = f.read().rsplit(b")", 1)[1].split()[0]
    except (OSError, IndexError):
        return True
    return state not in (b"Z", b"X")


def remove_stale_temps(target: Path) -> list[Path]:
    """Remove the temporaries of ``target`` left by writers of this host that no longer run.

    Parameters
    ----------
    target : Path
        The file about to be written.

    Returns
    -------
    list of Path
        The temporaries removed.
    """
    folder = target.parent if str(target.parent) else Path(".")
    pattern = _temp_pattern(target)
    prefix = f".{target.name}."
    removed = []
    try:
        entries = list(os.scandir(folder))
    except OSError:
        return removed
    for entry in entries:
        if not entry.name.startswith(prefix):
            continue
        m = pattern.fullmatch(entry.name)
        if m is None or process_alive(int(m.group(1))):
            continue
        with contextlib.suppress(OSError):
            os.unlink(entry.path)
            removed.append(Path(entry.path))
    return removed


def _make_folder(folder: Path) -> None:
    """Create ``folder`` and its missing parents; an error names the folder that failed."""
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except (FileExistsError, NotADirectoryError):  # a file where a folder should be: name it
        blocker = next((p for p in (folder, *folder.parents) if p.exists() and not p.is_dir()), folder)
        raise NotADirectoryError(errno.ENOTDIR, "a file is in the way of the folder", str(blocker)) from None
    except OSError as e:
        raise type(e)(e.errno, e.strerror, e.filename or str(folder)) from None


def _create_temp(target: Path) -> tuple[Path, int]:
    """A new empty file beside ``target`` and the mode a new file gets here (umask applied).

    The file is created with mode 0o666 and the system takes the umask (and any default ACL)
    off, as for any new file; reading that mode back avoids ``os.umask``, whose set-and-restore
    would briefly change the umask of every thread in the process.
    """
    folder = target.parent if str(target.parent) else Path(".")
    for _ in range(100):
        tmp = folder / temp_name(target, os.getpid(), secrets.token_hex(4))
        try:
            fd = os.open(tmp, _CREATE_FLAGS, 0o666)
        except FileExistsError:
            continue
        except OSError as e:  # the folder's fault (read-only, full, gone): name it, not ``tmp``
            raise type(e)(e.errno, e.strerror, str(folder)) from None
        try:
            mode = stat.S_IMODE(os.fstat(fd).st_mode)
        finally:
            os.close(fd)
        return tmp, mode
    raise FileExistsError(f"no free temporary name beside {target}")


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
    file it replaces; a new file gets 0o666 less the umask. Missing folders of ``path`` are
    created, and temporaries of ``path`` left by killed writers removed, first (see the module
    docstring).

    Parameters
    ----------
    path : str or os.PathLike
        The target.

    Yields
    ------
    Path
        The temporary path to write.
    """
    target = Path(path)
    _make_folder(target.parent if str(target.parent) else Path("."))
    remove_stale_temps(target)
    tmp_path, new_file_mode = _create_temp(target)
    try:
        yield tmp_path
        if interrupts.was_interrupted():  # a Ctrl+C a library swallowed (usd-core's plugin loading)
            raise KeyboardInterrupt
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
    """Open a temporary file for writing; it replaces ``path`` only if the block finishes.

    Parameters
    ----------
    path : str or os.PathLike
        The target.
    mode : str, default "wb"
        A writing mode of :func:`open`.
    **kwargs
        :func:`open`'s other keywords (``encoding``, ``newline``).

    Yields
    ------
    file object
        The temporary file, flushed and synced before the rename.
    """
    with atomic_path(path) as tmp:
        with open(tmp, mode, **kwargs) as f:
            yield f
            f.flush()
            os.fsync(f.fileno())
