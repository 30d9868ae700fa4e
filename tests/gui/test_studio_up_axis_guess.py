"""Opening hair from a format without an up axis: the studio takes the axis the hair hangs along,
says so in the status bar, and View ▸ Up axis overrides it; a format that says one is kept. What
a reader drops (USC-HairSalon's bald scalp samples) is said there too."""

from __future__ import annotations

import struct

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


def test_bald_scalp_samples_dropped_are_said_in_the_status_bar(make_window, tmp_path):
    w = make_window()
    hair = samples.scalp(strands=30, vertices=6, seed=3)
    path = tmp_path / "bald.data"
    io.write(path, hair)
    data = path.read_bytes()  # two one-point strands added after the hair, the count raised
    bald = (struct.pack("<i", 1) + np.zeros(3, "<f4").tobytes()) * 2
    path.write_bytes(struct.pack("<i", 32) + data[4:] + bald)
    assert w.open_path(path), w.errors
    assert w.scene.rest.strand_count == 30
    said = w.statusBar().currentMessage()
    assert "dropped 2 of 32 strands of one point (bald scalp samples)" in said and "Y up" in said
