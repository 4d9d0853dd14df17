"""An overexposed session's verdict says each image's finding and the advice they share once.

Before: ``run`` on the shipped dome with ``exposure_s`` five times too long named every image
with the same ~200 characters of advice ("a session keeps one exposure: shoot it again as a
new session with a shorter camera.exposure_s, or with --auto-exposure"), 48 times over.
"""

from __future__ import annotations

from pathlib import Path

from typer.testing import CliRunner

from rti_rig.cli import app

REPO = Path(__file__).resolve().parents[2]
ADVICE = "a session keeps one exposure: shoot it again as a new session with a shorter"


def test_an_overexposed_session_gives_its_advice_once(tmp_path: Path) -> None:
    text = (REPO / "rig_configs" / "simulated_dome.toml").read_text(encoding="utf-8")
    assert "exposure_s = 0.05" in text
    config = tmp_path / "over.toml"
    config.write_text(text.replace("exposure_s = 0.05", "exposure_s = 0.25"), encoding="utf-8")
    out = tmp_path / "s"
    r = CliRunner().invoke(app, ["run", str(config), "--out", str(out), "--lights", "12"])
    said = " ".join(r.output.split())
    assert r.exit_code == 0, said
    verdict = said.split("QA verdict: ", 1)[1]
    assert verdict.startswith("reshoot: image_001 (saturated: "), verdict
    assert verdict.count(ADVICE) == 1, verdict
    assert f"; for the 12 saturated images: {ADVICE}" in verdict, verdict
    for k in range(1, 13):  # each image still named with its own finding
        assert f"image_{k:03d} (saturated: " in verdict, (k, verdict)
