"""Opening files as the studio shows them: grooms, animations, and BVH captures as skeletons.

A BVH capture becomes an :class:`Animation` of line segments: every bone (joint → parent, and
each End Site → its joint) is one 2-vertex strand, root at the parent. Bones rather than whole
chains keep branching skeletons exact (a chain would have to repeat joints at each branch), and
the root-to-tip colour ramp then shows each bone's direction.
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Sequence
from pathlib import Path

from app.document.capture import skeleton_animation
from hairtool import io
from hairtool.errors import FormatError, ReaderNote
from hairtool.groom import Animation, Groom
from hairtool.io.obj import Mesh
from hairtool.mocap.bvh import Motion, read_bvh
from hairtool.project import SUFFIX as PROJECT_SUFFIX  # opened by the window's project controller

BVH_EXTENSIONS = (".bvh",)
USD_EXTENSIONS = (".usda", ".usdc", ".usd")


def readable_extensions() -> list[str]:
    """Every extension the studio opens: the groom formats, BVH and projects."""
    return [e for f in io.FORMATS if f.readable for e in f.extensions] + [*BVH_EXTENSIONS, PROJECT_SUFFIX]


def read_any(path: str | os.PathLike[str]) -> Groom | Animation:
    """A groom or an animation from any readable format, BVH included (as a skeleton)."""
    return read_with_capture(path)[0]


def read_with_capture(path: str | os.PathLike[str]) -> tuple[Groom | Animation, Motion | None]:
    """:func:`read_any`, and for a BVH the capture itself (what the studio poses by IK)."""
    suffix = Path(path).suffix.lower()
    if suffix not in readable_extensions() or suffix == PROJECT_SUFFIX:
        what = "projects are opened with Open Project" if suffix == PROJECT_SUFFIX else "supported"
        every = ", ".join(readable_extensions())
        raise FormatError(path, f"cannot read '{suffix or 'no extension'}' files; {what}: {every}")
    if suffix in BVH_EXTENSIONS:
        motion = read_bvh(path)
        try:
            return skeleton_animation(motion), motion
        except FormatError as e:
            raise FormatError(path, e.reason) from None
    return io.read(path), None


def read_with_notes(
    path: str | os.PathLike[str],
) -> tuple[Groom | Animation, Motion | None, list[str]]:
    """:func:`read_with_capture`, and what the reader left out of the file (its
    :class:`~hairtool.errors.ReaderNote` lines, for the status bar); other warnings go on as
    Python shows them."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", ReaderNote)
        obj, capture = read_with_capture(path)
    notes = []
    for w in caught:
        if issubclass(w.category, ReaderNote):
            notes.append(str(w.message))
        else:
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    return obj, capture, notes


def surface_of(path: str | os.PathLike[str]) -> Mesh | None:
    """The head mesh a groom file carries (USD: its Mesh prims), or None (other formats have none:
    a TressFX or HAIR groom's head comes as an OBJ beside it, through Load head mesh)."""
    if Path(path).suffix.lower() not in USD_EXTENSIONS:
        return None
    from hairtool.io.usd_mesh import read_mesh

    return read_mesh(path)


def dialog_filters(formats: Sequence[tuple[str, Sequence[str]]]) -> str:
    """File-dialog filters: "All supported (…)" first, then one per (name, extensions)."""
    parts = [f"{name} ({' '.join('*' + e for e in exts)})" for name, exts in formats]
    every = " ".join("*" + e for _, exts in formats for e in exts)
    return ";;".join([f"All supported ({every})", *parts])


def open_filters() -> str:
    """Every readable groom/animation format and BVH."""
    formats = [(f.name, f.extensions) for f in io.FORMATS if f.readable]
    extra = [
        ("BVH motion capture (skeleton)", BVH_EXTENSIONS),
        ("Character with hair bones", (".vrm", ".glb", ".gltf")),
        ("Hairtool project", (PROJECT_SUFFIX,)),
    ]
    return dialog_filters([*formats, *extra])


def save_filters() -> str:
    """Every writable groom/animation format."""
    return dialog_filters([(f.name, f.extensions) for f in io.FORMATS if f.writable])
