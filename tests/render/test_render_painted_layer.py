"""PaintedLayer: an image painted on the CPU (premultiplied RGBA, row 0 at the top) over a frame,
pixel for pixel, as ``src + dst·(1 − α)`` in 8 bits."""

from __future__ import annotations

import moderngl
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from app.render.painted_layer import PaintedLayer
from hairtool.errors import ParameterError


def _premultiplied(rng: np.random.Generator, h: int, w: int) -> np.ndarray:
    alpha = rng.integers(0, 256, (h, w, 1))
    alpha[rng.random((h, w)) < 0.3] = 0  # most of a painted layer is empty
    colour = rng.integers(0, 256, (h, w, 3)) * alpha // 255  # premultiplied: never above alpha
    return np.concatenate([colour, alpha], axis=2).astype(np.uint8)


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(seed=st.integers(0, 2**32 - 1), h=st.integers(1, 23), w=st.integers(1, 31))
def test_the_image_lands_pixel_for_pixel_with_its_alpha(gl_ctx, seed, h, w):
    rng = np.random.default_rng(seed)
    below = rng.integers(0, 256, (h, w, 4)).astype(np.uint8)
    over = _premultiplied(rng, h, w)
    texture = gl_ctx.texture((w, h), 4, np.ascontiguousarray(below[::-1]).tobytes())  # GL rows bottom-up
    fbo = gl_ctx.framebuffer(color_attachments=[texture])
    layer = PaintedLayer(gl_ctx)
    try:
        layer.draw(fbo, over)
        got = np.frombuffer(fbo.read(components=4), np.uint8).reshape(h, w, 4)[::-1].astype(int)
    finally:
        layer.release()
        fbo.release()
        texture.release()
    a = over[..., 3:].astype(float) / 255.0
    expected = over.astype(float) + below.astype(float) * (1.0 - a)
    assert np.abs(got - expected).max() <= 1.0  # GL's 8-bit rounding


def test_an_image_not_rgba8_is_refused(gl_ctx):
    layer = PaintedLayer(gl_ctx)
    fbo = gl_ctx.simple_framebuffer((4, 4))
    try:
        with pytest.raises(ParameterError, match="rgba"):
            layer.draw(fbo, np.zeros((4, 4, 3), np.uint8))
        with pytest.raises(ParameterError, match="rgba"):
            layer.draw(fbo, np.zeros((4, 4, 4), np.float32))
    finally:
        layer.release()
        fbo.release()
    assert isinstance(gl_ctx, moderngl.Context)
