"""`rti-rig check` on the shipped emulated dome (``emulated_dome.toml``, default profile) whose
board reboots right after its last handshake reply: the all-off the failed connect sends meets
the boot banner before it is written, and is sent once more after it.

That all-off had failed with a reset fault before a byte of it was written, and the lights line
said "all-off sent but not acknowledged" of it, and stopped there: a claim of a command never
sent, and no all-off at all to a board just booted (the Nab sketch boots with every LED lit).

The board's replies to the three handshakes (the connect's and the config's ``retries = 2``)
are damaged on the wire, and it reboots after the third: the emulator's own faults
(``[[emulator.faults]]``). The check waits, before that all-off, until the banner has reached
the port (a condition, bounded): the reboot then comes before the all-off, as the test means,
however loaded the machine."""

from __future__ import annotations

import sys
import time
from pathlib import Path

import pytest
from conftest import CONFIGS, emulators_built_by_check
from typer.testing import CliRunner

from rti_rig.cli import app

pytestmark = [
    pytest.mark.pty,
    pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux"),
]

SHIPPED = CONFIGS / "emulated_dome.toml"

#: commands 1-3 are the handshakes (garbled replies), the board reboots after the third reply
FAULTS = "".join(
    f'\n[[emulator.faults]]\nat_command = {n}\nkind = "{kind}"\n'
    for n, kind in [
        (1, "garble_reply"),
        (2, "garble_reply"),
        (3, "garble_reply"),
        (3, "reset_after_reply"),
    ]
)


def test_an_all_off_that_met_a_reboot_banner_before_it_was_written_is_sent_again(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from rti_rig.drivers.led_dome.driver import LedDomeDriver

    text = SHIPPED.read_text()
    assert "retries = 2" in text and 'profile = "default"' in text
    cfg = tmp_path / "rig.toml"
    cfg.write_text(text + FAULTS)
    (tmp_path / "example_dome_48.lp").write_bytes((CONFIGS / "example_dome_48.lp").read_bytes())
    emulators = emulators_built_by_check(monkeypatch)

    real_all_off = LedDomeDriver.all_off
    waited: list[bool] = []

    def all_off(self: LedDomeDriver) -> None:
        firmware = emulators[-1]
        if not waited and any(e.what == "reset" for e in firmware.history):
            # the banner the reboot sends, in this link's buffer or the port's, before the
            # all-off is written (bounded: a failure below says if it never came)
            deadline = time.monotonic() + 30.0
            port = self.transport._ser  # type: ignore[attr-defined]
            while not (self._rx or port.in_waiting) and time.monotonic() < deadline:
                time.sleep(0.005)
            waited.append(bool(self._rx or port.in_waiting))
        real_all_off(self)

    monkeypatch.setattr(LedDomeDriver, "all_off", all_off)
    r = CliRunner().invoke(app, ["check", str(cfg)], terminal_width=400)
    said = " ".join(r.output.split())
    assert waited == [True], (waited, said)
    assert r.exit_code != 0 and "Traceback" not in said, said
    assert "no handshake with the dome" in said, said
    assert "all-off sent but not acknowledged" not in said, said
    assert "all-off sent and acknowledged by the dome: lights are off" in said, said
    firmware = emulators[-1]
    events = [e.what for e in firmware.history]
    assert events.count("reset") == 1, events
    # three handshakes, then one all-off: the first never reached the board
    assert firmware.commands_received == 4, events
    assert firmware.lit is None
