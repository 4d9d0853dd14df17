"""`rti-rig fit --scheduler` with a malformed address: refused at once, no traceback.

A Client built on 'bogus' raised ValueError (turned into a clear error), but the half-built
Client then waited 40 s in its __del__ and printed "Exception ignored ... Traceback ...
TimeoutError" after it.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
ACQ = REPO / "tests" / "data" / "neuralrti_replay" / "dirs.lp"
RTI_RIG = [sys.executable, "-c", "from rti_rig.cli import main; main()"]


def test_a_malformed_scheduler_address_is_refused_cleanly(tmp_path: Path) -> None:
    out = tmp_path / "fit"
    r = subprocess.run(
        [*RTI_RIG, "fit", str(ACQ), "--out", str(out), "--scheduler", "bogus", "--no-qa"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    text = r.stdout + r.stderr
    assert r.returncode == 2, text
    assert "Traceback" not in text and "Exception ignored" not in text, text
    assert "bogus" in text and "tcp://HOST:8786" in text
    assert not out.exists()
