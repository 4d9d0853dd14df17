"""A calibration whose write is cut off (the file system refuses more bytes) leaves no partial
file, and the card session can be calibrated again once there is room.

Why: the file was written in place; cut off, a partial light_calibration.toml stayed in the
card session, and since a card session's own calibration is never replaced, every later
`calibrate-lights` of it was refused as "calibrated already".
"""

from __future__ import annotations

import resource
import signal
import subprocess
import sys
from pathlib import Path

import pytest
from card_support import card_rig, shoot
from conftest import REPO, said
from typer.testing import CliRunner

from rti_rig.cli import app

#: Bytes a file may grow to in the child: the calibration (about 3 kB) is cut off partway.
LIMIT = 1000


def _limited() -> None:
    """In the child: a file size limit, as a full disk or quota refuses the rest of a write
    (EFBIG rather than a signal that kills the process)."""
    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
    resource.setrlimit(resource.RLIMIT_FSIZE, (LIMIT, LIMIT))


@pytest.mark.skipif(sys.platform != "linux", reason="file size limits tested on Linux")
def test_a_cut_off_calibration_leaves_nothing_and_can_be_written_again(tmp_path: Path) -> None:
    rig = card_rig(tmp_path)
    card = tmp_path / "card é"
    shoot(rig, card)
    before = sorted(p.name for p in card.iterdir())
    argv = ["calibrate-lights", str(card), "--rig", str(rig)]

    cut = subprocess.run(
        [sys.executable, "-m", "rti_rig", *argv],
        cwd=REPO,
        capture_output=True,
        text=True,
        timeout=600,
        preexec_fn=_limited,
        check=False,
    )

    assert cut.returncode == 2, cut.stdout + cut.stderr
    assert "Traceback" not in cut.stderr, cut.stderr
    assert "cannot write" in cut.stderr and "nothing was written there" in cut.stderr, cut.stderr
    assert sorted(p.name for p in card.iterdir()) == before
    r = CliRunner().invoke(app, argv)
    assert r.exit_code == 0, r.output
    assert "calibrated already" not in said(r)
    assert 'format = "rti-rig-light-calibration/1"' in (card / "light_calibration.toml").read_text()
