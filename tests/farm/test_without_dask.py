"""Without the farm extra: every module imports, a job still runs in-process, and
``hairtool batch`` says in one line how to install Dask."""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap

SCRIPT = textwrap.dedent(
    """
    import sys

    class Block:
        def find_spec(self, name, path=None, target=None):
            if name.split(".")[0] in ("dask", "distributed"):
                raise ImportError(f"{name} is blocked in this test")
            return None

    sys.meta_path.insert(0, Block())

    import importlib
    import pkgutil

    import hairtool.farm

    for m in pkgutil.walk_packages(hairtool.farm.__path__, "hairtool.farm."):
        importlib.import_module(m.name)
    importlib.import_module("hairtool.farm.command")
    importlib.import_module("hairtool.farm.bench")

    from hairtool.cli import main
    from hairtool.farm.jobs import load_jobs
    from hairtool.farm.runner import run_job

    jobs = load_jobs(sys.argv[1])
    assert run_job(jobs[0])["status"] == "done"
    assert main(["batch", sys.argv[1]]) == 2
    assert not any(m.split(".")[0] in ("dask", "distributed") for m in sys.modules)
    """
)


def test_the_farm_imports_and_runs_jobs_without_dask(tmp_path):
    jobs = tmp_path / "jobs.json"
    jobs.write_text(
        json.dumps({"jobs": [{"command": "sample", "args": ["comb", "comb.obj", "--strands", "4"]}]})
    )
    r = subprocess.run([sys.executable, "-c", SCRIPT, str(jobs)], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "comb.obj").is_file()
    err = r.stderr.strip()
    assert err.startswith("hairtool batch: error: ") and "hairtool[farm]" in err and "\n" not in err
