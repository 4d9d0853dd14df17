"""`calibrate-lights` on a card shot with a dead LED names that LED and its session image, and
the way out it gives works through the CLI.

Why: it refused with "light 20 gives 0.000 of the median light's signal: ...; check that light
and drop its image". "light 20" was the 21st image of the session (image_021, the one the QA
verdict calls misfired), not LED 20's .lp name, and a card session with an image removed is
refused as "not as captured": the advice led nowhere. A card shot under every other LED (a
--plan of the session's lights.lp without that line) calibrates the rest.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

from card_support import card_rig
from conftest import CONFIGS, said
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.drivers.led_dome.messages import ERR_LED_FAULT, ERR_THERMAL

runner = CliRunner()

DEAD = 20  # LED index: led_20.jpg in example_dome_48.lp, the session's image_021


def test_a_dead_led_is_named_and_the_advice_calibrates_the_others(tmp_path: Path) -> None:
    # a board that does not sense LED current: the dead LED "fires" and leaves a black frame
    cfg = card_rig(tmp_path, serial_extra="senses_led_current = false\n")
    with cfg.open("a", encoding="utf-8") as f:
        f.write(f"dead_leds = [{DEAD}]\nreports_dead_leds = false\n")
    card = tmp_path / "card"
    r = runner.invoke(app, ["run", str(cfg), "--out", str(card)])
    assert (card / "image_048.jpg").exists(), r.output

    r = runner.invoke(app, ["calibrate-lights", str(card), "--rig", str(cfg)])

    assert r.exit_code == 2, r.output
    text = said(r)
    image = f"image_{DEAD + 1:03d}.jpg"
    said_as = f"LED {DEAD} (led_{DEAD}.jpg, az 254.4°, el 25.2°, session image {image})"
    assert said_as in text, text
    assert "drop its image" not in text and "Traceback" not in r.output
    # real names beside the card, not there yet (PLAN.lp and NEW_CARD had been said, and no
    # calibrate command): the plan written as said, the two commands then run as printed
    plan, again = tmp_path / f"card-without-led-{DEAD}.lp", tmp_path / f"card-without-led-{DEAD}"
    shoot = f"rti-rig run {cfg} --plan {plan} --out {again}"
    calibrate = f"rti-rig calibrate-lights {again} --rig {cfg}"
    assert f"as {plan}, run {shoot} and calibrate that with {calibrate}" in text, text
    assert not (card / "light_calibration.toml").exists()

    # the advice, followed as written: the session's lights.lp without that image's line
    lines = (card / "lights.lp").read_text().splitlines()
    kept = [ln for ln in lines[1:] if not ln.startswith(f"image_{DEAD + 1:03d}.jpg ")]
    assert len(kept) == len(lines) - 2
    plan.write_text("\n".join([str(len(kept)), *kept]) + "\n")
    r = runner.invoke(app, shoot.split()[1:])
    assert r.exit_code == 0, r.output
    r = runner.invoke(app, calibrate.split()[1:])
    assert r.exit_code == 0, r.output
    text = said(r)
    assert "47 of 48 LEDs measured" in text, text
    assert f"led_{DEAD}.jpg" in text  # named as not measured
    assert (again / "light_calibration.toml").exists()


def test_a_card_session_stopped_at_a_dead_led_says_how_to_shoot_the_others(
    tmp_path: Path,
) -> None:
    """A board that senses LED current refuses the dead LED and the card session stops there.
    calibrate-lights had said "continue it with rti-rig run --resume CARD, or shoot the card
    again": both light that LED again and stop on it again."""
    cfg = card_rig(tmp_path)
    with cfg.open("a", encoding="utf-8") as f:
        f.write(f"dead_leds = [{DEAD}]\n")
    card = tmp_path / "card"
    r = runner.invoke(app, ["run", str(cfg), "--out", str(card)])
    assert r.exit_code != 0 and (card / f"image_{DEAD:03d}.jpg").exists(), r.output
    manifest = json.loads((card / "manifest.json").read_text(encoding="utf-8"))
    assert manifest["runner"]["led_error"] == {
        "led": DEAD,
        "fault": "rejected",
        "code": ERR_LED_FAULT,
    }

    r = runner.invoke(app, ["calibrate-lights", str(card), "--rig", str(cfg)])

    assert r.exit_code == 2, r.output
    text = said(r)
    assert "continue it with rti-rig run --resume" not in text, text
    assert f"stopped at an LED after {DEAD} of 48 images" in text, text
    assert f"without the line of LED {DEAD} (led_{DEAD}.jpg, az 254.4°, el 25.2°)" in text, text
    plan, again = tmp_path / f"card-without-led-{DEAD}.lp", tmp_path / f"card-without-led-{DEAD}"
    shoot = f"rti-rig run {cfg} --plan {plan} --out {again}"
    calibrate = f"rti-rig calibrate-lights {again} --rig {cfg}"
    assert f"as {plan}, run {shoot} and calibrate that with {calibrate}" in text, text
    assert "Traceback" not in r.output

    # the advice, followed as written: the rig's LED .lp without that LED's line
    lines = (CONFIGS / "example_dome_48.lp").read_text().splitlines()
    kept = [ln for ln in lines[1:] if not ln.startswith(f"led_{DEAD}.jpg ")]
    assert "the rig's LED .lp" in text and len(kept) == 47
    plan.write_text("\n".join([str(len(kept)), *kept]) + "\n")
    r = runner.invoke(app, shoot.split()[1:])
    assert r.exit_code == 0, r.output
    r = runner.invoke(app, calibrate.split()[1:])
    assert r.exit_code == 0, r.output
    assert "47 of 48 LEDs measured" in said(r)


def test_a_card_session_stopped_by_a_board_reboot_under_an_led_is_resumed(
    tmp_path: Path,
) -> None:
    """A board that rebooted while an LED was lit (its power supply, its USB cable) stops the
    run with an error about that LED too, and the run says to resume. calibrate-lights had
    told the user to repair that LED and shoot the card without it: only a refused LED (one the
    board senses dead) stops a resume again."""
    cfg = card_rig(tmp_path)
    with cfg.open("a", encoding="utf-8") as f:  # the board reboots after acknowledging a light
        f.write('\n[[emulator.faults]]\nat_command = 40\nkind = "reset_after_reply"\n')
    card = tmp_path / "card"
    r = runner.invoke(app, ["run", str(cfg), "--out", str(card)])
    assert r.exit_code != 0 and "rebooted while LED" in said(r), r.output

    r = runner.invoke(app, ["calibrate-lights", str(card), "--rig", str(cfg)])

    assert r.exit_code == 2, r.output
    text = said(r)
    assert f"continue it with rti-rig run --resume {card}" in text, text
    assert "Repair LED" not in text and "without-led" not in text, text
    assert "Traceback" not in r.output

    # the advice, followed: each resume's emulator reboots at its 40th command again, and
    # each gets further (18 more images) until the card session is whole
    for _ in range(3):
        r = runner.invoke(app, ["run", "--resume", str(card)])
        if r.exit_code == 0:
            break
    assert r.exit_code == 0, r.output
    r = runner.invoke(app, ["calibrate-lights", str(card), "--rig", str(cfg)])
    assert r.exit_code == 0, r.output
    assert "48 of 48 LEDs measured" in said(r)


def test_a_card_session_an_led_s_thermal_refusal_stopped_is_resumed(tmp_path: Path) -> None:
    """A board refusing an LED for its temperature (firmware code ERR_THERMAL) stops the run
    with "LED <n> refused: …" too, and the run says to resume once it cooled (``dead_led_of``
    decides by the code). calibrate-lights decided by the words "LED <n> refused" and told
    the user to repair the LED: it now reads the run's typed ``runner.led_error``, the fact
    the run advised from. The emulated boards have no thermal sensor, so the dead-LED stop's
    record is given the thermal code the firmware would have sent."""
    cfg = card_rig(tmp_path)
    with cfg.open("a", encoding="utf-8") as f:
        f.write(f"dead_leds = [{DEAD}]\n")
    card = tmp_path / "card"
    r = runner.invoke(app, ["run", str(cfg), "--out", str(card)])
    assert r.exit_code != 0, r.output
    path = card / "manifest.json"
    manifest = json.loads(path.read_text(encoding="utf-8"))
    assert re.search(
        rf"LED {DEAD} \(az [-\d.]+°, el [-\d.]+°\) refused: ", manifest["runner"]["error"]
    )
    manifest["runner"]["led_error"]["code"] = ERR_THERMAL
    path.write_text(json.dumps(manifest), encoding="utf-8")

    r = runner.invoke(app, ["calibrate-lights", str(card), "--rig", str(cfg)])

    assert r.exit_code == 2, r.output
    text = said(r)
    assert f"continue it with rti-rig run --resume {card}" in text, text
    assert "without-led" not in text and "Traceback" not in r.output, text
