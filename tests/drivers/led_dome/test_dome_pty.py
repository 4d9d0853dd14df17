"""The real driver and real pyserial against the firmware emulator on a pseudo-terminal.

The policy runs on a VirtualClock (back-offs and cool-downs cost no real time); replies and
timeouts are real (the firmware emulator runs on the system clock). Its margins are wide enough
that scheduling cannot exhaust them in practice: a 1.5 s reply timeout, a 0.3 s boot (a command
sent right after a reset lands while the board boots), late replies 3 s late. With 0.3 s / 20 ms
/ 0.6 s, these tests failed about 1 run in 6 beside two CPU hogs on a loaded 2-core machine (a
reply later than 0.3 s; a command reaching the board after its 20 ms boot). A fault that waits
for the timeout costs 1.5 s of wall time.
"""

from __future__ import annotations

import sys
from pathlib import Path

import pytest
from conftest import line_within

from rti_rig.app.dome_factory import build_dome
from rti_rig.core.clock import SystemClock, VirtualClock
from rti_rig.core.errors import DeviceError
from rti_rig.drivers.led_dome import DomeSerialSettings
from rti_rig.runtime.dome_policy import DomeLedError, DomeLinkError, self_test
from rti_rig.simulator.dome_firmware import (
    Fault,
    FaultKind,
    FaultPlan,
    emulated_dome_on_pty,
    firmware_for,
)

pytestmark = [
    pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux"),
    pytest.mark.pty,
]

PROFILES = ["default", "framed", "binary"]
N_LEDS = 5
LIGHT_1 = 5  # commands: 1 handshake, 2 all off, then light(i) = 3 + 2i, all off = 4 + 2i
OFF_AFTER_1 = 6
REPLY_TIMEOUT_S = 1.5  # a reply later than this is lost or late
BOOT_S = 0.3  # the board's boot after a reset, before its banner
LATE_S = 2 * REPLY_TIMEOUT_S  # how late a DELAY_REPLY fault's reply comes


def settings(profile, **kw):
    base = {
        "port": "set-later",
        "reply_timeout_s": REPLY_TIMEOUT_S,
        "ready_timeout_s": 3.0,
        "reconnect_backoff_s": 0.0,
    }
    base.update(kw)
    return DomeSerialSettings(profile=profile, **base)


def run_on_pty(profile, faults=(), dead=(), **kw):
    """(firmware, link context, settings) ready to build a dome on the pty's port."""
    s = settings(profile, **kw)
    fw = firmware_for(
        s,
        clock=SystemClock(),
        led_count=N_LEDS,
        boot_delay_s=BOOT_S,
        dead_leds=frozenset(dead),
        faults=FaultPlan(tuple(faults)),
    )
    return fw, emulated_dome_on_pty(fw), s


def session(dome, fw, leds=range(N_LEDS)):
    dome.connect()
    for i in leds:
        dome.light(i, 1.0)
        assert fw.lit == (i, 255), f"LED {i} asked, firmware has {fw.lit}"
        dome.all_off()
        assert fw.lit is None


@pytest.mark.parametrize("profile", PROFILES)
def test_full_session_over_a_real_pty(profile):
    fw, pty, s = run_on_pty(profile)
    with pty as link:
        dome = build_dome(s.model_copy(update={"port": link.port}), VirtualClock())
        session(dome, fw)
        dome.shutter(30)
        dome.close()
        assert link.errors == []
    assert dome.link.banners_seen == 1  # waited for the banner after the auto-reset on open
    assert dome.stats.retries == 0
    assert [e.index for e in fw.history if e.what == "lit"] == list(range(N_LEDS))
    assert fw.lit is None


RECOVERABLE = [
    FaultKind.DROP_REPLY,
    FaultKind.GARBLE_REPLY,
    FaultKind.GARBLE_COMMAND,
    FaultKind.DELAY_REPLY,
    FaultKind.DISCONNECT,
    FaultKind.RESET,
]


@pytest.mark.slow
@pytest.mark.parametrize("profile", PROFILES)
@pytest.mark.parametrize("kind", RECOVERABLE)
def test_each_fault_while_lighting_recovers_with_the_right_led(profile, kind):
    delay = 0.0 if kind is FaultKind.DISCONNECT else LATE_S
    fw, pty, s = run_on_pty(profile, [Fault(LIGHT_1, kind, delay_s=delay)])
    with pty as link:
        dome = build_dome(s.model_copy(update={"port": link.port}), VirtualClock())
        session(dome, fw)
        dome.close()
        assert link.errors == []
    assert dome.stats.retries == 1, dome.stats
    if kind is FaultKind.DISCONNECT:
        assert dome.stats.reconnects == 1


@pytest.mark.parametrize("profile", PROFILES)
@pytest.mark.parametrize(
    ("kind", "at"),
    [
        (FaultKind.RESET_AFTER_REPLY, LIGHT_1),
        (FaultKind.RESET, OFF_AFTER_1),
        (FaultKind.DISCONNECT, OFF_AFTER_1),
    ],
)
def test_reset_or_drop_while_lit_stops_naming_the_led_and_command(profile, kind, at):
    fw, pty, s = run_on_pty(profile, [Fault(at, kind, delay_s=0.0)])
    with pty as link:
        dome = build_dome(s.model_copy(update={"port": link.port}), VirtualClock())
        dome.connect()
        dome.light(0, 1.0)
        dome.all_off()
        dome.light(1, 1.0)
        with pytest.raises(DomeLedError) as info:
            dome.all_off()
        assert info.value.led == 1 and info.value.command == "all off"
        assert fw.lit is None
        dome.light(2, 1.0)  # usable again: the controller may repeat the capture
        assert fw.lit == (2, 255)
        dome.close()


def test_dead_led_over_pty_stops_naming_it():
    fw, pty, s = run_on_pty("default", dead=[2])
    with pty as link:
        dome = build_dome(s.model_copy(update={"port": link.port}), VirtualClock())
        with pytest.raises(DomeLedError, match=r"light LED 2 at level 255.*LED fault") as info:
            session(dome, fw)
        assert info.value.led == 2
        assert fw.lit is None
        dome.close()


def test_unplugged_for_good_gives_up_naming_the_command():
    fw, pty, s = run_on_pty("default", [Fault(LIGHT_1, FaultKind.DISCONNECT, delay_s=30.0)])
    with pty as link:
        dome = build_dome(s.model_copy(update={"port": link.port}), VirtualClock())
        dome.connect()
        dome.light(0, 1.0)
        dome.all_off()
        with pytest.raises(DomeLinkError, match=r"light LED 1.*did not come back"):
            dome.light(1, 1.0)
        assert fw.lit is None


def test_self_test_over_pty_reports_the_dead_led():
    _fw, pty, s = run_on_pty("framed", dead=[3])
    with pty as link:
        clock = VirtualClock()
        dome = build_dome(s.model_copy(update={"port": link.port}), clock)
        report = self_test(dome, clock)
    assert [c.index for c in report.failed] == [3]
    assert report.firmware is not None and report.firmware.led_count == N_LEDS
    assert "RESULT: FAIL" in report.lines()


def test_wrong_port_is_a_clear_error():
    s = settings("default", port="/nonexistent/tty-dome")
    dome = build_dome(s, VirtualClock())
    with pytest.raises(
        DeviceError, match=r"port could not be opened.*cannot open serial port /nonexistent"
    ):
        dome.connect()
    # nothing was sent: the report says so rather than "all-off could not be sent"
    assert dome.off_report is not None and dome.off_report.outcome == "never-opened"
    dome.close()


def test_the_port_is_locked_against_a_second_program():
    fw, pty, s = run_on_pty("default")
    with pty as link:
        port_settings = s.model_copy(update={"port": link.port})
        first = build_dome(port_settings, VirtualClock())
        first.connect()
        second = build_dome(port_settings, VirtualClock())
        with pytest.raises(DeviceError, match=r"cannot open serial port.*lock"):
            second.connect()
        first.light(1)
        assert fw.lit == (1, 255)
        first.close()


def test_loop_url_transport_opens_without_a_lock():
    """``serial_for_url`` URLs work too (here nothing answers: a clear handshake timeout)."""
    s = settings("default", port="loop://", ready_timeout_s=0.05, reply_timeout_s=0.05)
    dome = build_dome(s, VirtualClock())
    with pytest.raises(DeviceError, match="no handshake"):
        dome.connect()


@pytest.mark.slow
def test_dry_run_against_the_emulator_in_another_process():
    """``python -m rti_rig.simulator.dome_firmware`` serves a dome any program can open by path."""
    import subprocess

    proc = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "rti_rig.simulator.dome_firmware",
            "--leds",
            "6",
            "--dead",
            "2",
            "--boot-delay-s",
            "0.02",
            "--seconds",
            "20",
        ],
        stdout=subprocess.PIPE,
        text=True,
        cwd=Path(__file__).resolve().parents[3],
    )
    try:
        line = line_within(proc, 120, "the emulator's port")
        assert line.startswith("emulated default dome with 6 LEDs on "), line
        port = line.split()[-1]
        clock = VirtualClock()
        report = self_test(build_dome(settings("default", port=port), clock), clock)
        assert [c.index for c in report.failed] == [2]
        assert len(report.checks) == 6 and report.firmware.firmware_id == "RTIDOME-EMU"
    finally:
        proc.terminate()
        proc.wait(timeout=5)
    # Terminated, it still removes the pty's temporary folder rather than leave it in /tmp.
    assert proc.returncode == 0
    assert not Path(port).parent.exists()


def test_a_dead_led_that_stops_a_session_says_to_repair_it_before_the_resume(
    tmp_path: Path,
) -> None:
    """A session on the emulated dome stops at its dead LED, and offers "Continue with: rti-rig
    run --resume": the refusal had said only "LED fault (open circuit: the LED draws no
    current)", and a resume lights the same LED and stops on it again. It says the LED needs
    repair first."""
    import shutil

    from typer.testing import CliRunner

    from rti_rig.cli import app

    configs = Path(__file__).resolve().parents[3] / "rig_configs"
    shutil.copy(configs / "example_dome_48.lp", tmp_path)
    cfg = tmp_path / "dome.toml"
    cfg.write_text((configs / "emulated_dome.toml").read_text() + "\n[emulator]\ndead_leds = [2]\n")
    r = CliRunner().invoke(app, ["run", str(cfg), "--out", str(tmp_path / "s"), "--no-verdict"])
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    assert "LED 2 (az 60.1°, el 9.6°) refused" in said and "LED fault" in said, said
    repair = (
        "the LED or its wiring needs repair: until then a session that lights it, or its "
        "resume, stops there again"
    )
    assert repair in said, said
