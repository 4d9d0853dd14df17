"""A dome lists each LED once: coincident directions are refused where they enter, by name.

Why: the planner would count a repeated direction as two lights and could choose both, and a
plan on such a dome cannot be run (both of its lights snap to the same LED).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from conftest import SMALL_DOME, write_config
from typer.testing import CliRunner

from rti_rig.app.config import load_rig_config
from rti_rig.cli import app
from rti_rig.core.errors import ConfigError
from rti_rig.core.geometry import direction_from_az_el
from rti_rig.core.rig_geometry import COINCIDENT_LED_DEG, coincident_leds


def test_coincident_leds_finds_the_first_pair_only_within_tolerance() -> None:
    dirs = direction_from_az_el(np.array([0.0, 90.0, 180.0, 90.0]), np.array([30, 30, 30, 30]))
    assert coincident_leds(dirs) == (1, 3)
    assert coincident_leds(dirs[:3]) is None
    near = direction_from_az_el(np.array([0.0, 0.5 * COINCIDENT_LED_DEG]), np.array([0.0, 0.0]))
    far = direction_from_az_el(np.array([0.0, 3 * COINCIDENT_LED_DEG]), np.array([0.0, 0.0]))
    assert coincident_leds(near) == (0, 1)
    assert coincident_leds(far) is None
    assert coincident_leds(dirs[:1]) is None
    # not unit length, as .lp files may be: still compared by direction
    assert coincident_leds(np.array([[0.0, 0.0, 1.0], [0.0, 0.0, 3.0]])) == (0, 1)


@pytest.mark.parametrize(
    ("rings", "fragment"),
    [
        (
            "{ elevation_deg = 90.0, count = 2 }",
            "LED 0 (rings[0], LED 1 of 2) and LED 1 (rings[0], LED 2 of 2) both point",
        ),
        (
            "{ elevation_deg = 40.0, count = 4 }, { elevation_deg = 40.0, count = 4 }",
            "LED 0 (rings[0], LED 1 of 4) and LED 4 (rings[1], LED 1 of 4) both point",
        ),
    ],
)
def test_rings_sharing_a_direction_are_refused(tmp_path: Path, rings: str, fragment: str) -> None:
    text = SMALL_DOME.split("rings = [")[0] + f"rings = [{rings}]\n[camera]"
    text += SMALL_DOME.split("[camera]")[1]
    with pytest.raises(ConfigError) as info:
        load_rig_config(write_config(tmp_path, text))
    assert info.value.key == "dome.rings"
    assert fragment in str(info.value)


def test_offset_rings_at_one_elevation_are_distinct_leds(tmp_path: Path) -> None:
    rings = "{ elevation_deg = 40.0, count = 4 }, "
    rings += "{ elevation_deg = 40.0, count = 4, azimuth_offset_deg = 45.0 }"
    text = SMALL_DOME.split("rings = [")[0] + f"rings = [{rings}]\n[camera]"
    text += SMALL_DOME.split("[camera]")[1]
    rig = load_rig_config(write_config(tmp_path, text))
    assert rig.config.dome is not None and len(rig.config.dome.rings) == 2


def test_lp_dome_with_a_repeated_light_is_refused(tmp_path: Path) -> None:
    (tmp_path / "rep.lp").write_text(
        "3\nled_1.jpg 0 0.6 0.8\nled_2.jpg 0.6 0 0.8\nled_3.jpg 0 0.6 0.8\n"
    )
    text = SMALL_DOME.replace('layout = "rings"', 'layout = "lp"\nlp_file = "rep.lp"')
    text = text.split("rings = [")[0] + "\n[camera]" + text.split("[camera]")[1]
    with pytest.raises(ConfigError) as info:
        load_rig_config(write_config(tmp_path, text))
    assert info.value.key == "dome.lp_file"
    msg = str(info.value)
    assert "rep.lp" in msg and "lights 1 (line 2: led_1.jpg) and 3 (line 4: led_3.jpg)" in msg


def test_plan_on_a_bare_lp_with_a_repeated_light_is_refused(tmp_path: Path) -> None:
    rig = tmp_path / "acq.lp"
    lines = [
        f"img_{i}.jpg {d[0]:.6f} {d[1]:.6f} {d[2]:.6f}"
        for i, d in enumerate(
            direction_from_az_el(np.arange(0.0, 360.0, 30.0), np.full(12, 35.0)), start=1
        )
    ]
    lines.append(lines[4].replace("img_5.jpg", "img_5_again.jpg"))
    rig.write_text(f"{len(lines)}\n" + "\n".join(lines) + "\n")
    out = tmp_path / "plan.lp"
    r = CliRunner().invoke(app, ["plan", "--rig", str(rig), "--lights", "6", "--out", str(out)])
    assert r.exit_code != 0
    assert "lights 5 (line 6: img_5.jpg) and 13 (line 14: img_5_again.jpg)" in r.output
    assert "acq.lp" in r.output
    assert not out.exists()
    # without the repeat the same rig plans
    rig.write_text(f"{len(lines) - 1}\n" + "\n".join(lines[:-1]) + "\n")
    r = CliRunner().invoke(app, ["plan", "--rig", str(rig), "--lights", "6", "--out", str(out)])
    assert r.exit_code == 0, r.output
