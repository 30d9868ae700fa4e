"""The ``hairtool`` program's first lines (the ``hairtool`` script runs :func:`entry`, as
``python -m hairtool`` does): Ctrl+C handling is installed before the command line's modules
(argparse, numpy, numba, usd-core, Dask) load, so an interrupt while they load is one line and
exit status 130 too (:mod:`hairtool.interrupts`)."""

import sys

from hairtool import interrupts


def entry() -> None:
    """Install the Ctrl+C handling, then run the command line (:func:`hairtool.cli.entry`)."""
    interrupts.install()
    try:
        from hairtool.cli import entry as run

        run()
    except KeyboardInterrupt:  # before the command line's own ``try`` (its modules loading)
        sys.exit(interrupts.report())


if __name__ == "__main__":  # not when multiprocessing re-imports it in a worker process
    entry()
