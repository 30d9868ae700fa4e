"""``interpolate`` on an animated groom: children grown once from the first frame's guides,
following their guides every frame, at the source's time codes. Checked frame by frame in
world space against the numpy twin of the children on that frame's guides, on generated
stages animated by points and by a parent's transform, of two hair prims."""

from __future__ import annotations

import json

import numpy as np
import pytest

from hairtool import io
from hairtool.cli import main
from hairtool.groom import Animation
from hairtool.guides.animated_prims import split_animation
from hairtool.guides.binding import bind_roots
from hairtool.guides.children import build_points_reference
from hairtool.guides.files import split_guides
from hairtool.guides.render import ChildClump, RenderHair
from hairtool.guides.root_motion import following
from hairtool.prims import shares

from .usd_scenes import Prim, Scene, write_stage


def two_prims(animated: str) -> Scene:
    hair = Prim("/Root0_0/Hair0", (("/Root0_0", "trs", (0.2, 0.1, 0.0, 30.0, 1.5)),), "linear",
                (5, 6, 5, 7, 5, 6), 3, True, True, True)  # fmt: skip
    brows = Prim("/Brows1", (), "catmullRom", (4, 5, 4, 4), 4, False, True, False)
    return Scene("Z", 1.0, (hair, brows), True, animated)


def children_reference(src: Animation, count: int, seed: int, clump: bool = False) -> list[np.ndarray]:
    """Per frame, the children of every prim (bound on the first frame's guides) built by the
    numpy twin on that frame's guides (``clump``: a fresh static render of that frame, clumped
    as the command's default), prim after prim."""
    parts = split_animation(src)
    out = [[] for _ in range(src.n_frames)]
    for part, n in zip(parts, shares(count, [p.strand_count for p in parts]), strict=True):
        binding = bind_roots(part.rest, count=n, k=min(4, part.strand_count), seed=seed)
        for f in range(src.n_frames):
            pose = part.frame(f)
            if clump:
                render = RenderHair(binding, ChildClump(seed=seed), follow_roots=True)
                out[f].append(render.update(pose).points)
            else:
                out[f].append(build_points_reference(following(binding, pose), pose))
    return [np.concatenate(f) for f in out]


@pytest.mark.parametrize("animated", ["points", "transform"])
def test_every_frame_follows_its_guides_at_the_source_time_codes(tmp_path, animated, capsys):
    write_stage(tmp_path / "s.usda", two_prims(animated))
    src = io.read(tmp_path / "s.usda")
    assert isinstance(src, Animation) and src.n_frames == 3
    out = tmp_path / "k.usda"
    args = ["interpolate", str(tmp_path / "s.usda"), str(out), "--count", "24", "--seed", "5"]
    assert main([*args, "--no-clump-children", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["frames"] == 3
    kids = io.read(out)
    assert isinstance(kids, Animation)
    assert list(kids.time_codes) == [1.0, 2.0, 3.0] == list(src.time_codes)
    assert (kids.metadata.start_time_code, kids.metadata.end_time_code) == (1.0, 3.0)
    paths = [c.path for c in src.metadata.curves]
    assert [(c.path, c.purpose) for c in kids.metadata.curves] == [
        x for p in paths for x in ((p + "Render", "default"), (p, "guide"))
    ]
    want = children_reference(src, 24, 5)
    hair = [p for p in split_animation(kids) if p.metadata.curves[0].purpose != "guide"]
    guides = [p for p in split_animation(kids) if p.metadata.curves[0].purpose == "guide"]
    scale = float(np.abs(src.frames).max())
    for f in range(3):
        got = np.concatenate([h.frames[f] for h in hair])
        np.testing.assert_allclose(got, want[f], rtol=0, atol=2e-6 * scale)
        moved = np.concatenate([g.frames[f] for g in guides])
        np.testing.assert_allclose(moved, src.frames[f], rtol=0, atol=2e-6 * scale)
    assert not np.array_equal(want[0], want[2])  # the children do move
    # clumped children (the default) equal a fresh static render of each frame's guides
    assert main([*args[:2], str(tmp_path / "c.usda"), *args[3:]]) == 0
    parts = split_animation(io.read(tmp_path / "c.usda"))
    clumped = [p for p in parts if p.metadata.curves[0].purpose != "guide"]
    want = children_reference(src, 24, 5, clump=True)
    for f in range(3):
        got = np.concatenate([h.frames[f] for h in clumped])
        np.testing.assert_allclose(got, want[f], rtol=0, atol=2e-6 * scale)


def test_frame_writes_one_static_pose_and_a_dense_animation_asks_for_it(tmp_path, capsys):
    write_stage(tmp_path / "s.usda", two_prims("points"))
    src = io.read(tmp_path / "s.usda")
    one = tmp_path / "one.usda"
    base = ["interpolate", str(tmp_path / "s.usda")]
    assert main([*base, str(one), "--count", "10", "--frame", "2", "--no-clump-children"]) == 0
    kids = io.read(one)
    assert not isinstance(kids, Animation) and kids.metadata.start_time_code is None
    guides = split_guides(kids)[1]
    np.testing.assert_allclose(guides.points, src.frames[2], rtol=0, atol=1e-6)
    capsys.readouterr()
    assert main([*base, str(tmp_path / "x.usda"), "--count", "10", "--frame", "3"]) == 2
    assert "frame" in capsys.readouterr().err
    assert main([*base, str(tmp_path / "d.usda"), "--from-dense", "--guides", "2"]) == 2
    err = capsys.readouterr().err
    assert "frame" in err and "animation of 3 frames" in err and len(err.strip().splitlines()) == 1
