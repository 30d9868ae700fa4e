"""Small hand-written BVH files for the mocap tests."""

from __future__ import annotations

import pytest

CHAIN = """HIERARCHY
ROOT hips
{
  OFFSET 0 0 0
  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
  JOINT knee
  {
    OFFSET 0 2 0
    CHANNELS 3 Zrotation Xrotation Yrotation
    End Site
    {
      OFFSET 0 1 0
    }
  }
}
MOTION
Frames: 3
Frame Time: 0.04
0 0 0 0 0 0 0 0 0
1 2 3 90 0 0 0 0 0
0 0 0 90 0 0 -90 0 0
"""


@pytest.fixture
def chain_bvh(tmp_path):
    """Two joints: hips (6 channels, ZXY) and knee 2 units above it, with an End Site 1 above that."""
    p = tmp_path / "chain.bvh"
    p.write_text(CHAIN)
    return p
