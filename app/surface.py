"""The OpenGL surface every studio window and test asks Qt for, set before the QApplication exists."""

from __future__ import annotations

import os

MSAA_ENV = "HAIRTOOL_MSAA"  # samples per pixel of the viewport; 0 (default) keeps llvmpipe interactive


def configure_gl() -> None:
    """A 3.3 core default surface with depth; must run before the QApplication exists.

    Multisampling is off unless ``HAIRTOOL_MSAA`` asks for it: on Mesa's llvmpipe 4× MSAA
    makes every viewport frame about 3–4× slower (stills are always rendered with 4×).
    """
    from PySide6.QtGui import QSurfaceFormat

    fmt = QSurfaceFormat()
    fmt.setVersion(3, 3)
    fmt.setProfile(QSurfaceFormat.OpenGLContextProfile.CoreProfile)
    fmt.setDepthBufferSize(24)
    try:
        samples = int(os.environ.get(MSAA_ENV, "0"))
    except ValueError:
        samples = 0
    fmt.setSamples(min(max(samples, 0), 16))
    QSurfaceFormat.setDefaultFormat(fmt)
