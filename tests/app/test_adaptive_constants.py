"""The decision constants a resume compares: which are exempt, and that the exemption by bare
name cannot hide a constant that steers decisions."""

from __future__ import annotations

import importlib

from rti_rig.app.usecases import adaptive as usecase
from rti_rig.app.usecases.adaptive_constants import (
    DECISION_MODULES,
    RESTORED_ON_RESUME,
    constant_differences,
    decision_constants,
)
from rti_rig.planner import adaptive_until

#: the module each exempt name belongs to (a resume takes its value from the session)
OWNERS = {
    "UPPER_FACTOR": adaptive_until,
    "UPPER_QUANTILE": adaptive_until,
    "RING_SPAN_DEG": usecase,
    "UNSOLVED_DEG": adaptive_until,
    "MISFIT_NOISE_K": adaptive_until,
}


def test_only_the_stop_factor_and_its_quantile_are_defined_under_the_exempt_names() -> None:
    """A decision module that defined its own UPPER_FACTOR (say, a bound for a design) would be
    exempt from the resume check by name: every module that holds one of these names must hold
    its owner's very object (an import of it)."""
    assert set(OWNERS) == RESTORED_ON_RESUME
    for name in DECISION_MODULES:
        module = importlib.import_module(name)
        for key in RESTORED_ON_RESUME:
            if hasattr(module, key):
                assert getattr(module, key) is getattr(OWNERS[key], key), f"{name}.{key}"


def test_the_exempt_names_are_exempt_under_any_module_and_nothing_else_is() -> None:
    now = decision_constants()
    assert now["planner.adaptive_until.UPPER_FACTOR"] == adaptive_until.UPPER_FACTOR
    recorded = dict(now)
    recorded["planner.adaptive_until.UPPER_FACTOR"] = 2.5
    recorded["planner.adaptive.UPPER_QUANTILE"] = 0.5  # recorded under another module
    assert constant_differences(recorded, now) == []
    recorded["planner.adaptive.SIM_MARGIN"] = -1.0
    del recorded["planner.adaptive_optimal.SEARCH_PIXELS"]
    lines = constant_differences(recorded, now)
    assert len(lines) == 2
    assert lines[0].startswith("planner.adaptive.SIM_MARGIN -1.0 → ")
    assert lines[1].startswith("planner.adaptive_optimal.SEARCH_PIXELS 'absent' → ")


def test_a_session_recorded_before_the_relight_floor_was_split_off_resumes_when_it_agrees(
    monkeypatch,  # type: ignore[no-untyped-def]
) -> None:
    """Sessions recorded before `RELIGHT_DEFAULT_FLOOR` existed lack it; their relight start
    was the normals objective's floor. Agreeing values are no difference; others are named."""
    from rti_rig.planner import adaptive

    key = "planner.adaptive.RELIGHT_DEFAULT_FLOOR"
    now = decision_constants()
    older = {k: v for k, v in now.items() if k != key}
    assert now[key] == now["planner.adaptive.DESIGN_DEFAULT_FLOOR"]
    assert constant_differences(older, now) == []
    monkeypatch.setattr(adaptive, "RELIGHT_DEFAULT_FLOOR", 30.0)
    lines = constant_differences(older, decision_constants())
    assert lines == [f"{key} 10.0 → 30.0"]


def test_a_session_recorded_before_a_constant_was_added_resumes_while_it_is_neutral(
    monkeypatch,  # type: ignore[no-untyped-def]
) -> None:
    """Sessions recorded before the clipped-as-bound variant existed lack its constants: this
    build decides as theirs did while the variant is off, and names it once it is on."""
    from rti_rig.app.usecases.adaptive_constants import ADDED_NEUTRAL
    from rti_rig.planner import adaptive_bias

    now = decision_constants()
    assert set(ADDED_NEUTRAL) <= set(now)  # each names a constant that exists
    assert {k: now[k] for k in ADDED_NEUTRAL} == ADDED_NEUTRAL  # what ships is neutral
    older = {k: v for k, v in now.items() if k not in ADDED_NEUTRAL}
    assert constant_differences(older, now) == []
    monkeypatch.setattr(adaptive_bias, "CLIPPED_CENSORED", True)
    key = "planner.adaptive_bias.CLIPPED_CENSORED"
    assert constant_differences(older, decision_constants()) == [f"{key} 'absent' → True"]
    # a session recorded with the constant is compared as any other
    assert constant_differences(now, decision_constants()) == [f"{key} False → True"]


def test_the_advice_only_constants_steer_nothing_and_live_in_the_usecase() -> None:
    """A name exempt from the resume check must not be a decision's constant anywhere: only
    the usecase defines RTI_FILE_LIGHTS, and its value never reaches a chooser."""
    from rti_rig.app.usecases.adaptive_constants import ADVICE_ONLY

    holders = {
        name
        for name in DECISION_MODULES
        for key in ADVICE_ONLY
        if hasattr(importlib.import_module(name), key)
    }
    assert holders == {"rti_rig.app.usecases.adaptive"}
    now = decision_constants()
    recorded = dict(now)
    recorded["app.usecases.adaptive.RTI_FILE_LIGHTS"] = [["fit.rti", "HSH of order 2", 9]]
    assert constant_differences(recorded, now) == []
