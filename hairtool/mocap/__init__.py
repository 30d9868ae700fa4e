"""Motion capture for DP keyframe extraction (seed 003): BVH reading and writing, quaternions,
joint features and seed 003's quaternion-distance segment table.

- :mod:`.bvh` the reader, writer and forward kinematics;
- :mod:`.quaternion` the quaternion algebra (slerp, distance, Euler orders);
- :mod:`.costs` per-frame features, the rotation cost table (numba and numpy twin), and
  reconstruction of a motion from its keys;
- :mod:`.ik` inverse kinematics on one pose (analytic two-bone, damped least squares);
- :mod:`.pose_edit` seed 003 §5: key poses edited by IK, carried to every frame with the
  residuals kept; :mod:`.channel_edit` the same on per-channel keys of the BVH channels;
  :mod:`.edit_file` the edits a studio project keeps, read and replayed (``keys --edit``).
"""

from hairtool.mocap.bvh import Motion, read_bvh, write_bvh
from hairtool.mocap.costs import (
    joint_position_errors,
    motion_features,
    reconstruct_motion,
    rotation_cost_table,
    rotation_cost_table_reference,
)
from hairtool.mocap.pose_edit import PoseEdit, PoseEditor, read_edits

__all__ = [
    "Motion",
    "PoseEdit",
    "PoseEditor",
    "joint_position_errors",
    "motion_features",
    "read_bvh",
    "read_edits",
    "reconstruct_motion",
    "rotation_cost_table",
    "rotation_cost_table_reference",
    "write_bvh",
]
