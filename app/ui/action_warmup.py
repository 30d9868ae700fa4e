"""The warm-up's steps for studio actions that reach kernels no other step compiles: a
character's spring bones, Colour ▸ Clump membership and Grow render hair…'s picked guides (no Qt
here: :mod:`app.ui.kernel_warmup` lists them among its steps and lanes).

Each calls the library as the studio's action calls it, on a small input of the same types
(numba compiles one kernel per argument types, not per size), so the action loads its kernels
from numba's cache. Without them the action compiled them first: seconds with the window frozen,
on a job's thread too (numba compiles holding the GIL).
"""

from __future__ import annotations


def character_step() -> None:
    """The bundled character (File ▸ New from sample ▸ Character) with its spring bones: the
    Character dock's Show ▸ Spring bones or Both (the springs, the paper's measure beside them),
    and File ▸ Export character ▸ Springs' optimal keys. The springs' kernel alone compiled for
    12 s on the GUI thread (a loaded two-core host)."""
    from app import resources
    from app.document.character import CharacterDocument
    from hairtool.character.read import load_character

    doc = CharacterDocument(load_character(resources.path("bunches.vrm")))
    doc.springs()
    doc.spring_keys()


def clump_colours_step() -> None:
    """Colour ▸ Clump membership: the strands' clumps at the clump radius (density basins of the
    engine's neighbour list), on the GUI thread when the colours are made."""
    from hairtool import samples
    from hairtool.frozen.pipeline import FrozenPipeline

    FrozenPipeline(samples.scalp(strands=40, vertices=8)).clump_ids()


def picked_guides_step() -> None:
    """Groom ▸ Grow render hair… ▸ Pick guides among these strands (a dense groom): the guides by
    farthest-point sampling of the roots, every strand bound to them (on a job's thread)."""
    from hairtool import samples
    from hairtool.guides.binding import bind_dense

    bind_dense(samples.scalp(strands=40, vertices=8), 8)
