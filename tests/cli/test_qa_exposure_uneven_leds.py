"""A correct image under a weak LED of an uneven dome is not "too dark for its light".

Found on the shipped emulated Nab dome with 24 lights from 3.2° up (``count`` and
``led_count`` 24, ``min_elevation_deg = 2``) over the flat plate, ``[emulator]
led_power_spread = 0.2`` (real domes' LEDs differ by about ±20 %), seed 4, every LED firing:
the verdict said "reshoot: image_021 (about 1.7× too dark for its light: the 2 images lit from
within 5° of its elevation are that much brighter …)". Its LED was drawn at 0.73 and its two
mates' at 1.26 and 1.16. The exposure check's 1.5× limit now widens by the scatter the
session's other images show against their mates (``exposure_limit`` in ``qa.json``), so the
session is good; an LED at 30 % power there is still named (measured over seeds 0-9 in
docs/reconstruction.md, "Exposure against its elevation").
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from conftest import qa_of, shipped_variant
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()
EDITS = (
    ('\nname = "tablet"\n', '\nname = "flat"\n'),
    ("\nseed = 0\n", "\nseed = 4\n"),
    ("count = 12\n", "count = 24\n"),
    ("led_count = 12 ", "led_count = 24 "),
    ("min_elevation_deg = 15.0", "min_elevation_deg = 2"),
)


def _session(folder: Path, emulator: str) -> Path:
    """A session of the shipped emulated Nab dome, 24 lights, on the flat plate, seed 4."""
    config = shipped_variant(folder, "emulated_nab_rti_v1.toml", EDITS, emulator)
    out = folder / "s"
    r = runner.invoke(app, ["run", str(config), "--out", str(out), "--no-verdict"])
    assert r.exit_code == 0, r.output
    return out


def test_a_weak_led_of_an_uneven_dome_is_not_too_dark(tmp_path: Path) -> None:
    said, qa = qa_of(_session(tmp_path, "led_power_spread = 0.2\n"), tmp_path / "f")
    image_021 = qa["images"][20]
    assert image_021["name"] == "image_021"
    assert image_021["exposure_ratio"] < 1.0 / 1.5, image_021  # judged, and under 1.5x
    assert "too dark for its light" not in said, said
    assert qa["good"], qa["verdict"]
    assert image_021["exposure_limit"] > 1.0 / image_021["exposure_ratio"], image_021


def test_an_led_at_30_percent_on_that_dome_is_still_named(tmp_path: Path) -> None:
    # the same dome's LEDs (the emulator's draws for seed 4), LED 20 at 30 % of its own
    power = np.exp(0.2 * np.random.default_rng([4, 0x1ED]).standard_normal(24))
    power[20] *= 0.3
    listed = ", ".join(f"{p:.6f}" for p in power)
    _, qa = qa_of(_session(tmp_path, f"led_power = [{listed}]\n"), tmp_path / "f")
    named = {c["name"]: c["problems"] for c in qa["images"] if c["problems"]}
    assert "image_021" in named, qa["verdict"]
    assert "dim" in named["image_021"][0] or "too dark" in named["image_021"][0], named
    assert not qa["good"]
