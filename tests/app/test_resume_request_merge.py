"""The new session a refused resume advises: the session's own options with those given put
in their place (``resume_request._merged``), as a command run takes.

Cases a review found: a planned session's ``--lights`` kept as a cap of an ``--until-error``
request (whose ``--min-lights`` then could not exceed it, "no new session takes it", which
was false); the session's ``--objective relight`` kept beside a given ``--until-error`` (which
goes with normals); ``--adaptive`` given to an ``--until-error`` session advised a "new
session" identical to it.
"""

from __future__ import annotations

from pathlib import Path

from rti_rig.app.usecases.resume_request import StartOptions, _merged, _same_request


def test_an_until_error_request_drops_the_sessions_count_and_relight_objective() -> None:
    planned = StartOptions(lights=16)
    asked = StartOptions(
        until_error_deg=2.0, min_lights=30, given=("--until-error", "--min-lights")
    )
    merged = _merged(asked, planned)
    assert (merged.lights, merged.until_error_deg, merged.min_lights) == (None, 2.0, 30)
    relight = StartOptions(adaptive=True, lights=8, objective="relight")
    merged = _merged(StartOptions(until_error_deg=2.0, given=("--until-error",)), relight)
    # an adaptive session's count stays, as the cap beside the stop (dropped, a session of 30
    # had been advised one of up to 100 lights: QA, 2026-12-05); the relight objective goes
    assert merged.objective is None and merged.lights == 8
    # ... unless a minimum given above it: the stop decides the count
    above = StartOptions(until_error_deg=2.0, min_lights=9, given=("--until-error", "--min-lights"))
    assert _merged(above, relight).lights is None
    # a count given with it stays: the first of the two reached stops
    both = StartOptions(until_error_deg=2.0, lights=12, given=("--until-error", "--lights"))
    assert _merged(both, relight).lights == 12


def test_adaptive_given_to_an_until_error_session_is_that_session() -> None:
    session = StartOptions(until_error_deg=2.0, min_lights=9)
    merged = _merged(StartOptions(adaptive=True, given=("--adaptive",)), session)
    assert _same_request(merged, session)
    assert not _same_request(merged, StartOptions(until_error_deg=3.0, min_lights=9))


def test_a_plan_given_replaces_the_sessions_count_and_a_count_its_plan() -> None:
    adaptive = StartOptions(adaptive=True, lights=7, max_elevation_deg=60.0)
    merged = _merged(StartOptions(plan=Path("p.lp"), given=("--plan",)), adaptive)
    assert (merged.plan, merged.lights, merged.is_adaptive) == (Path("p.lp"), None, False)
    assert merged.max_elevation_deg == 60.0  # the band kept: run checks the plan against it
    planned = StartOptions(plan=Path("p.lp"), auto_exposure=True)
    merged = _merged(StartOptions(adaptive=True, given=("--adaptive",)), planned)
    # made adaptive: the plan and the metering (which an adaptive session refuses) dropped
    assert (merged.plan, merged.auto_exposure, merged.is_adaptive) == (None, False, True)


def test_a_band_given_to_a_planned_session_asks_for_the_rigs_own_layout() -> None:
    """A plan kept beside a given band had advised a run that refuses its lights outside it."""
    planned = StartOptions(plan=Path("p.lp"))
    asked = StartOptions(max_elevation_deg=30.0, given=("--max-elevation-deg",))
    merged = _merged(asked, planned)
    assert (merged.plan, merged.lights, merged.max_elevation_deg) == (None, None, 30.0)
