"""``hairtool bench host``: the probes' kernel against its numpy twin, and the rows it reports."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from hairtool.bench import host
from hairtool.cli import main


@pytest.mark.parametrize("kernel", [host._step_rows_serial, host._step_rows_parallel])
def test_arithmetic_probe_matches_numpy(kernel):
    y = np.linspace(-2.0, 3.0, 6 * 40).reshape(6, 40)
    want = host.step_rows_reference(y, 0.75, 0.125, 9)
    kernel(y, 0.75, 0.125, 9)
    np.testing.assert_allclose(y, want, rtol=1e-14)


def test_quick_rows(capsys):
    assert main(["bench", "host", "--quick", "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)
    probes = rows[:-1]
    assert [r["probe"] for r in probes] == list(host.REFERENCE_MS)
    for r in probes:
        assert r["ms"] > 0 and r["speed"] == pytest.approx(r["reference_ms"] / r["ms"])
    summary = rows[-1]
    assert summary["probe"] == "host" and summary["threads"] >= 1 and summary["scaling"] > 0
    mean = math.exp(sum(math.log(r["speed"]) for r in probes) / len(probes))
    assert summary["speed"] == pytest.approx(mean)
