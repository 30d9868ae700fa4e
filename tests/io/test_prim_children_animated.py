"""``simulate`` and ``anime`` with ``--count`` on a scene of two hair prims (hair and brows):
each prim's children follow its own guides, frame by frame, and go to its own render prim
beside them, as ``interpolate --count`` does; the hair's custom primvar reaches its children
and not the brows'. Checked against the numpy twin of each prim's children built on that
prim's guides as the command wrote them."""

from __future__ import annotations

import numpy as np
import pytest

from hairtool import io
from hairtool.cli import main
from hairtool.groom import Animation
from hairtool.guides.animated_prims import split_animation
from hairtool.guides.binding import bind_roots
from hairtool.guides.children import build_points_reference
from hairtool.guides.root_motion import following
from hairtool.prims import shares, split

from .test_animated_interpolate import two_prims
from .test_child_primvars import primvar
from .usd_scenes import write_stage

COMMANDS = {
    "simulate": ["--frames", "3", "--substeps", "1", "--fit-head"],
    "anime": ["--frames", "3"],
}


@pytest.mark.parametrize("command", sorted(COMMANDS))
def test_each_prims_children_follow_their_own_guides(tmp_path, command):
    write_stage(tmp_path / "s.usda", two_prims(None))
    src = io.read(tmp_path / "s.usda")
    out = tmp_path / "k.usda"
    args = [command, str(tmp_path / "s.usda"), str(out), "--count", "20", "--seed", "3"]
    assert main([*args, *COMMANDS[command], "--no-clump-children"]) == 0
    kids = io.read(out)
    assert isinstance(kids, Animation) and kids.n_frames == 3
    paths = [c.path for c in src.metadata.curves]
    assert [(c.path, c.purpose) for c in kids.metadata.curves] == [
        x for p in paths for x in ((p + "Render", "default"), (p, "guide"))
    ]
    parts = split_animation(kids)  # each prim's children, then its guides
    sources = split(src)
    scale = float(np.abs(kids.frames).max())
    for k, (rest, n) in enumerate(zip(sources, shares(20, [p.strand_count for p in sources]), strict=True)):
        hair, guides = parts[2 * k], parts[2 * k + 1]
        binding = bind_roots(rest, count=n, k=min(4, rest.strand_count), seed=3)
        assert hair.strand_count == n
        for f in range(3):
            pose = guides.frame(f)
            want = build_points_reference(following(binding, pose), pose)
            np.testing.assert_allclose(hair.frames[f], want, rtol=0, atol=2e-6 * scale)
    weight, interp = primvar(out, "/Root0_0/Hair0Render", "clump_weight")
    assert interp == "vertex" and len(weight) == parts[0].vertex_count
    assert primvar(out, "/Brows1Render", "clump_weight") == (None, None)  # the brows had none


@pytest.mark.parametrize("command", sorted(COMMANDS))
def test_a_dense_groom_of_several_prims_is_refused_naming_them(tmp_path, command, capsys):
    """(Bound together, a brow child would follow hair guides.)"""
    write_stage(tmp_path / "s.usda", two_prims(None))
    args = [command, str(tmp_path / "s.usda"), str(tmp_path / "k.usda"), "--from-dense", "--guides", "3"]
    assert main([*args, *COMMANDS[command]]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "one hair prim for --from-dense" in err[0] and "/Brows1" in err[0]
    assert not (tmp_path / "k.usda").exists()


@pytest.mark.parametrize("command", [*sorted(COMMANDS), "interpolate"])
def test_to_npz_each_prims_children_are_on_its_render_prim_and_the_guides_beside(tmp_path, command):
    """(A format that cannot mark guides: the children alone, the guides in OUT.guides.npz; the
    animated ``interpolate`` of two prims failed on this before.)"""
    write_stage(tmp_path / "s.usda", two_prims(None if command != "interpolate" else "points"))
    src = io.read(tmp_path / "s.usda")
    out = tmp_path / "k.npz"
    args = [command, str(tmp_path / "s.usda"), str(out), "--count", "20"]
    assert main([*args, *COMMANDS.get(command, [])]) == 0
    kids, guides = io.read(out), io.read(tmp_path / "k.guides.npz")
    paths = [c.path for c in src.metadata.curves]
    want = shares(20, [g.strand_count for g in split(src.rest if command == "interpolate" else src)])
    assert [(c.path, c.strands) for c in kids.metadata.curves] == [
        (p + "Render", n) for p, n in zip(paths, want, strict=True)
    ]
    assert [c.path for c in guides.metadata.curves] == paths and guides.n_frames == kids.n_frames == 3
