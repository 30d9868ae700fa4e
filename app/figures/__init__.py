"""Scripts that redraw the papers' figures with hairtool: ``python -m app.figures.<name> OUTDIR``."""
