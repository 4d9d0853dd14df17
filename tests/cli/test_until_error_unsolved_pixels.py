"""`--until-error` counts the pixels no image determines yet in its upper estimate.

Under a ceiling of 15° on the shipped simulated dome, the four starting lights leave a sixth of
the relief lit by too few lights to solve: the stop had claimed 1.5° at those four lights on an
upper estimate of 0.70°, and the session measured 9.0° (docs/adaptive.md, "The stop's claim on
the shipped rigs"). The point estimate is simulated on the object model, which has no normal
for an unsolved pixel to be wrong about; the upper estimate now adds each such pixel at
``UNSOLVED_DEG`` (90°, the most its normal can be wrong).
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

from rti_rig.cli import app

DOME = Path(__file__).resolve().parents[2] / "rig_configs" / "simulated_dome.toml"
runner = CliRunner()


def _measured_deg(session: Path) -> float:
    from benchmarks.until_error_configs import session_error_deg

    return session_error_deg(DOME, session)


def _decisions(session: Path) -> list[dict]:  # type: ignore[type-arg]
    lines = (session / "journal.jsonl").read_text(encoding="utf-8").splitlines()
    return [json.loads(line)["decision"] for line in lines]


def _run(*args: str) -> str:
    r = runner.invoke(app, ["run", *args, "--no-verdict"])
    assert r.exit_code == 0, r.output
    return " ".join(r.output.split())


def test_a_claim_under_a_low_ceiling_is_true(tmp_path: Path) -> None:
    out = tmp_path / "s"
    said = _run(str(DOME), "--out", str(out), "--until-error", "1.5", "--max-elevation-deg", "15")
    result = json.loads((out / "manifest.json").read_text())["adaptive"]["result"]
    assert result["target_claimed"], said
    # the claim had come at the four starting lights, measured at 9°
    assert result["lights_used"] > 4, result
    assert _measured_deg(out) <= 1.5
    first = _decisions(out)[4]  # the first decision after the starting four
    assert first["unsolved_fraction"] > 0.05, first
    expected = first["estimated_error_deg"] * first["upper_factor"] + (
        first["unsolved_fraction"] * first["unsolved_deg"]
    )
    assert first["upper_error_deg"] == pytest.approx(expected, abs=0.01), first
    assert first["upper_error_deg"] > 1.5, first  # what held the stop


def test_the_stop_words_the_unsolved_term(tmp_path: Path) -> None:
    """A stop whose upper estimate holds unsolved pixels says so, so that an upper estimate far
    above estimate × factor is read for what it is."""
    out = tmp_path / "s"
    said = _run(str(DOME), "--out", str(out), "--until-error", "30", "--max-elevation-deg", "15")
    stop = json.loads((out / "manifest.json").read_text())["adaptive"]["result"]["stop"]
    assert stop["unsolved_fraction"] > 0, stop
    assert "% of pixels unsolved × 90°" in stop["reason"], stop
    assert "% of pixels unsolved × 90°" in said, said


def test_a_session_begun_before_the_term_is_judged_with_it(tmp_path: Path) -> None:
    """A session whose settings do not record the term (begun by an earlier build) resumes
    (the term decides only when to stop) and is judged with it: its claim had left the
    unsolved pixels out."""
    from conftest import begun_before, interrupted

    out = tmp_path / "s"
    interrupted(DOME, out, after_step=3, lights=None, until=1.5, band=(0.0, 15.0))
    begun_before(out, "unsolved_deg", "planner.adaptive_until.UNSOLVED_DEG")
    said = _run("--resume", str(out))
    result = json.loads((out / "manifest.json").read_text())["adaptive"]["result"]
    assert result["target_claimed"], said
    assert result["lights_used"] > 4, result
    assert result["unsolved_deg"] == 90.0, result
    assert _measured_deg(out) <= 1.5  # a NaN fails it too


def test_a_session_resumes_with_the_weight_it_recorded(tmp_path: Path) -> None:
    """A session that recorded its own weight for the unsolved pixels (a build with another
    UNSOLVED_DEG) is judged with it to the end, as the factor is: here 0°, which claims at the
    four starting lights as the build before the term did."""
    from conftest import interrupted

    out = tmp_path / "s"
    interrupted(DOME, out, after_step=3, lights=None, until=1.5, band=(0.0, 15.0))
    path = out / "manifest.json"
    manifest = json.loads(path.read_text())
    manifest["adaptive"]["unsolved_deg"] = 0.0
    path.write_text(json.dumps(manifest, indent=2))
    said = _run("--resume", str(out))
    result = json.loads(path.read_text())["adaptive"]["result"]
    assert result["target_claimed"] and result["lights_used"] == 4, said
    assert result["unsolved_deg"] == 0.0 and result["unsolved_fraction"] > 0.05, result
    assert "pixels unsolved" not in result["stop"]["reason"], result  # weighed at 0°: no term
