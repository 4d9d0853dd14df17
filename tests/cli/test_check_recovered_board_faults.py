"""`rti-rig check` says so when the board rebooted during the walk and was recovered from.

A Nab board that rebooted instead of taking a light command (no LED lit at that moment: the
check re-handshakes and resends) ended "RESULT: PASS" with "recovery: 1 retries, 0 reconnects,
1 re-handshakes" as the only trace, where a reboot while an LED was lit failed the check saying
to look at the power supply and the USB cable. A board that reboots by itself does it in a
session too.
"""

from __future__ import annotations

import sys
from pathlib import Path

import pytest
from conftest import CONFIGS, emulated_dome_as_hardware
from typer.testing import CliRunner

from rti_rig.cli import app

pytestmark = [
    pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux"),
    pytest.mark.pty,
]


def test_a_reboot_the_check_recovered_from_is_said(tmp_path: Path) -> None:
    cfg = tmp_path / "rig.toml"
    # commands 1-4: the init and connect all-offs, LED 0 and its all-off; 5 is LED 1's light
    cfg.write_text(
        (CONFIGS / "emulated_nab_rti_v1.toml").read_text()
        + '\n[[emulator.faults]]\nat_command = 5\nkind = "reset"\n'
    )
    r = CliRunner().invoke(app, ["check", str(cfg)], terminal_width=400)
    said = " ".join(r.output.split())
    assert "1 re-handshakes" in said, said
    assert "the board rebooted during the check (at 'light LED 1" in said, said
    assert "points to its power supply or its USB cable" in said


def test_only_reboots_and_usb_drops_are_named() -> None:
    from rti_rig.runtime.dome_policy import _recovered_board_faults

    assert _recovered_board_faults(["light LED 3 at level 1: timeout"]) == []
    lines = _recovered_board_faults(["all off: disconnected", "all off: reset", "hello: reset"])
    assert len(lines) == 2
    assert lines[0].startswith("the board dropped off the USB bus during the check (at 'all off')")
    assert lines[1].startswith("the board rebooted during the check (at 'all off', 'hello')")


def test_a_banner_later_than_the_boot_wait_is_not_called_a_reboot(tmp_path: Path) -> None:
    """A board whose bootloader outlasts the profile's boot wait prints its banner after the
    first command: the connect resends it, and its warning names boot_wait_s. It is no board
    rebooting by itself, which the line had said of it (power supply, USB cable).

    Its advice is in the report, above the result: it had reached stderr alone, beside a
    "RESULT: PASS" a user reads as nothing to change."""
    from rti_rig.simulator.domes import board_for
    from rti_rig.simulator.pty_link import serve_on_pty

    board = board_for("nab-rti-v1")
    board.boot_s = 5.0  # the profile waits 4 s
    with serve_on_pty(board, "nab-rti-v1") as link:
        cfg = emulated_dome_as_hardware(tmp_path, "emulated_nab_rti_v1.toml", link.port)
        r = CliRunner().invoke(app, ["check", str(cfg)], terminal_width=400)
    said = " ".join(r.output.split())
    assert "LEDs stepped: 12, acknowledged by the board: 12" in said, said
    assert "rebooted during the check" not in said, said
    # CliRunner mixes stderr into output: the report's own line is what is looked for
    assert "slow boot: the board printed its boot banner only" in said, said
    assert "set boot_wait_s = 7 in [dome.serial.protocol]" in said


def test_a_late_banner_that_ended_the_check_is_its_error_not_a_slow_boot_line(
    tmp_path: Path,
) -> None:
    """With no resend allowed (retries = 0) the late banner ends the connect: its advice is
    the check's error, and no "slow boot: … the check went on" line claims a walk that never
    ran. Which of the two the report says is decided by the link error's ``slow_boot`` flag
    (and the errors raised from it), not by finding the advice's words in the error."""
    from rti_rig.simulator.domes import board_for
    from rti_rig.simulator.pty_link import serve_on_pty

    board = board_for("nab-rti-v1")
    board.boot_s = 5.0  # the profile waits 4 s
    with serve_on_pty(board, "nab-rti-v1") as link:
        cfg = emulated_dome_as_hardware(tmp_path, "emulated_nab_rti_v1.toml", link.port)
        cfg.write_text(cfg.read_text().replace("retries = 2", "retries = 0"))
        r = CliRunner().invoke(app, ["check", str(cfg)], terminal_width=400)
    said = " ".join(r.output.split())
    assert r.exit_code != 0, said
    assert "ABORTED:" in said, said
    aborted = said[said.index("ABORTED:") :]
    assert "printed its boot banner only" in aborted, said  # the error says the slow boot
    assert "set boot_wait_s = 7 in [dome.serial.protocol]" in aborted, said
    assert "slow boot:" not in said and "the check went on" not in said, said


def test_only_a_slow_boot_error_or_one_raised_from_it_ended_the_check() -> None:
    """The decision itself, on errors worded alike: the flag and the explicit cause decide."""
    from rti_rig.core.dome_link import DomeLinkError, LinkFault
    from rti_rig.core.errors import DeviceError
    from rti_rig.runtime.dome_policy import _ended_by_slow_boot

    def link_error(slow: bool) -> DomeLinkError:
        return DomeLinkError(
            "dome", "banner late", "hello", LinkFault.RESET, retryable=True, slow_boot=slow
        )

    slow, other = link_error(True), link_error(False)
    assert _ended_by_slow_boot(slow) and not _ended_by_slow_boot(other)
    assert not _ended_by_slow_boot(None)
    restated = DeviceError("dome", "no handshake with the dome (reworded)", "hello")
    restated.__cause__ = slow
    assert _ended_by_slow_boot(restated)
    after = DeviceError("dome", "banner late", "hello")  # its words, but not raised from it
    after.__context__ = slow
    assert not _ended_by_slow_boot(after)
