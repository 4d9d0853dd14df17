"""`rti-rig run RIG --plan X` with X not an `.lp` says what X is and what to give.

Found by a front-door audit: `--plan` an image (a JPEG of the session) was told "line 1: the
line holds NUL bytes: not plain text (UTF-16 …?) … save it again as UTF-8", `--plan` the rig
config "line 4: expected 'name x y z'", and `--plan` a session folder "cannot read: Is a
directory". Nothing was shot in any case; the messages sent the user after the wrong fault.
A rig config given as the plan was then told "this is a TOML file (a rig config?)", a guess:
it is said to be one, with what --plan takes and the commands that make and run a plan.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import CONFIGS, at_key
from typer.testing import CliRunner

from rti_rig.cli import app

REPO = Path(__file__).resolve().parents[2]
ACQ = REPO / "tests" / "data" / "neuralrti_replay"
runner = CliRunner()


@pytest.mark.parametrize(
    ("given", "said"),
    [
        (ACQ / "image01.jpg", "this is an image, not an .lp file"),
        (ACQ, "is a folder, not an .lp file"),
    ],
)
def test_a_plan_that_is_not_an_lp_is_named_for_what_it_is(
    tmp_path: Path, given: Path, said: str
) -> None:
    out = tmp_path / "session"
    r = runner.invoke(
        app, ["run", str(CONFIGS / "simulated_dome.toml"), "--out", str(out), "--plan", str(given)]
    )
    text = "".join(r.output.split())
    assert r.exit_code == 2, r.output
    assert "Traceback" not in r.output
    assert "".join(f"{given}: {said}: --plan takes a plan, the .lp light list".split()) in text, (
        r.output
    )
    assert "NUL" not in text and "expected'namexyz'" not in text
    assert not out.exists()


def test_a_rig_config_given_as_the_plan_is_said_to_be_one_with_the_commands_to_make_a_plan(
    tmp_path: Path,
) -> None:
    rig = CONFIGS / "simulated_dome.toml"
    for given in (rig, CONFIGS / "example_dome_48_folder_watch.toml"):
        out = tmp_path / "session"
        r = CliRunner(env={"COLUMNS": "400"}).invoke(
            app, ["run", str(rig), "--out", str(out), "--plan", str(given)]
        )
        assert r.exit_code == 2, r.output
        assert "Traceback" not in r.output
        text = " ".join(r.output.split())
        assert f"--plan {given} is a rig config (" in text, text
        assert (
            "), not a plan: --plan takes a plan file, the .lp light list (a count line, then "
            "'name x y z' per image) that rti-rig plan writes; make one with: rti-rig plan "
            f"--rig {rig} --out plan.lp, then run it with: rti-rig run {rig} --plan plan.lp "
            f"--out {out} (or run a homogeneous layout without a plan: rti-rig run {rig} "
            f"--lights 12 --out {out})"
        ) in text, text
        assert "a rig config?" not in text
        assert not out.exists()


def test_a_toml_file_that_is_no_rig_config_given_as_the_plan_is_said_to_be_toml(
    tmp_path: Path,
) -> None:
    """Only a file that is a rig config is called one: another TOML file (a light
    calibration) is told it is TOML, not an .lp, and what --plan takes; it had been asked
    "(a rig config?)", where the file had just been found to be none."""
    other = tmp_path / "calibration.toml"
    other.write_text('format = "rti-rig-light-calibration/1"\nrig = "x"\n', encoding="utf-8")
    r = runner.invoke(
        app,
        [
            "run",
            str(CONFIGS / "simulated_dome.toml"),
            "--out",
            str(tmp_path / "s"),
            "--plan",
            str(other),
        ],
    )
    assert r.exit_code == 2, r.output
    text = "".join(r.output.split())
    assert "thisisaTOMLfile" in text and "isarigconfig" not in text, r.output
    assert "arigconfig?" not in text, r.output
    assert (
        "".join(f"{other}: this is a TOML file, not an .lp: --plan takes a plan, the .lp".split())
        in text
    ), r.output


def test_a_dome_lp_file_that_is_toml_is_told_what_the_key_names(tmp_path: Path) -> None:
    """A rig whose ``dome.lp_file`` names a TOML file is told what that key names, not asked
    "(a rig config?)": the rig config is the file that names it."""
    other = tmp_path / "lights.toml"
    other.write_text("a = 1\n", encoding="utf-8")
    text = (CONFIGS / "example_dome_48.toml").read_text(encoding="utf-8")
    assert 'lp_file = "example_dome_48.lp"' in text
    rig = tmp_path / "rig.toml"
    rig.write_text(text.replace('"example_dome_48.lp"', '"lights.toml"'), encoding="utf-8")
    r = runner.invoke(app, ["check", str(rig)])
    assert r.exit_code == 2, r.output
    assert "Traceback" not in r.output
    said = "".join(r.output.split())
    assert "arigconfig?" not in said, r.output
    assert (
        "".join(
            f"{at_key(rig, 'dome.lp_file')}: {other}: this is a TOML file, not an .lp: "
            "dome.lp_file "
            "names the dome's .lp light list".split()
        )
        in said
    ), r.output
