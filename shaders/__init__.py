"""GLSL programs of the studio, one per file (installed as ``app.shaders``)."""
