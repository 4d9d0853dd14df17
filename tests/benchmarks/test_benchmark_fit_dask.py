"""Smoke run of benchmarks/fit_dask.py: it times the three modes on a tiny batch, finds their
outputs identical, and writes nothing without --write."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]


@pytest.mark.slow
def test_fit_dask_benchmark_runs_and_finds_identical_outputs() -> None:
    before = (REPO / "docs" / "benchmarks.md").read_bytes()
    done = subprocess.run(
        [
            sys.executable,
            "-m",
            "benchmarks.fit_dask",
            "--sessions",
            "2",
            "--width",
            "40",
            "--height",
            "32",
            "--lights",
            "20",
            "--repeats",
            "1",
        ],
        capture_output=True,
        text=True,
        cwd=REPO,
        timeout=900,
    )
    assert done.returncode == 0, done.stderr
    rows = [line for line in done.stdout.splitlines() if line.startswith("| ")]
    assert len(rows) == 4  # the header and 3 modes
    assert rows[-2].endswith("| yes |") and rows[-1].endswith("| yes |")
    assert "not written" in done.stdout
    assert (REPO / "docs" / "benchmarks.md").read_bytes() == before
