"""`rti-rig run` refuses lights that cannot determine a normal before anything lights or moves.

Only `rti-rig plan` refused lights in one plane through the object: `run --plan` of a hand-made
.lp at one azimuth, or `run` of a replayed acquisition shot at one azimuth, captured the session
without a word, and `rti-rig fit` then wrote no normal maps from it.
"""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
from conftest import CONFIGS
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.lp_format import LpEntry, write_lp


def _one_azimuth(path: Path) -> Path:
    """8 lights at azimuth 0°, elevations 15-80°: in one plane through the object."""
    el = np.radians(np.linspace(15, 80, 8))
    write_lp(path, [LpEntry(f"i{k}.jpg", (np.cos(e), 0.0, np.sin(e))) for k, e in enumerate(el)])
    return path


def _refused(args: list[str], out: Path) -> str:
    r = CliRunner().invoke(app, ["run", *args, "--out", str(out), "--no-verdict"])
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    assert not out.exists()  # no session folder: nothing was captured
    assert "nothing was lit or moved" in said
    assert "ridge-regularised: along the direction the lights do not span" in said
    return said


def test_a_plan_at_one_azimuth_is_refused_before_the_arm_moves(tmp_path: Path) -> None:
    plan = _one_azimuth(tmp_path / "one_az.lp")
    said = _refused([str(CONFIGS / "virtual_arm.toml"), "--plan", str(plan)], tmp_path / "s")
    assert f"the 8 lights of --plan {plan} cannot determine a surface normal" in said
    assert "lights at one azimuth (0° or 180°)" in said


def test_a_replayed_acquisition_at_one_azimuth_is_refused(tmp_path: Path) -> None:
    acq = tmp_path / "acq"
    acq.mkdir()
    for k in range(8):
        cv2.imwrite(str(acq / f"i{k}.jpg"), np.full((16, 16, 3), 100 + 10 * k, np.uint8))
    said = _refused([str(_one_azimuth(acq / "dirs.lp"))], tmp_path / "s")
    assert "the 8 lights run takes by default cannot determine a surface normal" in said
    assert "widen" not in said  # no band was given


def test_allow_no_normals_captures_a_one_azimuth_plan_saying_so(tmp_path: Path) -> None:
    """A deliberate raking-light plan at one azimuth had no way past the refusal."""
    plan = _one_azimuth(tmp_path / "one_az.lp")
    out = tmp_path / "s"
    r = CliRunner().invoke(
        app,
        [
            "run",
            str(CONFIGS / "virtual_arm.toml"),
            "--plan",
            str(plan),
            "--out",
            str(out),
            "--no-verdict",
            "--allow-no-normals",
        ],
    )
    said = " ".join(r.output.split())
    assert r.exit_code == 0, said
    assert "captured as asked (--allow-no-normals)" in said
    assert "along the direction the lights do not span, their relighting is a guess" in said
    assert len(list(out.glob("image_*.jpg"))) == 8
    assert "--allow-no-normals" in (out / "manifest.json").read_text(encoding="utf-8")


def test_the_refusal_names_the_way_through(tmp_path: Path) -> None:
    plan = _one_azimuth(tmp_path / "one_az.lp")
    said = _refused([str(CONFIGS / "virtual_arm.toml"), "--plan", str(plan)], tmp_path / "s")
    assert "add --allow-no-normals" in said
