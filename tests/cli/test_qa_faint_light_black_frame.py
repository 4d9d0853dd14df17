"""A dead LED whose light reaches a flat plate only obliquely is named; a lit one is not judged.

On a flat matte plate a light below 11.5° reaches no pixel at n · l > 0.2, where an image's
gain against the fit is measured, so a dead grazing LED had no gain to judge: on the emulated
Nab dome (24 lights from 3.2° up) the dead 3.2° LED was told "about 338× too dark for its
light … auto-exposure left on?" where two lights at its elevation happened to be its mates,
and a frame with no light reached nothing else. A light that fired lifts every pixel its
prediction puts above the session's dark level, so a frame at the dark level there is a
black frame, named "misfired, no light"; a lit one that faint is said not judged, with the
elevation from which a black frame is told.
"""

from __future__ import annotations

from pathlib import Path

from conftest import qa_of, shipped_variant
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()


def _flat_session(folder: Path, emulator: str) -> Path:
    """24 lights of the shipped emulated Nab dome, from 3.2° up, over the flat plate."""
    edits = (
        ('\nname = "tablet"\n', '\nname = "flat"\n'),
        ("\ncount = 12\n", "\ncount = 24\n"),
        ("\nled_count = 12 ", "\nled_count = 24 "),
        ("\nmin_elevation_deg = 15.0\n", "\nmin_elevation_deg = 2.0\n"),
    )
    config = shipped_variant(folder, "emulated_nab_rti_v1.toml", edits, emulator)
    out = folder / "s"
    r = runner.invoke(app, ["run", str(config), "--out", str(out), "--no-verdict"])
    assert r.exit_code == 0, r.output
    return out


def test_a_dead_oblique_led_on_a_flat_plate_is_a_misfire(tmp_path: Path) -> None:
    _, qa = qa_of(_flat_session(tmp_path, "dead_leds = [0]\n"), tmp_path / "f")
    problems = {c["name"]: c["problems"] for c in qa["images"] if c["problems"]}
    assert set(problems) == {"image_001"}, qa["verdict"]
    assert problems["image_001"][0].startswith("misfired, no light"), problems


def test_lit_oblique_lights_on_a_flat_plate_are_said_not_judged(tmp_path: Path) -> None:
    said, qa = qa_of(_flat_session(tmp_path, "dead_leds = []\n"), tmp_path / "f")
    assert qa["good"], qa["verdict"]
    assert "misfired" not in said, said
    faint = [c["name"] for c in qa["images"] if c["faint_light"]]
    assert "image_001" in faint, qa["verdict"]
    assert "too obliquely to judge how bright it is" in said, said
    assert "named from 1.5° above the object's mean surface up" in said, said
