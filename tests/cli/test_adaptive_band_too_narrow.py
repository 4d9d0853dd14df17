"""`run --adaptive` (or `--until-error`) in a band too narrow for an adaptive session, on the
shipped Nab dome (12 LEDs, 16.8°–75.7°): the refusal says how many LEDs the band holds, what
the session needs, and a command that works — the band widened to hold it, with the user's
own options — as well as the planned run of the band's lights.

Below 20° the Nab dome holds one LED, and the only advice had been a planned run of
``--lights 1``: a single image, no normals, no fit. ``--until-error`` alone there ran that one
light and said "the target is not claimed" (nothing can be estimated from one image). The
advised commands are run here, as a user would paste them."""

from __future__ import annotations

import math
import shlex
from pathlib import Path

import pytest
from conftest import CONFIGS, journal, said, virtual_arm_variant
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()
NAB = CONFIGS / "emulated_nab_rti_v1.toml"


def _advised(text: str, lead: str, tmp_path: Path, name: str) -> list[str]:
    """The command after ``lead`` in ``text`` (up to its parenthesis), its ``--out`` the run's
    own (``tmp_path / "s"``: ``--out DIR`` had been printed, which pasted made a folder named
    DIR), then made ``name``, for a test that pastes more than one command."""
    command = text.split(lead, 1)[1].split(" (", 1)[0]
    argv = shlex.split(command)
    assert argv[:2] == ["rti-rig", "run"], command
    at = argv.index("--out") + 1
    assert argv[at] == str(tmp_path / "s"), command
    argv[at] = str(tmp_path / name)
    return argv[1:]


def _elevations(session: Path) -> list[float]:
    return [math.degrees(math.asin(s["actual_direction"][2])) for s in journal(session)]


@pytest.mark.parametrize(
    ("asked", "kept"),
    [(["--adaptive"], "--adaptive"), (["--until-error", "30"], "--until-error 30")],
)
def test_a_band_of_one_nab_led_is_refused_with_a_band_that_holds_the_session(
    tmp_path: Path, asked: list[str], kept: str
) -> None:
    out = tmp_path / "s"
    argv = ["run", str(NAB), "--out", str(out), *asked, "--max-elevation-deg", "20"]
    r = runner.invoke(app, argv)
    text = said(r)
    assert r.exit_code == 2, text
    assert not out.exists()
    assert "this rig offers 1 light between 0° and 20° elevation" in text, text
    assert "its 12 LEDs are at 16.8°–75.7° elevation" in text, text
    assert "an adaptive session needs at least 5: it starts from 4" in text, text
    assert f"--out {out} {kept} --max-elevation-deg 33 (5 lights between 0° and 33°" in text, text
    # the widened band's command works, and keeps to its band
    argv = _advised(text, "Widen the band to hold 5: ", tmp_path, "wide")
    r = runner.invoke(app, [*argv, "--no-verdict"])
    assert r.exit_code == 0, said(r)
    lit = _elevations(tmp_path / "wide")
    assert len(lit) >= 4 and max(lit) <= 33, lit
    # the planned run of the band's one light is said for what it is
    assert "(a test shot only: normals need 3 lights)" in text, text
    argv = _advised(text, "or shoot it with a planned run: ", tmp_path, "planned")
    r = runner.invoke(app, [*argv, "--no-verdict"])
    assert r.exit_code == 0, said(r)
    assert len(_elevations(tmp_path / "planned")) == 1


def test_the_widened_band_holds_the_lights_asked_for(tmp_path: Path) -> None:
    """--lights 9: the band advised holds 9, and the command keeps --lights 9."""
    out = tmp_path / "s"
    args = ["--adaptive", "--lights", "9", "--max-elevation-deg", "20"]
    r = runner.invoke(app, ["run", str(NAB), "--out", str(out), *args])
    text = said(r)
    assert r.exit_code == 2, text
    assert "this adaptive session (--lights 9) needs 9" in text, text
    argv = _advised(text, "Widen the band to hold 9: ", tmp_path, "wide")
    assert "--lights" in argv and argv[argv.index("--lights") + 1] == "9", argv
    r = runner.invoke(app, [*argv, "--no-verdict"])
    assert r.exit_code == 0, said(r)
    assert len(_elevations(tmp_path / "wide")) == 9


def test_a_floor_too_high_is_lowered(tmp_path: Path) -> None:
    out = tmp_path / "s"
    args = ["--adaptive", "--min-elevation-deg", "60"]
    r = runner.invoke(app, ["run", str(NAB), "--out", str(out), *args])
    text = said(r)
    assert r.exit_code == 2, text
    assert "this rig offers 2 lights between 60° and 90° elevation" in text, text
    argv = _advised(text, "Widen the band to hold 5: ", tmp_path, "wide")
    r = runner.invoke(app, [*argv, "--no-verdict"])
    assert r.exit_code == 0, said(r)
    low = float(argv[argv.index("--min-elevation-deg") + 1])
    assert min(_elevations(tmp_path / "wide")) >= low - 1e-6


def test_a_band_with_no_led_is_refused_with_one_that_holds_the_session(tmp_path: Path) -> None:
    """Above 80° on the simulated dome (its highest ring is at 70°): the refusal had been
    "widen --min-elevation-deg / --max-elevation-deg", with no value that would do."""
    out = tmp_path / "s"
    dome = CONFIGS / "simulated_dome.toml"
    r = runner.invoke(
        app, ["run", str(dome), "--out", str(out), "--adaptive", "--min-elevation-deg", "80"]
    )
    text = said(r)
    assert r.exit_code == 2, text
    assert "this rig offers 0 lights between 80° and 90° elevation" in text, text
    assert "planned run" not in text, text  # no light of the band to shoot
    argv = _advised(text, "Widen the band to hold 5: ", tmp_path, "wide")
    r = runner.invoke(app, [*argv, "--no-verdict"])
    assert r.exit_code == 0, said(r)
    low = float(argv[argv.index("--min-elevation-deg") + 1])
    assert len(_elevations(tmp_path / "wide")) >= 5
    assert min(_elevations(tmp_path / "wide")) >= low - 1e-6


@pytest.mark.parametrize("option", ["--lights", "--min-lights"])
def test_more_lights_than_the_band_holds_are_refused_with_a_band_that_holds_them(
    tmp_path: Path, option: str
) -> None:
    """`--lights 14` (or `--until-error … --min-lights 14`) below 10° on the simulated dome,
    whose 10° ring holds 12: "give at most 12 (or widen --min/--max-elevation-deg)" gave no
    value; the band that holds 14 is named, and the session runs in it."""
    dome = CONFIGS / "simulated_dome.toml"
    asked = ["--adaptive", "--lights", "14"] if option == "--lights" else []
    if option == "--min-lights":
        asked = ["--until-error", "30", "--min-lights", "14"]
    band = ["--max-elevation-deg", "10"]
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", str(dome), "--out", str(out), *asked, *band])
    text = said(r)
    assert r.exit_code == 2, text
    assert "this rig offers 12 lights between 0° and 10° elevation" in text, text
    ceiling = text.split("(or widen the band to hold 14: --max-elevation-deg ", 1)[1]
    ceiling = ceiling.split(")", 1)[0]
    r = runner.invoke(
        app,
        [
            "run",
            str(dome),
            "--out",
            str(tmp_path / "wide"),
            *asked,
            "--max-elevation-deg",
            ceiling,
            "--no-verdict",
        ],
    )
    assert r.exit_code == 0, said(r)
    lit = _elevations(tmp_path / "wide")
    assert len(lit) == 14 and max(lit) <= float(ceiling) + 1e-6, lit


@pytest.mark.slow
def test_more_lights_than_an_arm_offers_are_refused_with_a_command_that_runs(
    tmp_path: Path,
) -> None:
    """`--adaptive --lights 130 --max-elevation-deg 30` on the virtual arm: "give at most 120
    (or widen --min/--max-elevation-deg)" gave no value, and no value would do: an arm's
    candidates are a fixed number of directions spread over whatever band is asked, so a wider
    band holds no more. The refusal says so and gives the command with the count it offers,
    which runs in the band. The shipped virtual arm's relief at 96 px (virtual_arm_variant):
    the count an arm offers, the advice and the band are its poses', not its frame size's."""
    arm = virtual_arm_variant(tmp_path, "relief", 96)
    r = runner.invoke(
        app,
        ["run", str(arm), "--out", str(tmp_path / "s"), "--adaptive", "--lights", "130",
         "--max-elevation-deg", "30"],
    )  # fmt: skip
    text = said(r)
    assert r.exit_code == 2, text
    assert "widen --min/--max-elevation-deg" not in text and "a wider band holds no" in text, text
    offered = int(text.split("this rig offers ", 1)[1].split(" lights between 0° and 30°")[0])
    assert offered < 130
    # true of every band: asked at every elevation, the arm offers as many
    r = runner.invoke(app, ["run", str(arm), "--out", str(tmp_path / "s"), "--adaptive",
                            "--lights", "130"])  # fmt: skip
    assert f"this rig offers {offered} lights an adaptive" in said(r), said(r)
    argv = _advised(text, "lighting rules): ", tmp_path, "advised")
    assert argv[argv.index("--lights") + 1] == str(offered), argv
    r = runner.invoke(app, [*argv, "--no-verdict"])
    assert r.exit_code == 0, said(r)
    lit = _elevations(tmp_path / "advised")
    assert len(lit) == offered and max(lit) <= 30.0 + 1e-6, lit


@pytest.mark.parametrize("lights", ["4", "14"])
def test_lights_no_adaptive_session_takes_are_refused_first_with_the_range(
    tmp_path: Path, lights: str
) -> None:
    """--lights 4 (below the start's 4 + 1) and --lights 14 (above the Nab dome's 12 LEDs) in a
    band too narrow: the band's refusal came first, repeating the N asked ("this adaptive
    session (--lights 14) needs 14") and advising another count, so the range was learnt only
    from the advice. The count is refused first, with the range, and no command repeats it;
    the count advised comes with a band that holds it, as "give at most 12" alone was then
    refused for the band (QA, 2026-12-06): the two given together run."""
    out = tmp_path / "s"
    args = ["run", str(NAB), "--out", str(out), "--adaptive", "--lights", lights]
    r = runner.invoke(app, [*args, "--max-elevation-deg", "12"])
    text = said(r)
    assert r.exit_code == 2, text
    assert f"--adaptive --lights {lights}: an adaptive session on this dome takes 5 to 12" in text
    advised = "5" if lights == "4" else "12"
    words = "at least" if lights == "4" else "at most"
    held = f"give {words} {advised}, in a band that holds {advised} (this one between 0° and 12°"
    assert held in text and "elevation holds 0): --max-elevation-deg " in text, text
    assert "rti-rig run" not in text, text
    assert not out.exists()
    ceiling = text.split("elevation holds 0): --max-elevation-deg ")[1].split()[0]
    args[-1] = advised
    r = runner.invoke(app, [*args, "--max-elevation-deg", ceiling, "--no-verdict"])
    assert r.exit_code == 0, said(r)
    assert len(_elevations(out)) == int(advised)


@pytest.mark.parametrize(
    ("asked", "refused"),
    [
        (["--until-error", "3", "--objective", "relight"], "--until-error goes with --objective"),
        (["--adaptive", "--lights", "6", "--objective", "foo"], "--objective foo: an adaptive"),
    ],
)
def test_options_refused_on_their_own_are_refused_before_a_band_is_advised(
    tmp_path: Path, asked: list[str], refused: str
) -> None:
    """A band too narrow had been refused first with a command repeating the options, which
    pasted was refused for them ('--until-error 3 --objective relight … --max-elevation-deg
    20'): the options' own refusal comes first, and advises no such command."""
    out = tmp_path / "s"
    r = runner.invoke(
        app, ["run", str(NAB), "--out", str(out), *asked, "--max-elevation-deg", "12"]
    )
    text = said(r)
    assert r.exit_code == 2, text
    assert refused in text and "rti-rig run" not in text, text


def test_an_arm_asked_a_minimum_above_what_it_offers_too_is_advised_both_lowered(
    tmp_path: Path,
) -> None:
    """`--until-error 5 --lights 130 --min-lights 125 --max-elevation-deg 30` on the virtual
    arm (120 in reach): the command advised for --lights kept --min-lights 125, which that
    command then refused as "above --lights 120, the session's maximum"."""
    arm = CONFIGS / "virtual_arm.toml"
    r = runner.invoke(
        app,
        ["run", str(arm), "--out", str(tmp_path / "s"), "--until-error", "5", "--lights", "130",
         "--min-lights", "125", "--max-elevation-deg", "30"],
    )  # fmt: skip
    text = said(r)
    assert r.exit_code == 2 and "--lights 130: this rig offers" in text, text
    argv = _advised(text, "lighting rules): ", tmp_path, "advised")
    most = int(argv[argv.index("--lights") + 1])
    assert most < 125 and int(argv[argv.index("--min-lights") + 1]) == most, argv
    assert argv[argv.index("--until-error") + 1] == "5", argv
    assert not (tmp_path / "s").exists()


def test_the_band_advised_to_a_dome_keeps_the_objective_asked(tmp_path: Path) -> None:
    """``--objective relight`` is part of the session asked: the dome's widened-band command
    had left it out (the arm's kept it), so the pasted command chose for normals."""
    out = tmp_path / "s"
    args = ["--adaptive", "--lights", "6", "--objective", "relight", "--max-elevation-deg", "20"]
    r = runner.invoke(app, ["run", str(NAB), "--out", str(out), *args])
    text = said(r)
    assert r.exit_code == 2, text
    assert not out.exists()
    assert (
        f"--out {out} --adaptive --lights 6 --objective relight --max-elevation-deg 37 (6 lights"
    ) in text, text


def test_a_count_only_every_elevation_holds_is_advised_without_a_band(tmp_path: Path) -> None:
    """--lights 200 between 10° and 30° on a 48-LED dome: only every elevation holds 48, and
    the advice had ended in a colon with no option after it."""
    out = tmp_path / "s"
    r = runner.invoke(
        app,
        ["run", str(CONFIGS / "emulated_dome.toml"), "--out", str(out), "--adaptive",
         "--lights", "200", "--min-elevation-deg", "10", "--max-elevation-deg", "30"],
    )  # fmt: skip
    text = said(r)
    assert r.exit_code == 2, text
    assert "give at most 48, in a band that holds 48 (this one between 10° and 30° elevation " in (
        text
    )
    assert "every elevation (drop --min-elevation-deg and --max-elevation-deg)" in text, text
    assert not out.exists()
