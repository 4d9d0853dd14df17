"""``rti-rig check`` on the emulated arm, stopped by a Ctrl-C in the middle of a Protocol 2.0
exchange (a status packet half-read when the signal handler raises), with the arm at its park
pose and ``torque_policy = "release_on_close"``.

The stop unwinds through the SDK; the self-test's teardown then talks to the same port (its
stop, the read-back, the close's torque-off), which the driver releases after an interrupted
exchange. What the check says of the torque must be what the close did: the close finds the
arm at its park pose and releases it, and the stopped check had said "not parked and left at
az 0.0°, el 10.0°" with no word of the joints it had just let go limp."""

from __future__ import annotations

import signal
import sys
from pathlib import Path

import pytest
from conftest import emulators_built_by_check, inprocess_arm_config
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.drivers.dynamixel import control_table as ct
from rti_rig.drivers.dynamixel.arm import DynamixelArm
from rti_rig.simulator.dynamixel_emulator import InProcessPort

RELEASED = 'torque then released (torque_policy = "release_on_close", read back off on each servo)'


@pytest.mark.skipif(sys.platform != "linux", reason="signals tested on Linux")
def test_a_check_stopped_mid_exchange_at_the_park_pose_says_the_release(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    cfg = inprocess_arm_config(tmp_path)
    text = cfg.read_text()
    assert 'torque_policy = "hold"' in text
    cfg.write_text(text.replace('torque_policy = "hold"', 'torque_policy = "release_on_close"'))
    emulators = emulators_built_by_check(monkeypatch)
    parking: list[tuple[int, int]] = []  # the park's goal ticks, once the park has begun
    interrupted: list[int] = []
    real_park, real_read = DynamixelArm.park, InProcessPort.readPort

    def park(self, *args, **kwargs):  # type: ignore[no-untyped-def]
        s = self.settings
        parking.append(self.kin.ticks_of_pose(s.park_azimuth_deg, s.park_elevation_deg))
        return real_park(self, *args, **kwargs)

    def read(self, length):  # type: ignore[no-untyped-def]
        if parking and not interrupted:
            servos = [self.emulator.servos[i] for i in (1, 2)]
            at = [x.get(ct.PRESENT_POSITION) for x in servos]
            if all(abs(a - g) <= 2 for a, g in zip(at, parking[0], strict=True)):
                interrupted.append(length)
                got = real_read(self, min(length, 3))  # a status packet half-read, then
                signal.raise_signal(signal.SIGINT)  # the stop's handler raises here
                return got
        return real_read(self, length)

    monkeypatch.setattr(DynamixelArm, "park", park)
    monkeypatch.setattr(InProcessPort, "readPort", read)
    r = CliRunner().invoke(app, ["check", str(cfg)], terminal_width=400)
    said = " ".join(r.output.split())
    assert interrupted, said
    assert "Traceback" not in said, said
    assert r.exit_code == 130, said
    # the teardown reached the servos after the interrupted exchange: stopped and read back
    assert "Check stopped (Ctrl-C)" in said, said
    assert "el 10.0° (read back; the check was stopped (Ctrl-C)" in said, said
    (emu,) = emulators  # the truth: the close released both joints
    assert all(s.get(ct.TORQUE_ENABLE) == 0 for s in emu.servos.values())
    assert RELEASED in said and "hold no pose" in said, said
