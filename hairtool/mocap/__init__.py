"""Motion capture for DP keyframe extraction (seed 003): BVH reading and writing, quaternions,
joint features and seed 003's quaternion-distance segment table.

- :mod:`.bvh` the reader, writer and forward kinematics;
- :mod:`.quaternion` the quaternion algebra (slerp, distance, Euler orders);
- :mod:`.costs` per-frame features, the rotation cost table (numba and numpy twin), and
  reconstruction of a motion from its keys.
"""

from hairtool.mocap.bvh import Motion, read_bvh, write_bvh
from hairtool.mocap.costs import (
    joint_position_errors,
    motion_features,
    reconstruct_motion,
    rotation_cost_table,
    rotation_cost_table_reference,
)

__all__ = [
    "Motion",
    "joint_position_errors",
    "motion_features",
    "read_bvh",
    "reconstruct_motion",
    "rotation_cost_table",
    "rotation_cost_table_reference",
    "write_bvh",
]
