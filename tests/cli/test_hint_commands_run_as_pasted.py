"""A hint's command, pasted into bash as printed, does what the hint says.

Why: hints had printed templates (``--out DIR``, ``--lights 12`` whatever the dome holds):
pasted, ``--out DIR`` made a folder named DIR and ``--lights 12`` was refused on a dome of 8
LEDs. Each test below runs the CLI into the situation, takes the command it prints and runs it
through bash (``rti-rig`` as ``python -m rti_rig``) in the same folder.
"""

from __future__ import annotations

import json
import os
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import ASCII_LOCALE_ENV as ENV
from conftest import CONFIGS, NOT_UTF8_NAME, shipped_variant


def rti_rig(cwd: Path, *args: str | Path) -> subprocess.CompletedProcess[str]:
    """``rti-rig *args`` run in ``cwd``, as a user runs it; no traceback."""
    r = subprocess.run(
        [sys.executable, "-m", "rti_rig", *map(str, args)],
        capture_output=True,
        text=True,
        cwd=cwd,
        env={**ENV, "COLUMNS": "400"},
        timeout=600,
    )
    assert "Traceback" not in r.stderr, r.stderr
    return r


def pasted_run(cwd: Path, command: str) -> subprocess.CompletedProcess[str]:
    """``command`` (``rti-rig ...`` as printed) run by bash in ``cwd``."""
    assert command.startswith("rti-rig "), command
    r = subprocess.run(
        ["bash", "-c", command.replace("rti-rig", '"$PY" -m rti_rig', 1)],
        capture_output=True,
        text=True,
        cwd=cwd,
        env={**ENV, "PY": sys.executable, "COLUMNS": "400"},
        timeout=600,
    )
    assert "Traceback" not in r.stderr, r.stderr
    return r


def command_after(said: str, before: str, end: str = ")") -> str:
    """The command printed after ``before`` in ``said`` (one line however it wrapped), up to
    ``end``."""
    text = " ".join(said.split())
    assert before in text, text
    return text.split(before, 1)[1].split(end, 1)[0].strip()


def test_a_rig_config_given_as_plan_on_an_8_led_dome_suggests_a_run_of_8_lights(
    tmp_path: Path,
) -> None:
    """The shipped 8-LED dome (simulated, for speed: its geometry as shipped): the advised
    homogeneous run had said ``--lights 12``, which that dome refuses."""
    rig = shipped_variant(
        tmp_path, "emulated_rti_dome.toml", (('backend = "emulated"', 'backend = "simulated"'),)
    )
    r = rti_rig(tmp_path, "run", rig, "--out", "S", "--plan", rig)
    assert r.returncode == 2, r.stderr
    command = command_after(r.stderr, "run a homogeneous layout without a plan: ")
    assert " --lights 8 " in command, command
    done = pasted_run(tmp_path, command + " --no-verdict")
    assert done.returncode == 0, done.stderr
    lp = (tmp_path / "S" / "lights.lp").read_text(encoding="utf-8").split()
    assert lp[0] == "8", lp[:4]


def eight_led_dome(folder: Path) -> Path:
    """The shipped 8-LED dome, simulated (for speed: its geometry as shipped)."""
    return shipped_variant(
        folder, "emulated_rti_dome.toml", (('backend = "emulated"', 'backend = "simulated"'),)
    )


def test_a_finished_preview_given_again_suggests_a_plan_the_8_led_dome_takes(
    tmp_path: Path,
) -> None:
    """A preview folder given again to ``preview --out`` points to ``plan`` with the count the
    rig allows, recorded at capture: it had said plan's default ``--lights 12``, which the
    8-LED dome refuses."""
    rig = eight_led_dome(tmp_path)
    assert rti_rig(tmp_path, "preview", rig, "--out", "pv").returncode == 0
    r = rti_rig(tmp_path, "preview", rig, "--out", "pv")
    assert r.returncode == 2, r.stderr
    command = command_after(r.stderr, "a finished preview: plan from it with ")
    assert " --lights 8 " in command, command
    done = pasted_run(tmp_path, command)
    assert done.returncode == 0, done.stderr
    lp = (tmp_path / "plan.lp").read_text(encoding="utf-8").split()
    assert lp[0] == "8", lp[:4]


RUN_8 = ("run", "rig.toml", "--lights", "8", "--no-verdict", "--out")


@pytest.fixture(scope="module")
def finished_8(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A folder holding the simulated 8-LED dome's ``rig.toml`` and a finished session of it
    whose name is not UTF-8, with a space and a quote (:data:`NOT_UTF8_NAME`)."""
    folder = tmp_path_factory.mktemp("finished_8")
    eight_led_dome(folder)
    assert rti_rig(folder, *RUN_8, os.fsdecode(NOT_UTF8_NAME)).returncode == 0
    return folder


def test_a_run_into_a_finished_session_names_a_new_out_folder_that_pastes(
    finished_8: Path, tmp_path: Path
) -> None:
    """``run --out S`` into a finished session is refused with a folder that does not exist
    yet (it said "choose a new --out folder" and named none); the run given it, pasted, writes
    there and leaves the first session as it was. The word printed must paste back as the
    folder name's bytes."""
    shutil.copytree(finished_8, tmp_path, dirs_exist_ok=True)
    first = os.fsdecode(NOT_UTF8_NAME)
    run = RUN_8
    before = sorted(p.name for p in (tmp_path / first).iterdir())
    r = rti_rig(tmp_path, *run, first)
    assert r.returncode == 2, r.stderr
    word = command_after(r.stderr, "choose a new --out folder (such as --out ", ", which")
    command = "rti-rig " + " ".join(map(shlex.quote, map(str, run))) + " " + word
    done = pasted_run(tmp_path, command)
    assert done.returncode == 0, done.stderr
    lp = (tmp_path / os.fsdecode(NOT_UTF8_NAME + b"-2") / "lights.lp").read_text(encoding="utf-8")
    assert lp.split()[0] == "8", lp[:40]
    assert sorted(p.name for p in (tmp_path / first).iterdir()) == before


def test_a_bare_lp_rig_refused_a_2_light_plan_is_offered_the_test_shot_on_its_config(
    tmp_path: Path,
) -> None:
    """``plan --rig dome.lp --lights 2``: the test shot offered names the rig config beside
    the .lp whose lp_file it is (it said ``RIG.toml``, which pasted was a file not there), and
    pasted it shoots one image into a folder beside the plan."""
    (tmp_path / "example_dome_48.lp").write_bytes((CONFIGS / "example_dome_48.lp").read_bytes())
    config = shipped_variant(
        tmp_path, "emulated_dome.toml", (('backend = "emulated"', 'backend = "simulated"'),)
    )
    r = rti_rig(tmp_path, "plan", "--rig", "example_dome_48.lp", "--lights", "2", "--out", "p.lp")
    assert r.returncode == 2, r.stderr
    command = command_after(r.stderr, "a test shot of 1 or 2 lights needs no plan: ", "\n")
    assert command == "rti-rig run rig.toml --lights 1 --out test-shot", command
    done = pasted_run(tmp_path, command + " --no-verdict")
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "test-shot" / "lights.lp").read_text(encoding="utf-8").split()[0] == "1"
    assert config.is_file() and not (tmp_path / "p.lp").exists()


def test_a_resume_of_a_session_whose_manifest_names_no_config_names_the_session(
    finished_8: Path, tmp_path: Path
) -> None:
    """A manifest that does not say which rig config it was shot with: the resume to give
    names the session as a word that pastes back (it said ``--resume DIR``); the config,
    which nothing records, is the one word left to fill in."""
    shutil.copytree(finished_8, tmp_path, dirs_exist_ok=True)
    session = tmp_path / os.fsdecode(NOT_UTF8_NAME)
    manifest = json.loads((session / "manifest.json").read_text(encoding="utf-8"))
    del manifest["rig"]["config_path"]
    (session / "manifest.json").write_text(json.dumps(manifest), encoding="utf-8")
    r = rti_rig(tmp_path, "run", "--resume", session.name)
    assert r.returncode != 0, r.stderr
    command = command_after(r.stderr, "give it: ", " (RIG.toml")
    done = pasted_run(tmp_path, command.replace("RIG.toml", "rig.toml", 1))
    assert "does not say which rig config" not in done.stderr, done.stderr
    assert "is complete" in done.stderr + done.stdout, done.stderr + done.stdout


def accepted_as_pasted(cwd: Path, command: str, out: str) -> None:
    """``command``, pasted in ``cwd``, passes every check of its options: with its ``--out``
    (``out``) made non-empty first, the folder is all it is refused for (a refusal of an
    option comes before the folder's; the session itself is not run, for speed)."""
    (cwd / out).mkdir()
    (cwd / out / "keep.txt").write_text("x", encoding="utf-8")
    done = pasted_run(cwd, command)
    assert done.returncode == 2, done.stderr
    said = " ".join(done.stderr.split())
    assert f"{out} is not empty: refusing to write a session over existing files" in said, said


def test_a_relight_objective_with_a_target_advises_a_count_the_8_led_dome_takes(
    tmp_path: Path,
) -> None:
    """``--objective relight`` with ``--until-error`` had advised "--lights 12, say", which the
    8-LED dome refuses ("give at most 8"), as an option to add to a command the user had to
    rebuild; it is a whole command with 8 (the refusal without ``--lights`` words the same
    command: test_adaptive_objective)."""
    rig = eight_led_dome(tmp_path)
    given = ("--until-error", "3", "--objective", "relight")
    r = rti_rig(tmp_path, "run", rig, "--out", "S", "--adaptive", *given)
    assert r.returncode == 2, r.stderr
    command = command_after(r.stderr, "a count: ", " (or")
    assert " --lights 8 --objective relight" in command, command
    accepted_as_pasted(tmp_path, command, "S")


def test_a_minimum_without_a_target_advises_a_whole_command_with_one(tmp_path: Path) -> None:
    """``--adaptive --min-lights 6`` without ``--until-error``: "add --until-error DEG" pasted
    was refused as no number; the advice is the run with the guide's 2° and the band given."""
    rig = eight_led_dome(tmp_path)
    r = rti_rig(
        tmp_path,
        "run",
        rig,
        "--out",
        "S",
        "--adaptive",
        "--min-lights",
        "6",
        "--max-elevation-deg",
        "60",
    )
    assert r.returncode == 2, r.stderr
    # the command ends the message: printed before ", or leave --min-lights out", its last
    # word read "60," up to the comma
    command = command_after(r.stderr, "as the guide shows): ", "\n")
    assert command.endswith("--until-error 2 --min-lights 6 --max-elevation-deg 60"), command
    accepted_as_pasted(tmp_path, command, "S")


def test_an_adaptive_auto_exposure_advises_a_metering_run_into_a_free_folder(
    tmp_path: Path,
) -> None:
    """The metering run advised had been ``--out TEST``: pasted where a TEST folder of an
    earlier metering run was left, it was refused; the folder named is one not there yet, and
    pasted, the run meters ("Exposure fixed at")."""
    rig = eight_led_dome(tmp_path)
    (tmp_path / "TEST").mkdir()
    (tmp_path / "TEST" / "keep.txt").write_text("x", encoding="utf-8")
    r = rti_rig(tmp_path, "run", rig, "--out", "S", "--adaptive", "--auto-exposure")
    assert r.returncode == 2, r.stderr
    command = command_after(r.stderr, "Meter once with a planned run (", " prints")
    assert " --out S-metering " in command, command
    done = pasted_run(tmp_path, command + " --no-verdict")
    assert done.returncode == 0, done.stderr
    assert "Exposure fixed at" in " ".join((done.stdout + done.stderr).split())


@pytest.mark.pty
def test_a_card_session_of_too_few_images_advises_the_card_shot_again_as_a_command(
    tmp_path: Path,
) -> None:
    """``calibrate-lights`` of a card shot under 3 LEDs had said "rti-rig run RIG --out
    CARD_SESSION", which pasted ran a rig file named RIG: it names the session's own config
    and a folder not there yet, and pasted, that run is accepted."""
    from card_support import card_rig

    cfg = card_rig(tmp_path)
    assert rti_rig(tmp_path, "run", cfg, "--lights", "3", "--out", "card").returncode == 0
    r = rti_rig(tmp_path, "calibrate-lights", "card", "--rig", cfg)
    assert r.returncode == 2, r.stderr
    command = command_after(r.stderr, "(with no --lights): ", "\n")
    assert command == f"rti-rig run {shlex.quote(str(cfg))} --out card-again", command
    accepted_as_pasted(tmp_path, command, "card-again")


def test_a_finished_run_ends_with_the_fit_that_pastes(tmp_path: Path) -> None:
    """A finished run's last line is its next step, `rti-rig fit S --out S-fit`, which pasted
    fits the session (a finished run had ended on its QA verdict with no next step, where a
    resume of the same complete session named the fit)."""
    rig = shipped_variant(
        tmp_path,
        "simulated_dome.toml",
        (("width = 512", "width = 48"), ("height = 512", "height = 48")),
    )
    r = rti_rig(tmp_path, "run", rig, "--out", "my session", "--lights", "6", "--no-verdict")
    assert r.returncode == 0, r.stderr
    last = r.stdout.rstrip().splitlines()[-1]
    assert last == "Next: rti-rig fit 'my session' --out 'my session-fit'", r.stdout
    fitted = pasted_run(tmp_path, last.removeprefix("Next: "))
    assert fitted.returncode == 0, fitted.stderr
    fit = tmp_path / "my session-fit"
    assert (fit / "normals.png").exists() and (fit / "fit.rti").exists(), sorted(fit.iterdir())
