"""Groom ▸ Grow render hair…: children grown from the groom's strands as guides (on the head
mesh where there is one, over the region the artist picks), or guides picked among the strands
of a dense groom, every strand then bound to them (:mod:`hairtool.guides.binding`).

API: ``GrowOptions`` (what the dialog edits, a plain value), ``ask_grow_options(parent,
options, groom, mesh)`` (the dialog: GrowOptions or None) and :func:`grow`, the job body, which
returns ``(guides, binding)``: the guides are the groom itself when children are grown from it,
or the strands picked from a dense one.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from PySide6.QtWidgets import (
    QComboBox,
    QDialog,
    QDialogButtonBox,
    QDoubleSpinBox,
    QFormLayout,
    QLabel,
    QSpinBox,
    QVBoxLayout,
    QWidget,
)

from hairtool.groom import Groom
from hairtool.guides import limits
from hairtool.guides.binding import ChildBinding, bind_dense, bind_roots, bind_scalp

GROW, DENSE = "grow", "dense"
NEAR_GUIDES = ""  # the region where hair grows: the faces near the guides' roots …
NEAR_MASKED = "@mask"  # … near the guides the mask brush painted …
WHOLE_MESH = "*"  # … every face of the head mesh, or a face set's name


@dataclass(frozen=True)
class GrowOptions:
    """``mode`` GROW: ``count`` children from the strands as guides, each following its
    ``guides_per_child`` nearest, with a seeded length variation and frizz, rooted on the head
    mesh over ``region`` (or around the guide roots without a mesh); DENSE: ``guides`` strands
    picked from the groom, every strand bound to them exactly."""

    mode: str = GROW
    count: int = 20_000
    guides_per_child: int = limits.DEFAULT_K
    seed: int = 0
    length_variation: float = limits.DEFAULT_LENGTH_VARIATION
    frizz: float = limits.DEFAULT_FRIZZ
    region: str = NEAR_GUIDES
    guides: int = 200


def grow(
    options: GrowOptions, groom: Groom, mesh=None, painted: np.ndarray | None = None
) -> tuple[Groom, ChildBinding]:
    """``(guides, binding)`` for ``options`` on ``groom`` (and the head ``mesh``, if any;
    ``painted``: the strands the mask brush painted, for :data:`NEAR_MASKED`)."""
    o = options
    k = o.guides_per_child
    if o.mode == DENSE:
        return bind_dense(groom, o.guides, k=k, seed=o.seed, mesh=mesh)
    shape = {"k": k, "seed": o.seed, "length_variation": o.length_variation, "frizz": o.frizz}
    if mesh is None:
        return groom, bind_roots(groom, count=o.count, **shape)
    if o.region == WHOLE_MESH:
        region = np.ones(len(mesh.faces), bool)
    elif o.region == NEAR_MASKED:
        from hairtool.guides.scatter import default_region

        region = default_region(mesh, groom, near=painted if painted is not None else np.zeros(0, bool))
    else:
        region = o.region or None  # None: near the guides' roots
    return groom, bind_scalp(groom, mesh, o.count, region=region, **shape)


class GrowDialog(QDialog):
    def __init__(
        self, parent: QWidget | None, options: GrowOptions, groom: Groom, mesh=None, painted: int = 0
    ) -> None:
        """``painted``: how many strands the mask brush painted (offered as a region if any)."""
        super().__init__(parent)
        self.setWindowTitle("Grow render hair")
        self._strands = groom.strand_count
        layout = QVBoxLayout(self)
        form = self._form = QFormLayout()
        layout.addLayout(form)
        self.mode = QComboBox()
        self.mode.addItem("Grow children from these strands (guides)", GROW)
        self.mode.addItem("Pick guides among these strands (a dense groom)", DENSE)
        self.mode.setToolTip(
            "Grow: the strands become guides and render hair is interpolated from them.\n"
            "Pick: a dense groom is edited through a few of its strands; untouched, it stays as it is."
        )
        form.addRow("Render hair", self.mode)
        self.count = QSpinBox()
        self.count.setRange(1, limits.MAX_CHILDREN)
        self.count.setGroupSeparatorShown(True)
        self.count.setToolTip("how many render strands to grow")
        form.addRow("Children", self.count)
        self.guides = QSpinBox()
        self.guides.setRange(1, max(1, groom.strand_count))
        self.guides.setToolTip("how many strands become guides (farthest apart at the roots)")
        form.addRow("Guides", self.guides)
        self.k = QSpinBox()
        self.k.setRange(1, max(1, min(16, groom.strand_count)))
        self.k.setToolTip("each render strand blends this many nearest guides (k)")
        form.addRow("Guides per strand", self.k)
        self.length = QDoubleSpinBox()
        self.length.setRange(0.0, limits.MAX_LENGTH_VARIATION)
        self.length.setSingleStep(0.05)
        self.length.setToolTip("children's lengths vary by up to this share of their guides'")
        form.addRow("Length variation", self.length)
        self.frizz = QDoubleSpinBox()
        self.frizz.setRange(0.0, limits.MAX_FRIZZ)
        self.frizz.setDecimals(3)
        self.frizz.setSingleStep(0.005)
        self.frizz.setToolTip("curl radius at the tip, as a share of the child's length")
        form.addRow("Frizz", self.frizz)
        self.region = QComboBox()
        if mesh is None:
            self.region.addItem("Around the guide roots (no head mesh)", NEAR_GUIDES)
            self.region.setEnabled(False)
        else:
            self.region.addItem("Near the guide roots", NEAR_GUIDES)
            if painted:
                self.region.addItem(f"Near the {painted:,} masked guides", NEAR_MASKED)
            self.region.addItem("The whole head mesh", WHOLE_MESH)
            for name in sorted(getattr(mesh, "groups", {})):
                self.region.addItem(f"Face set: {name}", name)
        self.region.setToolTip(
            "where on the head the children take root; paint guides with the Mask brush to grow "
            "hair only near them"
        )
        form.addRow("Grows on", self.region)
        self.seed = QSpinBox()
        self.seed.setRange(0, 2**31 - 1)
        self.seed.setToolTip("the same seed gives the same hair")
        form.addRow("Seed", self.seed)
        self.note = QLabel()
        self.note.setWordWrap(True)
        layout.addWidget(self.note)
        ok_cancel = QDialogButtonBox.StandardButton.Ok | QDialogButtonBox.StandardButton.Cancel
        buttons = QDialogButtonBox(ok_cancel)
        buttons.accepted.connect(self.accept)
        buttons.rejected.connect(self.reject)
        layout.addWidget(buttons)
        self.mode.currentIndexChanged.connect(self._sync)
        self.set_options(options)

    def _sync(self) -> None:
        dense = self.mode.currentData() == DENSE
        for w, shown in ((self.count, not dense), (self.length, not dense), (self.frizz, not dense),
                         (self.region, not dense), (self.guides, dense)):  # fmt: skip
            w.setVisible(shown)
            self._form.labelForField(w).setVisible(shown)
        self.note.setText(
            f"{self._strands:,} strands become guides; the render hair follows them as you brush."
            if not dense
            else f"The {self._strands:,} strands follow the guides picked among them as you brush."
        )

    def set_options(self, o: GrowOptions) -> None:
        self.mode.setCurrentIndex(max(0, self.mode.findData(o.mode)))
        self.count.setValue(o.count)
        self.guides.setValue(min(o.guides, self.guides.maximum()))
        self.k.setValue(min(o.guides_per_child, self.k.maximum()))
        self.length.setValue(o.length_variation)
        self.frizz.setValue(o.frizz)
        self.region.setCurrentIndex(max(0, self.region.findData(o.region)))
        self.seed.setValue(o.seed)
        self._sync()

    def options(self) -> GrowOptions:
        return replace(
            GrowOptions(),
            mode=self.mode.currentData(),
            count=self.count.value(),
            guides=self.guides.value(),
            guides_per_child=self.k.value(),
            length_variation=self.length.value(),
            frizz=self.frizz.value(),
            region=self.region.currentData(),
            seed=self.seed.value(),
        )


def ask_grow_options(
    parent: QWidget | None, options: GrowOptions, groom: Groom, mesh=None, painted: int = 0
) -> GrowOptions | None:
    dialog = GrowDialog(parent, options, groom, mesh, painted)
    return dialog.options() if dialog.exec() == QDialog.DialogCode.Accepted else None
