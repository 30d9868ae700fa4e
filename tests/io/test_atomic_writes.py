"""A writer that fails part-way leaves no file behind and never destroys the previous one."""

from __future__ import annotations

import contextlib
import os
import stat

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


def test_unwritable_folder_is_a_format_error(tmp_path, groom):
    with pytest.raises(FormatError, match="cannot write"):
        write(tmp_path / "missing" / "g.hair", groom)


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
