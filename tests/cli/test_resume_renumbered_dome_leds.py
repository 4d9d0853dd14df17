"""``run --resume --accept-rig-change`` of a dome session on its config given an LED more on a
ring: every LED after it is numbered one higher, so the steps still to shoot (which name their
LEDs by number) are refused. Each was said "the plan was made for another dome layout", of a
session whose plan was made for this very dome as it began, with no plan given; now the
refusal says the LEDs were renumbered (or moved) since the session began, how many LEDs the
dome had then and has now, and why that puts the steps' LEDs elsewhere.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import CONFIGS, REPO, said
from sigterm_support import signal_at_commit
from typer.testing import CliRunner

from rti_rig.cli import app


@pytest.mark.slow
@pytest.mark.e2e
@pytest.mark.skipif(sys.platform == "win32", reason="signals tested on POSIX")
def test_an_led_added_to_the_dome_is_said_to_renumber_the_steps_still_to_shoot(
    tmp_path: Path,
) -> None:
    shipped = (CONFIGS / "simulated_dome.toml").read_text()
    ring = "elevation_deg = 25.0, count = 12,"
    assert ring in shipped
    config = tmp_path / "dome.toml"
    config.write_text(shipped)
    out = tmp_path / "s"
    args = ["run", str(config), "--out", str(out), "--lights", "8", "--no-verdict"]
    proc = subprocess.run(  # Ctrl-C as image_003 is committed: the run stops after it
        [sys.executable, "-c", signal_at_commit("SIGINT"), "2", *args],
        capture_output=True,
        text=True,
        timeout=300,
        env={**os.environ, "PYTHONPATH": str(REPO)},
    )
    assert proc.returncode == 130, proc.stdout + proc.stderr
    config.write_text(shipped.replace(ring, "elevation_deg = 25.0, count = 13,"))

    # without the flag: refused, and told what the flag can and cannot do here (it had been
    # advised alone, and the resume with it then refused every step)
    r = CliRunner().invoke(app, ["run", "--resume", str(out)])
    text = said(r)
    assert r.exit_code == 2, text
    assert "add --accept-rig-change to record it (the dome had 48 LEDs and has 49 LEDs: an LED" in (
        text
    ), text
    assert "it goes on only if each step still to shoot names an LED that stands where it did" in (
        text
    )

    r = CliRunner().invoke(app, ["run", "--resume", str(out), "--accept-rig-change"])

    text = said(r)
    assert r.exit_code == 2, text
    assert "another dome layout" not in text, text
    assert "calibrated direction: renumbered or moved since this session began" in text, text
    assert (
        "This dome has 49 LEDs and had 48 LEDs when the session began: an LED added or taken "
        "out changes the number of every LED after it, and the session's steps name their LEDs "
        "by number: the LED each of these names stands elsewhere than planned. The rig change "
        "accepted (lights: 48 LEDs → 49 LEDs"
    ) in text, text
    assert "back as it began" in text and "Traceback" not in r.output, text
