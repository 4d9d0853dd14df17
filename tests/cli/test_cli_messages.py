"""What the command line says must read right (issue #30, finding 10): a config line to paste
comes out whole, a good second calibration does not read as a failure, flags take no value."""

from __future__ import annotations

from pathlib import Path

import pytest
from card_support import card_rig, shoot
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()
#: A user's terminal, 80 columns (the tests' consoles are wider: tests/conftest.py's
#: ``_wide_console``): where a config line longer than that must still come out whole.
at_80 = CliRunner(env={"COLUMNS": "80"})


@pytest.mark.parametrize(
    "command", ["run", "preview", "plan", "export-lp", "calibrate-lights", "lights-from-sphere"]
)
def test_flags_show_no_value_type_in_help(command: str) -> None:
    r = runner.invoke(app, [command, "--help"], terminal_width=100)
    assert r.exit_code == 0, r.output
    assert "<bool>" not in r.output
    assert "--force" in r.output or "--auto-exposure" in r.output or "--linear" in r.output


def test_calibration_config_line_is_whole_and_a_good_second_report_is_no_failure(
    tmp_path: Path,
) -> None:
    deep = tmp_path / "a-rather-long-folder-name-for-the-rig" / "and-its-calibration-sessions"
    deep.mkdir(parents=True)
    cfg = card_rig(deep)
    card1 = "card1-the-matte-white-card-shot-under-every-led"
    shoot(cfg, deep / card1)
    r = at_80.invoke(app, ["calibrate-lights", str(deep / card1), "--rig", str(cfg)])
    assert r.exit_code == 0, r.output
    line = f'intensity_correction_file = "{card1}/light_calibration.toml"'
    assert len(line) > 80
    assert line in r.output.splitlines()  # one line, as pasted, on an 80-column terminal
    assert "shoot the card again" in r.output

    cfg2 = card_rig(deep, f"{line}\n", "cal.toml")
    shoot(cfg2, deep / "card2")
    r = at_80.invoke(app, ["calibrate-lights", str(deep / "card2"), "--rig", str(cfg2)])
    assert r.exit_code == 0, r.output
    text = " ".join(r.output.split())
    assert "with the intensity correction in force" in text and "the dome is even" in text
    assert "no new calibration is needed" in text
    assert "shoot the card again" not in text
    assert 'intensity_correction_file = "card2/light_calibration.toml"' in r.output.splitlines()


def test_resume_refuses_options_it_would_otherwise_ignore(tmp_path):
    """A resumed session runs as it began: an option that would change it is refused, not
    silently ignored (the user would believe the stopping rule or the exposure changed). The
    session's own options are accepted (tests/cli/test_resume_same_command_line.py)."""
    from conftest import SMALL_DOME, cut_new_session, write_config
    from typer.testing import CliRunner

    from rti_rig.app.usecases.session import NewSessionRequest
    from rti_rig.cli import app

    out = tmp_path / "s"
    cut_new_session(NewSessionRequest(write_config(tmp_path, SMALL_DOME), out, lights=6), 1)
    args = ["run", "--resume", str(out), "--until-error", "1", "--auto-exposure"]
    r = CliRunner().invoke(app, args)
    assert r.exit_code == 2
    text = " ".join(r.output.split())
    assert "the session ran a planned layout; this asks for an adaptive one" in text
    assert "It began with --lights 6" in text


def _small_run(tmp_path: Path) -> tuple[int, str, Path]:
    """A 6-light dry run on the small simulated dome: exit code, what it said, its folder."""
    from conftest import SMALL_DOME, write_config

    out = tmp_path / "s"
    r = runner.invoke(
        app, ["run", str(write_config(tmp_path, SMALL_DOME)), "--out", str(out), "--lights", "6"]
    )
    return r.exit_code, " ".join(r.output.split()), out


def test_ctrl_c_during_the_verdict_of_a_complete_session_says_it_is_complete(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Ctrl-C while the QA verdict is computed (seconds, after the last image) had ended the
    command with exit code 130 and no word: a complete session read as an interrupted one. It
    is said; the exit is a Ctrl-C's (130), as a SIGTERM there exits 143 (it had exited 0, so
    ``run && fit`` fitted after the user asked to stop)."""
    import rti_rig.app.usecases.fit as fit_usecase

    def interrupted(session: Path) -> str:
        raise KeyboardInterrupt

    monkeypatch.setattr(fit_usecase, "verdict_for_session", interrupted)
    code, said, out = _small_run(tmp_path)
    assert code == 130, said
    assert "6 image(s) in the session" in said and "Traceback" not in said
    assert "QA verdict skipped (Ctrl-C): the session is complete" in said
    assert f"rti-rig fit {out} --out {out}-fit" in said


def test_a_late_ctrl_c_does_not_cut_the_summary(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A second Ctrl-C (meant as "stop at once") that arrives just after the session stopped
    had landed on Python's default handler while the summary was printed: exit 130 and no
    summary or resume hint. Until the summary is out, a late Ctrl-C is ignored."""
    import os
    import signal

    import rti_rig.cli.session as session_cli

    real = session_cli._time_line

    def with_a_late_ctrl_c(*args):  # type: ignore[no-untyped-def]
        os.kill(os.getpid(), signal.SIGINT)
        return real(*args)

    monkeypatch.setattr(session_cli, "_time_line", with_a_late_ctrl_c)
    before = signal.getsignal(signal.SIGINT)
    code, said, _ = _small_run(tmp_path)
    assert code == 0, said
    assert "6 image(s) in the session" in said and "Session time on the real rig" in said
    assert signal.getsignal(signal.SIGINT) is before  # the handlers before are back


def _run_signalled(
    tmp_path: Path, module: str, function: str, signal_name: str, then: str, *extra: str
) -> tuple[int, str, Path]:
    """``rti-rig run`` of 6 lights on the simulated dome in a process of its own, where
    ``module.function`` first sends the process ``signal_name``, then ``then`` (a statement:
    ``return real(*a, **k)`` to go on). Exit code, what it said (and whether SIGTERM's handler
    was the default again at the end), the session folder."""
    import subprocess
    import sys

    script = (
        "import os, signal, sys\n"
        f"import {module} as target\n"
        f"real = target.{function}\n"
        "def signalled(*a, **k):\n"
        f"    os.kill(os.getpid(), signal.{signal_name})\n"
        f"    {then}\n"
        f"target.{function} = signalled\n"
        "from rti_rig.cli import app\n"
        "try:\n"
        "    app(sys.argv[1:], prog_name='rti-rig')\n"
        "finally:\n"
        "    default = signal.getsignal(signal.SIGTERM) is signal.SIG_DFL\n"
        "    print('SIGTERM handler restored:', default)\n"
    )
    cfg = Path(__file__).resolve().parents[2] / "rig_configs" / "simulated_dome.toml"
    out = tmp_path / "s"
    args = ["run", str(cfg), "--out", str(out), "--lights", "6", *extra]
    proc = subprocess.run(
        [sys.executable, "-c", script, *args], capture_output=True, text=True, timeout=300
    )
    return proc.returncode, " ".join((proc.stdout + proc.stderr).split()), out


@pytest.mark.skipif(not hasattr(__import__("signal"), "SIGUSR1"), reason="no SIGUSR1")
def test_a_late_sigusr1_does_not_end_the_run_before_its_verdict(tmp_path: Path) -> None:
    """SIGUSR1 (pause) that arrives once the capture is over, while the QA verdict is computed,
    had met Python's default action: the process ended at once with exit 138 and no word, the
    verdict unsaid. It is ignored there, and said to be; the handlers before are back after."""
    code, said, _ = _run_signalled(
        tmp_path, "rti_rig.app.usecases.fit", "verdict_for_session", "SIGUSR1",
        "return real(*a, **k)",
    )  # fmt: skip
    assert code == 0, (code, said)
    assert "SIGUSR1 ignored" in said and "QA verdict:" in said, said


@pytest.mark.skipif(not hasattr(__import__("signal"), "SIGUSR1"), reason="no SIGUSR1")
def test_an_early_sigusr1_does_not_end_the_run_while_the_rig_opens(tmp_path: Path) -> None:
    """SIGUSR1 (pause) that arrives while the rig opens (an emulator starting, metering with
    the rig lit) met Python's default action: exit 138, no word, no all-off. It is ignored
    there too, and said to be, and the session runs."""
    code, said, _ = _run_signalled(
        tmp_path, "rti_rig.app.usecases.session", "open_new_session", "SIGUSR1",
        "return real(*a, **k)", "--no-verdict",
    )  # fmt: skip
    assert code == 0, (code, said)
    assert "SIGUSR1 ignored" in said and "6 image(s) in the session" in said, said


def test_a_sigterm_during_the_verdict_says_the_session_is_complete(tmp_path: Path) -> None:
    """SIGTERM (a service manager, ``timeout``) while the QA verdict is computed had ended the
    process silently with exit 143: a complete session read as a failed one. It is said as a
    Ctrl-C there is, and the exit is still a SIGTERM's (143); SIGTERM's handler is back after."""
    code, said, out = _run_signalled(
        tmp_path, "rti_rig.app.usecases.fit", "verdict_for_session", "SIGTERM",
        "raise AssertionError('the SIGTERM should have stopped the verdict')",
    )  # fmt: skip
    assert code == 143, (code, said)
    assert "6 image(s) in the session" in said
    assert "QA verdict skipped (SIGTERM): the session is complete" in said, said
    assert f"rti-rig fit {out} --out {out}-fit gives the verdict" in said
    assert "SIGTERM handler restored: True" in said and "Traceback" not in said


def test_a_session_cancelled_before_its_first_image_offers_no_resume(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Ctrl-C before the first image had printed "0 image(s) in the session; lights.lp lists
    the lights that fired … Continue with: rti-rig run --resume" for a folder with no lights.lp
    and nothing to resume (SIGTERM at the same moment said it may be used again)."""
    import os
    import signal

    from rti_rig.simulator.sim_lights import SimulatedDome

    real = SimulatedDome.connect

    def ctrl_c_while_connecting(self):  # type: ignore[no-untyped-def]
        os.kill(os.getpid(), signal.SIGINT)
        return real(self)

    monkeypatch.setattr(SimulatedDome, "connect", ctrl_c_while_connecting)
    code, said, _ = _small_run(tmp_path)
    assert code == 130, said
    assert "Session cancelled. Lights were switched off. Nothing was captured" in said, said
    assert "--resume" not in said and "lists the lights" not in said


def test_calibration_names_the_weakest_led_by_its_session_image(tmp_path: Path) -> None:
    """The weakest and strongest LEDs were named only by the dome .lp's labels (led_18.jpg),
    not by the session image a user opens to look at them (image_019.jpg)."""
    import json

    import numpy as np
    from card_support import TRUE_POWER

    cfg = card_rig(tmp_path)
    shoot(cfg, tmp_path / "card")
    r = runner.invoke(app, ["calibrate-lights", str(tmp_path / "card"), "--rig", str(cfg)])
    assert r.exit_code == 0, r.output
    said = " ".join(r.output.split())
    steps = [json.loads(line) for line in (tmp_path / "card" / "journal.jsonl").open()]
    image_of = {s["led"]: s["image"] for s in steps}
    weak = int(np.argmin(TRUE_POWER))
    assert f"(LED {weak}, " in said and f"session image {image_of[weak]})" in said, said
    # the calibration file's comment names it by its number and direction too
    written = (tmp_path / "card" / "light_calibration.toml").read_text(encoding="utf-8")
    assert f"weakest LED {weak} (led_{weak}.jpg, az " in written, written


@pytest.mark.parametrize(
    "lights, note",
    [
        (2, "too few for normals or any relighting fit"),
        # 3 had been silent, its verdict "good", and plain `rti-rig fit` then failed
        (3, "`rti-rig fit` with its default --model auto cannot fit them"),
        (6, None),
    ],
)
def test_too_few_lights_to_fit_are_said_before_the_rig_moves(
    tmp_path: Path, lights: int, note: str | None
) -> None:
    """`run --lights 1` or `2` is accepted (a test shot), but had been told only afterwards, by
    the QA's "unavailable", that nothing can be fitted; `plan` refuses fewer than 3."""
    cfg = Path(__file__).resolve().parents[2] / "rig_configs" / "simulated_dome.toml"
    r = runner.invoke(
        app, ["run", str(cfg), "--out", str(tmp_path / "s"), "--lights", str(lights)],
        terminal_width=400,
    )  # fmt: skip
    assert r.exit_code == 0, r.output
    text = " ".join(r.output.split())
    if note is None:
        assert "`rti-rig fit`" not in text, text
    else:
        assert text.index(note) < text.index("Rig simulated-dome-48")  # before anything moves


@pytest.mark.parametrize(
    ("config", "sentence"),
    [
        # a firmware that never confirms: the all-off was sent, and that is all that is known
        ("emulated_rti_dome.toml", "All-off sent; this firmware never acknowledges"),
        ("simulated_dome.toml", "Lights were switched off."),
        # a cancel parks (park_after_session), read back at the park pose
        ("virtual_arm.toml", "Lamp off and stop were requested; the arm parked (read back at"),
    ],
)
def test_a_cancelled_session_says_what_is_known_of_the_lights(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, config: str, sentence: str
) -> None:
    """One Ctrl-C (cancel after the current image) had said only "Session cancelled; the
    images captured so far are kept": nothing of the lights, where a stop says what it knows."""
    import os
    import signal

    from rti_rig.simulator.sim_camera import SimulatedCamera

    real, shots = SimulatedCamera.capture, []

    def ctrl_c_at_the_third(self, *args, **kwargs):  # type: ignore[no-untyped-def]
        shots.append(1)
        if len(shots) == 3:
            os.kill(os.getpid(), signal.SIGINT)
        return real(self, *args, **kwargs)

    monkeypatch.setattr(SimulatedCamera, "capture", ctrl_c_at_the_third)
    cfg = Path(__file__).resolve().parents[2] / "rig_configs" / config
    r = runner.invoke(
        app, ["run", str(cfg), "--out", str(tmp_path / "s"), "--lights", "6"], terminal_width=400
    )
    said = " ".join(r.output.split())
    assert r.exit_code == 130, said
    assert "Session cancelled; the images captured so far are kept." in said
    tail = said[said.index("Session cancelled") :]
    assert sentence in tail, said


@pytest.mark.skipif(not hasattr(__import__("signal"), "SIGUSR1"), reason="no SIGUSR1")
@pytest.mark.parametrize(
    ("config", "sentence"),
    [
        # a firmware that never confirms: the all-off after the image was sent, nothing more
        ("emulated_elexol.toml", "this firmware never acknowledges"),
        ("emulated_dome.toml", "all-off sent and acknowledged by the dome: lights are off"),
        ("simulated_dome.toml", "lights were switched off"),
        ("virtual_arm.toml", "lamp off requested after the last image"),
    ],
)
def test_a_paused_session_says_what_is_known_of_the_lights(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, config: str, sentence: str
) -> None:
    """SIGUSR1 had printed "Pausing after this image (lights off)" whatever the rig: also for a
    firmware that never acknowledges its all-off. The pause says what the last all-off
    established, once it holds."""
    import os
    import signal

    from rti_rig.runtime.controller import CancelToken
    from rti_rig.simulator.sim_camera import SimulatedCamera

    real, shots = SimulatedCamera.capture, []

    def pause_at_the_third(self, *args, **kwargs):  # type: ignore[no-untyped-def]
        shots.append(1)
        if len(shots) == 3:
            os.kill(os.getpid(), signal.SIGUSR1)
        return real(self, *args, **kwargs)

    monkeypatch.setattr(SimulatedCamera, "capture", pause_at_the_third)
    monkeypatch.setattr(CancelToken, "wait_while_paused", lambda self, *a: self.resume())
    cfg = Path(__file__).resolve().parents[2] / "rig_configs" / config
    r = runner.invoke(
        app, ["run", str(cfg), "--out", str(tmp_path / "s"), "--lights", "6"], terminal_width=400
    )
    said = " ".join(r.output.split())
    assert r.exit_code == 0, said
    assert "lights off)" not in said, said
    assert "Paused before image 4: " in said, said
    tail = said[said.index("Paused before image 4: ") :]
    assert sentence in tail.split(". SIGUSR1 resumes.")[0], said


def test_a_metering_failure_says_what_is_known_of_the_lights_and_that_nothing_was_written(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Metering lights the rig's brightest light; an error there had printed only the error."""
    import rti_rig.drivers.cameras.exposure as exposure
    from rti_rig.core.errors import CaptureError

    def failing(camera, *args, **kwargs):  # type: ignore[no-untyped-def]
        raise CaptureError("camera", "the camera stopped answering", "capture")

    monkeypatch.setattr(exposure, "meter_exposure", failing)
    cfg = Path(__file__).resolve().parents[2] / "rig_configs" / "emulated_rti_dome.toml"
    out = tmp_path / "s"
    r = runner.invoke(
        app, ["run", str(cfg), "--out", str(out), "--lights", "6", "--auto-exposure"],
        terminal_width=400,
    )  # fmt: skip
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    assert "the camera stopped answering" in said
    assert "All-off sent; this firmware never acknowledges" in said
    assert f"nothing was captured or written to {out}" in said
    assert not out.exists()


def _hardware_arm(tmp_path: Path) -> Path:
    """The shipped arm config on hardware, its port a path that does not exist."""
    text = (Path(__file__).resolve().parents[2] / "rig_configs" / "simulated_arm.toml").read_text()
    text = text.replace('backend = "emulated"', 'backend = "hardware"')
    text = text.replace('port = "emulated"', f'port = "{tmp_path / "ttyUSB9"}"')
    text = "\n".join(line for line in text.splitlines() if not line.startswith("transport ="))
    text = text[: text.index("[scene]")]
    text = text.replace(
        "exposure_s = 0.05\n",
        f'exposure_s = 0.05\n[camera.device]\nkind = "opencv"\ndevice = "{tmp_path / "video9"}"\n'
        'response = "srgb"\n',
        1,
    )
    cfg = tmp_path / "arm.toml"
    cfg.write_text(text)
    return cfg


def test_an_arm_that_could_not_be_connected_is_not_said_to_be_stopped(tmp_path: Path) -> None:
    """Its port could not be opened: nothing was sent. `check` had said "CommunicationError: …
    (not parked: the arm was stopped where it was)" and `run` "Lamp off and stop were
    requested"; neither said to check the adapter and the config's port."""
    cfg = _hardware_arm(tmp_path)
    r = runner.invoke(app, ["check", str(cfg)], terminal_width=400)
    said = " ".join(r.output.split())
    assert r.exit_code == 1 and "RESULT: FAIL" in said, said
    assert "nothing was commanded: the arm could not be connected" in said
    assert "stopped where it was" not in said and "CommunicationError" not in said
    assert "the rig config's [arm.dynamixel] port names it" in said  # the table, not eaten
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", str(cfg), "--out", str(out), "--lights", "4"])
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    assert "Nothing was commanded: the arm could not be connected" in said
    assert "Lamp off and stop were requested" not in said
    assert "U2D2" in said and not out.exists()


def _finished_run(tmp_path: Path, config: str) -> str:
    """A 4-light run of a shipped config to its end (no verdict), its output on one line."""
    cfg = Path(__file__).resolve().parents[2] / "rig_configs" / config
    r = runner.invoke(
        app,
        ["run", str(cfg), "--out", str(tmp_path / "s"), "--lights", "4", "--no-verdict"],
        terminal_width=400,
    )
    said = " ".join(r.output.split())
    assert r.exit_code == 0, said
    return said


@pytest.mark.parametrize(
    ("config", "sentence"),
    [
        ("emulated_dome.toml", "All-off sent and acknowledged by the dome: lights are off."),
        ("emulated_elexol.toml", "this firmware never acknowledges"),
        ("simulated_arm.toml", "Lamp off and stop were requested; the arm parked (read back at"),
    ],
)
def test_a_finished_session_on_a_rig_with_devices_says_what_is_known_of_the_lights(
    tmp_path: Path, config: str, sentence: str
) -> None:
    """A finished run had said nothing of the lights (only a stop or an error did): the user
    took the object out not told whether the dome had acknowledged its all-off. It now says
    what the teardown established, in the words a stop uses, and no more."""
    said = _finished_run(tmp_path, config)
    tail = said[said.index("Session time on the real rig") :]
    assert sentence in tail, said
    if "never acknowledges" in sentence:
        assert "lights are off" not in said, said


def test_a_dry_run_of_a_simulated_dome_claims_nothing_of_lights_it_does_not_have(
    tmp_path: Path,
) -> None:
    said = _finished_run(tmp_path, "simulated_dome.toml")
    assert "lights are off" not in said and "switched off" not in said, said


def test_the_resume_hint_runs_as_printed_for_a_folder_with_spaces(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A museum's session folders are named after the object ("object 12 recto"). The hint
    after a Ctrl-C printed the folder bare: pasted into a shell, "rti-rig run --resume
    .../object 12 recto" resumed a folder "object" with "12" and "recto" as stray arguments.
    The command as printed (split as a shell splits it) continues the session."""
    import os
    import shlex
    import signal

    from conftest import SMALL_DOME, write_config

    from rti_rig.simulator.sim_lights import SimulatedDome

    real, lit = SimulatedDome.light, []

    def ctrl_c_at_the_third_light(self, *a, **k):  # type: ignore[no-untyped-def]
        lit.append(1)
        if len(lit) == 3:
            os.kill(os.getpid(), signal.SIGINT)  # stops after this image
        return real(self, *a, **k)

    out = tmp_path / "object 12 recto"
    cfg = write_config(tmp_path, SMALL_DOME)
    with monkeypatch.context() as m:
        m.setattr(SimulatedDome, "light", ctrl_c_at_the_third_light)
        r = runner.invoke(app, ["run", str(cfg), "--out", str(out), "--lights", "6"])
    said = " ".join(r.output.split())
    assert r.exit_code == 130, said
    hint = said.split("Continue with: ", 1)[1]
    argv = shlex.split(hint)
    assert argv[:3] == ["rti-rig", "run", "--resume"] and argv[3] == str(out), argv
    r = runner.invoke(app, [*argv[1:], "--no-verdict"])
    assert r.exit_code == 0, r.output
    assert "6 image(s) in the session" in " ".join(r.output.split())


def test_a_sigterm_while_metering_switches_the_lights_off_and_says_so(tmp_path: Path) -> None:
    """SIGTERM (a service manager, ``timeout``) while `--auto-exposure` metered, with an LED
    lit, met Python's default action: exit 143, no word, no all-off, though `run --help`
    promises that SIGTERM stops at once with the lights off. Metering's teardown runs, what it
    established is said, nothing is written, and SIGTERM's handler is back after."""
    code, said, out = _run_signalled(
        tmp_path, "rti_rig.drivers.cameras.exposure", "meter_exposure", "SIGTERM",
        "raise AssertionError('the SIGTERM should have stopped the metering')",
        "--auto-exposure",
    )  # fmt: skip
    assert code == 143, (code, said)
    assert (
        f"Stopped (SIGTERM) before the first image: nothing was captured or written to {out}"
        in said
    )
    assert "metering was stopped, and then: lights were switched off" in said, said
    assert "SIGTERM handler restored: True" in said and "Traceback" not in said, said
    assert not out.exists()


@pytest.mark.parametrize("signal_name, code", [("SIGTERM", 143), ("SIGINT", 130)])
def test_a_stop_while_the_preview_meters_switches_the_lights_off_and_says_so(
    tmp_path: Path, signal_name: str, code: int
) -> None:
    """`preview --auto-exposure` lights the rig to meter. A SIGTERM there had ended the process
    at once (exit 143, no word, no all-off), a Ctrl-C said only "rti-rig: stopped (Ctrl-C)":
    neither said anything of the lights. Both now stop through metering's teardown and say
    what it established."""
    import subprocess
    import sys

    script = (
        "import os, signal, sys\n"
        "signal.signal(signal.SIGINT, signal.default_int_handler)\n"
        "import rti_rig.drivers.cameras.exposure as target\n"
        "def signalled(*a, **k):\n"
        f"    os.kill(os.getpid(), signal.{signal_name})\n"
        "    raise AssertionError('the signal should have stopped the metering')\n"
        "target.meter_exposure = signalled\n"
        "from rti_rig.launch import main\n"
        "sys.argv[0] = 'rti-rig'\n"
        "main()\n"
    )
    cfg = Path(__file__).resolve().parents[2] / "rig_configs" / "simulated_dome.toml"
    out = tmp_path / "p"
    proc = subprocess.run(
        [sys.executable, "-c", script, "preview", str(cfg), "--out", str(out), "--auto-exposure"],
        capture_output=True,
        text=True,
        timeout=300,
    )
    said = " ".join((proc.stdout + proc.stderr).split())
    why = "SIGTERM" if signal_name == "SIGTERM" else "Ctrl-C"
    assert proc.returncode == code, (proc.returncode, said)
    assert f"Stopped ({why}) before the preview image: nothing was captured" in said, said
    assert "metering was stopped, and then: lights were switched off" in said, said
    assert "Traceback" not in said and not out.exists()
