"""The dome's duty ledger: an LED's lightings survive from one command to the next.

Each "command" here is a fresh :class:`DomePolicy` on a fresh virtual clock (as each rti-rig
process has), over the in-process firmware emulator, sharing one ledger file; the ledger's
wall clock is a counter the test moves, so nothing depends on real time passing."""

from __future__ import annotations

import json
import os
import time
import warnings
from pathlib import Path

import pytest

from rti_rig.app.dome_factory import build_dome
from rti_rig.core.clock import VirtualClock
from rti_rig.drivers.led_dome import DomeSerialSettings
from rti_rig.runtime import duty_ledger
from rti_rig.runtime.dome_policy import ThermalGuard, ThermalLimits
from rti_rig.runtime.duty_ledger import LEDGER_DIR_ENV, DutyLedger
from rti_rig.simulator.dome_firmware import InProcessDomeTransport, firmware_for

# an LED lit 10 s uses up its duty for the minute: 10 s on of 0.3 × 60 s, less max_on_s 10 s
THERMAL = {"max_on_s": 10.0, "max_duty": 0.3, "duty_window_s": 60.0}
LIMITS = ThermalLimits(**THERMAL)


class Wall:
    """The ledger's wall clock (``time.time()`` in a real command), moved by the test."""

    def __init__(self, t: float = 1_800_000_000.0) -> None:
        self.t = t

    def __call__(self) -> float:
        return self.t


def command(ledger: DutyLedger):  # type: ignore[no-untyped-def]
    """A fresh process's dome on the shared ledger: its own clock starting at 0."""
    clock = VirtualClock()
    s = DomeSerialSettings(port="emulated", profile="default", thermal=THERMAL)
    fw = firmware_for(s, clock=clock, led_count=12, boot_delay_s=0.2)
    dome = build_dome(s, clock, transport=InProcessDomeTransport(fw), ledger=ledger)
    return dome, clock


def lit_for(dome, clock, index: int, seconds: float) -> None:  # type: ignore[no-untyped-def]
    dome.light(index, 1.0)
    clock.sleep(seconds)
    dome.all_off()


def test_an_led_lit_by_an_earlier_command_waits_for_its_duty_in_the_next(tmp_path: Path) -> None:
    wall = Wall()
    ledger = DutyLedger("port:/dev/ttyACM0", wall=wall)
    first, clock = command(ledger)
    first.connect()
    lit_for(first, clock, 7, 9.8)
    first.close()
    wall.t += clock.now() + 41.0  # the first command's time, then 41 s until the next

    second, clock2 = command(DutyLedger("port:/dev/ttyACM0", wall=wall))
    second.connect()
    at = clock2.now()  # the connect's own time
    with pytest.warns(RuntimeWarning) as said:
        second.light(7, 1.0)
    # without the ledger LED 7 would light at once; with it, it waits for its lighting of
    # [-50.8, -41] s to leave the minute but for the 8 s budget: until 11 s on this clock
    wait = second.duty_wait()
    assert wait.waited_s == pytest.approx(11.0 - at, abs=0.01)
    assert wait.for_earlier_s == pytest.approx(wait.waited_s)
    text = str(said[0].message)
    expected = f"LED 7 was lit 9.8 s by an earlier command 41 s ago: waiting {11.0 - at:.1f} s"
    assert text.startswith(expected), text
    assert "max_duty = 0.3 over duty_window_s = 60 s" in text, text
    second.all_off()
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # said once: LED 7 again, or another LED, says nothing
        second.light(3, 1.0)
        second.all_off()
    second.close()


def test_another_led_and_another_dome_do_not_wait(tmp_path: Path) -> None:
    wall = Wall()
    first, clock = command(DutyLedger("port:/dev/ttyACM0", wall=wall))
    first.connect()
    lit_for(first, clock, 7, 9.8)
    first.close()
    wall.t += clock.now() + 1.0
    other, _ = command(DutyLedger("port:/dev/ttyACM1", wall=wall))
    other.connect()
    other.light(7, 1.0)  # another dome's LED 7: cold
    assert other.stats.thermal_wait_s == 0.0
    other.close()
    same, _ = command(DutyLedger("port:/dev/ttyACM0", wall=wall))
    same.connect()
    same.light(6, 1.0)  # the same dome's LED 6: cold
    assert same.stats.thermal_wait_s == 0.0
    with pytest.warns(RuntimeWarning, match="LED 7 was lit 9.8 s"):
        same.light(7, 1.0)
    assert same.stats.thermal_wait_s > 0
    same.close()


def test_lightings_older_than_the_window_are_dropped(tmp_path: Path) -> None:
    wall = Wall()
    ledger = DutyLedger("port:/dev/ttyACM0", wall=wall)
    first, clock = command(ledger)
    first.connect()
    lit_for(first, clock, 2, 9.0)
    clock.sleep(70.0)  # LED 2 long cold, then LED 5 lit last
    lit_for(first, clock, 5, 9.0)
    first.close()
    kept = json.loads(ledger.path.read_text())["lit"]
    assert set(kept) == {"5"}, kept  # LED 2's lighting ended over a window before the save
    wall.t += clock.now() + 61.0
    assert ledger.load(60.0).spans == {}


def test_a_ledger_from_the_future_counts_as_just_ended(tmp_path: Path) -> None:
    """A clock set back a day (or an emulated run's rig time, which outruns the wall clock):
    the LEDs are taken as just switched off, never as cold for a day."""
    wall = Wall()
    ledger = DutyLedger("port:/dev/ttyACM0", wall=wall)
    future = wall.t + 86_400
    ledger.path.parent.mkdir(parents=True, exist_ok=True)
    ledger.path.write_text(
        json.dumps(
            {"format": 1, "lit": {"4": [[future - 30.0, future - 20.2], [future - 1, future]]}}
        )
    )
    read = ledger.load(60.0)
    assert read.shifted_s == pytest.approx(86_400)
    assert read.spans == {4: [(wall.t - 30.0, wall.t - 20.2), (wall.t - 1, wall.t)]}
    dome, _ = command(ledger)
    dome.connect()
    with pytest.warns(RuntimeWarning, match=r"LED 4 was lit 10\.8 s by an earlier command 0 s ago"):
        dome.light(4, 1.0)
    assert 0 < dome.stats.thermal_wait_s <= 60.0  # waited, at most a window
    dome.close()


@pytest.mark.parametrize(
    "body",
    [
        b"{broken",
        b"\xff\xfe",
        b'{"format": 1, "lit": {"3": [[5, 1]]}}',
        b'{"format": 99}',
        b"[]",
        b"[" * 100_000 + b"]" * 100_000,  # nested past the parser's recursion limit
    ],
)
def test_a_damaged_ledger_is_a_note_and_is_written_afresh(tmp_path: Path, body: bytes) -> None:
    wall = Wall()
    ledger = DutyLedger("port:/dev/ttyACM0", wall=wall)
    ledger.path.parent.mkdir(parents=True, exist_ok=True)
    ledger.path.write_bytes(body)
    dome, clock = command(ledger)
    with pytest.warns(RuntimeWarning, match="is damaged .*which LEDs an earlier command lit"):
        dome.connect()
    lit_for(dome, clock, 1, 2.0)
    dome.close()
    assert set(json.loads(ledger.path.read_text())["lit"]) == {"1"}


def test_a_ledger_that_cannot_be_written_is_a_note_not_a_failure(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    blocker = tmp_path / "not-a-folder"
    blocker.write_text("")
    monkeypatch.setenv(LEDGER_DIR_ENV, str(blocker / "ledgers"))
    dome, clock = command(DutyLedger("port:/dev/ttyACM0", wall=Wall()))
    dome.connect()
    lit_for(dome, clock, 1, 2.0)
    with pytest.warns(RuntimeWarning, match="could not be written .*will not know"):
        dome.close()
    assert dome.off_report is not None and dome.link.port_open is False


def test_a_write_cut_short_keeps_the_previous_ledger(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    wall = Wall()
    ledger = DutyLedger("port:/dev/ttyACM0", wall=wall)
    ledger.save({3: [(wall.t - 5, wall.t - 1)]}, wall.t, 60.0)
    before = ledger.path.read_bytes()

    def crash(*_args: object) -> None:
        raise KeyboardInterrupt  # Ctrl-C (or a crash) between writing and renaming

    monkeypatch.setattr(duty_ledger.os, "replace", crash)
    with pytest.raises(KeyboardInterrupt):
        ledger.save({3: [(wall.t - 5, wall.t)]}, wall.t, 60.0)
    assert ledger.path.read_bytes() == before
    assert [p.name for p in ledger.path.parent.iterdir()] == [ledger.path.name]  # no temp left


def test_a_port_is_the_same_dome_by_any_path_to_it(tmp_path: Path) -> None:
    """A ``/dev/serial/by-id`` link and the device it names are one dome: a key that told
    them apart would let a config naming the other path overdrive the LEDs."""
    device = tmp_path / "ttyACM0"
    device.write_text("")
    by_id = tmp_path / "usb-Arduino_Mega_2560-if00"
    os.symlink(device, by_id)
    assert DutyLedger.for_port(str(by_id)).path == DutyLedger.for_port(str(device)).path
    assert DutyLedger.for_port("COM3").path != DutyLedger.for_port("COM4").path
    assert DutyLedger.for_port(str(device)).path.parent == Path(os.environ[LEDGER_DIR_ENV])


def test_the_guard_tells_an_earlier_commands_lighting_from_its_own() -> None:
    guard = ThermalGuard(LIMITS)
    guard.remember(0, -20.0, -10.0)
    assert guard.earliest_start(0, 0.0, earlier=False) == 0.0
    assert guard.earliest_start(0, 0.0) == pytest.approx(
        -20 + 2 + 60, abs=1e-6
    )  # 2 s of it may stay
    guard.record(0, 50.0, 55.0)
    assert guard.spans() == {0: [(-20.0, -10.0), (50.0, 55.0)]}


def test_a_dome_back_on_usb_under_another_number_keeps_its_ledger(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A dome that drops off USB while a command holds its ``ttyACM0`` comes back as
    ``ttyACM1``: its by-id name is the same dome, and keeps the LEDs the last command lit."""
    dev = tmp_path / "dev"
    by_id = dev / "serial" / "by-id"
    by_id.mkdir(parents=True)
    (dev / "ttyACM0").write_text("")
    (dev / "ttyACM1").write_text("")
    name = by_id / "usb-Arduino_Dome_7543-if00"
    name.symlink_to(dev / "ttyACM0")
    monkeypatch.setattr(duty_ledger, "BY_ID_DIR", by_id)
    first = DutyLedger.for_port(str(dev / "ttyACM0")).path  # a config naming the node
    assert DutyLedger.for_port(str(name)).path == first  # one naming the by-id link
    name.unlink()  # unplugged: the link is gone, a config naming it is still that dome
    assert DutyLedger.for_port(str(name)).path == first
    name.symlink_to(dev / "ttyACM1")  # back, under the next number
    assert DutyLedger.for_port(str(name)).path == first  # had been ttyACM1's: no ledger
    assert DutyLedger.for_port(str(dev / "ttyACM1")).path == first
    assert DutyLedger.for_port(str(dev / "ttyACM0")).path != first  # now another device's


def test_ledgers_no_window_can_reach_are_removed_as_another_is_written(tmp_path: Path) -> None:
    """A temporary config's or a retired dome's ledger (and a write's stray temporary file)
    older than any duty window is removed; a recent one, and anything not a ledger, is kept."""
    wall = Wall()
    ledger = DutyLedger("port:/dev/ttyACM0", wall=wall)
    folder = ledger.path.parent
    folder.mkdir(parents=True, exist_ok=True)
    old_json, old_tmp = folder / "old-0123.json", folder / ".x.tmp"
    recent, other = folder / "recent-4567.json", folder / "notes.txt"
    for f in (old_json, old_tmp, recent, other):
        f.write_text("{}")
    now = time.time()  # files are dated by the file system's clock, not the ledger's
    long_ago = now - duty_ledger.STALE_AFTER_S - 60
    for f in (old_json, old_tmp, other):
        os.utime(f, (long_ago, long_ago))
    os.utime(recent, (now - 3600, now - 3600))
    ledger.save({2: [(wall.t - 5, wall.t - 1)]}, wall.t, 60.0)
    assert ledger.path.exists() and recent.exists() and other.exists()
    assert not old_json.exists() and not old_tmp.exists()


def test_the_stale_sweep_is_made_once_per_command_not_at_every_write(tmp_path: Path) -> None:
    """A session writes its ledger every SAVE_EVERY_S at an all-off: only the first write of a
    command lists the folder for stale ledgers (the next command sweeps what is left)."""
    wall = Wall()
    ledger = DutyLedger("port:/dev/ttyACM0", wall=wall)
    ledger.save({2: [(wall.t - 5, wall.t - 1)]}, wall.t, 60.0)
    stale = ledger.path.parent / "old-0123.json"
    stale.write_text("{}")
    long_ago = time.time() - duty_ledger.STALE_AFTER_S - 60
    os.utime(stale, (long_ago, long_ago))
    ledger.save({2: [(wall.t - 5, wall.t - 1)]}, wall.t, 60.0)
    assert stale.exists()
    DutyLedger("port:/dev/ttyACM0", wall=wall).save({2: [(wall.t - 5, wall.t - 1)]}, wall.t, 60.0)
    assert not stale.exists()


class CountingLedger(DutyLedger):
    """A ledger that counts its writes."""

    def __init__(self, key: str, *, wall: Wall) -> None:
        super().__init__(key, wall=wall)
        self.saves = 0

    def save(self, spans, now, window_s):  # type: ignore[no-untyped-def]
        self.saves += 1
        super().save(spans, now, window_s)


def test_a_close_writes_the_ledger_once(tmp_path: Path) -> None:
    """The closing all-off's throttled write and the close's own were both made (a close
    SAVE_EVERY_S after the last write had the ledger written twice over)."""
    ledger = CountingLedger("port:/dev/ttyACM0", wall=Wall())
    dome, clock = command(ledger)
    dome.connect()
    clock.sleep(duty_ledger.SAVE_EVERY_S)
    dome.light(7, 1.0)
    clock.sleep(THERMAL["max_on_s"] - 1.0)
    dome.close()
    assert ledger.saves == 1
    assert json.loads(ledger.path.read_text())["lit"]["7"]
