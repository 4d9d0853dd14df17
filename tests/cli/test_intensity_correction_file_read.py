"""A light calibration file named by ``[dome.serial] intensity_correction_file`` is read as
tolerantly as the rig config that names it, and an image or binary file given for it refused
as one.

It had been read as UTF-8 alone: a calibration saved again by Notepad as "Unicode" (UTF-16
with a byte-order mark; Windows PowerShell 5.1's ``>`` writes it too) was refused with Python's
decoder's words ("not valid TOML: 'utf-8' codec can't decode byte 0xff in position 0"), as was
an image given for it, which says neither what the file is nor what to give."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from conftest import CONFIGS, at_key
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner(env={"COLUMNS": "400"})
KEY = "key 'dome.serial.intensity_correction_file'"
FACTORS = [0.9] * 47 + [0.5]
MEASURED = [True] * 47 + [False]


def _card_rig(folder: Path) -> Path:
    """The shipped card rig (small frames), naming cal.toml beside it as its calibration."""
    text = (CONFIGS / "emulated_dome_card.toml").read_text(encoding="utf-8")
    for old, new in (
        ('lp_file = "example_dome_48.lp"', f'lp_file = "{CONFIGS / "example_dome_48.lp"}"'),
        ('profile = "default"\n', 'profile = "default"\nintensity_correction_file = "cal.toml"\n'),
        ("width = 256", "width = 48"),
        ("height = 256", "height = 48"),
    ):
        assert old in text, old
        text = text.replace(old, new)
    cfg = folder / "card.toml"
    cfg.write_text(text, encoding="utf-8")
    return cfg


def _calibration() -> str:
    return (
        'format = "rti-rig-light-calibration/1"\nrig = "emulated-dome-48-card"\n'
        f"intensity_correction = [{', '.join(map(str, FACTORS))}]\n"
        f"measured = [{', '.join('true' if m else 'false' for m in MEASURED)}]\n"
    )


@pytest.mark.parametrize("encoding", ["utf-16", "utf-16-be", "utf-8-sig"])
def test_a_calibration_saved_with_a_byte_order_mark_is_read(tmp_path: Path, encoding: str) -> None:
    cfg = _card_rig(tmp_path)
    data = _calibration().encode(encoding)
    if encoding == "utf-16-be":
        data = b"\xfe\xff" + data  # the codec writes no mark: a big-endian one, by hand
    (tmp_path / "cal.toml").write_bytes(data)
    r = runner.invoke(app, ["plan", "--rig", str(cfg), "--out", str(tmp_path / "plan.lp")])
    assert r.exit_code == 0, r.output
    assert "Traceback" not in r.output


def test_a_utf16_calibration_is_applied_with_its_measured_leds(tmp_path: Path) -> None:
    """Through a session: the factors and the flags of the LEDs measured are those of the
    file (a reader of the flags alone that failed on the encoding had dropped them unsaid)."""
    cfg = _card_rig(tmp_path)
    (tmp_path / "cal.toml").write_text(_calibration(), encoding="utf-16")
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", str(cfg), "--out", str(out), "--lights", "6", "--no-verdict"])
    assert r.exit_code == 0, r.output
    serial = json.loads((out / "manifest.json").read_text())["rig"]["config"]["dome"]["serial"]
    assert serial["intensity_correction"] == FACTORS
    assert serial["intensity_correction_measured"] == MEASURED


JPEG = Path(__file__).parents[1] / "data" / "neuralrti_replay" / "image01.jpg"


@pytest.mark.parametrize(
    ("content", "what"),
    [
        (JPEG.read_bytes(), "this is an image (JPEG), not a light calibration file"),
        (
            bytes(range(256)) * 8,
            "this is a binary file (not text), so not a light calibration file",
        ),
    ],
)
def test_an_image_or_binary_file_given_as_the_calibration_is_refused_as_one(
    tmp_path: Path, content: bytes, what: str
) -> None:
    cfg = _card_rig(tmp_path)
    cal = tmp_path / "cal.toml"
    cal.write_bytes(content)
    r = runner.invoke(app, ["plan", "--rig", str(cfg), "--out", str(tmp_path / "plan.lp")])
    assert r.exit_code == 2, r.output
    text = " ".join(r.output.split())
    assert (
        f"{at_key(cfg, 'dome.serial.intensity_correction_file')}: {cal}: {what}: give the "
        "light_calibration.toml that rti-rig "
        "calibrate-lights wrote"
    ) in text, text
    assert "codec" not in text and "Traceback" not in text, text
    assert not (tmp_path / "plan.lp").exists()
