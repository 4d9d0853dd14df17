"""A command right after another on the same dome respects the LEDs the first one left hot.

The thermal guard's duty limit (``[dome.serial.thermal] max_duty`` over ``duty_window_s``) had
lived in one process: ``rti-rig check`` right after a ``run`` could light the run's LEDs again
at once. Its lightings are now kept in a duty ledger per dome (``rti_rig.runtime.duty_ledger``),
here the emulated dome with its real driver, on the rig's simulated clock: an LED's wait is
simulated time, so nothing here depends on how fast the machine is. The window is 10 minutes,
so that the second command finds the first one's lightings whatever the load between them.
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import CONFIGS, said
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.runtime.duty_ledger import LEDGER_DIR_ENV, DutyLedger

# an LED shot once (about 1.7 s lit at a 0.6 s exposure) must cool before it lights again
# within the 10 minutes: 0.006 × 600 s = 3.6 s, less max_on_s 3 s, leaves 0.6 s
THERMAL = """
[dome.serial.thermal]
max_on_s = 3.0
max_duty = 0.006
duty_window_s = 600.0
"""

EARLIER = re.compile(
    r"LED 0 \(az [-\d.]+°, el [-\d.]+°\) was lit (\d+\.\d) s by an earlier command (\d+) s ago: "
    r"waiting (\d+\.\d) s for its "
    r"duty limit \(\[dome\.serial\.thermal\] max_duty = 0\.006 over duty_window_s = 600 s\)"
)


def _duty_limited_dome(folder: Path) -> Path:
    """emulated_dome.toml with a 0.6 s exposure and a tight duty limit."""
    text = (CONFIGS / "emulated_dome.toml").read_text(encoding="utf-8")
    lp = 'lp_file = "example_dome_48.lp"'
    assert lp in text and "exposure_s = 0.05" in text
    text = text.replace(lp, f'lp_file = "{(CONFIGS / "example_dome_48.lp").as_posix()}"')
    config = folder / "rig.toml"
    config.write_text(text.replace("exposure_s = 0.05", "exposure_s = 0.6") + THERMAL)
    return config


def _run(config: Path, out: Path) -> tuple[int, str]:
    argv = ["run", str(config), "--lights", "6", "--out", str(out), "--no-verdict"]
    r = CliRunner().invoke(app, argv, terminal_width=400)
    return r.exit_code, said(r)


def _waited(text: str) -> tuple[float, float]:
    """The time line's cooling wait, and the part of it for an earlier command's LEDs."""
    m = re.search(
        r"LEDs waited dark (\d+\.\d) s to cool, (\d+\.\d) s of it for LEDs an earlier command "
        r"left hot",
        text,
    )
    assert m, text
    return float(m.group(1)), float(m.group(2))


def test_a_check_right_after_a_run_waits_for_the_runs_leds_and_says_so(tmp_path: Path) -> None:
    """Through ``python -m rti_rig`` itself: the note is what a user reads on the console."""
    config = _duty_limited_dome(tmp_path)
    env = {**os.environ, LEDGER_DIR_ENV: str(tmp_path / "ledgers")}
    cmd = [sys.executable, "-m", "rti_rig"]
    run = subprocess.run(
        [*cmd, "run", str(config), "--lights", "6", "--out", str(tmp_path / "s"), "--no-verdict"],
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert run.returncode == 0, run.stdout + run.stderr
    assert "earlier command" not in run.stdout + run.stderr  # the first one finds LEDs cold
    check = subprocess.run(
        [*cmd, "check", str(config)], env=env, capture_output=True, text=True, timeout=600
    )
    text = " ".join((check.stdout + check.stderr).split())
    assert check.returncode == 0, text
    m = EARLIER.search(text)
    assert m, text
    assert text.count("earlier command") == 1, text  # said once, not for each LED
    # the run lit LED 0 first, one shot's time (over a second, under max_on_s), and waited for
    # nothing: LED 0 waits for most of the window before it lights again
    assert 1.0 < float(m.group(1)) < 3.0, text
    assert 300.0 < float(m.group(3)) <= 600.0, text
    assert "note: LED 0 (az " in text, text  # the note names the LED by its direction
    assert "RESULT: PASS" in text, text
    assert "lights: all-off sent and acknowledged by the dome: lights are off" in text, text
    assert "Traceback" not in text, text


def test_a_second_run_says_how_long_it_waited_for_the_first_runs_leds(tmp_path: Path) -> None:
    config = _duty_limited_dome(tmp_path)
    code, first = _run(config, tmp_path / "s1")
    assert code == 0, first
    assert "to cool" not in first, first
    with pytest.warns(RuntimeWarning, match=EARLIER.pattern):
        code, second = _run(config, tmp_path / "s2")
    assert code == 0, second
    waited, earlier = _waited(second)
    assert 300.0 < earlier <= waited, second
    assert "All-off sent and acknowledged by the dome: lights are off." in second, second


def test_a_run_on_another_copy_of_the_config_is_another_emulated_dome(tmp_path: Path) -> None:
    """An emulated dome is keyed by its config's path: another config's LEDs are cold."""
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    code, first = _run(_duty_limited_dome(tmp_path / "a"), tmp_path / "s1")
    assert code == 0, first
    code, other = _run(_duty_limited_dome(tmp_path / "b"), tmp_path / "s2")
    assert code == 0, other
    assert "to cool" not in other, other


@pytest.mark.parametrize("body", ["{broken", '{"format": 1, "lit": {"0": [[9, 1]]}}'])
def test_a_damaged_ledger_is_a_note_and_the_run_goes_on(tmp_path: Path, body: str) -> None:
    config = _duty_limited_dome(tmp_path)
    ledger = DutyLedger.for_emulated(config)
    ledger.path.parent.mkdir(parents=True, exist_ok=True)
    ledger.path.write_text(body)
    with pytest.warns(RuntimeWarning, match="duty ledger .* is damaged"):
        code, text = _run(config, tmp_path / "s")
    assert code == 0, text
    assert "Traceback" not in text, text
    assert "to cool" not in text, text
    assert "0" in json.loads(ledger.path.read_text())["lit"]  # written afresh: LED 0 is hot


def test_a_ledger_folder_that_cannot_be_written_is_a_note_not_a_refusal(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    blocker = tmp_path / "a-file"
    blocker.write_text("")
    monkeypatch.setenv(LEDGER_DIR_ENV, str(blocker / "ledgers"))
    config = _duty_limited_dome(tmp_path)
    with pytest.warns(RuntimeWarning, match="duty ledger .* could not be written"):
        code, text = _run(config, tmp_path / "s")
    assert code == 0, text
    assert "6 image(s) in the session" in text, text
    assert "All-off sent and acknowledged by the dome: lights are off." in text, text
    assert "Traceback" not in text, text


def test_a_ledger_from_the_future_is_taken_as_just_ended(tmp_path: Path) -> None:
    """A clock set back a day: LED 0, lit 1.5 s "tomorrow", is taken as lit just now."""
    import time

    config = _duty_limited_dome(tmp_path)
    ledger = DutyLedger.for_emulated(config)
    ledger.path.parent.mkdir(parents=True, exist_ok=True)
    tomorrow = time.time() + 86_400
    ledger.path.write_text(json.dumps({"format": 1, "lit": {"0": [[tomorrow, tomorrow + 1.5]]}}))
    with pytest.warns(
        RuntimeWarning,
        match=r"LED 0 \(az [-\d.]+°, el [-\d.]+°\) was lit 1\.5 s by an earlier command 0 s ago",
    ):
        code, text = _run(config, tmp_path / "s")
    assert code == 0, text
    waited, earlier = _waited(text)
    assert 500.0 < earlier <= waited <= 600.0 + 60.0, text


@pytest.mark.pty
def test_a_hardware_dome_keeps_its_ledger_under_its_port(tmp_path: Path) -> None:
    """A hardware config's dome is keyed by its port, not its config file: the check's LEDs
    are in the port's ledger, where another config naming the same port will find them."""
    from conftest import emulated_dome_as_hardware

    from rti_rig.simulator.domes import board_for
    from rti_rig.simulator.pty_link import serve_on_pty

    board = board_for("elexol-24r1")
    with serve_on_pty(board, "elexol-24r1") as link:
        cfg = emulated_dome_as_hardware(tmp_path, "emulated_elexol.toml", link.port)
        r = CliRunner().invoke(app, ["check", str(cfg)], terminal_width=400)
        # the port is a link to the pty: keyed by what it points to (no by-id name does)
        ledger = DutyLedger.for_port(link.port).path
        assert ledger == DutyLedger.for_port(os.path.realpath(link.port)).path
    text = said(r)
    assert r.exit_code == 0, text
    assert not DutyLedger.for_emulated(cfg).path.exists()
    lit = json.loads(ledger.read_text())["lit"]
    assert sorted(map(int, lit)) == list(range(12)), lit  # the check lit each LED once
