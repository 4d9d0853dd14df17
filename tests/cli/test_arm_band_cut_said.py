"""An elevation band asked of an arm beyond its reach is said to be cut, once, by ``run`` and by
``plan``; a band within reach is used as given, and nothing is said.

Why: the layout was spread over the reachable part alone, silently: "--min-elevation-deg 70
--max-elevation-deg 90" on the shipped virtual arm (which reaches 80°) lit only 70°..80°.
"""

from __future__ import annotations

from pathlib import Path

from conftest import CONFIGS, said
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.lp_format import read_lp

runner = CliRunner(env={"COLUMNS": "400"})
ARM = str(CONFIGS / "virtual_arm.toml")
CUT = "the arm reaches elevations 5°..80°"


def _elevations(lp: Path) -> list[float]:
    import numpy as np

    from rti_rig.core.geometry import az_el_from_direction

    dirs = np.array([e.direction for e in read_lp(lp, upper_hemisphere=True)])
    return [float(x) for x in az_el_from_direction(dirs)[1]]


def test_run_says_once_that_the_band_was_cut(tmp_path: Path) -> None:
    out = tmp_path / "s"
    band = ["--min-elevation-deg", "70", "--max-elevation-deg", "90"]
    r = runner.invoke(app, ["run", ARM, "--lights", "6", "--out", str(out), "--no-verdict", *band])
    text = said(r)
    assert r.exit_code == 0, text
    assert text.count(CUT) == 1, text
    assert "so the lights are spread over 70°..80° only" in text, text
    assert all(69.9 <= el <= 80.1 for el in _elevations(out / "lights.lp"))


def test_plan_says_that_the_band_was_cut(tmp_path: Path) -> None:
    out = tmp_path / "p.lp"
    argv = ["plan", "--rig", ARM, "--lights", "8", "--method", "uniform", "--out", str(out)]
    r = runner.invoke(app, [*argv, "--min-elevation-deg", "0", "--max-elevation-deg", "50"])
    text = said(r)
    assert r.exit_code == 0, text
    assert CUT in text and "spread over 5°..50° only" in text, text


def test_a_band_within_reach_is_not_said(tmp_path: Path) -> None:
    out = tmp_path / "p.lp"
    argv = ["plan", "--rig", ARM, "--lights", "8", "--method", "uniform", "--out", str(out)]
    r = runner.invoke(app, [*argv, "--min-elevation-deg", "20", "--max-elevation-deg", "60"])
    assert r.exit_code == 0, said(r)
    assert "the arm reaches" not in said(r)


def test_an_explicit_full_band_beyond_reach_is_said_by_run_and_plan(tmp_path: Path) -> None:
    """``--max-elevation-deg 90`` typed on an arm reaching 80° had been cut in silence, as the
    default 0..90 is (every elevation the rig offers); typed, it is said, with the arm's limit."""
    run = ["run", ARM, "--lights", "6", "--out", str(tmp_path / "s"), "--no-verdict"]
    plan = ["plan", "--rig", ARM, "--lights", "8", "--out", str(tmp_path / "p.lp")]
    for argv in (run, plan):
        r = runner.invoke(app, [*argv, "--max-elevation-deg", "90"])
        text = said(r)
        assert r.exit_code == 0, text
        assert text.count(CUT) == 1, text
        assert "--max-elevation-deg 90: the arm reaches elevations 5°..80° (its elevation " in text
        assert "so the lights are spread over 5°..80° only" in text, text
        # only what was typed: it had said "--min-elevation-deg 0 --max-elevation-deg 90"
        assert "--min-elevation-deg" not in text, text


def test_only_the_bound_typed_is_named_by_run_and_plan(tmp_path: Path) -> None:
    """``--min-elevation-deg 2`` alone (below the arm's 5°) names that option, not a
    ``--max-elevation-deg 90`` the user never typed."""
    run = ["run", ARM, "--lights", "6", "--out", str(tmp_path / "s"), "--no-verdict"]
    plan = ["plan", "--rig", ARM, "--lights", "8", "--out", str(tmp_path / "p.lp")]
    for argv in (run, plan):
        r = runner.invoke(app, [*argv, "--min-elevation-deg", "2"])
        text = said(r)
        assert r.exit_code == 0, text
        assert text.count(CUT) == 1, text
        assert "--min-elevation-deg 2: the arm reaches elevations 5°..80°" in text, text
        assert "--max-elevation-deg" not in text, text


def test_the_default_band_is_not_said_to_be_cut(tmp_path: Path) -> None:
    """Not typed, 0..90 means every elevation the arm offers: nothing to say."""
    run = ["run", ARM, "--lights", "6", "--out", str(tmp_path / "s"), "--no-verdict"]
    plan = ["plan", "--rig", ARM, "--lights", "8", "--out", str(tmp_path / "p.lp")]
    for argv in (run, plan):
        r = runner.invoke(app, argv)
        assert r.exit_code == 0, said(r)
        assert "the arm reaches" not in said(r), said(r)


def test_a_dynamixel_arm_s_configured_limit_is_said_as_written(tmp_path: Path) -> None:
    """The shipped Dynamixel arm's config lets its elevation joint turn to 90°; the 15° keep-out
    cone stops the lamp at 75°. The note had said "its elevation limits 0°..75°", as if the
    config's 90° had been misread: it says the config's limit and why less is used."""
    arm = str(CONFIGS / "simulated_arm.toml")
    out = tmp_path / "p.lp"
    argv = ["plan", "--rig", arm, "--lights", "8", "--method", "uniform", "--out", str(out)]
    r = runner.invoke(app, [*argv, "--max-elevation-deg", "90"])
    text = said(r)
    assert r.exit_code == 0, text
    assert "the arm reaches elevations 0°..75° " in text, text
    assert "(its elevation joint may turn to 90° as configured ([arm.dynamixel.elevation] " in text
    assert "max_deg), but above 75° the lamp would be inside the 15° keep-out cone" in text
    assert "elevation limits 0°..75°" not in text, text
    assert "so the lights are spread over 0°..75° only" in text, text
