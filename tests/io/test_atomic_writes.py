"""A writer that fails part-way leaves no file behind and never destroys the previous one."""

from __future__ import annotations

import contextlib
import os
import stat
import subprocess
import sys
import time

import numpy as np
import pytest

from hairtool.errors import FormatError
from hairtool.io import atomic, read, usd, write

WRITABLE = ("hair", "obj", "npz", "usda", "usdc", "usd")


class Boom(RuntimeError):
    pass


def _fail_mid_write(monkeypatch, ext):
    def boom(*args, **kwargs):
        raise Boom("simulated failure mid-write")

    if ext.startswith("usd"):
        monkeypatch.setattr(usd, "_extent", boom)  # runs after the stage exists, before it is saved
    else:
        monkeypatch.setattr(atomic.os, "fsync", boom)  # after every byte is written, before the rename


@pytest.mark.parametrize("ext", WRITABLE)
def test_failed_write_keeps_the_old_file(tmp_path, monkeypatch, groom, ext):
    target = tmp_path / f"groom.{ext}"
    write(target, groom.subset([0, 1]))
    before = target.read_bytes()
    _fail_mid_write(monkeypatch, ext)
    with pytest.raises(Boom):
        write(target, groom)
    assert target.read_bytes() == before
    assert [p.name for p in tmp_path.iterdir()] == [target.name]
    monkeypatch.undo()
    assert read(target).strand_count == 2


@pytest.mark.parametrize("ext", WRITABLE)
def test_failed_write_leaves_no_file(tmp_path, monkeypatch, groom, ext):
    _fail_mid_write(monkeypatch, ext)
    with pytest.raises(Boom):
        write(tmp_path / f"new.{ext}", groom)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("ext", WRITABLE)
def test_missing_folders_of_the_output_are_created(tmp_path, groom, ext):
    target = tmp_path / "shot" / "v2" / f"g.{ext}"
    write(target, groom)
    assert read(target).strand_count == groom.strand_count
    assert [p.name for p in target.parent.iterdir()] == [target.name]  # no temporaries


@pytest.mark.parametrize("inside", ["", "sub"])
def test_a_file_in_the_way_of_the_folder_is_one_line_naming_both(tmp_path, groom, inside):
    (tmp_path / "taken").write_bytes(b"")
    target = tmp_path / "taken" / inside / "g.hair"
    with pytest.raises(FormatError) as e:
        write(target, groom)
    message = str(e.value)
    assert str(target) in message and f"'{tmp_path / 'taken'}'" in message and "in the way" in message
    assert ".tmp" not in message and "\n" not in message
    assert [p.name for p in tmp_path.iterdir()] == ["taken"]


def test_a_folder_refusing_new_files_is_named_not_the_temporary(tmp_path, groom, monkeypatch):
    """Root ignores permission bits, so the refusal is simulated where the temporary is made."""
    real_open = os.open

    def refuse(path, *args, **kwargs):
        if ".tmp" in os.fspath(path):
            raise PermissionError(13, "Permission denied", os.fspath(path))
        return real_open(path, *args, **kwargs)

    monkeypatch.setattr(atomic.os, "open", refuse)
    with pytest.raises(FormatError) as e:
        write(tmp_path / "g.hair", groom)
    assert str(e.value).endswith(f"cannot write: [Errno 13] Permission denied: '{tmp_path}'")
    assert list(tmp_path.iterdir()) == []


@contextlib.contextmanager
def _umask(mask: int):
    old = os.umask(mask)
    try:
        yield
    finally:
        os.umask(old)


@pytest.mark.skipif(os.name != "posix", reason="POSIX permission bits")
@pytest.mark.parametrize("ext", WRITABLE)
def test_new_file_gets_the_umask_mode_not_0600(tmp_path, groom, ext):
    target = tmp_path / f"new.{ext}"
    with _umask(0o027):
        write(target, groom)
    assert stat.S_IMODE(target.stat().st_mode) == 0o640
    with _umask(0o022):
        write(tmp_path / f"other.{ext}", groom)
    assert stat.S_IMODE((tmp_path / f"other.{ext}").stat().st_mode) == 0o644


@pytest.mark.skipif(os.name != "posix", reason="POSIX permission bits")
@pytest.mark.parametrize("ext", WRITABLE)
def test_replaced_file_keeps_its_mode(tmp_path, groom, ext):
    target = tmp_path / f"groom.{ext}"
    write(target, groom.subset([0]))
    target.chmod(0o604)
    with _umask(0o077):
        write(target, groom)
    assert stat.S_IMODE(target.stat().st_mode) == 0o604
    assert read(target).strand_count == groom.strand_count


@pytest.mark.skipif(os.name != "posix", reason="POSIX permission bits")
def test_atomic_path_mode_and_no_leftovers(tmp_path):
    target = tmp_path / "sheet.csv"
    with _umask(0o002), atomic.atomic_path(target) as tmp:
        assert tmp.parent == tmp_path and tmp.suffix == ".csv" and tmp.name.startswith(".sheet.csv.")
        tmp.write_text("frame,picture\n")
    assert stat.S_IMODE(target.stat().st_mode) == 0o664
    assert [p.name for p in tmp_path.iterdir()] == ["sheet.csv"]


# -- writers killed outright (kill -9) -----------------------------------------------------------
_BLOCKED_WRITER = """
import sys
from hairtool.io.atomic import atomic_open
with atomic_open(sys.argv[1], "wb") as f:
    f.write(b"half of a new file")
    f.flush()
    print("writing", flush=True)
    sys.stdin.readline()  # blocks until the parent says go (or kills it)
    f.write(b", finished by " + sys.argv[2].encode())
"""


def _start_blocked_writer(target, name: str = "child") -> subprocess.Popen:
    """A real process inside an atomic write of ``target``: its temporary exists when this returns."""
    p = subprocess.Popen(
        [sys.executable, "-c", _BLOCKED_WRITER, str(target), name],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
    )
    assert p.stdout.readline() == b"writing\n"
    return p


def _temps(folder, target_name: str) -> list[str]:
    return sorted(p.name for p in folder.iterdir() if p.name.startswith(f".{target_name}."))


@pytest.mark.skipif(os.name != "posix", reason="SIGKILL and process ids as on POSIX")
def test_temporaries_of_killed_writers_go_on_the_next_write(tmp_path, groom):
    target = tmp_path / "groom.hair"
    write(target, groom.subset([0]))
    before = target.read_bytes()
    for _ in range(3):
        p = _start_blocked_writer(target)  # its own write first removes the last one's temporary
        p.kill()  # SIGKILL: no handler, no cleanup runs
        p.wait()
        p.stdin.close()
        p.stdout.close()
        (left,) = _temps(tmp_path, target.name)
        assert f"-{p.pid}." in left
        assert target.read_bytes() == before  # the old file is intact
    write(target, groom)
    assert [p.name for p in tmp_path.iterdir()] == [target.name]
    assert read(target).strand_count == groom.strand_count


@pytest.mark.skipif(os.name != "posix", reason="SIGKILL and process ids as on POSIX")
def test_killed_but_unreaped_writer_counts_as_gone(tmp_path):
    """A killed child its parent has not waited for yet is a zombie: it writes nothing more."""
    target = tmp_path / "sheet.csv"
    p = _start_blocked_writer(target)
    p.kill()
    deadline = time.monotonic() + 10
    while atomic.process_alive(p.pid) and time.monotonic() < deadline:
        time.sleep(0.01)
    assert len(_temps(tmp_path, target.name)) == 1
    with atomic.atomic_open(target, "w") as f:
        f.write("frame\n")
    assert _temps(tmp_path, target.name) == []
    p.wait()
    p.stdin.close()
    p.stdout.close()


@pytest.mark.skipif(os.name != "posix", reason="process ids as on POSIX")
def test_a_live_writers_temporary_is_never_removed(tmp_path):
    target = tmp_path / "keys.json"
    p = _start_blocked_writer(target, "the live writer")
    try:
        (theirs,) = _temps(tmp_path, target.name)
        with atomic.atomic_open(target, "w") as f:
            f.write("ours")
        assert target.read_text() == "ours"
        assert _temps(tmp_path, target.name) == [theirs]
        p.stdin.write(b"go\n")
        p.stdin.flush()
        assert p.wait(timeout=30) == 0
    finally:
        p.kill()
        p.wait()
        p.stdin.close()
        p.stdout.close()
    assert target.read_bytes() == b"half of a new file, finished by the live writer"
    assert _temps(tmp_path, target.name) == []


@pytest.mark.skipif(os.name != "posix", reason="process ids as on POSIX")
def test_only_this_targets_temporaries_of_this_host_are_removed(tmp_path):
    """Other targets' temporaries, other hosts' and files that merely look alike stay; usd-core's
    own ``.XXXXXX`` file made from a dead writer's temporary name goes."""
    gone = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True)
    dead = int(gone.stdout)
    assert not atomic.process_alive(dead)
    target = tmp_path / "shot.usda"
    ours = atomic.temp_name(target, dead, "0123abcd")
    usd_own = ours[: -len(".usda")] + ".l6EGe5"
    other_host = ours.replace(f".{atomic.host_tag()}-", ".abcdef-")
    other_target = atomic.temp_name(tmp_path / "other.usda", dead, "0123abcd")
    lookalikes = [f".shot.usda.{atomic.host_tag()}-{dead}.zz.tmp.usda", "shot.usda.bak"]
    for name in (ours, usd_own, other_host, other_target, *lookalikes):
        (tmp_path / name).write_text("left")
    with atomic.atomic_open(target, "w") as f:
        f.write("#usda 1.0\n")
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(
        [target.name, other_host, other_target, *lookalikes]
    )


_SAVING_LOOP = """
import sys
import numpy as np
from hairtool import project
from hairtool.groom import Groom

rest = Groom(np.random.default_rng(0).standard_normal((200_000, 3)), np.full(10_000, 20))
print("saving", flush=True)
while True:
    project.save(sys.argv[1], project.Project(rest=rest))
"""


@pytest.mark.skipif(os.name != "posix", reason="SIGKILL as on POSIX")
def test_project_saves_killed_at_random_leave_nothing_after_the_next_save(tmp_path):
    """The issue's case: project saves killed over and over (470 MB of temporaries after 20)."""
    from hairtool import project
    from hairtool.groom import Groom

    target = tmp_path / "shot.hairproj"
    delays = np.random.default_rng(17).uniform(0.0, 0.4, 4)
    for delay in delays:
        p = subprocess.Popen([sys.executable, "-c", _SAVING_LOOP, str(target)], stdout=subprocess.PIPE)
        try:
            assert p.stdout.readline() == b"saving\n"
            time.sleep(delay)
        finally:
            p.kill()
            p.wait()
            p.stdout.close()
        assert len(_temps(tmp_path, target.name)) <= 1  # at most the one just killed
    small = project.Project(rest=Groom(np.zeros((4, 3)), [2, 2]))
    project.save(target, small)
    assert [p.name for p in tmp_path.iterdir()] == [target.name]
    assert project.load(target).rest.strand_count == 2
