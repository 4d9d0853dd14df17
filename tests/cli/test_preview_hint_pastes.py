"""The preview's closing lines run when pasted as printed, and a word given to a whole-number
or number option is refused naming the option and the value, through the front door.

Why: the preview said ``rti-rig plan PREVIEW --rig RIG --lights N --out plan.lp`` (and, after
``--auto-exposure``, ``run ... --out SESSION``); pasted, ``--lights N`` was refused with typer's
"Input should be a valid integer, unable to parse string as an integer", naming neither the
option's value nor what to give."""

from __future__ import annotations

import os
import shlex
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import REPO, dome_variant
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()


def _line(output: str, start: str) -> list[str]:
    """The words of the printed line that begins with ``start``, after "rti-rig"."""
    for line in output.splitlines():
        if line.startswith(start):
            words = shlex.split(line[len(start) :])
            assert words[0] == "rti-rig", line
            return words[1:]
    raise AssertionError(f"no line starting {start!r} in:\n{output}")


@pytest.fixture(scope="module")
def small_dome(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return dome_variant(tmp_path_factory.mktemp("dome"), "tablet", 64)


def test_the_preview_plan_line_runs_as_printed(
    small_dome: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    (tmp_path / "plan.lp").write_text("taken\n")  # a name already used is not suggested
    preview = tmp_path / "preview"
    r = runner.invoke(app, ["preview", str(small_dome), "--out", str(preview)])
    assert r.exit_code == 0, r.output
    words = _line(r.output, "Plan from it: ")
    assert "N" not in words and words[words.index("--out") + 1] == "plan-2.lp", words
    r = runner.invoke(app, words)
    assert r.exit_code == 0, r.output
    assert (tmp_path / "plan-2.lp").is_file() and (tmp_path / "plan.lp").read_text() == "taken\n"


def test_a_band_with_fewer_leds_than_the_default_count_is_planned_as_printed(
    small_dome: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Above 60° the shipped dome has 6 LEDs: the line asks for those 6, not for 12 (which
    plan would refuse), and carries the band."""
    monkeypatch.chdir(tmp_path)
    preview = tmp_path / "preview"
    argv = ["preview", str(small_dome), "--out", str(preview), "--min-elevation-deg", "60"]
    r = runner.invoke(app, argv)
    assert r.exit_code == 0, r.output
    words = _line(r.output, "Plan from it: ")
    assert words[words.index("--lights") + 1] == "6", words
    assert words[words.index("--min-elevation-deg") + 1] == "60", words
    r = runner.invoke(app, words)
    assert r.exit_code == 0, r.output
    assert "Planned 6 lights" in " ".join(r.output.split())


def test_a_word_for_a_count_names_the_option_and_the_value(tmp_path: Path) -> None:
    r = runner.invoke(app, ["plan", "--lights", "N", "--out", str(tmp_path / "p.lp")])
    assert r.exit_code == 2
    text = " ".join(r.output.split())
    assert "--lights: 'N' is not a whole number: give one in digits, e.g. --lights 12" in text
    assert "Input should be" not in text and not (tmp_path / "p.lp").exists()


@pytest.mark.parametrize(
    ("argv", "said"),
    [
        (["run", "RIG", "--lights", "1.5"], "--lights: '1.5' is not a whole number"),
        (["plan", "--min-elevation-deg", "low"], "--min-elevation-deg: 'low' is not a number"),
        (["fit", "S", "--out", "F", "--hsh-order", "two"], "--hsh-order: 'two' is not a whole"),
    ],
)
def test_numbers_refused_through_python_m(argv: list[str], said: str, tmp_path: Path) -> None:
    r = subprocess.run(
        [sys.executable, "-m", "rti_rig", *argv],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        env={**os.environ, "PYTHONPATH": str(REPO)},
        timeout=300,
    )
    assert r.returncode == 2, r.stderr
    text = " ".join(r.stderr.split())
    assert said in text and "Input should be" not in text and "Traceback" not in text, text


def test_a_number_out_of_range_keeps_its_own_words(tmp_path: Path) -> None:
    r = runner.invoke(app, ["plan", "--lights", "0", "--out", str(tmp_path / "p.lp")])
    assert r.exit_code == 2 and "not a whole number" not in r.output
