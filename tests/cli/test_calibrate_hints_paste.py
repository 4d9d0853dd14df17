"""``calibrate-lights`` refusals give the command to run next, pasteable, with the user's options.

Why: a card session calibrated already was refused only after every card image had been read
(minutes for a real dome's full-size TIFFs), then told "give --out"; an object's session was
told "Shoot a level matte white card" and "give --not-flat-ok". The user had to rebuild each
command, their --card-normal and --min-elevation-deg included. Each hint's command is run here
as printed (split as a shell splits it).
"""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import pytest
from card_support import card_rig
from conftest import said
from typer.testing import CliRunner

from rti_rig.app.usecases import calibrate as usecase
from rti_rig.cli import app

runner = CliRunner()


@pytest.fixture(scope="module")
def card(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    """A card rig and a card session of 12 of its LEDs (enough to calibrate: the others are
    taken at the median), in a folder whose name holds a space."""
    where = tmp_path_factory.mktemp("card hints")
    rig = card_rig(where)
    session = where / "card sess"
    r = runner.invoke(app, ["run", str(rig), "--out", str(session), "--lights", "12"])
    assert r.exit_code == 0, r.output
    return rig, session


def _advised(text: str, start: str) -> list[str]:
    """The command beginning ``start`` in ``text`` (up to the end or a ``;``/``)``), as a shell
    splits it, without the leading ``rti-rig``."""
    found = re.search(re.escape(start) + r"[^;)]*", text)
    assert found, text
    words = shlex.split(found.group(0))
    assert words[0] == "rti-rig", words
    return words[1:]


def test_a_session_calibrated_already_is_refused_before_its_images_are_read(
    card: tuple[Path, Path], monkeypatch: pytest.MonkeyPatch
) -> None:
    rig, session = card
    first = runner.invoke(app, ["calibrate-lights", str(session), "--rig", str(rig)])
    assert first.exit_code == 0, first.output
    with monkeypatch.context() as m:
        read: list[Path] = []
        m.setattr(usecase, "read_card_session", lambda root, **_: read.append(root))
        r = runner.invoke(
            app,
            ["calibrate-lights", str(session), "--rig", str(rig), "--min-elevation-deg", "7"],
        )
    text = said(r)
    assert r.exit_code == 2, text
    assert "calibrated already" in text, text
    assert read == [], "the card images were read before the refusal"
    again = _advised(text, "rti-rig calibrate-lights")
    assert again[again.index("--min-elevation-deg") + 1] == "7", again
    out = Path(again[again.index("--out") + 1])
    assert not out.exists() and out.parent == session.parent, again
    done = runner.invoke(app, again)
    assert done.exit_code == 0, done.output
    assert 'format = "rti-rig-light-calibration/1"' in out.read_text()
    out.unlink()
    (session / "light_calibration.toml").unlink()  # the session as the next test finds it


def test_a_session_not_of_a_flat_card_is_told_both_commands(
    card: tuple[Path, Path], monkeypatch: pytest.MonkeyPatch
) -> None:
    rig, session = card
    (session / "light_calibration.toml").unlink(missing_ok=True)  # whatever the last test left
    # the refusal's words, not the spread's measure, are under test: the card reads as relief
    monkeypatch.setattr(usecase, "card_spread_deg", lambda _card: 14.0)
    r = runner.invoke(
        app, ["calibrate-lights", str(session), "--rig", str(rig), "--card-normal", "0,0.05,1"]
    )
    text = said(r)
    assert r.exit_code == 2, text
    assert "not of a flat card" in text, text
    shoot_again = _advised(text, "rti-rig run")
    assert shoot_again[:2] == ["run", str(rig)], shoot_again
    assert not Path(shoot_again[shoot_again.index("--out") + 1]).exists(), shoot_again
    anyway = _advised(text, "rti-rig calibrate-lights")
    assert "--not-flat-ok" in anyway and "--card-normal" in anyway, anyway
    done = runner.invoke(app, anyway)
    assert done.exit_code == 0, done.output
    assert (session / "light_calibration.toml").is_file()
    (session / "light_calibration.toml").unlink()
