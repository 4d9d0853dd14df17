"""`calibrate-lights` refuses a rig config whose LEDs are numbered otherwise than the card's.

Why: the correction is a list by LED number, and only the rig's name was compared with the
card session's. A config of the same name whose `.lp` lists the LEDs in another order was
given the correction measured under other LEDs (its LED 18, led_42.jpg, corrected by what the
card measured under led_18.jpg), with no word; the session's recorded rig identity says which
LED each number was.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from card_support import card_rig, shoot
from conftest import CONFIGS, said
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()


def _rig_with_lights(rig: Path, name: str, lines: list[str]) -> Path:
    """The card rig's config, beside it as other.toml, given ``lines`` as its .lp
    (``name``.lp) in place of the shipped example_dome_48.lp the card was shot with."""
    lp = rig.parent / f"{name}.lp"
    lp.write_text("\n".join(lines) + "\n")
    text = rig.read_text().replace(f"{CONFIGS}/example_dome_48.lp", str(lp))
    assert str(lp) in text
    other = rig.parent / "other.toml"
    other.write_text(text)
    return other


def _card_and_reordered_rig(tmp_path: Path) -> tuple[Path, Path, Path]:
    """A card session shot on the card rig, and that rig with its LEDs listed in another
    order (the second half first): the rig config, the card folder and the reordered config."""
    rig = card_rig(tmp_path)
    card = tmp_path / "card"
    shoot(rig, card)
    count, *rows = (CONFIGS / "example_dome_48.lp").read_text().splitlines()
    return rig, card, _rig_with_lights(rig, "reordered", [count, *rows[24:], *rows[:24]])


def test_a_card_session_calibrated_against_reordered_leds_is_refused(tmp_path: Path) -> None:
    _, card, other = _card_and_reordered_rig(tmp_path)
    out = tmp_path / "cal.toml"

    r = runner.invoke(app, ["calibrate-lights", str(card), "--rig", str(other), "--out", str(out)])

    assert r.exit_code == 2, r.output
    message = said(r)
    assert "Traceback" not in r.output
    assert "light positions: 48 of 48 LEDs moved" in message, message
    assert "shoot the card again on the rig as it is now" in message, message
    assert not out.exists()


def test_a_card_of_other_leds_is_refused_for_them_before_any_image_is_read(
    tmp_path: Path,
) -> None:
    """The LEDs a card was shot with are in its manifest: a card of others is refused for
    that before its images are read. Every image was read (and checked against the journal)
    first, so a card whose images were gone was refused for those, never for its LEDs."""
    _, card, other = _card_and_reordered_rig(tmp_path)
    for image in [*card.glob("image_*"), *(card / "linear").glob("*.tif")]:
        image.unlink()  # nothing left to read: a refusal that reads them says so instead
    out = tmp_path / "cal.toml"

    r = runner.invoke(app, ["calibrate-lights", str(card), "--rig", str(other), "--out", str(out)])

    assert r.exit_code == 2, r.output
    message = said(r)
    assert "Traceback" not in r.output
    assert "light positions: 48 of 48 LEDs moved" in message, message
    assert "missing" not in message, message
    assert not out.exists()


def test_the_rig_config_the_card_was_shot_with_still_calibrates(tmp_path: Path) -> None:
    rig = card_rig(tmp_path)
    card = tmp_path / "card"
    shoot(rig, card)
    out = tmp_path / "cal.toml"

    r = runner.invoke(app, ["calibrate-lights", str(card), "--rig", str(rig), "--out", str(out)])

    assert r.exit_code == 0, r.output
    assert out.is_file()


def _re_measured(rig: Path) -> Path:
    """The card rig with its .lp measured again: the whole dome 0.5° further round, every
    LED moved and each still nearest its own old position."""
    count, *rows = (CONFIGS / "example_dome_48.lp").read_text().splitlines()
    turn = np.radians(0.5)
    c, s = np.cos(turn), np.sin(turn)
    moved = []
    for row in rows:
        name, x, y, z = row.split()
        xf, yf = float(x), float(y)
        moved.append(f"{name} {c * xf - s * yf:.6f} {s * xf + c * yf:.6f} {z}")
    return _rig_with_lights(rig, "remeasured", [count, *moved])


def _as_recorded_with_a_digest_alone(card: Path) -> None:
    """The card session's manifest as versions before per-LED identity wrote it: its rig
    identity holds the positions' digest (light_positions) and no light_directions,
    dome_firmware or dome_protocol."""
    manifest = json.loads((card / "manifest.json").read_text())
    for key in ("light_directions", "dome_firmware", "dome_protocol"):
        del manifest["rig"]["identity"][key]
    assert "light_positions" in manifest["rig"]["identity"]
    (card / "manifest.json").write_text(json.dumps(manifest))


def test_leds_re_measured_in_place_still_calibrate(tmp_path: Path) -> None:
    """The same LEDs with re-measured positions (each still nearest its own recorded one, a
    finer .lp written after the card was shot) are not "other LEDs": the correction by LED
    number holds. They were refused as LEDs "others than the rig config gives now"."""
    rig = card_rig(tmp_path)
    card = tmp_path / "card"
    shoot(rig, card)
    other = _re_measured(rig)
    out = tmp_path / "cal.toml"

    r = runner.invoke(app, ["calibrate-lights", str(card), "--rig", str(other), "--out", str(out)])

    assert r.exit_code == 0, r.output
    message = said(r)
    assert "others than" not in message, message
    assert "48 of 48 LEDs moved" in message, message
    assert "each still nearest its own recorded position" in message, message
    assert out.is_file()


def test_an_older_card_session_of_leds_re_measured_in_place_still_calibrates(
    tmp_path: Path,
) -> None:
    """A card session recorded with a digest of the LEDs' positions alone, calibrated after
    the .lp was measured again, is compared at the positions its steps record (where the
    card is read): the same LEDs re-measured, with the note a newer session gets. It was
    refused as "others" (its positions "not known"), though a session recorded before
    identities at all is not asked."""
    rig = card_rig(tmp_path)
    card = tmp_path / "card"
    shoot(rig, card)
    _as_recorded_with_a_digest_alone(card)
    out = tmp_path / "cal.toml"

    r = runner.invoke(
        app, ["calibrate-lights", str(card), "--rig", str(_re_measured(rig)), "--out", str(out)]
    )

    assert r.exit_code == 0, r.output
    message = said(r)
    assert "others than" not in message, message
    assert "each still nearest its own recorded position (as its steps record them" in message
    assert out.is_file()


def test_an_older_card_session_of_reordered_leds_is_still_refused(tmp_path: Path) -> None:
    _, card, other = _card_and_reordered_rig(tmp_path)
    _as_recorded_with_a_digest_alone(card)
    out = tmp_path / "cal.toml"

    r = runner.invoke(app, ["calibrate-lights", str(card), "--rig", str(other), "--out", str(out)])

    assert r.exit_code == 2, r.output
    assert "others than" in said(r), r.output
    assert not out.exists()


@pytest.mark.parametrize(
    "era",
    [("identity",), ("light_directions", "dome_firmware", "dome_protocol")],
    ids=["before-identities", "before-positions-and-firmware"],
)
def test_a_card_session_recorded_before_the_keys_it_lacks_still_calibrates(
    tmp_path: Path, era: tuple[str, ...]
) -> None:
    """A card session written before the rig identity (or before its positions and firmware
    profile were part of it) is not asked what it does not record, as a resume does not ask."""
    rig = card_rig(tmp_path)
    card = tmp_path / "card"
    shoot(rig, card)
    manifest = json.loads((card / "manifest.json").read_text())
    for key in era:
        if key == "identity":
            del manifest["rig"]["identity"]
        else:
            del manifest["rig"]["identity"][key]
    (card / "manifest.json").write_text(json.dumps(manifest))
    out = tmp_path / "cal.toml"

    r = runner.invoke(app, ["calibrate-lights", str(card), "--rig", str(rig), "--out", str(out)])

    assert r.exit_code == 0, r.output
    assert out.is_file()
