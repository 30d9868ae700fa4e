"""A clone of the repository alone passes its tests: the real data they read lives in tests/data."""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
TEST_DATA = ROOT / "tests" / "data"
GROOMS, MOTION = TEST_DATA / "grooms", TEST_DATA / "motion"

LICENCES = {
    "grooms": ("LICENSE-ratboy.txt", "LICENSE-tressfx.txt", "CREDITS-sintel.txt"),
    "motion": ("LICENSE-bvh-python.txt", "LICENSE-pymo.txt"),
    "interop": ("LICENSE-CC0.txt",),
}


def test_the_real_data_and_its_licences_are_in_the_repository():
    assert {p.name for p in GROOMS.glob("*.tfx")} >= {"sintel_hair.tfx", "bear.tfx", "ratboy_mohawk.tfx"}
    assert {p.name for p in MOTION.glob("*.bvh")} == {"pymo_walk.bvh", "mocapbank_walk.bvh", "freebvh.bvh"}
    for folder, names in LICENCES.items():
        for name in names:
            assert (TEST_DATA / folder / name).is_file(), f"{folder}/{name} is missing"
    readme = (TEST_DATA / "README.md").read_text()
    for path in TEST_DATA.rglob("*"):
        if path.is_file() and path.suffix in {".tfx", ".obj", ".bvh", ".usda", ".usdc"}:
            assert path.name in readme, f"{path.name} has no source or licence line in tests/data/README.md"


def test_no_test_reads_data_beside_the_checkout():
    beside = re.compile(r"""["']shared["']\s*/\s*["']data["']|\.\./shared""")
    offenders = [
        str(p.relative_to(ROOT))
        for p in (ROOT / "tests").rglob("*.py")
        if p.name != "test_test_data.py" and beside.search(p.read_text())
    ]
    assert offenders == []
