"""What Save writes, as one file: the groom with its head in USD is byte for byte what the groom
written first and its head added after made before; other formats are :func:`hairtool.io.write`'s
own; a file that cannot be written names itself, never the temporary beside it."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from app.document.groom_file import write_groom
from hairtool import io, samples
from hairtool.errors import FormatError
from hairtool.io.obj import Mesh
from hairtool.io.usd_mesh import add_mesh, read_mesh


def _head() -> Mesh:
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], np.float32)
    f = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]], np.int32)
    return Mesh(v, f, np.zeros_like(v))


@pytest.mark.parametrize("suffix", [".usda", ".usdc"])
def test_a_groom_with_its_head_is_the_bytes_of_the_two_step_write(tmp_path, suffix):
    groom, head = samples.portrait(strands=6, vertices=4), _head()
    before, now = tmp_path / f"before{suffix}", tmp_path / f"now{suffix}"
    io.write(before, groom)  # how Save wrote it until the write went off the GUI thread
    add_mesh(before, head)
    write_groom(now, groom, head)
    assert now.read_bytes() == before.read_bytes()
    assert np.array_equal(read_mesh(now).faces, head.faces)
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".")] == []  # no temporary left


def test_without_a_head_or_in_another_format_it_is_the_plain_write(tmp_path):
    groom = samples.portrait(strands=6, vertices=4)
    for name, head in (("plain.usda", None), ("head.hair", _head())):
        write_groom(tmp_path / name, groom, head)
        io.write(tmp_path / f"ref_{name}", groom)
        assert (tmp_path / name).read_bytes() == (tmp_path / f"ref_{name}").read_bytes()


def test_a_file_that_cannot_be_written_is_named_and_the_old_one_stays(tmp_path, monkeypatch):
    groom, head = samples.portrait(strands=6, vertices=4), _head()
    blocker = tmp_path / "gone"
    blocker.write_text("a file where the folder should be")
    with pytest.raises(FormatError) as caught:
        write_groom(blocker / "groom.usda", groom, head)
    assert str(caught.value).startswith(str(blocker / "groom.usda")) and ".tmp" not in str(caught.value)
    kept = tmp_path / "kept.usda"
    write_groom(kept, groom, head)
    old = kept.read_bytes()

    def broken_mesh(path: Path, mesh: Mesh) -> None:
        raise FormatError(path, "cannot write: [Errno 28] No space left on device")

    monkeypatch.setattr("hairtool.io.usd_mesh.add_mesh", broken_mesh)
    with pytest.raises(FormatError, match="No space left") as caught:
        write_groom(kept, samples.portrait(strands=3, vertices=4), head)
    assert str(caught.value).startswith(f"{kept}: ") and kept.read_bytes() == old
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".")] == []


def test_written_apart_it_is_the_same_file_and_a_failure_names_it(tmp_path):
    """The helper process writes the bytes :func:`write_groom` writes here; its failure comes
    back as a FormatError naming the file."""
    from app.document.groom_file import write_groom_apart

    groom, head = samples.portrait(strands=6, vertices=4), _head()
    write_groom(tmp_path / "here.usda", groom, head)
    write_groom_apart(tmp_path / "apart.usda", groom, head)
    assert (tmp_path / "apart.usda").read_bytes() == (tmp_path / "here.usda").read_bytes()
    blocker = tmp_path / "gone"
    blocker.write_text("a file where the folder should be")
    with pytest.raises(FormatError) as caught:
        write_groom_apart(blocker / "groom.usda", groom, head)
    assert str(caught.value).startswith(f"{blocker / 'groom.usda'}: cannot write")
