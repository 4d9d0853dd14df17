"""A preview in a band that holds fewer LEDs than a plan needs is refused before anything lights.

Before: on a dome with 2 LEDs at 85°, ``rti-rig preview DOME --out P --min-elevation-deg 80``
shot one of them and printed "Plan from it: rti-rig plan P --rig DOME --lights 3
--min-elevation-deg 80 ...", which, pasted, was refused: "asked for 3 lights but the dome has
only 2 LEDs at or above 80° elevation". A preview is the input of a plan in its band.
"""

from __future__ import annotations

from pathlib import Path

from typer.testing import CliRunner

from rti_rig.cli import app

REPO = Path(__file__).resolve().parents[2]
runner = CliRunner()
LAST_RING = "  { elevation_deg = 70.0, count = 6, azimuth_offset_deg = 0.0 },\n"


def _dome_with_two_high_leds(tmp_path: Path) -> Path:
    text = (REPO / "rig_configs" / "simulated_dome.toml").read_text(encoding="utf-8")
    assert LAST_RING in text  # the shipped dome's top ring, a 2-LED ring added above it
    config = tmp_path / "dome.toml"
    two = "  { elevation_deg = 85.0, count = 2, azimuth_offset_deg = 0.0 },\n"
    config.write_text(text.replace(LAST_RING, LAST_RING + two), encoding="utf-8")
    return config


def test_a_band_of_two_leds_is_refused_before_the_preview(tmp_path: Path) -> None:
    config = _dome_with_two_high_leds(tmp_path)
    out = tmp_path / "P"
    r = runner.invoke(app, ["preview", str(config), "--out", str(out), "--min-elevation-deg", "80"])
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    assert "only 2 LEDs between 80° and 90° elevation" in said, said
    assert "a plan in that band needs at least 3" in said and "widen --min-elevation-deg" in said
    assert "Traceback" not in said and not out.exists()


def test_the_plan_a_preview_prints_runs_as_printed(tmp_path: Path) -> None:
    # a band that holds enough (the 70° ring and the two at 85°): the printed plan command works
    config = _dome_with_two_high_leds(tmp_path)
    out = tmp_path / "P"
    band = ["--min-elevation-deg", "65"]
    r = runner.invoke(app, ["preview", str(config), "--out", str(out), *band])
    said = " ".join(r.output.split())
    assert r.exit_code == 0, said
    line = said.split("Plan from it: rti-rig ", 1)[1].split(" --out ")[0].split()
    assert line[line.index("--lights") + 1] == "8", line  # every LED of the band
    plan = tmp_path / "plan.lp"
    r = runner.invoke(app, [*line, "--out", str(plan)])
    assert r.exit_code == 0, r.output
    assert plan.exists()


def test_a_dome_of_two_leds_is_told_no_plan_can_be_made_not_to_widen(tmp_path: Path) -> None:
    text = (REPO / "rig_configs" / "simulated_dome.toml").read_text(encoding="utf-8")
    start, end = text.index("rings = ["), text.index("]\n", text.index("rings = [")) + 2
    two = "rings = [\n  { elevation_deg = 40.0, count = 2, azimuth_offset_deg = 0.0 },\n]\n"
    config = tmp_path / "two.toml"
    config.write_text(text[:start] + two + text[end:], encoding="utf-8")
    r = runner.invoke(app, ["preview", str(config), "--out", str(tmp_path / "P")])
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    assert "the dome has only 2 LEDs, and a plan needs at least 3" in said, said
    assert "widen" not in said and not (tmp_path / "P").exists()
