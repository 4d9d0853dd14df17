"""A plan whose lights cannot determine a normal is refused, not written, naming the case.

A bare .lp rig with its lights on one ring at the horizon: every choice of lights is coplanar.
`rti-rig plan` had written the plan with "expected RMS normal error 90.00" as its only sign,
and `rti-rig fit` refused the session shot from it ("ill-conditioned for photometric stereo").
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.lp_format import LpEntry, read_lp, write_lp


@pytest.mark.parametrize("method", ["optimal", "uniform"])
def test_a_horizon_ring_rig_gets_no_plan(tmp_path: Path, method: str) -> None:
    az = np.radians(np.arange(20) * 18.0)
    rig = tmp_path / "ring.lp"
    write_lp(
        rig, [LpEntry(f"led_{k:02d}.jpg", (np.cos(a), np.sin(a), 0.0)) for k, a in enumerate(az)]
    )
    out = tmp_path / "plan.lp"
    r = CliRunner().invoke(
        app, ["plan", "--rig", str(rig), "--lights", "12", "--method", method, "--out", str(out)]
    )
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    assert "the 12 planned lights cannot determine a surface normal" in said
    assert "in one plane through the object: the horizon" in said
    assert "bunched" not in said
    assert not out.exists()


def _ring(el_deg: float, n: int) -> list[tuple[float, float, float]]:
    e, az = np.radians(el_deg), np.radians(np.arange(n) * 360.0 / n)
    return [(np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e)) for a in az]


def test_lights_bunched_at_the_zenith_are_named_so_without_a_band_to_widen(
    tmp_path: Path,
) -> None:
    """Rings at 89.2° and 89.6° had been told to widen a band that was already 0..90°, and
    every refusal said "one plane through the object, or bunched at the zenith": which of the
    two is now named from the Lambert matrix's singular vectors."""
    rig = tmp_path / "cap.lp"
    lights = _ring(89.2, 12) + _ring(89.6, 8)
    write_lp(rig, [LpEntry(f"led_{k:02d}.jpg", d) for k, d in enumerate(lights)])
    out = tmp_path / "plan.lp"
    r = CliRunner().invoke(
        app, ["plan", "--rig", str(rig), "--lights", "12", "--method", "uniform", "--out", str(out)]
    )
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    assert "they are bunched at the zenith" in said
    assert "widen" not in said and "plane" not in said
    assert not out.exists()


def _horizon_ring(path: Path) -> Path:
    az = np.radians(np.arange(20) * 18.0)
    write_lp(
        path, [LpEntry(f"led_{k:02d}.jpg", (np.cos(a), np.sin(a), 0.0)) for k, a in enumerate(az)]
    )
    return path


def test_the_refusal_names_the_way_through(tmp_path: Path) -> None:
    rig, out = _horizon_ring(tmp_path / "ring.lp"), tmp_path / "plan.lp"
    r = CliRunner().invoke(app, ["plan", "--rig", str(rig), "--lights", "12", "--out", str(out)])
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    assert "add --allow-no-normals" in said
    assert not out.exists()


@pytest.mark.parametrize("objective", ["relight", "normals"])
def test_allow_no_normals_plans_a_horizon_ring_saying_so(tmp_path: Path, objective: str) -> None:
    """`run` had --allow-no-normals and `plan` had not: a ring of raking lights for a
    relightable PTM/HSH only could be captured but not planned."""
    rig, out = _horizon_ring(tmp_path / "ring.lp"), tmp_path / "plan.lp"
    r = CliRunner().invoke(
        app,
        [
            *("plan", "--rig", str(rig), "--lights", "12", "--objective", objective),
            *("--out", str(out), "--allow-no-normals"),
        ],
    )
    said = " ".join(r.output.split())
    assert r.exit_code == 0, said
    assert "the 12 planned lights cannot determine a surface normal" in said
    assert "planned as asked (--allow-no-normals)" in said
    assert "along the direction the lights do not span, their relighting is a guess" in said
    # a bare .lp with no config beside it that lists it: RIG.toml, the word left to fill in
    # (the .lp itself pasted would be replayed as an acquisition, and refused for its images)
    planned = tmp_path / "planned"
    assert f"rti-rig run RIG.toml --plan {out} --out {planned} --allow-no-normals" in said
    assert len(read_lp(out)) == 12


def test_allow_no_normals_is_silent_where_the_lights_determine_normals(tmp_path: Path) -> None:
    out = tmp_path / "plan.lp"
    r = CliRunner().invoke(app, ["plan", "--lights", "12", "--out", str(out), "--allow-no-normals"])
    said = " ".join(r.output.split())
    assert r.exit_code == 0, said
    assert "cannot determine" not in said and "--allow-no-normals" not in said


def test_the_advised_run_command_names_the_rig_and_plan_and_runs(tmp_path: Path) -> None:
    """The warning advised `rti-rig run --plan PLAN.lp --allow-no-normals`, which `run`
    refuses ("give a RIG_CONFIG and --out DIR"). It now names the rig config given to `plan`
    and the plan written, shell-quoted, and the command it gives runs the plan."""
    import shlex

    from conftest import CONFIGS

    text = (CONFIGS / "simulated_dome.toml").read_text()
    start, end = text.index("rings = ["), text.index("]\n", text.index("rings = [")) + 2
    ring = "rings = [{ elevation_deg = 0.0, count = 20, azimuth_offset_deg = 0.0 }]\n"
    folder = tmp_path / "my rigs"
    folder.mkdir()
    rig, plan_file = folder / "raking ring.toml", folder / "raking plan.lp"
    rig.write_text(text[:start] + ring + text[end:])
    r = CliRunner().invoke(
        app,
        [
            *("plan", "--rig", str(rig), "--lights", "6", "--objective", "relight"),
            *("--out", str(plan_file), "--allow-no-normals"),
        ],
    )
    said = " ".join(r.output.split())
    assert r.exit_code == 0, said
    advised = said[
        said.index("rti-rig run ") : said.index("--allow-no-normals", said.index("rti-rig run "))
        + len("--allow-no-normals")
    ]
    # into a folder beside the plan that does not exist yet (``--out DIR`` had made DIR)
    planned = folder / "planned"
    assert advised == (
        f"rti-rig run {shlex.quote(str(rig))} --plan {shlex.quote(str(plan_file))} --out "
        f"{shlex.quote(str(planned))} --allow-no-normals"
    ), advised
    r = CliRunner().invoke(app, [*shlex.split(advised)[1:], "--no-verdict"])
    assert r.exit_code == 0, " ".join(r.output.split())
    assert len(read_lp(planned / "lights.lp")) == 6
