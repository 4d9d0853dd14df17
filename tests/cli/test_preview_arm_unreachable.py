"""`rti-rig preview` on an arm, asked for a light the arm cannot reach, names what to change.

Found by a front-door audit: `rti-rig preview rig_configs/virtual_arm.toml --light 0,90` said
only "preview light az 0°, el 90°: direction is 0.00° from the camera axis, inside the 10°
keep-out cone" — neither the option that put it there nor what to do; a dome's light outside the
band asked for names `--light` and says to give one within the band.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import CONFIGS
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()


def _refusal(tmp_path: Path, *args: str) -> str:
    out = tmp_path / "preview"
    r = runner.invoke(app, ["preview", str(CONFIGS / "virtual_arm.toml"), "--out", str(out), *args])
    text = " ".join(r.output.split())
    assert r.exit_code == 2, text
    assert "Traceback" not in text
    assert not out.exists() or not any(out.iterdir())  # nothing shot, nothing written
    return text


def test_a_light_inside_the_keep_out_cone_names_the_option_and_the_remedy(tmp_path: Path) -> None:
    text = _refusal(tmp_path, "--light", "0,90")
    assert "--light 0,90: the arm cannot go there" in text, text
    assert "inside the 10° keep-out cone" in text
    assert "give a --light AZ,EL the arm can reach" in text


def test_a_default_light_pushed_out_of_reach_by_the_band_says_so(tmp_path: Path) -> None:
    # the default light's elevation is clamped into the band asked for: 85°, past the arm's 80°
    text = _refusal(tmp_path, "--min-elevation-deg", "85")
    assert "the default preview light (az 135°, el 85°): the arm cannot go there" in text, text
    assert "--min-elevation-deg / --max-elevation-deg" in text


def test_a_ceiling_below_the_arm_is_refused_naming_the_option(tmp_path: Path) -> None:
    """``--max-elevation-deg 3`` on an arm whose lowest elevation is 5° is refused as ``run``
    and ``plan`` refuse it; the preview had blamed the light, and with ``--light`` had said to
    give one the arm can reach, which the band then refused."""
    run_said = "--max-elevation-deg 3 is at or below the arm's lowest elevation (5°): no light"
    for light in ([], ["--light", "0,3"], ["--light", "0,20"]):
        text = _refusal(tmp_path, "--max-elevation-deg", "3", *light)
        assert run_said in text, text
        assert "the arm cannot go there" not in text, text


def test_a_default_light_beyond_the_azimuth_stops_takes_the_nearest_reachable(
    tmp_path: Path,
) -> None:
    """A bare ``rti-rig preview`` on an arm whose azimuth joint turns -90°..60° (a cable, a
    stand) had been refused: the default light, az 135°, is past its stop, and the user was
    told to "give --light AZ,EL the arm can reach" of a light they never gave. The default is
    the rig's to choose, as a dome's nearest LED is: the nearest pose it reaches is shot, and
    said."""
    text = (CONFIGS / "simulated_arm.toml").read_text()
    text = text.replace("min_deg = -170.0", "min_deg = -90.0").replace(
        "max_deg = 170.0", "max_deg = 60.0"
    )
    text = text.replace('transport = "pty"', 'transport = "inprocess"')
    cfg = tmp_path / "arm.toml"
    cfg.write_text(text)
    out = tmp_path / "preview"
    r = runner.invoke(app, ["preview", str(cfg), "--out", str(out)], terminal_width=400)
    said = " ".join(r.output.split())
    assert r.exit_code == 0, said
    assert (
        "the default preview light (az 135°, el 50°) is beyond the arm's reach (azimuth "
        "135.00° is outside the arm's range [-90°, 60°]): the nearest it reaches, az 60°, "
        "el 50°, is used" in said
    ), said
    lines = (out / "lights.lp").read_text().split("\n")
    x, y, z = (float(v) for v in lines[1].split()[1:])
    assert (x, y, z) == pytest.approx((0.5 * 0.642788, 0.866025 * 0.642788, 0.766044), abs=2e-3)
