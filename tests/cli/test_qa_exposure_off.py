"""An image halved or doubled in brightness is named, "about N× too dark/bright", on the coin.

The shipped simulated dome with its scene set to the coin at 1024 px, 12 lights: image_009
(55°) halved and image_005 (25°) doubled, as a flash at part power or an exposure left to the
camera would make them, had been "good" apart from the image_012 every session of that rig
clips: the robust fit of 12 lights took the halved image in (1.01 of its prediction on the
pixels it explains) and the doubled one is no Lambertian rendering of the glossy coin, so its
brightness was not judged. Each is now judged against the images lit from its elevation; the
clean session names no image for its exposure. A doubled image no longer gets a correct one
named beside it: it enters the QA's reference fit scaled back to its mates' level.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.image_files import read_linear_tiff, write_linear_tiff

runner = CliRunner()


def _scaled_copy(session: Path, dst: Path, name: str, factor: float) -> Path:
    """``session`` copied with ``name``'s linear TIFF scaled by ``factor`` (clipped)."""
    shutil.copytree(session, dst)
    for f in ("journal.jsonl", "manifest.json"):  # a fault injected, not a file changed
        (dst / f).unlink(missing_ok=True)
    tif = dst / "linear" / f"{name}.tif"
    px = read_linear_tiff(tif).astype(np.float64) * factor
    tif.unlink()
    write_linear_tiff(tif, np.clip(np.round(px), 0, 65535).astype(np.uint16))
    return dst


def _fit(session: Path, out: Path) -> tuple[dict, str]:
    r = runner.invoke(
        app, ["fit", str(session), "--out", str(out), "--no-ptm", "--no-hsh", "--no-normals"]
    )
    assert r.exit_code == 0, r.output
    return json.loads((out / "qa.json").read_text()), " ".join(r.output.split())


def _exposure_named(qa: dict) -> dict[str, str]:
    return {
        c["name"]: p
        for c in qa["images"]
        for p in c["problems"]
        if "too dark for its light" in p or "too bright for its light" in p
    }


@pytest.fixture(scope="module")
def coin_session(dome_coin_1024_12: Path) -> Path:
    """The shipped simulated dome with its scene set to the coin at 1024 px, 12 lights (read
    only: the tests scale an image in a copy)."""
    return dome_coin_1024_12


@pytest.mark.slow  # the coin at 1024 px, 12 lights: three fits of the session
def test_a_halved_and_a_doubled_image_are_named_on_the_glossy_coin(
    coin_session: Path, tmp_path: Path
) -> None:
    session = coin_session
    clean, _ = _fit(session, tmp_path / "fit_clean")
    assert _exposure_named(clean) == {}, clean["verdict"]
    assert "image_005" not in clean["reshoot"] and "image_009" not in clean["reshoot"]

    halved, said = _fit(
        _scaled_copy(session, tmp_path / "halved", "image_009", 0.5), tmp_path / "f1"
    )
    assert list(_exposure_named(halved)) == ["image_009"], halved["verdict"]
    assert "image_009" in halved["reshoot"]
    assert "image_009 (about 2.0× too dark for its light" in said, said
    (c,) = [c for c in halved["images"] if c["name"] == "image_009"]
    assert 0.4 < c["exposure_ratio"] < 0.6, c

    doubled, said = _fit(
        _scaled_copy(session, tmp_path / "doubled", "image_005", 2.0), tmp_path / "f2"
    )
    assert list(_exposure_named(doubled)) == ["image_005"], doubled["verdict"]
    assert "image_005" in doubled["reshoot"]
    assert "image_005 (about 1.9× too bright for its light" in said or (
        "image_005 (about 2.0× too bright for its light" in said
    ), said


@pytest.mark.slow  # the coin at 1024 px, 12 lights: one fit of the session
def test_a_doubled_image_does_not_get_a_correct_one_named_dim_beside_it(
    coin_session: Path, tmp_path: Path
) -> None:
    # image_007 (40°) doubled had tilted the reference fit until the correct image_002 (10°,
    # lighting the same side) read "misfired or dim light: 33%": now image_007 enters the fit
    # scaled back to its mates' level, and is still named for its exposure
    doubled, said = _fit(
        _scaled_copy(coin_session, tmp_path / "doubled", "image_007", 2.0), tmp_path / "f"
    )
    named = {c["name"] for c in doubled["images"] if c["problems"]}
    # image_012 (70°) clips in every session of that rig: named saturated, as on the clean one
    assert named == {"image_007", "image_012"}, doubled["verdict"]
    assert list(_exposure_named(doubled)) == ["image_007"], doubled["verdict"]
    assert doubled["reshoot"] == ["image_007", "image_012"], doubled["verdict"]
    assert "image_007 (about 1.9× too bright for its light" in said, said
