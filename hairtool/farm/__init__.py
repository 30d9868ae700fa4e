"""Batches of shots on a farm: ``hairtool batch`` runs the CLI's commands as jobs on Dask.

- :mod:`~hairtool.farm.jobs`: the jobs file (.json or .toml), glob templates, validation.
- :mod:`~hairtool.farm.manifest`: what is done, by content hash, for skipping and resuming.
- :mod:`~hairtool.farm.runner`: one job in a worker process, through :func:`hairtool.cli.main`.
- :mod:`~hairtool.farm.fields`: the numbers a report row takes from a command's ``--json``.
- :mod:`~hairtool.farm.cluster`: a local Dask cluster or a running scheduler (Dask imported
  only here, so the rest of hairtool works without the ``farm`` extra).
- :mod:`~hairtool.farm.batch`: skip, submit, collect, record.
- :mod:`~hairtool.farm.progress`, :mod:`~hairtool.farm.report`: the terminal line and the report.
"""
