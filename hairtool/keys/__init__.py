"""Globally optimal keyframes (seeds 000 and 003).

- :mod:`.features` seed 000's frame vectors: arc-length resampling, root translation removed,
  root-relative coordinates, tip-heavier weights (steps 1–5);
- :mod:`.gram` the terms every segment cost shares; :mod:`.segment_linear`,
  :mod:`.segment_hermite` (seed 003's cubic Hermite) and :mod:`.segment_worst` the tables, each
  with its numpy twin; :mod:`.segment_direct` the slow oracle; :mod:`.costs` picks one;
- :mod:`.dp` the exact dynamic program: K keys, a price tau per key, a budget, a worst frame;
- :mod:`.session` the whole solve for every caller; :mod:`.channels` seed 003's per-channel keys;
- :mod:`.reconstruct` key curves and their errors; :mod:`.edit` seed 003's key edits that
  spread to every frame; :mod:`.export` keys to JSON, CSV and USD.
"""

from hairtool.keys.channels import ChannelKeys, per_channel_keys
from hairtool.keys.costs import INTERPOLATIONS, OBJECTIVES, cost_table
from hairtool.keys.dp import Selection, select_keys, uniform_keys
from hairtool.keys.edit import KeyEditor, edit_animation
from hairtool.keys.features import FeatureOptions, frame_features, hair_features
from hairtool.keys.reconstruct import KeyPoses, compare_with_uniform, key_poses, reconstruct
from hairtool.keys.session import KeySession, KeySettings, analyse, find_keys, solve

__all__ = [
    "INTERPOLATIONS",
    "OBJECTIVES",
    "ChannelKeys",
    "FeatureOptions",
    "KeyEditor",
    "KeyPoses",
    "KeySession",
    "KeySettings",
    "Selection",
    "analyse",
    "compare_with_uniform",
    "cost_table",
    "edit_animation",
    "find_keys",
    "frame_features",
    "hair_features",
    "key_poses",
    "per_channel_keys",
    "reconstruct",
    "select_keys",
    "solve",
    "uniform_keys",
]
