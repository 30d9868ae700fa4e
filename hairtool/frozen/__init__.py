"""Frozen hair (seed 002): stiffness-based deformation without simulation.

- :mod:`.freeze` FreezeDeform, eqs. 2–7: seeded stretch and bend of every rest segment;
- :mod:`.align` UserAlign, eqs. 8–13: strands near the cursor turn toward it, root to tip;
- :mod:`.clump` ClumpWithGaps, eqs. 14–19: the adhesion kernel with the gap-keeping correction,
  over the neighbour lists of :mod:`.spatial`; :mod:`.local` redoes it (and the brush) only on
  the strands under the brush and those their clumps reach, through the kept grid of
  :mod:`.vertex_grid`; :mod:`.strand_clumps` labels clumps and picks the automatic radius;
- :mod:`.brushes` the brushes, one module each found by its registry, with the falloff,
  symmetry and front-facing strands they share; :mod:`.strand_state` the per-strand state
  they paint; :mod:`.selection` selecting and hiding strands; :mod:`.strokes`
  stroke logs as JSON files; :mod:`.sample_schema` one description per sample type, which the
  stroke logs, the project's columns (:mod:`.sample_columns`) and the studio build from;
- :mod:`.pipeline` the three in order, with the stroke log the studio and the CLI replay;
- :mod:`.noise` the counter-based noise they share.
"""

from hairtool.frozen.align import align, align_reference
from hairtool.frozen.clump import clump, clump_reference
from hairtool.frozen.freeze import freeze, freeze_reference, strand_multipliers
from hairtool.frozen.pipeline import AlignSample, FrozenParams, FrozenPipeline, FrozenSnapshot
from hairtool.frozen.strand_clumps import auto_clump_radius, strand_clumps

__all__ = [
    "AlignSample",
    "FrozenParams",
    "FrozenPipeline",
    "FrozenSnapshot",
    "align",
    "align_reference",
    "auto_clump_radius",
    "clump",
    "clump_reference",
    "freeze",
    "freeze_reference",
    "strand_clumps",
    "strand_multipliers",
]
