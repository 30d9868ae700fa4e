"""Hairtool Studio: the Qt desktop view over the ``hairtool`` library."""
