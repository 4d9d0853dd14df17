"""An error names its folder or file as the path on disk, where the streams cannot print it,
and calibrate-lights' line to paste into a rig config is a TOML string that reads back as its
file's name.

Why: the errors began with the raw path (``f"{root}: ..."``): in a C locale with an ASCII stdout,
a folder whose name is not UTF-8 was said as ``caf?`` or ``caf\\udce9``, neither of which names
it; and ``intensity_correction_file = "{rel}"`` was printed unescaped, a line TOML refuses (a
quote, a backslash) or cannot hold (bytes that are not UTF-8). Through ``python -m rti_rig``,
each word given to bash as the user would paste it.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import tomllib
from pathlib import Path

import pytest
from card_support import card_rig, shoot
from conftest import CONFIGS, pasted, rti_rig_in_ascii_locale
from conftest import DOLLAR_WORD as WORD
from conftest import NOT_UTF8_NAME as NAME


def rti_rig(*args: str | Path) -> subprocess.CompletedProcess[bytes]:
    r = rti_rig_in_ascii_locale(*args)
    assert b"unexpected" not in r.stderr, r.stderr
    assert b"udce9" not in r.stderr + r.stdout, r.stderr
    return r


def first_word_after_error(said: bytes) -> bytes:
    """The ``$'...'`` word that opens the error, as bash reads it back pasted."""
    assert said.startswith(b"error: $'"), said
    word = WORD.match(said, len(b"error: "))
    assert word is not None, said
    return pasted(word[0])


@pytest.fixture
def odd(tmp_path: Path) -> Path:
    """A folder whose name is not UTF-8."""
    folder = tmp_path / os.fsdecode(NAME)
    folder.mkdir()
    return folder


def test_a_fit_of_a_folder_with_no_lp_names_it_as_on_disk(odd: Path, tmp_path: Path) -> None:
    (odd / "empty").mkdir()
    r = rti_rig("fit", odd / "empty", "--out", tmp_path / "fit")
    assert r.returncode == 2, r.stderr
    assert b"holds no .lp file" in r.stderr, r.stderr
    assert first_word_after_error(r.stderr) == os.fsencode(odd / "empty")


def test_a_resume_of_a_folder_that_is_no_session_names_it_as_on_disk(odd: Path) -> None:
    r = rti_rig("run", "--resume", odd)
    assert r.returncode == 2, r.stderr
    assert b"has no manifest.json" in r.stderr, r.stderr
    assert first_word_after_error(r.stderr) == os.fsencode(odd)


def test_a_check_of_a_missing_rig_config_names_it_as_on_disk(odd: Path) -> None:
    r = rti_rig("check", odd / "rig.toml")
    assert r.returncode == 2, r.stderr
    assert b"cannot read the file" in r.stderr, r.stderr
    assert first_word_after_error(r.stderr) == os.fsencode(odd / "rig.toml")


def test_a_run_with_a_plan_in_such_a_folder_that_is_no_lp_names_it_as_on_disk(odd: Path) -> None:
    (odd / "plan.lp").write_text("not a light list\n", encoding="utf-8")
    r = rti_rig(
        "run", CONFIGS / "simulated_dome.toml", "--plan", odd / "plan.lp", "--out", odd / "S"
    )
    assert r.returncode == 2, r.stderr
    assert first_word_after_error(r.stderr) == os.fsencode(odd / "plan.lp")
    assert not (odd / "S").exists()


def test_a_plan_s_note_and_refusal_name_it_as_on_disk(odd: Path) -> None:
    """The .lp's notes ("count line says 3") and the plan's refusal for a light no LED is near
    had begun with the raw path: ``caf\\udce9`` in a C locale, naming no file."""
    # a count one too many, and a light 7.65° from the nearest LED of the simulated dome
    (odd / "plan.lp").write_text("3\nx1.jpg 0.3 0.3 0.9055\nx2.jpg 0.2 0.1 0.97\n")
    r = rti_rig(
        "run", CONFIGS / "simulated_dome.toml", "--plan", odd / "plan.lp", "--out", odd / "S"
    )
    assert r.returncode == 2, r.stderr
    note = r.stderr[r.stderr.index(b"note: ") + len(b"note: ") :]
    word = WORD.match(note)
    assert word is not None and b", line 1: count line says 3 lights" in note, r.stderr
    assert pasted(word[0]) == os.fsencode(odd / "plan.lp")
    error = r.stderr[r.stderr.index(b"error: ") :]
    assert first_word_after_error(error) == os.fsencode(odd / "plan.lp")
    assert b"light 1 (x1.jpg): no LED of this dome within" in error, error
    assert b"(nearest is LED 43 (az 60.0" in error, error  # by its direction, as words say LEDs
    assert not (odd / "S").exists()


@pytest.fixture(scope="module")
def card(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    """A card session shot on the emulated dome, and its rig config (both in ASCII folders)."""
    root = tmp_path_factory.mktemp("card")
    cfg = card_rig(root)
    # the emulator waits out the rig's timing: short ones keep 48 images quick
    text = cfg.read_text(encoding="utf-8")
    for key in ("settle_s = 0.1", "readout_s = 0.3", "transfer_s = 0.7"):
        assert key in text, key
        text = text.replace(key, key.split("=")[0] + "= 0.01")
    cfg.write_text(text, encoding="utf-8")
    shoot(cfg, root / "card")
    return root / "card", cfg


def test_a_calibration_named_in_bytes_toml_cannot_hold_is_refused_before_it_is_measured(
    card: tuple[Path, Path], odd: Path
) -> None:
    session, cfg = card
    target = odd / "cal.toml"
    r = rti_rig("calibrate-lights", session, "--rig", cfg, "--out", target)
    assert r.returncode == 2, r.stderr
    assert b"not UTF-8 text, which a TOML file cannot hold" in r.stderr, r.stderr
    assert b"nothing was measured or written" in r.stderr, r.stderr
    assert first_word_after_error(r.stderr) == os.fsencode(target)
    assert not target.exists()


def test_the_line_to_paste_names_a_quote_and_backslash_as_toml_reads_them(
    card: tuple[Path, Path], tmp_path: Path
) -> None:
    session, cfg = card
    target = tmp_path / 'a "cal" \\ b' / "c.toml"
    target.parent.mkdir()
    r = rti_rig("calibrate-lights", session, "--rig", cfg, "--out", target)
    assert r.returncode == 0, r.stderr
    [line] = [ln for ln in r.stdout.decode("ascii").splitlines() if "correction_file" in ln]
    named = tomllib.loads(line)["intensity_correction_file"]
    assert (cfg.parent / named).resolve() == target.resolve(), line
    assert target.is_file()


def test_a_calibration_written_into_such_a_card_session_says_how_to_give_it_to_toml(
    card: tuple[Path, Path], odd: Path
) -> None:
    session, cfg = card
    copy = odd / "card"
    shutil.copytree(session, copy)
    r = rti_rig("calibrate-lights", copy, "--rig", cfg)
    assert r.returncode == 0, r.stderr  # measured and written: nothing to refuse
    target = copy / "light_calibration.toml"
    # written whole, and TOML: the session's name recorded in it as text (it had ended in a
    # traceback, UnicodeEncodeError, as the file was written)
    written = tomllib.loads(target.read_text(encoding="utf-8"))
    assert len(written["intensity_correction"]) == 48
    assert written["session"].endswith("caf\\xe9 it's/card"), written["session"]
    assert b"intensity_correction_file = " not in r.stdout, r.stdout  # no line TOML holds
    said = r.stderr.split(b"warning: ", 1)[1]
    assert b"not UTF-8 text, which a TOML file cannot hold" in said, r.stderr
    assert pasted(WORD.match(said)[0]) == os.fsencode(target), r.stderr
    assert pasted(WORD.match(said.split(b"(cp ", 1)[1])[0]) == os.fsencode(target), r.stderr


def test_tradeoff_from_a_folder_with_no_lp_names_it_as_on_disk(odd: Path) -> None:
    """`bench tradeoff --from` had said the folder as Python's escape ('caf\\udce9'), which no
    shell reads back as the folder."""
    r = rti_rig("bench", "tradeoff", "--from", odd)
    assert r.returncode == 2, r.stderr
    said = r.stderr + r.stdout
    assert b"a folder with no .lp file" in said, said
    assert said.startswith(b"error: --from $'"), said
    word = WORD.match(said, len(b"error: --from "))
    assert word is not None and pasted(word[0]) == os.fsencode(odd), said
