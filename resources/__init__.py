"""Data files the studio ships (installed as ``app.resources``)."""
