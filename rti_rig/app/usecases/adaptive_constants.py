"""The constants an adaptive session's decisions depend on, recorded in its manifest.

Why: a decision is a function of the images *and* of the planner's constants (margins, floors,
the search's budget, the object model's settings). The decision format names what a session
records; it does not catch a constant changed between two builds of the same format. Recording
every constant lets a reader see what a session was chosen under, and lets ``--resume`` refuse,
from the manifest alone and naming the constant, a session whose choices this build would not
repeat.

The constants are collected, not listed by hand, so one added to a module is recorded without
anyone remembering to: every public upper-case module attribute holding plain data (numbers,
strings, booleans, None, or tuples/dicts of them) of the modules below, keyed by the module's
path under ``rti_rig`` (``planner.adaptive.SIM_MARGIN``, ``app.usecases.adaptive.FIT_PX``).
"""

from __future__ import annotations

import importlib
import json
from typing import Any

#: The modules whose constants shape an adaptive decision (the choosers, the object model, the
#: fitted designs' searches and the objectives they call, the starting layout, the robust fit
#: the designs are scored by and the sample is fitted with, the usecase's image reduction).
DECISION_MODULES = (
    "rti_rig.planner.adaptive",
    "rti_rig.planner.adaptive_bias",
    "rti_rig.planner.adaptive_optimal",
    "rti_rig.planner.adaptive_relief",
    "rti_rig.planner.adaptive_relight",
    "rti_rig.planner.adaptive_relight_design",
    "rti_rig.planner.adaptive_until",
    "rti_rig.planner.objectives",
    "rti_rig.planner.optimal",
    "rti_rig.planner.uniform",
    "rti_rig.reconstruct.photometric_stereo",
    "rti_rig.reconstruct.robust_ps",
    "rti_rig.reconstruct.solve",
    "rti_rig.app.usecases.adaptive",
)

#: Constants (by bare name, under whichever module records them: the dedup below keeps an import
#: under the first module that holds it) whose difference is no reason to refuse a resume: the
#: stop's factor decides only when to stop, never which light, and a resume takes it from the
#: session's settings (``upper_factor``); the quantile only derived that factor and is read by
#: nothing at run time. ``UNSOLVED_DEG`` (what each unsolved pixel adds to the upper estimate)
#: decides only when to stop too: a resume takes the session's own (``unsolved_deg``), and one begun
#: before the term existed is judged with this build's (its claim had left those pixels out: the
#: stop may come later; each light is the one it would have chosen). ``MISFIT_NOISE_K`` (the misfit
#: bound's allowance for noise) decides only when to stop as well: a resume takes the session's
#: own (``misfit_noise_k``), and a session begun before the bound is judged with it (it can only
#: hold a claim back). ``RING_SPAN_DEG`` (when a
#: band's start is spread round one ring) is the session's own on a resume too
#: (``resume_adaptive_source``): one begun before it existed resumes without it, as it began (a new
#: constant had refused every earlier session, those it changes nothing for too). A test checks that
#: no decision module defines another constant under these names (it would be exempted too).
RESTORED_ON_RESUME = frozenset(
    {
        "UPPER_FACTOR",
        "UPPER_QUANTILE",
        "RING_SPAN_DEG",
        "UNSOLVED_DEG",
        "MISFIT_NOISE_K",
    }
)

#: Constants of a decision module that only word the advice a session prints (how many lights
#: `rti-rig fit` needs for each file), never a choice of light: recorded, not compared, so a
#: build that words the advice otherwise still resumes the sessions of an earlier one. A test
#: checks that they live where they are expected and nowhere else.
ADVICE_ONLY = frozenset({"RTI_FILE_LIGHTS"})

#: How many differing constants a refusal names (the rest are counted).
NAMED_DIFFERENCES = 5


def _plain(value: Any) -> bool:
    if value is None or isinstance(value, bool | int | float | str):
        return True
    if isinstance(value, tuple | list):
        return all(_plain(v) for v in value)
    if isinstance(value, dict):
        return all(isinstance(k, str) and _plain(v) for k, v in value.items())
    return False


def decision_constants() -> dict[str, Any]:
    """``module.NAME`` (the module's path under ``rti_rig``) → value (as JSON reads it back:
    tuples as lists) for every constant of :data:`DECISION_MODULES`, read now (so a value a
    benchmark sets on the module is what is recorded). A constant a function takes as a
    default argument (``SIM_PIXELS``, ``ESTIMATE_SCALE`` …) was bound when its module was
    imported: one set on the module later is recorded but not used — set it before the import,
    or pass the argument."""
    out: dict[str, Any] = {}
    seen: dict[str, list[object]] = {}  # name → the objects earlier modules hold under it
    for name in DECISION_MODULES:
        module = importlib.import_module(name)
        short = name.removeprefix("rti_rig.")
        for key, value in sorted(vars(module).items()):
            if not (key.isupper() and not key.startswith("_") and _plain(value)):
                continue
            # the same object under the same name as in a module listed before is (almost
            # always) an import of it: recorded once, under the first (else a resume would
            # compare a stale copy). Two equal small ints or interned strings defined apart
            # collapse too; a later change then shows as "absent", which refuses, never
            # accepts silently
            if any(value is v for v in seen.get(key, ())):
                continue
            seen.setdefault(key, []).append(value)
            out[f"{short}.{key}"] = value
    return json.loads(json.dumps(out))


#: Constants split off an older one: a session recorded before the split lacks the new name,
#: and its value then was the old constant's (``--objective relight`` started from the normals
#: objective's default floor until ``RELIGHT_DEFAULT_FLOOR`` existed), so such a session still
#: resumes when the values agree.
SPLIT_FROM = {"planner.adaptive.RELIGHT_DEFAULT_FLOOR": "planner.adaptive.DESIGN_DEFAULT_FLOOR"}


#: Constants added after sessions were recorded, with the value that makes this build decide as
#: the builds before it did: a session recorded without one resumes while the build holds that
#: value (a new constant had refused every earlier session, including those it changes nothing
#: for), and is refused, naming it, once the value differs. The clipped-as-bound object model
#: (2026-12-05) is a benchmark variant, off in what ships; its level matters only when on.
ADDED_NEUTRAL: dict[str, Any] = {
    "planner.adaptive_bias.CLIPPED_CENSORED": False,
    "planner.adaptive_bias.CLIP_LEVEL": 0.999,
}


def constant_differences(recorded: dict[str, Any], current: dict[str, Any]) -> list[str]:
    """What differs between a session's recorded constants and this build's, one line each
    (``NAME recorded → now``; a constant one side lacks shows as ``absent``, unless it was
    split off a recorded one, :data:`SPLIT_FROM`, or added since at its neutral value,
    :data:`ADDED_NEUTRAL`), apart from :data:`RESTORED_ON_RESUME` and :data:`ADVICE_ONLY`."""
    lines = []
    for key in sorted(set(recorded) | set(current)):
        if key.rsplit(".", 1)[-1] in RESTORED_ON_RESUME | ADVICE_ONLY:
            continue
        was = recorded.get(key, recorded.get(SPLIT_FROM.get(key, ""), "absent"))
        now = current.get(key, "absent")
        if key not in recorded and key in ADDED_NEUTRAL and now == ADDED_NEUTRAL[key]:
            continue  # added since the session was recorded, at the value it decided under
        if was != now:
            lines.append(f"{key} {was!r} → {now!r}")
    return lines


def describe_differences(lines: list[str]) -> str:
    """The first :data:`NAMED_DIFFERENCES` differences, then how many more."""
    shown = "; ".join(lines[:NAMED_DIFFERENCES])
    more = len(lines) - NAMED_DIFFERENCES
    return shown + (f"; and {more} more" if more > 0 else "")
