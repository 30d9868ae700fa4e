"""Opening hair from a format without an up axis: the studio takes the axis the hair hangs along,
says so in the status bar, and View ▸ Up axis overrides it; a format that says one is kept."""

from __future__ import annotations

import numpy as np
import pytest

from hairtool import io, samples

pytestmark = pytest.mark.gui


def z_up(groom):
    """The same hair turned from Y-up to Z-up: (x, y, z) ↦ (x, −z, y)."""
    p = groom.points
    return type(groom)(np.column_stack([p[:, 0], -p[:, 2], p[:, 1]]).astype(np.float32), groom.counts)


@pytest.mark.parametrize("suffix", [".hair", ".data"])
def test_z_up_hair_opens_z_up_and_says_so_and_the_menu_overrides(make_window, tmp_path, suffix):
    w = make_window()
    hair = samples.scalp(strands=60, vertices=8, seed=1)
    path = tmp_path / f"lying{suffix}"
    io.write(path, z_up(hair))
    assert w.open_path(path), w.errors
    assert w.scene.up_axis == "Z"
    said = w.statusBar().currentMessage()
    assert "Z up" in said and suffix in said and "View ▸ Up axis" in said
    assert w.up_axis_actions["Z"].isChecked()
    w.up_axis_actions["Y"].trigger()  # the artist knows better
    assert w.scene.up_axis == "Y"
    path = tmp_path / f"hanging{suffix}"
    io.write(path, hair)
    assert w.open_path(path), w.errors
    assert w.scene.up_axis == "Y" and "Y up" in w.statusBar().currentMessage()


def test_a_format_that_says_its_up_axis_keeps_it(make_window, tmp_path):
    w = make_window()
    hair = z_up(samples.scalp(strands=40, vertices=6, seed=2))  # hangs along Z, but the file says Y
    path = tmp_path / "said.usda"
    io.write(path, hair)
    w.statusBar().clearMessage()
    assert w.open_path(path), w.errors
    assert w.scene.up_axis == io.read_groom(path).metadata.up_axis
    assert "Up axis" not in w.statusBar().currentMessage()
