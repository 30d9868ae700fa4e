"""Hairtool Studio: the Qt desktop view over the ``hairtool`` library.

Importing it first keeps None, True and False alive against the PySide6 bindings that drop
references to them on Python 3.11 (:mod:`app.singletons`), before any Qt call can.
"""

from app import singletons

singletons.protect()
