"""Fixing a session's exposure before it starts, from short test series at its brightest light.

One exposure serves the whole session (RTI fitting assumes it): it must keep the brightest
image under the saturation limit. The planned lights are ranked by the light a level object
receives from each (the direction's height × the step's intensity), and metering starts at the
first; the metering itself — test shots, prediction, verification — is the camera driver
layer's ``meter`` function, injected here so that this policy stays free of drivers. The chosen
exposure is written into every step of the schedule, and the evidence into its provenance,
which the manifest records.

Where the lights' own outputs are not known — a dome whose LEDs were never evened out
(``rti-rig calibrate-lights``), which differ by tens of percent — the light nearest the zenith
need not be the brightest: on the emulated card dome 7 of 48 images metered that way clipped
56–100 %. There the next brightest-ranked lights, up to :data:`PROBE_LIGHTS` in all, are each
lit and checked at the chosen exposure (``recheck``, one shot each when they keep within the
rule), and a brighter one shortens it; the evidence names every light metered and the test
exposures shot under each.

Where the lights go dark by themselves a fixed time after they light (a timed firmware: RTIPy
lights an LED for 2 s), a series of test shots under one lighting outlasts it: each shot takes
settle + exposure + readout + transfer (about 1.1 s on the shipped configs), so the third shot
of a series was dark, metered as "nothing bright" and the exposure chosen the longest allowed
(0.95 s where 0.00136 s was right on the emulated RTIPy dome), and the off after the series
refused ("went dark by itself"). There each test shot is taken under its own lighting
(``shot_per_lighting``).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from rti_rig.core.deferred_signals import signals_deferred
from rti_rig.core.devices import ExposingCamera, Frame
from rti_rig.core.errors import DeviceError
from rti_rig.core.exposure_range import Bound, longer_than, shared_range
from rti_rig.core.schedule import LightSchedule, LightStep
from rti_rig.runtime.controller import (
    check_capture_fits_lit,
    lit_limit_s,
    shoot_step,
    validate_schedule,
)
from rti_rig.runtime.lighting import attempt_all, port_close_failures, unsafe_failures
from rti_rig.runtime.rig import Rig

#: ``meter(camera, start_exposure_s) -> choice`` where ``choice.exposure_s`` is the pick,
#: ``choice.to_manifest()`` the evidence and ``choice.test_exposures_s`` the shots it took.
Meter = Callable[[Any, float], Any]

#: Lights metering checks where their outputs are not known (brightest-ranked first). Each
#: costs at least one test shot (more where a brighter one is metered again). Measured by
#: ``python -m benchmarks.exposure_probes`` (the emulator's log-normal LED draws at 20 % RMS on
#: the shipped 48-LED layout, 4000 domes, a level Lambertian object, headroom 1.25): metering at
#: the highest light alone leaves some image over the limit in 57.8 % of domes, the 4 highest
#: in 12.8 %, the 6 highest 3.7 %, the 8 highest 2.2 %; 6 lights spread in elevation and
#: azimuth 64.1 % (they spend shots on low lights, which a level object receives least from).
#: With --lights 8, the 4 highest already leave none.
PROBE_LIGHTS = 6


@dataclass(frozen=True)
class Recheck:
    """What ``recheck(camera, exposure_s)`` found at one more light: the exposures of the test
    shots it took there, and a shorter exposure's choice (of ``meter``'s kind) where that light
    needs one, else None."""

    tested_s: tuple[float, ...]
    choice: Any | None = None

    @property
    def shots(self) -> int:
        return len(self.tested_s)


#: ``recheck(camera, exposure_s) -> Recheck``, at the light currently lit.
Rechecker = Callable[[Any, float], Recheck]


def exposure_steps(camera: object) -> Callable[[float], float] | None:
    """The camera's ``representable_exposure_s`` (an exposure it takes exactly, rounded
    down: a UVC camera's whole ``exposure_unit_s`` steps), or None for a camera that takes
    any exposure in its range or offers a list of its own (a DSLR's shutter speeds).

    Why one place: the metering asks the camera only for exposures it takes, its start, its
    test shots and its bound alike; each had looked the method up for itself."""
    steps = getattr(camera, "representable_exposure_s", None)
    return steps if callable(steps) else None


def representable_s(camera: object, exposure_s: float) -> float:
    """``exposure_s`` as the camera takes it exactly (:func:`exposure_steps`), unchanged on
    a camera with no steps."""
    steps = exposure_steps(camera)
    return float(steps(exposure_s)) if steps is not None else exposure_s


def _at_least_s(camera: object, exposure_s: float) -> float:
    """The shortest exposure the camera takes exactly at or above ``exposure_s``.

    Only the camera's rounding down (:func:`representable_s`) is known, so the step above is
    found by probing a growing distance past ``exposure_s``: the first probe that rounds down
    past the step under ``exposure_s`` lands on the next step (each probe at most doubles the
    distance, so it cannot skip one)."""
    under = representable_s(camera, exposure_s)
    if under >= exposure_s * (1 - 1e-9):
        return under
    gap = exposure_s - under
    for _ in range(64):
        above = representable_s(camera, exposure_s + gap)
        if above > under * (1 + 1e-9):
            return above
        gap *= 2
    return exposure_s  # a camera whose rounding never moves up: it takes this one


def metering_start(
    camera: object, exposure_s: float, within: tuple[Bound, Bound] | None = None
) -> tuple[float, str | None]:
    """Where the metering starts from ``[camera] exposure_s``, and a note saying why it is
    not ``exposure_s`` (None when it is): an exposure the camera takes
    exactly (:func:`representable_s`, rounded down, or up where that left the range) inside
    both the metering's own range ``within`` (``[camera] min_exposure_s`` … ``max_exposure_s``,
    less what a light's lit time allows; its ends with the phrases that name their keys) and
    the camera's: no shorter than the shortest it takes (a UVC camera's
    ``shortest_exposure_s``, its ``[camera.device] min_exposure_s``) and no longer than the
    longest (its ``longest_exposure_s``: ``[camera.device] max_exposure_s`` or the frame
    period, known once connected).

    Why one function: ``run --auto-exposure`` starts here, ``rti-rig check --auto-exposure``
    judges this start, and the note says it. The run had clamped again into ``within``
    without rounding: with ``[camera] min_exposure_s = exposure_s = 0.00125`` on a camera of
    0.0001 s units the check judged 0.0012 s while the metering shot 0.00125 s, which the
    camera cannot take exactly. And exposure_s is only a start: one under the device's
    minimum had stopped the run at the metering's first test shot, one over its maximum had
    been refused before any LED lit, while the docs say it "is only where the metering
    starts". The note is given whatever moved the start: the camera's range, ``within`` or
    the camera's units (a start moved by the last two had been taken silently, the user left
    to think the metering began at exposure_s). Raises :class:`DeviceError` naming both
    keys when no exposure the camera takes lies inside both ranges (before anything is
    lit)."""
    name = getattr(camera, "name", "camera")
    shortest = getattr(camera, "shortest_exposure_s", None)
    low: Bound | None = shortest() if callable(shortest) else None
    longest = getattr(camera, "longest_exposure_s", None)
    high: Bound | None = longest() if callable(longest) else None
    if high is not None:
        high = (representable_s(camera, high[0]), high[1])
    # the camera's range first: it is the one said on a tie
    shared = shared_range((low, high), within or (None, None))
    floor, cap = shared.floor, shared.cap
    start = exposure_s
    if cap is not None:
        start = min(start, cap[0])
    if floor is not None:
        start = max(start, floor[0])
    start = representable_s(camera, start)
    if floor is not None and start < floor[0] * (1 - 1e-9):
        start = _at_least_s(camera, floor[0])
    # no exposure in both ranges (the judgement the config check makes when it loads), or
    # none the camera takes exactly in what they share
    if cap is not None and (shared.empty or longer_than(start, cap)):
        raise DeviceError(
            name,
            f"no exposure the camera takes exactly lies between {floor[1] if floor else '0'} "
            f"and {cap[1]}: run --auto-exposure has nowhere to start its metering; lower the "
            "first or raise the second (nothing was lit)",
        )
    # the bound that moved the start is said: above both the camera's longest and [camera]'s
    # max_exposure_s, the lower of the two (the note had blamed the camera's frame period
    # while [camera] max_exposure_s had set the start)
    if high is not None and cap is high and exposure_s > high[0] * (1 + 1e-9):
        return start, (
            f"[camera] exposure_s = {exposure_s:g} s is longer than the camera {name} can "
            f"take ({high[1]}): the metering started at {start:g} s instead"
        )
    if low is not None and floor is low and exposure_s < low[0] * (1 - 1e-9):
        return start, (
            f"[camera] exposure_s = {exposure_s:g} s is shorter than the camera {name} can "
            f"take ({low[1]}): the metering started at {start:g} s instead"
        )
    if math.isclose(start, exposure_s, rel_tol=1e-9):
        return start, None
    # moved by [camera]'s own range (less what a light's lit time allows) or by the camera's
    # units: said the same way as a move by the camera's range, or the user is left to think
    # the metering began at exposure_s
    if within is not None and exposure_s > within[1][0] * (1 + 1e-9):
        why = f"is longer than the metering may go ({within[1][1]})"
    elif within is not None and exposure_s < within[0][0] * (1 - 1e-9):
        why = f"is shorter than the metering may go ({within[0][1]})"
    else:
        units = getattr(camera, "exposure_units_said", None)
        said = units() if callable(units) else None
        of = f" of {said}" if said else ""
        why = f"is not an exposure the camera {name} takes exactly (it takes whole units{of})"
        under = representable_s(camera, exposure_s)
        if within is not None and start > under and under < within[0][0] * (1 - 1e-9):
            why += f" and the one it takes under it is shorter than {within[0][1]}"
    return start, (
        f"[camera] exposure_s = {exposure_s:g} s {why}: the metering started at {start:g} s instead"
    )


def metering_start_s(
    camera: object, exposure_s: float, within: tuple[Bound, Bound] | None = None
) -> float:
    """The start of :func:`metering_start` alone (for callers that do not say it)."""
    return metering_start(camera, exposure_s, within)[0]


def metering_steps(schedule: LightSchedule, count: int = 1) -> list[int]:
    """Up to ``count`` step indices, one per light, brightest first by the light a level object
    receives from each (its direction's height × the step's intensity; ties keep plan order)."""
    lit = schedule.directions[:, 2] * np.array([s.intensity for s in schedule.steps])
    chosen: list[int] = []
    seen: set[object] = set()
    for i in np.argsort(-lit, kind="stable"):
        step = schedule.steps[int(i)]
        light = step.led if step.led is not None else step.direction
        if light in seen:
            continue
        seen.add(light)
        chosen.append(int(i))
        if len(chosen) == count:
            break
    return chosen


def brightest_step(schedule: LightSchedule) -> int:
    """Index of the planned light a level object receives most from (nearest the camera axis
    at full intensity)."""
    return metering_steps(schedule, 1)[0]


class _LitForEachShot:
    """The rig's camera for test shots at one light, lit and settled by the caller at
    ``lit_at``.

    With ``relight_each``, before each shot after the first the light is switched off, lit
    again and the settle waited, as the session does for each image: on a timed firmware the
    off waits for the end of the LED's window and refuses a shot that outlasted it, and the
    light command opens a new window (RTIPy's firmware blocks till its window ends: the new
    one follows it, never overlaps it).

    On a light with a time limit (a dome's ``max_on_s``), a camera that can say when its
    exposure is over (a DSLR) takes each test shot as a session's image is taken
    (:func:`rti_rig.runtime.controller.shoot_step`): a busy camera awaited lit only while its
    next try fits in ``max_on_s``, else in the dark, the light lit again for the shot; the
    light off once the exposure is over, the download and decode done in the dark, and the
    light lit again and settled for the next shot of the series. Until 2026-11-29 a series
    was shot under one lighting with every download and RAW decode lit, and every busy retry:
    three test shots of a bright object at a 3 s download each stopped ``run
    --auto-exposure`` at the thermal guard ("LED 40 stayed on 9.3 s, beyond max_on_s = 8 s;
    raise max_on_s or shorten settle and exposure"), as did a body busy 10 s.

    Every other attribute is the camera's (its shutter speeds, its name)."""

    def __init__(
        self,
        rig: Rig,
        step: LightStep,
        lit_at: float,
        relight_each: bool = False,
        strays: list[dict[str, Any]] | None = None,
    ) -> None:
        self._rig = rig
        #: pictures the camera delivered besides its test shots (``stray_originals``: taken
        #: behind a busy answer), said by the caller: a test shot is no session image, but a
        #: picture of the object had vanished with the metering's private folder unsaid
        self._strays = strays if strays is not None else []
        self._step = step
        self._lit_at = lit_at
        self._relight_each = relight_each
        self._lit_for_next = True  # lit and settled by the caller for the first shot
        self._dark = False  # switched off after the last shot (no other all-off needed)

    def capture(self, exposure_s: float) -> Frame:
        rig = self._rig
        # a longer test exposure is a longer frame period for a UVC camera, whose capture
        # reads several frames lit: refused before its light is lit again, not at the guard
        check_capture_fits_lit(
            rig, [exposure_s], f"the metering stopped before its test shot at {exposure_s:g} s"
        )
        if not self._lit_for_next:
            if not self._dark:
                rig.lighting.off()
            rig.lighting.set(self._step)
            self._lit_at = rig.clock.now()
            rig.clock.sleep(rig.timing.settle_s)
        camera = rig.camera
        if lit_limit_s(rig) is not None and isinstance(camera, ExposingCamera):
            self._lit_for_next, self._dark = False, True  # the shot ends with the light off
            frame, _ = shoot_step(rig, self._step, exposure_s, self._lit_at)
        else:
            self._lit_for_next, self._dark = not self._relight_each, False
            frame = camera.capture(exposure_s)
        for stray in frame.metadata.get("stray_originals") or []:
            self._strays.append(
                {
                    "camera_file": str(stray.get("name") or stray.get("path")),
                    "kept": "on the camera's card" if stray.get("left_on_card") else "not kept",
                }
            )
        return frame

    def __getattr__(self, name: str) -> Any:
        return getattr(self._rig.camera, name)


#: The attribute of the error or stop that ended metering which carries what its teardown
#: could not do: named once, here, for :func:`carry_teardown_failures` and
#: :func:`teardown_failures_of` alone.
_CARRIED = "teardown_failures"


def carry_teardown_failures(exc: BaseException, failures: list[str]) -> None:
    """Attach to ``exc``, the error or stop (Ctrl-C, SIGTERM, a fault no part of rti-rig
    named) that ended metering, what metering's teardown could not do.

    Why an attribute set here, not one each error type declares: a KeyboardInterrupt or a
    camera driver's TypeError is raised on as it is (wrapped, it would be said otherwise and
    stop otherwise), and their types cannot declare it. Its writer and readers had each
    spelt the name (a ``# type: ignore`` and a ``getattr``), so a misspelt one was read as
    "nothing failed"."""
    setattr(exc, _CARRIED, failures)


def teardown_failures_of(exc: BaseException) -> list[str]:
    """What metering's teardown could not do, as :func:`carry_teardown_failures` attached it
    to ``exc`` (empty: ``exc`` did not end metering, or its teardown did all); each as it
    was (a port's close a :class:`~rti_rig.runtime.lighting.PortCloseFailure`, told by type)."""
    return list(getattr(exc, _CARRIED, None) or ())


def fix_session_exposure(
    rig: Rig,
    schedule: LightSchedule,
    meter: Meter,
    recheck: Rechecker | None = None,
    probes: int = 1,
    *,
    shot_per_lighting: bool = False,
    within: tuple[Bound, Bound] | None = None,
    say: Callable[[str], None] | None = None,
) -> LightSchedule:
    """Meter at the brightest-ranked planned light, check up to ``probes`` - 1 more with
    ``recheck`` (each may shorten the exposure, never lengthen it), and return the schedule
    with the exposure fixed.

    The schedule is validated first (nothing moves for a schedule the rig cannot run), each
    light is switched off after its shots and at the end, and devices are closed so that the
    session starts from a clean connect, except a dome's port, which a lighting that can
    (``hold``) keeps open, switched off: reopening it resets an Uno-class board, and the Nab
    sketch boots with every LED lit until the session's all-off. A failed metering closes all.

    ``shot_per_lighting``: the lights go dark by themselves a fixed time after they light (a
    timed firmware's window, which holds one capture but not a series), so each test shot is
    taken under its own lighting (:class:`_LitForEachShot`), as each image of the session is.

    ``within``: the metering's own range, its ends with the keys that set them, for its start
    (:func:`metering_start`), which ``meter`` is given as it is (it had clamped it again).

    The evidence records the time metering took on the rig's clock (``rig_time_s``, from the
    connect to the teardown; on a dry run the simulated rig's) and on the wall
    (``wall_time_s``): the session's time on the real rig includes it (it had left out the
    test shots: 7 shots, about 8 s, on the emulated card dome).

    ``say``: where a dome's lost port, reopened while metering, is said as it happens, as a
    run says it (the metering's connect had no listener: a drop there was reopened with
    nothing said); its teardown's reopening is said as being for the all-off.
    """
    if probes < 1:
        raise ValueError(f"probes must be at least 1, got {probes}")
    validate_schedule(rig, schedule)
    steps = metering_steps(schedule, probes if recheck is not None else 1)

    # a light with a time limit (a dome's max_on_s) holds one shot, not a series, for a camera
    # that holds it lit until its frame is in (a dry run's simulated camera, an OpenCV one):
    # a series under one lighting had overrun it ("LED 41 stayed on 2.235 s, beyond max_on_s
    # = 1.16 s"), each shot alone fitting (a DSLR's shots end dark, see _LitForEachShot)
    relight_each = shot_per_lighting or lit_limit_s(rig) is not None

    strays: list[dict[str, Any]] = []

    def camera_at(step: LightStep, lit_at: float) -> Any:
        return _LitForEachShot(rig, step, lit_at, relight_each=relight_each, strays=strays)

    def teardown(keep_lights: bool = False) -> list[str]:
        # every step of the teardown runs, whatever one device does; what failed is said. A
        # Ctrl-C or SIGTERM is held until it is done (as the capture's teardown holds them):
        # a second Ctrl-C ("stop at once") had cut the all-off short with an LED lit, and the
        # dome's last all-off, the one between two metered lights, was then reported as the
        # state of the lights ("acknowledged by the dome: lights are off")
        with signals_deferred():
            # (a dome's safe() marks the teardown first: a reopening now is for its all-off)
            failures = rig.lighting.safe()
            # a dome kept open (hold) only once its all-off went through: one that failed is
            # closed, and the error says so
            hold = keep_lights and not failures
            failures += attempt_all(
                [
                    ("camera close", rig.camera.close),
                    ("lights close", rig.lighting.hold if hold else rig.lighting.close),
                ]
            )
            if not (hold and rig.lighting.link_open):  # closed (a hold that cannot, closes)
                # a port that did not close cleanly was said as it happened, never raised:
                # kept with the rest, as the run's teardown keeps it (it had been in no record)
                failures += port_close_failures(rig.lighting)
            return failures

    at = steps[0]
    tested: list[list[float]] = []
    started, wall_started = rig.clock.now(), time.perf_counter()
    rig.lighting.listen(say)
    try:
        rig.lighting.connect()
        rig.camera.connect()
        # the metering's first shot, the shortest it starts from: a UVC camera's drain that
        # does not fit the light's limit then would stop it at the thermal limit, lit
        # [camera] exposure_s is only where the metering starts, in what the camera takes
        # exactly (whole exposure_unit_s) inside both ranges (metering_start, decided once
        # here and judged so by check): refusing 0.00125 s as "not a whole number" of
        # 0.0001 s stopped a run whose metering never asks for it
        start = metering_start_s(rig.camera, rig.camera_config.exposure_s, within)
        check_capture_fits_lit(rig, [start], "nothing was lit")
        rig.lighting.set(schedule.steps[at])
        lit_at = rig.clock.now()
        rig.clock.sleep(rig.timing.settle_s)
        choice = meter(camera_at(schedule.steps[at], lit_at), start)
        tested.append([float(t) for t in getattr(choice, "test_exposures_s", ())])
        for j in steps[1:] if recheck is not None else ():
            rig.lighting.off()  # one light at a time: the last one's off before the next lights
            rig.lighting.set(schedule.steps[j])
            lit_at = rig.clock.now()
            rig.clock.sleep(rig.timing.settle_s)
            found = recheck(camera_at(schedule.steps[j], lit_at), float(choice.exposure_s))
            tested.append([float(t) for t in found.tested_s])
            if found.choice is not None and found.choice.exposure_s < choice.exposure_s:
                choice, at = found.choice, j
    except BaseException as exc:
        # a Ctrl-C or an error while metering: what the teardown could not do travels with it
        # (it had been dropped, and the user told an all-off was sent)
        carry_teardown_failures(exc, teardown())
        raise
    failures = teardown(keep_lights=True)
    rig_time_s, wall_time_s = rig.clock.now() - started, time.perf_counter() - wall_started
    if unsafe := unsafe_failures(failures):
        # the port's close too (said as it happened), and the failures carried with the error
        # as with any other that ends metering: the error had named the all-off alone, and
        # the port's failure went with nothing (never said to be in no record)
        # (named, not repeated: the dome's own line said it in full)
        closed = len(unsafe) < len(failures)
        also = ", and its lights' port did not close cleanly (said above)" if closed else ""
        error = DeviceError(
            rig.name,
            "metering could not make the rig safe (" + "; ".join(unsafe) + f"){also}: check "
            "the lights before anything else",
            "meter",
        )
        carry_teardown_failures(error, failures)
        raise error
    steps_fixed = tuple(replace(s, exposure_s=float(choice.exposure_s)) for s in schedule.steps)
    evidence = {
        **choice.to_manifest(),
        "metered_at_step": at + 1,
        "lights_metered_at_steps": [i + 1 for i in steps],
        "test_exposures_by_light_s": tested,
        # a meter that names no test exposure took one shot at least
        "metering_shots": max(len(tested[0]), 1) + sum(len(t) for t in tested[1:]),
        "shot_per_lighting": shot_per_lighting,
        **({"metering_strays": strays} if strays else {}),
        # what the teardown could not do, none unsafe (a port's close, said as it happened):
        # recorded with the exposure it fixed, in the session's manifest
        **({"teardown_failures": failures} if failures else {}),
        "rig_time_s": rig_time_s,
        "wall_time_s": wall_time_s,
    }
    fixed = replace(
        schedule, steps=steps_fixed, provenance={**schedule.provenance, "exposure": evidence}
    )
    validate_schedule(rig, fixed)
    return fixed
