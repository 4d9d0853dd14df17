"""A session stopped at a dead LED (the board senses LED current and refuses it) is told what
works: a plan without that LED, or a resume once it is repaired.

Why: ``run`` ended "Continue with: rti-rig run --resume S" right after the driver said that a
resume stops there again (it lights that LED first); following it stopped at the same LED.
The advice is followed here as written, through the CLI.
"""

from __future__ import annotations

import json
import re
import shutil
from pathlib import Path

import pytest
from conftest import CONFIGS, said
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner(env={"COLUMNS": "400"})  # rich folds a long path mid-word at 80

DEAD = 2


def test_a_stop_at_a_dead_led_advises_a_plan_without_it_that_works(tmp_path: Path) -> None:
    shutil.copy(CONFIGS / "example_dome_48.lp", tmp_path)
    cfg = tmp_path / "dome.toml"
    cfg.write_text(
        (CONFIGS / "emulated_dome.toml").read_text() + f"\n[emulator]\ndead_leds = [{DEAD}]\n"
    )
    s = tmp_path / "s"
    r = runner.invoke(app, ["run", str(cfg), "--out", str(s), "--no-verdict"])
    text = said(r)
    assert r.exit_code == 2, text
    assert (
        re.search(rf"LED {DEAD} \(az [-\d.]+°, el [-\d.]+°\) refused", text) and "LED fault" in text
    ), text
    assert "Continue with: rti-rig run --resume" not in text, text
    assert f"A resume lights LED {DEAD} (led_0{DEAD}.jpg, az " in text, text
    assert "°) first and stops there again" in text, text
    assert f"continue with: rti-rig run --resume {s}" in text, text  # once repaired

    # the advice, followed as written: the rig's LED .lp it names, without that LED's line
    named = re.search(r"copy (\S+) \(the rig's LED \.lp\) without the line of LED", text)
    assert named is not None, text
    lines = Path(named.group(1)).read_text().splitlines()
    kept = [ln for ln in lines[1:] if not ln.startswith(f"led_0{DEAD}.jpg ")]
    assert len(kept) == len(lines) - 2
    # the plan's name and the new folder real ones beside the session (PLAN.lp and NEW_DIR,
    # pasted, had made a folder named NEW_DIR)
    plan, new = tmp_path / f"s-without-led-{DEAD}.lp", tmp_path / f"s-without-led-{DEAD}"
    assert f"one less, as {plan} and run rti-rig run" in text, text
    plan.write_text("\n".join([str(len(kept)), *kept]) + "\n")
    command = f"rti-rig run {cfg} --plan {plan} --out {new}"
    assert command in text, text
    r = runner.invoke(app, [*command.removeprefix("rti-rig ").split(), "--no-verdict"])
    assert r.exit_code == 0, r.output
    assert "47 image(s) in the session" in said(r), r.output


def _dead_dome(tmp_path: Path) -> Path:
    shutil.copy(CONFIGS / "example_dome_48.lp", tmp_path)
    cfg = tmp_path / "dome.toml"
    cfg.write_text(
        (CONFIGS / "emulated_dome.toml").read_text() + f"\n[emulator]\ndead_leds = [{DEAD}]\n"
    )
    return cfg


@pytest.mark.parametrize("partial", ["--lights", "--plan"])
def test_a_partial_plan_stopped_at_a_dead_led_is_given_a_plan_that_runs(
    tmp_path: Path, partial: str
) -> None:
    """A run of some of the LEDs (``--lights N``, ``--plan P``) had been told "write the lights
    to shoot without the direction of LED 2 (0.4918 0.8546 0.1666) as PLAN.lp": coordinates,
    rounded, of lights the user had no file of (--lights chose them). The plan is written for
    them, beside the session (never in it), and the command said runs it."""
    cfg = _dead_dome(tmp_path)
    chosen = ["--lights", "24"]
    if partial == "--plan":
        plan = tmp_path / "mine.lp"
        r = runner.invoke(app, ["plan", "--rig", str(cfg), "--lights", "24", "--out", str(plan)])
        assert r.exit_code == 0, r.output
        chosen = ["--plan", str(plan)]
    s = tmp_path / "s"
    r = runner.invoke(app, ["run", str(cfg), "--out", str(s), *chosen, "--no-verdict"])
    text = said(r)
    assert r.exit_code == 2, text
    assert (
        re.search(rf"LED {DEAD} \(az [-\d.]+°, el [-\d.]+°\) refused", text)
        and "Continue with: rti-rig run --resume" not in text
    )
    assert f"continue with: rti-rig run --resume {s}" in text, text  # once repaired
    written = tmp_path / f"s-without-led-{DEAD}.lp"
    new = tmp_path / f"s-without-led-{DEAD}"  # beside the session, not there yet
    command = f"rti-rig run {cfg} --plan {written} --out {new}."
    assert (
        f"The session's 23 other lights, in its order, were written beside it as {written.name}"
        in text
    )
    assert command in text, text
    assert [p.name for p in s.glob("*.lp")] == ["lights.lp"]  # nothing added in the session

    # the command, run as said: the other 23 lights, LED 2 not among them
    argv = command.removeprefix("rti-rig ").removesuffix(".")
    r = runner.invoke(app, [*argv.split(), "--no-verdict"])
    assert r.exit_code == 0, r.output
    assert "23 image(s) in the session" in said(r), r.output
    fired = json.loads((new / "manifest.json").read_text())["steps"]
    planned = json.loads((s / "manifest.json").read_text())["schedule"]["steps"]
    assert [st["led"] for st in fired] == [st["led"] for st in planned if st["led"] != DEAD]


def test_an_adaptive_session_stopped_at_a_dead_led_it_chose_is_given_no_plan_of_its_design(
    tmp_path: Path,
) -> None:
    """An adaptive session's schedule is only its first design; the LED it stopped at is one it
    chose later. Its first design had been written as "the session's 3 other lights" (it held
    4, the dead LED not among them), a plan of a few lights offered in the session's place
    (found by a review). It is told that no plan of its other lights exists, the rig's LED .lp
    without that LED (every other LED), and the resume once the LED is repaired."""
    shutil.copy(CONFIGS / "example_dome_48.lp", tmp_path)
    clean = tmp_path / "clean.toml"
    clean.write_text((CONFIGS / "emulated_dome.toml").read_text())
    first = tmp_path / "first"
    adaptive = ["--adaptive", "--lights", "12", "--no-verdict"]
    r = runner.invoke(app, ["run", str(clean), "--out", str(first), *adaptive])
    assert r.exit_code == 0, r.output
    design = {
        st["led"] for st in json.loads((first / "manifest.json").read_text())["schedule"]["steps"]
    }
    fired = [json.loads(line)["led"] for line in (first / "journal.jsonl").read_text().splitlines()]
    dead = next(led for led in fired if led not in design)  # one it chose as it went

    cfg = tmp_path / "dome.toml"
    cfg.write_text(clean.read_text() + f"\n[emulator]\ndead_leds = [{dead}]\n")
    s = tmp_path / "s"
    r = runner.invoke(app, ["run", str(cfg), "--out", str(s), *adaptive])
    text = said(r)
    assert r.exit_code == 2, text
    assert (
        re.search(rf"LED {dead} \(az [-\d.]+°, el [-\d.]+°\) refused", text)
        and "Continue with: rti-rig run --resume" not in text
    )
    assert "no plan of its other lights exists" in text, text
    assert (
        f"copy {tmp_path / 'example_dome_48.lp'} (the rig's LED .lp) without the line of LED {dead}"
        in text
    )
    assert f"continue with: rti-rig run --resume {s}" in text, text  # once repaired
    assert "were written beside it" not in text, text
    assert not list(tmp_path.glob("s-without-led-*.lp")), text


def test_a_resume_stopped_at_the_same_dead_led_reuses_the_plan_it_wrote(tmp_path: Path) -> None:
    """Each resume stopped at the same LED had written another identical plan (``-2.lp``,
    ``-3.lp``) beside the session. The identical file is reused and said to be there; a file
    that differs (edited by the user) is never overwritten: the next name is written."""
    cfg = _dead_dome(tmp_path)
    s = tmp_path / "s"
    r = runner.invoke(app, ["run", str(cfg), "--out", str(s), "--lights", "24", "--no-verdict"])
    assert r.exit_code == 2, said(r)
    first = tmp_path / f"s-without-led-{DEAD}.lp"
    assert f"were written beside it as {first.name}" in said(r), said(r)
    content = first.read_bytes()

    r = runner.invoke(app, ["run", "--resume", str(s), "--no-verdict"])
    text = said(r)
    assert r.exit_code == 2 and re.search(
        rf"LED {DEAD} \(az [-\d.]+°, el [-\d.]+°\) refused", text
    ), text
    assert f"other lights, in its order, are already beside it as {first.name}" in text, text
    assert f"--plan {first} --out {tmp_path / f's-without-led-{DEAD}'}" in text, text
    assert sorted(p.name for p in tmp_path.glob("s-without-led-*.lp")) == [first.name]
    assert first.read_bytes() == content

    edited = content + b"# the user's note\n"
    first.write_bytes(edited)
    r = runner.invoke(app, ["run", "--resume", str(s), "--no-verdict"])
    text = said(r)
    second = tmp_path / f"s-without-led-{DEAD}-2.lp"
    assert r.exit_code == 2 and f"were written beside it as {second.name}" in text, text
    assert first.read_bytes() == edited and second.read_bytes() == content
