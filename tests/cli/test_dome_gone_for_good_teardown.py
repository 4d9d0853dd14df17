"""A dome whose USB port goes for good mid-session: the teardown waits its reconnect window once.

Found by a field audit: the lighting's all-off, then the port close's, each waited the whole
reconnection window (2 × 7 s on the shipped emulated configs) for a port the first had already
found gone, a user on battery with a dead dome waiting for nothing the second time. The close's
all-off now opens the port once more at once (had it come back, the all-off is sent).

Through ``rti-rig run`` on the shipped emulated dome (the real driver and pyserial on a pty),
its USB drop the emulator's ``disconnect`` fault, away for longer than the run; the reconnect
window shortened to 0.7 s through the config (``reconnect_backoff_s = 0.1``).
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest
from conftest import CONFIGS
from typer.testing import CliRunner

from rti_rig.cli import app

pytestmark = [
    pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux"),
    pytest.mark.pty,
]


def test_a_dome_gone_for_good_is_waited_for_once_by_the_teardown(tmp_path: Path) -> None:
    text = (CONFIGS / "emulated_dome.toml").read_text()
    text = text.replace(
        'lp_file = "example_dome_48.lp"', f'lp_file = "{CONFIGS}/example_dome_48.lp"'
    )
    text = text.replace(
        "reconnect_attempts = 3\n", "reconnect_attempts = 3\nreconnect_backoff_s = 0.1\n"
    )
    assert "reconnect_backoff_s = 0.1" in text
    cfg = tmp_path / "dome.toml"
    # command 6: the second light (after the handshake, its all-off, the first light and its off)
    cfg.write_text(
        text + '\n[[emulator.faults]]\nat_command = 6\nkind = "disconnect"\ndelay_s = 60.0\n'
    )
    out = tmp_path / "s"
    r = CliRunner().invoke(
        app,
        ["run", str(cfg), "--out", str(out), "--lights", "4", "--no-verdict"],
        terminal_width=400,
    )
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    # the session's reconnection, then the teardown's lighting all-off's: each a whole window
    assert said.count("attempts over 0.7 s); ") == 2, said
    assert said.count("The dome's port did not come back, after 3 attempts") == 2, said
    # the close's all-off: one opening at once, said as such
    assert (
        said.count(
            "The dome's port is still gone at 'all off': this teardown already waited 0.7 s for "
            "it, so it is opened once more without waiting again"
        )
        == 1
    ), said
    assert said.count("The dome's port did not come back, after 1 attempt ") == 1, said
    assert "All-off could NOT be sent" in said and "switch the dome off at its power supply" in said
    assert (out / "lights.lp").read_text().split()[0] == "1", said
    assert "Traceback" not in said
    runner = json.loads((out / "manifest.json").read_text())["runner"]
    assert [k["attempts"] for k in runner["dome_reconnections"]] == [3, 3, 1], runner
