"""An elevation band with no light in it says where the rig's lights do stand.

It had said "asked for 3 lights but the dome has only 0 LEDs at or above 80° elevation" of a
dome whose highest LED stands at 70° (and "has only 0 images" of a replayed acquisition): the
elevations to widen the band to were the one thing the user needed and was not told.
"""

from __future__ import annotations

from pathlib import Path

from typer.testing import CliRunner

from rti_rig.cli import app

ROOT = Path(__file__).resolve().parents[2]
DOME = ROOT / "rig_configs" / "simulated_dome.toml"
ACQ = ROOT / "tests" / "data" / "neuralrti_replay" / "dirs.lp"


def _said(args: list[str]) -> str:
    r = CliRunner().invoke(app, args)
    assert r.exit_code == 2, r.output
    return " ".join(r.output.split())


def test_a_dome_plan_names_where_its_leds_stand(tmp_path: Path) -> None:
    said = _said(
        ["plan", "--rig", str(DOME), "--lights", "3", "--min-elevation-deg", "80",
         "--out", str(tmp_path / "p.lp")]
    )  # fmt: skip
    assert (
        "the dome has no LED at or above 80° elevation (its LEDs stand between 10° and 70°)" in said
    )
    assert "only 0" not in said and "widen --min-elevation-deg" in said
    assert not (tmp_path / "p.lp").exists()


def test_a_dome_run_names_where_its_leds_stand(tmp_path: Path) -> None:
    said = _said(
        ["run", str(DOME), "--lights", "3", "--min-elevation-deg", "80", "--out",
         str(tmp_path / "s")]
    )  # fmt: skip
    assert "no LED at or above 80° elevation (its LEDs stand between 10° and 70°)" in said
    assert not (tmp_path / "s").exists()


def test_a_replay_names_where_its_images_lights_stand(tmp_path: Path) -> None:
    said = _said(
        ["run", str(ACQ), "--lights", "3", "--min-elevation-deg", "85", "--out",
         str(tmp_path / "s")]
    )  # fmt: skip
    assert (
        "has no image at or above 85° elevation (its images' lights stand between 11.8° and 78.6°)"
        in said
    )
    assert "only 0" not in said and not (tmp_path / "s").exists()


def test_a_band_with_too_few_still_counts_them(tmp_path: Path) -> None:
    said = _said(
        ["plan", "--rig", str(DOME), "--lights", "9", "--min-elevation-deg", "65",
         "--out", str(tmp_path / "p.lp")]
    )  # fmt: skip
    assert "the dome has only 6 LEDs at or above 65° elevation; use --lights 6 or fewer" in said
