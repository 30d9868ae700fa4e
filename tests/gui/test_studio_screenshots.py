"""The manual's screenshots are made by driving the real studio: the script must keep working."""

from __future__ import annotations

import numpy as np
import pytest
from PIL import Image
from PySide6.QtWidgets import QApplication


@pytest.mark.slow(seconds=16)
def test_screenshot_script_drives_the_studio_and_writes_both_pictures(qapp, tmp_path):
    from app.figures import screenshots

    assert screenshots.main([str(tmp_path)]) == 0
    for name in ("screenshot-studio.png", "screenshot-timeline.png"):
        image = np.asarray(Image.open(tmp_path / name).convert("RGB"))
        assert image.shape[0] >= screenshots.WINDOW_SIZE[1] and image.shape[1] == screenshots.WINDOW_SIZE[0]
        assert len(np.unique(image.reshape(-1, 3), axis=0)) > 1000  # hair, head and docks, not a blank
    QApplication.processEvents()
    assert not [w for w in QApplication.topLevelWidgets() if w.isVisible()]
