"""After a metered preview, the run its plan leads to is told to meter too, through the front
door: a plan holds lights, not an exposure, so ``run --plan`` used the config's exposure_s
(0.05 s on the emulated dome, after a preview metered at 0.0074 s: the run clipped and its
verdict said reshoot)."""

from __future__ import annotations

from pathlib import Path

from typer.testing import CliRunner

from rti_rig.cli import app

REPO = Path(__file__).resolve().parents[2]
DOME = REPO / "rig_configs" / "simulated_dome.toml"
runner = CliRunner()


def said(result) -> str:  # type: ignore[no-untyped-def]
    return " ".join(result.output.split())


def test_a_metered_preview_says_the_run_meters_again(tmp_path: Path) -> None:
    import json

    r = runner.invoke(app, ["preview", str(DOME), "--out", str(tmp_path / "p"), "--auto-exposure"])
    assert r.exit_code == 0, r.output
    metered = json.loads((tmp_path / "p" / "manifest.json").read_text())["steps"][0]["exposure_s"]
    assert abs(metered - 0.05) > 0.0005  # this dome meters away from its config's 0.05 s
    text = said(r)
    assert (
        f"--plan plan.lp --out {tmp_path / 'planned'} --auto-exposure (this preview was metered "
        f"at {metered:.4g} s" in text
    )
    assert "the run uses the config's exposure_s = 0.05 s" in text


def test_an_unmetered_preview_adds_nothing(tmp_path: Path) -> None:
    r = runner.invoke(app, ["preview", str(DOME), "--out", str(tmp_path / "p")])
    assert r.exit_code == 0, r.output
    assert "Plan from it:" in said(r) and "--auto-exposure" not in said(r)
    assert "(dry run): 1 light →" in said(r)  # it had said "1 lights"
