"""Normals are not read from a PTM its lights cannot determine.

On one ring of lights ``l_u^2 + l_v^2`` is constant, at the horizon or one direction repeated
the PTM's terms are not separable either: the PTM is ridge-regularised and its Lambertian
reading had been written as the normal map, 22° off on a matte object on a ring (71° on one
repeated direction), said only as "relighting ... not trustworthy". Photometric stereo is fine
on a ring; on the other sets nothing gives normals, and none are written.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from conftest import REPO
from typer.testing import CliRunner

from rti_rig.cli import app
from tests.fit_sessions import _rings, make_session


def _fit(session: Path, out: Path, model: str) -> str:
    r = CliRunner().invoke(
        app, ["fit", str(session), "--out", str(out), "--model", model, "--no-qa"]
    )
    assert r.exit_code == 0, r.output
    return " ".join(r.output.split())


def _error_deg(out: Path, truth: np.ndarray) -> float:
    n = np.load(out / "normals.npy")
    return float(np.degrees(np.arccos(np.clip((n * truth).sum(-1), -1, 1))).mean())


def _one_azimuth() -> np.ndarray:
    """10 lights at azimuth 28.6°, elevations 10-80°: in one plane through the object."""
    return np.array(
        [
            (np.cos(e) * np.cos(0.5), np.cos(e) * np.sin(0.5), np.sin(e))
            for e in np.radians(np.linspace(10, 80, 10))
        ]
    )


def test_a_ring_gets_photometric_stereo_normals(tmp_path: Path) -> None:
    session, _, truth = make_session(
        tmp_path / "s", scene="tablet", size=(48, 48), lights=_rings(((35, 12, 0),))
    )
    said = _fit(session, tmp_path / "f", "ptm")
    assert "normals from robust photometric stereo, not the PTM" in said
    assert json.loads((tmp_path / "f" / "fit.json").read_text())["normals_from"] == "ps-robust"
    assert _error_deg(tmp_path / "f", truth) < 5.0


def test_one_direction_repeated_writes_no_normals(tmp_path: Path) -> None:
    lights = np.repeat(_rings(((40, 1, 30),)), 8, axis=0)
    session, _, _ = make_session(tmp_path / "s", scene="tablet", size=(32, 32), lights=lights)
    said = _fit(session, tmp_path / "f", "ptm")
    assert "normals.png/.npy and albedo not written" in said
    assert not (tmp_path / "f" / "normals.npy").exists()
    assert (tmp_path / "f" / "fit.ptm").exists()


def test_an_hsh_fit_on_one_azimuth_is_written_without_normals(tmp_path: Path) -> None:
    # it had been refused whole ("ill-conditioned for photometric stereo"), its normals being
    # robust PS's; the relighting file is written regularised, as a PTM's is
    session, _, _ = make_session(tmp_path / "s", size=(32, 32), lights=_one_azimuth())
    said = _fit(session, tmp_path / "f", "hsh2")
    assert "normals.png/.npy and albedo not written" in said
    assert (tmp_path / "f" / "fit.rti").exists()
    assert not (tmp_path / "f" / "normals.npy").exists()
    r = CliRunner().invoke(
        app, ["fit", str(session), "--out", str(tmp_path / "ps"), "--model", "robust-ps"]
    )
    assert r.exit_code == 2 and "ill-conditioned for photometric stereo" in r.output


@pytest.mark.parametrize("scene", ["tablet", "coin"])
def test_auto_on_one_azimuth_writes_relighting_files_without_normals(
    tmp_path: Path, scene: str
) -> None:
    # auto had chosen Lambert on the tablet and refused the whole fit (exit 2), but the PTM on
    # the coin and written its relighting files: the outcome hung on the object, not the lights
    session, _, _ = make_session(tmp_path / "s", scene=scene, size=(32, 32), lights=_one_azimuth())
    said = _fit(session, tmp_path / "f", "auto")
    assert "Lambert left out of the choice" in said
    assert "lights at one azimuth (29° or 209°)" in said
    assert "normals.png/.npy and albedo not written" in said
    # said once: the Model line and the normals warning had both given the layout in full
    assert said.count("cannot determine a surface normal: they lie") == 1, said
    assert said.count("lights at one azimuth (29° or 209°)") == 1, said
    fit = json.loads((tmp_path / "f" / "fit.json").read_text())
    assert fit["model"] != "lambert" and not fit["normals_from"]
    assert (tmp_path / "f" / "fit.rti").exists()
    assert not (tmp_path / "f" / "normals.npy").exists()


def test_auto_without_normal_maps_says_why_lambert_was_left_out_once(tmp_path: Path) -> None:
    # with --no-normals no normals warning gives the reason: the Model line keeps it
    session, _, _ = make_session(tmp_path / "s", size=(32, 32), lights=_one_azimuth())
    r = CliRunner().invoke(
        app,
        ["fit", str(session), "--out", str(tmp_path / "f"), "--no-qa", "--no-normals"],
    )
    said = " ".join(r.output.split())
    assert r.exit_code == 0, said
    assert "Lambert left out of the choice: the 10 lights of this session cannot" in said
    assert said.count("lights at one azimuth (29° or 209°)") == 1, said


def test_photometric_stereo_by_name_on_one_azimuth_names_the_cli_way_out(tmp_path: Path) -> None:
    session, _, _ = make_session(tmp_path / "s", size=(32, 32), lights=_one_azimuth())
    r = CliRunner().invoke(
        app, ["fit", str(session), "--out", str(tmp_path / "f"), "--model", "lambert"]
    )
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    assert "--model auto, --model hsh2 or --model ptm write the relighting files" in said
    assert "from Python" not in said


def test_a_ptm_over_its_noise_gain_limit_gives_no_ptm_normals(tmp_path: Path) -> None:
    # lights on one side only: the PTM is not regularised (condition 40) but amplifies noise
    # 15.2x (limit 10); its Lambertian reading had been written as the normal map, 25° off
    side = np.array(
        [
            (np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e))
            for e in np.radians((20, 45, 70))
            for a in np.radians(np.linspace(0, 90, 6))
        ]
    )
    session, _, truth = make_session(tmp_path / "s", size=(48, 48), lights=side)
    said = _fit(session, tmp_path / "f", "ptm")
    assert "normals from robust photometric stereo, not the PTM" in said
    assert "noise gain 15.2, limit 10" in said
    assert json.loads((tmp_path / "f" / "fit.json").read_text())["normals_from"] == "ps-robust"
    assert _error_deg(tmp_path / "f", truth) < 2.0
    assert (tmp_path / "f" / "fit.ptm").exists()


def test_real_light_sets_keep_the_ptm_normals() -> None:
    # the shipped dome and the recorded acquisitions: noise gains 0.45-2.0, left as they were
    from rti_rig.app.usecases.fit import conditioned_normal_source
    from rti_rig.core.lp_format import read_lp

    for lp in (
        "rig_configs/example_dome_48.lp",
        "tests/data/neuralrti/dirs.lp",
        "tests/data/neuralrti_replay/dirs.lp",
    ):
        lights = np.array([e.direction for e in read_lp(REPO / lp, upper_hemisphere=True)])
        assert conditioned_normal_source("ptm", lights) == ("ptm", ""), lp


def test_auto_on_four_lights_at_one_azimuth_does_not_advise_photometric_stereo(
    tmp_path: Path,
) -> None:
    # too few for a PTM or HSH with Lambert left out: it advised "--model ps", itself refused
    session, _, _ = make_session(tmp_path / "s", size=(24, 24), lights=_one_azimuth()[::3])
    r = CliRunner().invoke(app, ["fit", str(session), "--out", str(tmp_path / "f"), "--no-qa"])
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    assert "Nor can photometric stereo be fitted" in said
    assert "--model ps" not in said
