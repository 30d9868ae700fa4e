"""`hairtool anime` with render hair: the guides wave and OUT receives the children."""

from __future__ import annotations

import json

from hairtool import io
from hairtool.cli import main
from hairtool.guides.binding import bind_roots
from hairtool.guides.files import split_guides
from hairtool.guides.render import ChildClump, RenderHair
from hairtool.samples import scalp


def test_cycle_of_guides_written_as_render_hair(tmp_path, capsys):
    src = tmp_path / "g.npz"
    io.write(src, scalp(24, 8, seed=2))
    out = tmp_path / "cycle.usda"
    argv = ["anime", str(src), str(out), "--frames", "6", "--count", "250", "--seed", "1", "--json"]
    assert main(argv) == 0
    report = json.loads(capsys.readouterr().out)
    assert (report["children"], report["guides"], report["output_frames"]) == (250, 24, 6)
    hair, guides = split_guides(io.read(out))
    plain = tmp_path / "plain.npz"
    assert main(["anime", str(src), str(plain), "--frames", "6", "--seed", "1"]) == 0
    assert guides.frames.tobytes() == io.read(plain).frames.tobytes()
    binding = bind_roots(io.read_groom(src), count=250, seed=1)
    clumped = RenderHair(binding, ChildClump(seed=1)).update(guides.frame(3))  # grown: clumped
    assert hair.frames[3].tobytes() == clumped.points.tobytes()
    loose = tmp_path / "loose.usda"
    assert main([*argv[:2], str(loose), *argv[3:], "--no-clump-children"]) == 0
    hair = split_guides(io.read(loose))[0]
    assert hair.frames[3].tobytes() == binding.build(guides.frame(3)).points.tobytes()


def test_from_dense_takes_the_guide_count_from_guides(tmp_path, capsys):
    src = tmp_path / "dense.npz"
    io.write(src, scalp(120, 8, seed=2))
    out = tmp_path / "cycle.npz"
    assert main(["anime", str(src), str(out), "--frames", "4", "--from-dense", "--guides", "12"]) == 0
    text = capsys.readouterr().out
    assert "120 children following 12 guides" in text and "cycle.guides.npz" in text
    assert io.read(out).strand_count == 120 and io.read(tmp_path / "cycle.guides.npz").strand_count == 12
    assert main(["anime", str(src), str(out), "--frames", "4", "--from-dense", "--guides", "0,3"]) == 2
    assert "guides" in capsys.readouterr().err
    assert main(["anime", str(src), "--count", "10"]) == 2  # no OUT to write the render hair to
    assert "count" in capsys.readouterr().err
