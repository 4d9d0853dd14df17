"""`rti-rig run RIG --adaptive --lights N --objective relight` through the front door, on the
shipped simulated dome (its LEDs and scene, with small frames) and on a replayed real
acquisition: the designs are scored by their simulated relighting PSNR, the objective is data
(settings and every decision), a resume continues it and refuses another objective, and what it
cannot mean is refused clearly."""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import interrupted, journal, manifest, said, shipped_variant
from typer.testing import CliRunner

from rti_rig.app.usecases.adaptive import FORMAT
from rti_rig.cli import app
from rti_rig.runtime.controller import FinishReason

REPO = Path(__file__).resolve().parents[2]
DOME = REPO / "rig_configs" / "simulated_dome.toml"
runner = CliRunner()
RELIGHT = ("--objective", "relight", "--no-verdict")


def files(folder: Path) -> list[tuple[str, bytes]]:
    return sorted(
        (str(p.relative_to(folder)), p.read_bytes()) for p in folder.rglob("*") if p.is_file()
    )


@pytest.fixture(scope="module")
def dome(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The shipped simulated dome (its 48 LEDs, scene and timing) with 96 px frames: the
    objective, its designs and a resume's choices are the LEDs' and the scene's, and its
    512 px frames made this module's sessions several times as long."""
    side = (("width = 512", "width = 96"), ("height = 512", "height = 96"))
    return shipped_variant(tmp_path_factory.mktemp("dome"), "simulated_dome.toml", side)


@pytest.fixture(scope="module")
def relight_session(tmp_path_factory: pytest.TempPathFactory, dome: Path) -> Path:
    out = tmp_path_factory.mktemp("relight") / "s"
    r = runner.invoke(
        app,
        ["run", str(dome), "--out", str(out), "--adaptive", "--lights", "8", *RELIGHT],
    )
    assert r.exit_code == 0, r.output
    assert "Adaptive (designs for relight): 8 lights; stopped: reached" in said(r)
    return out


def test_the_relight_objective_is_in_the_settings_and_every_decision(relight_session: Path) -> None:
    steps = journal(relight_session)
    assert len(steps) == 8
    assert all(s["decision"]["objective"] == "relight" for s in steps)
    header = manifest(relight_session)["adaptive"]
    assert header["result"]["objective"] == "relight"
    assert header["objective"] == "relight" and header["format"] == FORMAT == "rti-rig-adaptive/9"
    for s in steps[4:]:
        d = s["decision"]
        assert d["kind"] == "adaptive" and d["design_objective"] == "relight"
        # every floor's design and the fitted relight design (planner.adaptive_relight_design)
        # scored by its simulated relighting PSNR (dB), none by normals; this dome's lowest
        # LEDs are at 10°, so the designs above 0° and 10° are one layout, listed once as 10°
        # (they had been listed twice with equal scores)
        assert set(d["design_psnr_db"]) == {"10", "20", "30", "fitted"}
        assert all(5.0 < v < 100.0 for v in d["design_psnr_db"].values())
        assert "design_error_deg" not in d and "relighting PSNR" in d["reason"]
        # the design chosen is one whose PSNR is within the margin of the best (the journal
        # rounds the PSNRs to 3 decimals, hence the 1e-3)
        best = max(d["design_psnr_db"].values())
        key = "fitted" if d.get("design") == "fitted" else f"{d['design_floor_deg']:g}"
        assert d["design_psnr_db"][key] >= best - 0.5 - 1e-3
    # the manifest's steps carry the same decisions as the journal
    assert [s["decision"] for s in manifest(relight_session)["steps"]] == [
        s["decision"] for s in steps
    ]


def test_the_starting_lights_are_above_the_start_floor(relight_session: Path) -> None:
    """Through the front door on the shipped dome: the 4 lights shot before anything is known
    are all at or above START_FLOOR_DEG, in the order lights.lp lists what fired (format 9; the
    10° layout of 8 on this dome has a 10° light, which a /8 session shot first)."""
    import numpy as np

    from rti_rig.core.lp_format import directions_of, read_lp
    from rti_rig.planner.adaptive import START_FLOOR_DEG, START_LIGHTS

    dirs = directions_of(read_lp(relight_session / "lights.lp"))
    el = np.degrees(np.arcsin(dirs[:, 2]))
    assert len(el) == 8
    assert el[:START_LIGHTS].min() >= START_FLOOR_DEG - 1e-6


def test_the_default_objective_is_normals_and_says_so(tmp_path: Path, dome: Path) -> None:
    out = tmp_path / "s"
    r = runner.invoke(
        app, ["run", str(dome), "--out", str(out), "--adaptive", "--lights", "6", "--no-verdict"]
    )
    assert r.exit_code == 0, r.output
    assert manifest(out)["adaptive"]["objective"] == "normals"
    last = journal(out)[-1]["decision"]
    assert last["objective"] == "normals" and last["design_objective"] == "normals"
    # the floors' completions and the fitted design (planner.adaptive_optimal; the relight
    # objective is offered its own, planner.adaptive_relight_design)
    # (the designs above 0° and 10° are one layout on this dome, whose lowest LEDs are at 10°:
    # listed once, by the floor every light of it lies above)
    assert set(last["design_error_deg"]) == {"10", "20", "30", "fitted"}
    assert "design_psnr_db" not in last


@pytest.mark.parametrize(
    ("args", "fragment"),
    [
        (
            ["--adaptive", "--lights", "8", "--until-error", "2", "--objective", "relight"],
            "--until-error goes with --objective normals only",
        ),
        (["--until-error", "2", "--objective", "relight"], "--objective normals only"),
        (
            ["--adaptive", "--objective", "relight"],
            "give the count with --lights: rti-rig run ",
        ),
        (["--lights", "8", "--objective", "relight"], "goes with --adaptive"),
        (["--adaptive", "--lights", "8", "--objective", "psnr"], "normals or relight"),
    ],
)
def test_what_the_objective_cannot_mean_is_refused_before_anything_moves(
    tmp_path: Path, args: list[str], fragment: str
) -> None:
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", str(DOME), "--out", str(out), *args])
    assert r.exit_code == 2, r.output
    assert fragment in said(r)
    assert "Traceback" not in r.output
    assert not out.exists()


def test_a_relight_session_resumes_to_the_same_session_and_refuses_another_objective(
    relight_session: Path, tmp_path: Path, dome: Path
) -> None:
    out = tmp_path / "cut"
    result = interrupted(dome, out, after_step=5, objective="relight")
    assert result.finish_reason is FinishReason.CANCELLED and len(journal(out)) == 6
    before = files(out)
    r = runner.invoke(app, ["run", "--resume", str(out), "--objective", "normals"])
    assert r.exit_code == 2, r.output
    text = said(r)
    assert "begun with --objective relight" in text and "Drop --objective normals" in text
    assert files(out) == before  # refused from the manifest alone: nothing touched
    # naming its own objective, or none, continues it: the same lights as uninterrupted
    r = runner.invoke(app, ["run", "--resume", str(out), "--objective", "relight", "--no-verdict"])
    assert r.exit_code == 0, r.output
    assert (out / "lights.lp").read_text() == (relight_session / "lights.lp").read_text()

    def choices(session: Path) -> list[dict]:
        return [
            {k: v for k, v in s["decision"].items() if k != "decision_s"} for s in journal(session)
        ]

    assert choices(out) == choices(relight_session)


def test_a_normals_session_refuses_a_resume_for_relighting(tmp_path: Path, dome: Path) -> None:
    out = tmp_path / "cut"
    interrupted(dome, out, after_step=4, objective="normals")
    r = runner.invoke(app, ["run", "--resume", str(out), "--objective", "relight"])
    assert r.exit_code == 2 and "begun with --objective normals" in said(r)


def test_a_fixed_session_refuses_an_objective_on_resume(tmp_path: Path, dome: Path) -> None:
    out = tmp_path / "fixed"
    r = runner.invoke(app, ["run", str(dome), "--out", str(out), "--lights", "5", "--no-verdict"])
    assert r.exit_code == 0, r.output
    r = runner.invoke(app, ["run", "--resume", str(out), "--objective", "relight"])
    assert r.exit_code == 2 and "not" in said(r) and "drop --objective relight" in said(r)


def test_relight_objective_on_a_replayed_real_acquisition(tmp_path: Path) -> None:
    acq = REPO / "tests" / "data" / "neuralrti_replay" / "dirs.lp"
    out = tmp_path / "s"
    r = runner.invoke(
        app,
        ["run", str(acq), "--out", str(out), "--adaptive", "--lights", "7", *RELIGHT],
    )
    assert r.exit_code == 0, r.output
    steps = journal(out)
    assert len(steps) == 7 and manifest(out)["adaptive"]["objective"] == "relight"
    assert all("design_psnr_db" in s["decision"] for s in steps[4:])
