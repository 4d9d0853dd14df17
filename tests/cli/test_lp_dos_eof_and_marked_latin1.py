"""Two ways old Windows tools save an `.lp`, read as the reader reads each harmless variant:

* DOS's end-of-file mark, Ctrl-Z (0x1A), after the last line (``COPY /A``, DOS editors; CP/M
  padded the last record with them): it had been refused as a light line, "expected 'name x y
  z', found 1 field(s): '\\x1a'", or, with no line end before it, as "z component '0.8\\x1a'
  is not a number";
* a UTF-8 byte-order mark ("UTF-8 with BOM") before names that are not UTF-8 (a Windows tool's
  ANSI names): each alone was read, together they were refused at "count line 'ï»¿6'", a reason
  that was not the file's.
"""

from __future__ import annotations

import codecs
from pathlib import Path

import cv2
import numpy as np
import pytest
from typer.testing import CliRunner

from rti_rig.cli import app

LIGHTS = b"3\r\na_1.jpg 0 0 1\r\na_2.jpg 0 0.6 0.8\r\na_3.jpg 0.6 0 0.8"


@pytest.mark.parametrize(
    "end", [b"\r\n\x1a", b"\x1a", b"\r\n" + b"\x1a" * 20], ids=["own-line", "no-eol", "padded"]
)
def test_a_rig_lp_ending_in_dos_eof_is_read(tmp_path: Path, end: bytes) -> None:
    lp = tmp_path / "dome.lp"
    lp.write_bytes(LIGHTS + end)
    out = tmp_path / "plan.lp"
    args = ["plan", "--rig", str(lp), "--lights", "3", "--out", str(out)]
    r = CliRunner().invoke(app, args, terminal_width=400)
    said = " ".join(r.output.split())
    assert r.exit_code == 0, said
    assert "\\x1a" not in said and "field(s)" not in said, said
    assert out.read_text().startswith("3\n"), said


@pytest.mark.parametrize("mark", [codecs.BOM_UTF8, b""], ids=["utf8-mark", "no-mark"])
def test_an_acquisition_lp_of_latin1_names_fits_with_or_without_a_utf8_mark(
    tmp_path: Path, mark: bytes
) -> None:
    lines = [b"6"]
    for i in range(6):
        az, el = 2 * np.pi * i / 6, np.radians(30 + 30 * (i % 2))
        d = (np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el))
        grey = np.full((24, 32), 40 + 30 * i, np.uint8)
        name = f"café_{i}.jpg"  # on disk as this system names it; in the .lp as Windows did
        (tmp_path / name).write_bytes(cv2.imencode(".jpg", grey)[1].tobytes())
        xyz = " ".join(f"{c:.6f}" for c in d)
        lines.append(f"{name} {xyz}".encode("latin-1"))
    lp = tmp_path / "dirs.lp"
    lp.write_bytes(mark + b"\r\n".join(lines) + b"\r\n")
    args = ["fit", str(lp), "--out", str(tmp_path / "fit"), "--model", "ps", "--no-qa"]
    r = CliRunner().invoke(app, args, terminal_width=400)
    said = " ".join(r.output.split())
    assert r.exit_code == 0, said
    assert "count line" not in said, said
    assert (tmp_path / "fit" / "normals.png").is_file()
