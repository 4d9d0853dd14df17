"""Uneven LEDs are not a move; a real shift of one image still is.

Found on the emulated Nab dome's 48 px tablet with ``[emulator] led_power_spread = 0.2`` (real
domes' LEDs are uneven) and nothing else changed: the verdict said image_001 "moved: shifted
(+1.0, -0.6) px", and the simulator never moves the object. The tablet's shading edges lean
towards each light (x shift against the light's x: correlation 0.94); with even LEDs their
spread (0.37 px) left the edges untrusted, with these uneven ones it read 0.25 px, trusted, and
the most grazing light's image, 1.2 px off along its light, was called moved on its edges'
word alone. Now only the part of an edge shift that does not follow the light counts; a
session with one image really shifted 1-2 px names that image, and only it (it had named
image_001 beside it).

A 2 px shift of an image whose LED is about 20 % off power had still been missed: with the
moved image among them the edges spread 0.41 px about their median, untrusted, and against a
fit of 12 lights that had taken the image in it read 0.8 px (seed 0's image_008, LED at 0.84;
12 of 16 such shifts over seeds 0-3 called good). The edges' noise is now their spread about
the light's trend (0.1-0.2 px there), and those shifts are named; still sessions over several
seeds stay unmoved.
"""

from __future__ import annotations

import hashlib
import json
import re
import shutil
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.image_files import read_linear_tiff, write_linear_tiff

REPO = Path(__file__).resolve().parents[2]
runner = CliRunner()


def _sha(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _uneven_session(folder: Path, seed: int) -> tuple[Path, str]:
    """A still session of the shipped emulated dome with uneven LEDs drawn from ``seed``, and
    its run's output."""
    config = folder / "rig.toml"
    text = (REPO / "rig_configs" / "emulated_nab_rti_v1.toml").read_text()
    assert "\nseed = 0\n" in text
    text = text.replace("\nseed = 0\n", f"\nseed = {seed}\n")
    config.write_text(text + "\n[emulator]\nled_power_spread = 0.2\n")
    out = folder / "s"
    r = runner.invoke(app, ["run", str(config), "--out", str(out)])
    assert r.exit_code == 0, r.output
    return out, " ".join(r.output.split())


@pytest.fixture(scope="module")
def uneven(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, str]:
    """A still session of the shipped emulated dome with uneven LEDs, and its run's output."""
    return _uneven_session(tmp_path_factory.mktemp("uneven"), 0)


def _shifted_copy(session: Path, dst: Path, image: int, dx: int, dy: int) -> Path:
    """``session`` with linear image ``image`` (1-based) shifted by ``(dx, dy)`` px (x right, y
    down: the object nudged and put back), its checksum updated as the capture would have."""
    shutil.copytree(session, dst)
    f = dst / "linear" / f"image_{image:03d}.tif"
    before = _sha(f)
    img = np.roll(read_linear_tiff(f), (dy, dx), axis=(0, 1))
    f.unlink()
    write_linear_tiff(f, img)
    for name in ("journal.jsonl", "manifest.json"):
        p = dst / name
        p.write_text(p.read_text().replace(before, _sha(f)))
    return dst


def test_uneven_leds_on_a_still_tablet_are_not_called_moved(uneven: tuple[Path, str]) -> None:
    _, output = uneven
    assert "QA verdict" in output, output
    assert "moved" not in output, output


@pytest.mark.parametrize("seed", [1, 2, 3, 4])
def test_still_sessions_of_other_uneven_leds_are_not_called_moved(
    tmp_path: Path, seed: int
) -> None:
    _, output = _uneven_session(tmp_path, seed)
    assert "QA verdict" in output, output
    assert "moved" not in output, output


# image_008's LED gives 0.84 of nominal (seed 0): its (2, 0) px shift had been called good
@pytest.mark.parametrize(("image", "dx", "dy"), [(7, 2, 0), (7, 1, 1), (4, 0, 1), (8, 2, 0)])
def test_a_real_shift_of_one_image_under_uneven_leds_is_caught(
    uneven: tuple[Path, str], tmp_path: Path, image: int, dx: int, dy: int
) -> None:
    session, _ = uneven
    moved = _shifted_copy(session, tmp_path / "moved", image, dx, dy)
    out = tmp_path / "f"
    r = runner.invoke(app, ["fit", str(moved), "--out", str(out), "--no-ptm", "--no-hsh"])
    assert r.exit_code == 0, r.output
    qa = json.loads((out / "qa.json").read_text())
    called = [c["name"] for c in qa["images"] if any("moved" in p for p in c["problems"])]
    assert called == [f"image_{image:03d}"], qa["verdict"]
    # and by how much it moved, not that plus where its light leans a still image's edges
    # (image_004, moved (0, 1) px, had been said "shifted (+0.5, -1.2)")
    said = next(p for p in qa["images"][image - 1]["problems"] if "moved" in p)
    found = re.search(r"shifted \(([-+][0-9.]+), ([-+][0-9.]+)\) px", said)
    assert found is not None, said
    stated = np.array([float(found[1]), float(found[2])])
    assert np.hypot(*(stated - (dx, -dy))) <= 0.35, said  # x right, y up
