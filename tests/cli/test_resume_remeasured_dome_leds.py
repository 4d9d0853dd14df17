"""``run --resume --accept-rig-change`` of a fixed dome plan on LEDs re-measured since it began.

Found by an audit: the flag is documented for recalibrated light positions, but the plan still
held each LED's old direction, so any LED still to shoot that had moved by more than 0.5° was
refused ("planned direction is 1.00° from LED 9's calibrated direction: the plan was made for
another dome layout"), right after "rig change accepted". The steps still to shoot now light
the same LEDs (by the index the plan and journal record), from where they are now, and
lights.lp, the journal and the manifest say those directions; an LED of the plan gone from the
dome is refused by its number before any change is said accepted.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

from conftest import SMALL_DOME, cut_new_session, write_config
from typer.testing import CliRunner

from rti_rig.app.usecases.session import NewSessionRequest
from rti_rig.cli import app
from rti_rig.core.lp_format import read_lp
from rti_rig.runtime.controller import FinishReason

runner = CliRunner()


def said(result) -> str:  # type: ignore[no-untyped-def]
    return " ".join(result.output.split())


def folder_bytes(out: Path) -> dict[str, bytes]:
    return {str(p.relative_to(out)): p.read_bytes() for p in out.rglob("*") if p.is_file()}


def journal(out: Path) -> list[dict]:
    return [json.loads(line) for line in (out / "journal.jsonl").read_text().splitlines()]


def cut_after_three(tmp_path: Path) -> tuple[Path, Path]:
    """A fixed 8-light plan on :data:`SMALL_DOME` (LEDs 0-7 at 20°, 8-11 at 50°), stopped as
    Ctrl-C would once its third image is in: LEDs 0, 1, 3 shot, 4 and 6 and three of the
    upper ring still to shoot."""
    cfg = write_config(tmp_path, SMALL_DOME)
    out = tmp_path / "s"
    result = cut_new_session(NewSessionRequest(cfg, out, lights=8), after_step=2)
    assert result.finish_reason is FinishReason.CANCELLED
    assert len(journal(out)) == 3
    return cfg, out


def test_re_measured_leds_accepted_on_resume_are_lit_where_they_are_now(tmp_path: Path) -> None:
    cfg, out = cut_after_three(tmp_path)
    plan = [s["led"] for s in json.loads((out / "manifest.json").read_text())["schedule"]["steps"]]
    before = folder_bytes(out)
    # both rings re-measured 1° higher: LEDs shot (0, 1, 3) and still to shoot alike
    cfg.write_text(
        SMALL_DOME.replace("elevation_deg = 20.0", "elevation_deg = 21.0").replace(
            "elevation_deg = 50.0", "elevation_deg = 51.0"
        )
    )

    r = runner.invoke(app, ["run", "--resume", str(out)])  # not without the flag
    assert r.exit_code == 2, r.output
    assert "light positions: 12 of 12 LEDs moved, by up to 1.00°" in said(r), said(r)
    assert "add --accept-rig-change to record it" in said(r), said(r)
    assert folder_bytes(out) == before

    r = runner.invoke(app, ["run", "--resume", str(out), "--accept-rig-change"])
    text = said(r)
    assert r.exit_code == 0, text
    assert "rig change accepted" in text and "planned direction is" not in text, text
    # the images shot under LEDs since re-measured are not said to be beyond the change
    assert "could not be taken on the rig as changed" not in text, text

    steps = journal(out)
    assert [s["led"] for s in steps] == plan  # the same LEDs, in the plan's order
    elevations = [math.degrees(math.asin(s["actual_direction"][2])) for s in steps]
    upper = [s["led"] >= 8 for s in steps]
    shot_at = [20.0] * 3 + [51.0 if up else 21.0 for up in upper[3:]]
    assert [round(e, 6) for e in elevations] == shot_at
    for s in steps[3:]:  # planned where the LED now is, and lit from there
        assert s["planned_direction"] == s["actual_direction"]
    lp = read_lp(out / "lights.lp")
    assert [round(math.degrees(math.asin(e.direction[2])), 3) for e in lp] == shot_at
    m = json.loads((out / "manifest.json").read_text())
    run = m["runs"][-1]
    assert [c.split(" (")[0] for c in run["rig_change"]] == [
        "light positions: 12 of 12 LEDs moved, by up to 1.00°"
    ]
    assert "shot_before_rig_change" not in run
    # the schedule as shot; the one the session began with kept in the run
    assert [s["direction"] for s in m["schedule"]["steps"]] == [
        s["planned_direction"] for s in steps
    ]
    old = run["schedule_before_rig_change"]["steps"]
    assert [round(math.degrees(math.asin(s["direction"][2])), 6) for s in old] == [
        50.0 if up else 20.0 for up in upper
    ]


def test_an_led_of_the_plan_gone_from_the_dome_is_refused_by_its_number(tmp_path: Path) -> None:
    """The upper ring with an LED fewer: LED 11, still to shoot, no longer exists, and the
    ring's others are numbered and placed otherwise. Refused by number, with what to do, and
    "rig change accepted" never said (it had been, above the refusal); nothing moved."""
    cfg, out = cut_after_three(tmp_path)
    before = folder_bytes(out)
    cfg.write_text(SMALL_DOME.replace("count = 4,", "count = 3,"))

    r = runner.invoke(app, ["run", "--resume", str(out), "--accept-rig-change"])
    text = said(r)
    assert r.exit_code == 2, text
    assert (
        "step 8 (LED 11, az 315.0°, el 50.0°): LED 11 does not exist: this dome has LEDs 0..10"
        in (text)
    ), text
    assert "The rig change accepted (lights: 12 LEDs → 11 LEDs" in text, text
    assert "set it back" in text or "back as it began" in text, text
    assert "rig change accepted (recorded" not in text, text
    assert "Traceback" not in r.output
    assert folder_bytes(out) == before
