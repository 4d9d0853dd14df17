"""`rti-rig bench` as the installed command runs it (README: `rti-rig bench tradeoff ...`).

The console script's ``sys.path`` has neither the current folder nor the checkout, so the
benchmarks (not installed) were not found even from the repository's folder; only
``python -m rti_rig bench`` worked.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]


def test_installed_rti_rig_bench_finds_the_checkout_benchmarks(tmp_path: Path) -> None:
    script = Path(sys.executable).parent / "rti-rig"
    assert script.is_file(), "rti-rig is installed in this environment (pip install -e .)"
    missing = tmp_path / "nowhere" / "dirs.lp"
    for cwd in (REPO, tmp_path):
        r = subprocess.run(
            [str(script), "bench", "tradeoff", "--from", str(missing)],
            cwd=cwd,
            capture_output=True,
            text=True,
            timeout=300,
        )
        text = " ".join((r.stdout + r.stderr).split())
        assert r.returncode == 2, text
        assert "checkout" not in text, text  # the benchmarks were found
        assert "Traceback" not in text and "dirs.lp" in text, text
