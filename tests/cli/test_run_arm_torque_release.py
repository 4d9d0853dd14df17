"""``rti-rig run`` on an arm whose ``torque_policy = "release_on_close"`` says what the close did
to its torque.

The close comes after the teardown's read-back: it releases the torque when it finds the arm
at its park pose (within a few ticks). ``run`` said "the arm parked" with no word of the
release (``check`` said it), and of a final park a Ctrl-C stopped with the arm already at the
park pose, "held where it stopped, torque on", of an arm the close then let go limp. Run
in-process on the shipped emulated arm (its servos emulated in-process: real Protocol 2.0
packets); the servos' Torque Enable is read from the emulator afterwards, the truth."""

from __future__ import annotations

import json
import signal
import sys
from pathlib import Path

import pytest
from conftest import emulators_built_by_check, inprocess_arm_config
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.geometry import direction_from_az_el
from rti_rig.core.shell_words import shell_word
from rti_rig.drivers.dynamixel import control_table as ct
from rti_rig.drivers.dynamixel.arm import DynamixelArm
from rti_rig.runtime.lighting import ArmLighting

RELEASE = ('torque_policy = "hold"', 'torque_policy = "release_on_close"')
RELEASED = 'torque then released (torque_policy = "release_on_close", read back off on each servo)'


def _config(tmp_path: Path) -> Path:
    cfg = inprocess_arm_config(tmp_path)
    text = cfg.read_text()
    assert RELEASE[0] in text and "park_azimuth_deg = 0.0" in text
    assert "park_elevation_deg = 10.0" in text
    cfg.write_text(text.replace(*RELEASE))
    return cfg


def _run(tmp_path: Path, *argv: str) -> tuple[int, str, dict]:  # type: ignore[type-arg]
    out = tmp_path / "s"
    r = CliRunner().invoke(
        app,
        ["run", str(_config(tmp_path)), *argv, "--out", str(out), "--no-verdict"],
        terminal_width=400,
    )
    said = " ".join(r.output.split())
    assert "Traceback" not in said, said
    end = json.loads((out / "manifest.json").read_text())["runner"]["arm_end"]
    return r.exit_code, said, end


def test_a_park_released_at_the_close_is_said_by_run(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    emulators = emulators_built_by_check(monkeypatch)
    code, said, end = _run(tmp_path, "--lights", "2")
    assert code == 0, said
    assert (
        f"the arm parked (read back at az 0.0°, el 10.0°, within 1° of its park pose); {RELEASED}"
        in said
    ), said
    assert "hold no pose" in said and 'set torque_policy = "hold"' in said, said
    assert end["outcome"] == "parked" and end["torque"].startswith(RELEASED[:22]), end
    (emu,) = emulators  # the truth: released
    assert all(s.get(ct.TORQUE_ENABLE) == 0 for s in emu.servos.values())


@pytest.mark.skipif(sys.platform != "linux", reason="signals tested on Linux")
def test_a_stopped_park_released_at_the_close_is_not_said_to_hold(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The one light is at the park pose (az 0°, el 10°): a Ctrl-C as the teardown stops the
    arm stops its park before it starts, with the arm already parked, and the close releases
    it. The run had said "held where it stopped, torque on"."""
    emulators = emulators_built_by_check(monkeypatch)
    plan = tmp_path / "park.lp"
    x, y, z = (float(v) for v in direction_from_az_el(0.0, 10.0))
    plan.write_text(f"1\nimage_001.jpg {x:.8f} {y:.8f} {z:.8f}\n")
    tearing: list[str] = []
    real_safe, real_stop = ArmLighting.safe, DynamixelArm.stop

    def safe(self, *args, **kwargs):  # type: ignore[no-untyped-def]
        tearing.append("safe")
        return real_safe(self, *args, **kwargs)

    def stop(self):  # type: ignore[no-untyped-def]
        real_stop(self)
        if tearing == ["safe"]:  # the teardown's stop, once (the close stops again)
            tearing.append("ctrl-c")
            signal.raise_signal(signal.SIGINT)

    monkeypatch.setattr(ArmLighting, "safe", safe)
    monkeypatch.setattr(DynamixelArm, "stop", stop)
    code, said, end = _run(tmp_path, "--plan", str(plan))
    assert tearing == ["safe", "ctrl-c"], said
    assert code == 130, said
    assert "torque on" not in said, said
    assert (
        "the park was stopped by Ctrl-C: held where it stopped, close enough to the park pose "
        f"for the close to release it); {RELEASED}" in said
    ), said
    assert end["outcome"] == "left" and "torque on" not in end["why"], end
    assert end["torque"].startswith(RELEASED[:22]), end
    (emu,) = emulators  # the truth: released
    assert all(s.get(ct.TORQUE_ENABLE) == 0 for s in emu.servos.values())


def test_a_preview_s_released_park_is_said(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """``preview`` closes the arm as ``run`` does: its release is said the same way."""
    emulators = emulators_built_by_check(monkeypatch)
    out = tmp_path / "p"
    r = CliRunner().invoke(
        app, ["preview", str(_config(tmp_path)), "--out", str(out)], terminal_width=400
    )
    said = " ".join(r.output.split())
    assert r.exit_code == 0, said
    assert f"within 1° of its park pose); {RELEASED}" in said, said
    (emu,) = emulators
    assert all(s.get(ct.TORQUE_ENABLE) == 0 for s in emu.servos.values())


KEPT = (
    "arm: torque stays on: the arm is not at its park pose, and torque_policy = "
    '"release_on_close" releases it only there'
)


def _run_unparked(tmp_path: Path) -> tuple[int, str, dict, Path]:  # type: ignore[type-arg]
    """Run 2 lights, no park (``park_after_session = false``): the close keeps the torque on.
    Returns the exit code, the words, the manifest's arm end and the rig config run."""
    cfg = _config(tmp_path)
    text = cfg.read_text()
    assert "\n[arm]\n" in text
    cfg.write_text(text.replace("\n[arm]\n", "\n[arm]\npark_after_session = false\n", 1))
    out = tmp_path / "s"
    r = CliRunner().invoke(
        app,
        ["run", str(cfg), "--lights", "2", "--out", str(out), "--no-verdict"],
        terminal_width=400,
    )
    said = " ".join(r.output.split())
    assert "Traceback" not in said, said
    end = json.loads((out / "manifest.json").read_text())["runner"]["arm_end"]
    return r.exit_code, said, end, cfg


def test_a_torque_kept_on_at_the_close_is_in_the_manifest(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Away from the park pose the close keeps the torque on and says so; the manifest had
    recorded no torque at all, as of an arm whose close released nothing. It now records what
    the close established: no torque-off sent, Torque Enable read back on from each servo,
    with the pose read back."""
    emulators = emulators_built_by_check(monkeypatch)
    code, said, end, cfg = _run_unparked(tmp_path)
    assert code == 0, said
    assert said.count(KEPT) == 1, said
    # the check that parks it names the rig config, ready to paste (a bare 'rti-rig check'
    # is refused for its missing config)
    assert (
        f"Park it with rti-rig check {shell_word(cfg)} --park-only before switching off" in said
    ), said
    assert end["outcome"] == "left" and end["azimuth_deg"] is not None, end
    assert end["torque"] is None, end  # nothing released: no release note
    assert end["torque_at_close"] == {
        "policy": "release_on_close",
        "off_sent": False,
        "read_back": {"1": "on", "2": "on"},
    }, end
    (emu,) = emulators  # the truth: both still hold
    assert all(s.get(ct.TORQUE_ENABLE) == 1 for s in emu.servos.values())


def test_a_kept_torque_read_back_off_is_not_said_to_hold(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A servo whose torque went off before the close (switched off on the bus, as a servo's
    shutdown does) is recorded and said limp, never "torque stays on"."""
    emulators = emulators_built_by_check(monkeypatch)
    real_safe = ArmLighting.safe

    def safe(self, *args, **kwargs):  # type: ignore[no-untyped-def]
        failures = real_safe(self, *args, **kwargs)
        emulators[0].servos[2].write(ct.TORQUE_ENABLE.address, b"\x00")
        return failures

    monkeypatch.setattr(ArmLighting, "safe", safe)
    code, said, end, cfg = _run_unparked(tmp_path)
    assert code == 0, said
    assert "torque stays on" not in said, said
    assert f"and park it with rti-rig check {shell_word(cfg)} --park-only." in said, said
    assert (
        "Torque Enable reads back ON from servo 1 (azimuth); reads back OFF (limp) from servo 2 "
        "(elevation)" in said
    ), said
    assert end["torque_at_close"] == {
        "policy": "release_on_close",
        "off_sent": False,
        "read_back": {"1": "on", "2": "off"},
    }, end


def test_a_released_torque_is_in_the_manifest_as_read_back(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    emulators_built_by_check(monkeypatch)
    code, said, end = _run(tmp_path, "--lights", "2")
    assert code == 0, said
    assert end["torque_at_close"] == {
        "policy": "release_on_close",
        "off_sent": True,
        "read_back": {"1": "off", "2": "off"},
    }, end


def test_a_held_torque_is_recorded_as_the_policy_left_it(tmp_path: Path) -> None:
    """``torque_policy = "hold"`` (the shipped arm): the close sends no torque-off and reads
    nothing back, and the record says just that."""
    out = tmp_path / "s"
    r = CliRunner().invoke(
        app,
        [
            "run",
            str(inprocess_arm_config(tmp_path)),
            "--lights",
            "2",
            "--out",
            str(out),
            "--no-verdict",
        ],
        terminal_width=400,
    )
    assert r.exit_code == 0, r.output
    end = json.loads((out / "manifest.json").read_text())["runner"]["arm_end"]
    assert end["torque_at_close"] == {"policy": "hold", "off_sent": False, "read_back": None}
