"""A dome's lost port, reopened mid-run, is said as the product speaks: one line as the
reopening begins (what happened, and that the session goes on once the dome is back), one with
its outcome, and the detail kept in the manifest.

Before, the reopening was told only as Python log records, which the command line (configuring
no logging) printed raw on stderr in the middle of the progress bar: "dome on /tmp/…/tty-… :
light LED 1 at level 1 failed (disconnected, attempt 1): port lost: read from … failed", then
"reconnection 1 failed: … cannot open serial port …" once per failed attempt, on every firmware,
and nothing on disk said the dome had been reopened.
"""

from __future__ import annotations

import json
import re
import sys
from pathlib import Path

import pytest
from conftest import CONFIGS
from typer.testing import CliRunner

from rti_rig.cli import app

pytestmark = [
    pytest.mark.slow,  # real firmware timing over a pty, and a USB drop of 1 s or more
    pytest.mark.pty,
    pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux"),
]

#: What the raw log records had said (the link's and the policy's own words).
RAW_RECORDS = ("failed (disconnected", "reconnection 1 failed", "; reopening it")


def _run(tmp_path: Path, config: str, fault: str) -> tuple[object, str, Path]:
    cfg = tmp_path / "rig.toml"
    cfg.write_text((CONFIGS / config).read_text() + f"\n[[emulator.faults]]\n{fault}\n")
    out = tmp_path / "S"
    argv = ["run", str(cfg), "--lights", "6", "--out", str(out), "--no-verdict"]
    r = CliRunner().invoke(app, argv, terminal_width=400)
    return r, " ".join(r.output.split()), out


def test_a_port_lost_between_lights_is_said_once_with_its_outcome_and_kept(
    tmp_path: Path,
) -> None:
    # the Nab sketch: command 6 is the second light, sent with no LED lit
    r, said, out = _run(tmp_path, "emulated_nab_rti_v1.toml", 'at_command = 6\nkind = "disconnect"')
    assert r.exit_code == 0, said  # type: ignore[attr-defined]
    lost = (
        "The dome dropped off the USB bus during 'light LED 1 at level 1': reopening its port "
        "(up to 4 attempts over 7.5 s); the session goes on once it is back."
    )
    assert said.count(lost) == 1, said
    back = said.index("The dome is back: its port reopened and it answered, after ")
    assert said.count("The dome is back") == 1 and back > said.index(lost), said
    for raw in RAW_RECORDS:
        assert raw not in said, (raw, said)
    assert "6 image(s) in the session" in said, said
    runner = json.loads((out / "manifest.json").read_text())["runner"]
    [kept] = runner["dome_reconnections"]
    assert kept["during"] == "light LED 1 at level 1" and kept["outcome"] == "reconnected"
    assert kept["attempts"] >= 2  # the port is away for 1 s: the first reopening finds none
    assert "port lost" in str(kept["lost"])


def test_a_port_lost_at_the_handshake_that_does_not_come_back_is_said_before_the_error(
    tmp_path: Path,
) -> None:
    fault = 'at_command = 1\nkind = "disconnect"\ndelay_s = 60.0'
    r, said, _out = _run(tmp_path, "emulated_elexol.toml", fault)
    assert r.exit_code == 2, said  # type: ignore[attr-defined]
    lost = "The dome dropped off the USB bus during the handshake: reopening its port (up to 4"
    assert said.count(lost) == 1, said
    gone = said.index("The dome's port did not come back, after 4 attempts (said below).")
    assert said.index(lost) < gone < said.index("port was lost during the handshake ("), said
    for raw in RAW_RECORDS:
        assert raw not in said, (raw, said)


@pytest.mark.parametrize("command", [8, 9])
def test_a_port_lost_at_the_teardowns_all_off_is_not_said_to_let_the_session_go_on(
    tmp_path: Path, command: int
) -> None:
    """The Nab sketch, two lights: commands 8 and 9 are the teardown's all-offs after the last
    image (the lighting's safe() one, then its close's). The session was ending ("the session
    goes on once it is back" had been said of it): the reopening is said for what it is, the
    all-off sent again."""
    r, said, out = _run_lights(tmp_path, f'at_command = {command}\nkind = "disconnect"', 2)
    assert r.exit_code == 0, said  # type: ignore[attr-defined]
    lost = (
        "The dome dropped off the USB bus during 'all off': reopening its port (up to 4 "
        "attempts over 7.5 s); the closing all-off is sent again once it is back."
    )
    assert said.count(lost) == 1, said
    assert "goes on once it is back" not in said, said
    assert "2 image(s) in the session" in said, said
    assert "All-off sent and acknowledged by the dome: lights are off." in said, said
    runner = json.loads((out / "manifest.json").read_text())["runner"]
    assert [k["outcome"] for k in runner["dome_reconnections"]] == ["reconnected"]


def test_a_port_lost_with_an_led_lit_does_not_say_it_went_dark(tmp_path: Path) -> None:
    """Command 7 is the all-off after the second light: the port goes with LED 9 lit. A board
    powered apart from its USB link keeps it lit, so its going dark is not claimed."""
    r, said, _out = _run_lights(tmp_path, 'at_command = 7\nkind = "disconnect"', 2)
    assert r.exit_code == 2, said  # type: ignore[attr-defined]
    assert re.search(
        r"LED 9 \(az [-\d.]+°, el [-\d.]+°\) was meant to be lit when the port went, so the "
        r"session stops at its image\.",
        said,
    ), said
    assert "went dark with it" not in said, said


def _run_lights(tmp_path: Path, fault: str, lights: int) -> tuple[object, str, Path]:
    cfg = tmp_path / "rig.toml"
    text = (CONFIGS / "emulated_nab_rti_v1.toml").read_text()
    cfg.write_text(text + f"\n[[emulator.faults]]\n{fault}\n")
    out = tmp_path / "S"
    argv = ["run", str(cfg), "--lights", str(lights), "--out", str(out), "--no-verdict"]
    r = CliRunner().invoke(app, argv, terminal_width=400)
    return r, " ".join(r.output.split()), out
