"""Fixtures of the renderer tests: one headless EGL context (Mesa llvmpipe), no display needed."""

from __future__ import annotations

import numpy as np
import pytest


@pytest.fixture(scope="session")
def _standalone_ctx():
    from app.render.offscreen import shared_context

    return shared_context()


@pytest.fixture
def gl_ctx(_standalone_ctx):
    """The standalone context, current for the test (a GUI test may have made Qt's current)."""
    with _standalone_ctx:
        yield _standalone_ctx


@pytest.fixture
def renderer(gl_ctx):
    from app.render.strands import StrandRenderer

    r = StrandRenderer(gl_ctx)
    yield r
    r.release()


def _window(image: np.ndarray, xy, radius: int = 2) -> np.ndarray:
    """Pixels ``(n, 4)`` of the square window of ``radius`` around pixel coordinates ``xy`` (y down)."""
    x, y = int(np.floor(xy[0])), int(np.floor(xy[1]))
    h, w = image.shape[:2]
    return image[
        max(y - radius, 0) : min(y + radius + 1, h), max(x - radius, 0) : min(x + radius + 1, w)
    ].reshape(-1, 4)


@pytest.fixture
def pixel_window():
    """``pixel_window(image, xy, radius)`` → the pixels around a projected point."""
    return _window
