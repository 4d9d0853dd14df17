"""A recorded acquisition mixing 8-bit JPEGs with 16-bit images, replayed: said as `fit` of the
same `.lp` says it (8-bit read as sRGB, 16-bit as linear: a gamma-encoded 16-bit export among
JPEGs is wrong in its mid-tones). `check` and `run` had passed it without a word, and the
session then holds every image as a linear TIFF, the mix no longer visible."""

from __future__ import annotations

import shutil
import struct
import zlib
from pathlib import Path

import cv2
from conftest import REPO, said
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()
MIXES = "mixes 17 8-bit image(s), decoded as sRGB, with 1 16-bit one(s), taken as linear"


def test_a_replay_of_jpegs_and_a_16_bit_png_says_the_mix(tmp_path: Path) -> None:
    acq = tmp_path / "acq"
    shutil.copytree(REPO / "tests" / "data" / "neuralrti_replay", acq)
    lp = acq / "dirs.lp"
    for argv in (["check", str(lp)], ["run", str(lp), "--out", str(tmp_path / "jpegs")]):
        r = runner.invoke(app, argv)
        assert r.exit_code == 0 and "mixes" not in said(r), said(r)

    pixels = cv2.imread(str(acq / "image25.jpg"))
    assert cv2.imwrite(str(acq / "image25.png"), pixels.astype("uint16") * 257)  # a 16-bit export
    lp.write_text(lp.read_text().replace("image25.jpg", "image25.png"))
    for argv in (["check", str(lp)], ["run", str(lp), "--out", str(tmp_path / "mixed")]):
        r = runner.invoke(app, argv)
        text = said(r)
        assert r.exit_code == 0, text
        assert f"{MIXES} (image25.png)" in text
        assert "they are replayed wrongly; export every image of the acquisition alike" in text


def test_a_16_bit_srgb_png_among_jpegs_is_not_said_taken_as_linear(tmp_path: Path) -> None:
    """A 16-bit PNG that says sRGB (its sRGB chunk) is converted by the replay, its curve
    undone: neither of the note's guesses, so no mix is said of it (as fit says none)."""
    acq = tmp_path / "acq"
    shutil.copytree(REPO / "tests" / "data" / "neuralrti_replay", acq)
    lp = acq / "dirs.lp"
    pixels = cv2.imread(str(acq / "image25.jpg"))
    ok, encoded = cv2.imencode(".png", pixels.astype("uint16") * 257)
    assert ok
    data = encoded.tobytes()
    chunk = b"sRGB\0"  # ISO/IEC 15948 11.3.3.5, after the signature (8) and IHDR (25)
    srgb = struct.pack(">I", 1) + chunk + struct.pack(">I", zlib.crc32(chunk))
    (acq / "image25.png").write_bytes(data[:33] + srgb + data[33:])
    lp.write_text(lp.read_text().replace("image25.jpg", "image25.png"))
    r = runner.invoke(app, ["check", str(lp)])
    assert r.exit_code == 0 and "mixes" not in said(r), said(r)
