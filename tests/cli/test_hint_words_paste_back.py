"""Every command a user is told to run names its folder as a word the shell reads back as that
folder, where the streams cannot print the name (bytes that are not UTF-8, an ASCII locale).

Why: the hints built below the CLI (the runtime's "continue it with rti-rig run --resume ...",
the fit's "rti-rig export-lp ...", the calibration's) used ``shlex.quote``, which said such a
folder as ``'/s/caf\\udce9'``: pasted back, that names no folder. Through ``python -m rti_rig``
in a C locale with an ASCII stdout, as a script on a legacy system runs it; each word is given
to bash as the user would paste it.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from card_support import card_rig
from conftest import ASCII_LOCALE_ENV as ENV
from conftest import CONFIGS, pasted
from conftest import DOLLAR_WORD as WORD
from conftest import NOT_UTF8_NAME as NAME
from conftest import rti_rig_in_ascii_locale as rti_rig


def words_after(said: bytes, before: bytes) -> list[bytes]:
    """The ``$'...'`` words that follow ``before`` in ``said``, each pasted into bash."""
    assert before in said, said
    return [pasted(w) for w in WORD.findall(said.split(before, 1)[1])]


@pytest.fixture(scope="module")
def session(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A finished 4-light simulated session in a folder whose name is not UTF-8."""
    root = tmp_path_factory.mktemp("words") / os.fsdecode(NAME) / "S"
    r = rti_rig(
        "run", CONFIGS / "simulated_dome.toml", "--lights", "4", "--out", root, "--no-verdict"
    )
    assert r.returncode == 0, r.stderr
    assert (root / "lights.lp").is_file()
    return root


def test_a_run_into_a_finished_session_names_it_and_its_fit_as_words_that_paste_back(
    session: Path,
) -> None:
    r = rti_rig("run", CONFIGS / "simulated_dome.toml", "--lights", "4", "--out", session)
    assert r.returncode == 2, r.stderr
    assert b"is not empty" in r.stderr and b"udce9" not in r.stderr, r.stderr
    # the folder refused, the new folder it offers (free, beside it), the fit its hint gives
    # (the session's own bytes) and the free folder beside it the hint gives the fit's --out
    here, fit_out = os.fsencode(session), os.fsencode(session) + b"-fit"
    assert words_after(r.stderr, b"error: ") == [here, here + b"-2", here, fit_out], r.stderr
    assert b"rti-rig fit $'" in r.stderr, r.stderr


def test_a_resume_of_a_complete_session_gives_its_fit_as_a_word_that_pastes_back(
    session: Path,
) -> None:
    r = rti_rig("run", "--resume", session)
    assert r.returncode == 0, r.stderr
    # the fit's --out is a folder beside the session, free, as a word too (it had been FOLDER)
    fit_out = os.fsencode(session.with_name(session.name + "-fit"))
    said_session = os.fsencode(session)
    assert words_after(r.stdout, b"Next: rti-rig fit ") == [said_session, fit_out], r.stdout
    assert words_after(r.stdout, b" --out ") == [fit_out], r.stdout
    assert words_after(r.stdout, b": this session is complete") == [said_session, fit_out]
    assert r.stdout.startswith(b"$'"), r.stdout  # and the session it names, as said first
    words = [pasted(w) for w in WORD.findall(r.stdout)]
    assert words == [said_session, said_session, fit_out], r.stdout
    assert b"udce9" not in r.stdout, r.stdout


def test_a_fit_of_a_session_without_its_lp_gives_an_export_lp_that_runs_as_pasted(
    session: Path, tmp_path: Path
) -> None:
    copy = tmp_path / os.fsdecode(b"\xe9 lp") / "S"
    shutil.copytree(session, copy)
    (copy / "lights.lp").unlink()
    r = rti_rig("fit", copy, "--out", tmp_path / "fit")
    assert r.returncode == 2, r.stderr
    said = r.stderr.decode("ascii")
    command = said.split("with: ", 1)[1].split("\n", 1)[0].strip()
    assert command.startswith("rti-rig export-lp $'"), said
    folder, lp = os.fsencode(copy), os.fsencode(copy / "lights.lp")
    assert words_after(r.stderr, b"error: ") == [folder, folder, lp], said
    # the command as printed, run by bash: it writes the .lp back into the same folder
    done = subprocess.run(
        ["bash", "-c", command.replace("rti-rig", '"$PY" -m rti_rig', 1)],
        capture_output=True,
        env={**ENV, "PY": sys.executable},
        timeout=600,
    )
    assert done.returncode == 0, done.stderr
    assert (copy / "lights.lp").read_bytes() == (session / "lights.lp").read_bytes()


def test_a_calibration_of_an_unfinished_card_session_gives_its_resume_as_a_word_that_pastes_back(
    tmp_path: Path,
) -> None:
    # its rig config in such a folder too: its emulated dome's duty ledger is keyed by its path
    (tmp_path / os.fsdecode(b"rig \xe9")).mkdir()
    cfg = card_rig(tmp_path / os.fsdecode(b"rig \xe9"))
    card = tmp_path / os.fsdecode(b"card \xe9") / "C"
    r = rti_rig("run", cfg, "--lights", "6", "--out", card, "--no-verdict")
    assert r.returncode == 0, r.stderr
    # as a kill leaves it: the manifest as the run began, its images in the journal
    manifest = json.loads((card / "manifest.json").read_text(encoding="utf-8"))
    manifest["runner"], manifest["steps"] = {"state": "running", "finish_reason": None}, []
    (card / "manifest.json").write_text(json.dumps(manifest), encoding="utf-8")
    r = rti_rig("calibrate-lights", card, "--rig", cfg)
    assert r.returncode == 2, r.stderr
    assert b"did not finish" in r.stderr, r.stderr
    said = words_after(r.stderr, b"continue it with rti-rig run --resume ")
    assert said == [os.fsencode(card)], r.stderr
    assert words_after(r.stderr, b"error: ") == [os.fsencode(card)] * 2, r.stderr
