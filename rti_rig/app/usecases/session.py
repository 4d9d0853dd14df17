"""Capture sessions as use cases: start one, resume one, shoot a preview, run what was opened.

Everything that can be checked is checked here, once, before anything moves: the options, the
light count, the session folder, then the rig is opened and the schedule checked against it. The
CLI only parses its options into a request, calls these functions and prints what they report.
"""

from __future__ import annotations

import contextlib
import math
import signal
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from rti_rig.app.usecases.replay_advice import new_session_command
from rti_rig.app.usecases.run_options import band_options, run_words
from rti_rig.core.errors import ConfigError, RtiRigError, ScheduleError
from rti_rig.core.out_folders import free_folder_beside, free_name
from rti_rig.core.rig_geometry import DomeGeometry, in_band, led_fields
from rti_rig.core.schedule import LightSchedule, LightStep
from rti_rig.core.shell_words import shell_word, shown_path
from rti_rig.runtime.controller import (
    CancelToken,
    EmergencyStop,
    Event,
    FinishReason,
    SessionResult,
    run_session,
    validate_schedule,
)
from rti_rig.runtime.lighting import ANOTHER_LAYOUT
from rti_rig.runtime.rig import Rig
from rti_rig.runtime.session import (
    NoSpaceError,
    SessionFolder,
    check_free_space,
    image_names,
)


@dataclass(frozen=True)
class Note:
    """A message for the user while a session is being opened.

    ``level`` is ``"info"`` (what happens: the exposure chosen, what resume found) or
    ``"warning"`` (something the user should know before the lights come on).
    """

    text: str
    level: str = "info"


NoteSink = Callable[[Note], None]


def _ignore(_note: Note) -> None:
    pass


@dataclass(frozen=True)
class NewSessionRequest:
    """Start a session of a homogeneous layout (``lights``) or of a plan (``plan``, an .lp)."""

    rig_config: Path
    out_dir: Path
    lights: int | None = None
    plan: Path | None = None
    min_elevation_deg: float = 0.0
    max_elevation_deg: float = 90.0
    #: each bound of the band was typed, not defaulted: an arm that cannot reach the band says
    #: so even of 0..90, naming only the options typed
    min_elevation_given: bool = False
    max_elevation_given: bool = False
    auto_exposure: bool = False
    max_saturated: float = 0.001
    #: Choose each next light from the images so far (up to ``lights``; docs/adaptive.md).
    adaptive: bool = False
    #: Adaptive: stop once the upper estimate of the mean normal error is at most this (°).
    until_error_deg: float | None = None
    #: Adaptive: what the design of ``lights`` is chosen for, ``normals`` or ``relight``
    #: (None: normals; refused for a session that is not adaptive).
    objective: str | None = None
    #: Adaptive with ``until_error_deg``: the fewest lights the stop may claim the target at
    #: (None: no minimum; a PTM needs 6, an HSH fit.rti 5).
    min_lights: int | None = None
    #: Capture lights that cannot determine a normal (one plane, bunched at the zenith) with a
    #: warning, in place of the refusal: raking-light documentation at one azimuth.
    allow_no_normals: bool = False

    @property
    def is_adaptive(self) -> bool:
        return self.adaptive or self.until_error_deg is not None

    @property
    def adaptive_option(self) -> str:
        """The option that made the session adaptive, as a refusal should name it. Why: a run
        given only ``--until-error`` was told "--adaptive chooses its own lights", an option
        the user never typed."""
        if self.adaptive:
            return "--adaptive"
        return "--until-error (an adaptive session)"


@dataclass(frozen=True)
class ResumeRequest:
    """Continue an interrupted session; ``rig_config`` defaults to the session's own.

    The rig must be the one the session began on (see :mod:`rti_rig.app.rig_identity`); a
    deliberate change to its lights (a repaired LED, recalibrated positions) needs
    ``accept_rig_change`` and is recorded in the manifest's run. A change to what the images
    are (exposure, gain, size, decoding, camera) is refused even then.
    """

    session_dir: Path
    rig_config: Path | None = None
    max_saturated: float = 0.001
    accept_rig_change: bool = False
    #: An adaptive session's objective, if the user names it: it must be the session's own.
    objective: str | None = None
    #: A session that completed: reshoot the images lost or changed since capture (the QA
    #: verdict names them), with the object where it was.
    reshoot_lost: bool = False
    #: A session that completed: reshoot these images too (``image_006`` or its file name),
    #: their files intact but named by the user (``--reshoot``: an image the QA verdict calls
    #: misfired); set aside in recovered/ as a lost image's are. Implies ``reshoot_lost``.
    reshoot: tuple[str, ...] = ()
    #: A session whose journal lost records (deleted, cut short, overwritten): rebuild it from
    #: the manifest's records whose files and lights are as recorded (the rest set aside).
    rebuild_journal: bool = False
    #: The options that begin a session, given again (a script's same command line): the
    #: resume goes on only if they are the session's own (a ``StartOptions`` of
    #: :mod:`rti_rig.app.usecases.resume_request`; None: none given).
    start: Any = None


@dataclass(frozen=True)
class PreviewRequest:
    """Shoot one image under one light (``light_az_el_deg``; default: the planner's choice)."""

    rig_config: Path
    out_dir: Path
    light_az_el_deg: tuple[float, float] | None = None
    auto_exposure: bool = False
    max_saturated: float = 0.001
    #: the elevation band (°) the preview's light keeps to (``--min/--max-elevation-deg``, as
    #: ``plan`` and ``run`` take them): the band the session will be planned in
    min_elevation_deg: float = 0.0
    max_elevation_deg: float = 90.0


@dataclass
class OpenedSession:
    """A rig opened and checked, its schedule, and the session folder to write into.

    Use it as a context manager (or pass it to :func:`run_opened_session`) so the rig is
    closed whatever happens.
    """

    rig: Rig
    schedule: LightSchedule
    folder: SessionFolder
    out_dir: Path
    resumed: bool = False
    extra: dict[str, Any] = field(default_factory=dict)
    #: An adaptive session's step source (:mod:`rti_rig.app.usecases.adaptive`); None: the
    #: schedule is run as it is.
    source: Any = None
    #: whether a card camera lists its card before the first shot (a capture session, `run`;
    #: not the one-image session of `preview`, which had waited minutes on a full card)
    list_card: bool = True
    #: the request a resumed session was opened by (None: a new session): what the user gave
    #: (a rig config, --accept-rig-change …), which the command to continue with must repeat
    request: ResumeRequest | None = None
    #: whether :meth:`close` has been called (the capture's ``with`` closes the rig; a stop
    #: before it took the rig leaves the command to close it, once)
    closed: bool = False
    #: what :meth:`close` could not do in making safe a rig the controller's teardown never
    #: took (for the command to say, through :meth:`take_close_failures`)
    close_failures: list[str] = field(default_factory=list)
    #: whether :attr:`close_failures` are recorded on disk too, in the run's cut end
    #: (``runner.teardown_failures``); False where this run wrote no record to keep them in (it
    #: never began: no manifest of it exists, and none is made up for them)
    close_recorded: bool = False
    #: the finish reason of the stop that left the capture's ``with`` (an emergency stop, a
    #: Ctrl-C), for :meth:`close` to record where it cut the run's end; None: no stop
    cut_by: str | None = None
    #: a stop the user insisted on (a second Ctrl-C) once the capture had ended, which stopped
    #: no image: the command stops after its summary (``run`` before its QA verdict,
    #: ``preview`` after its plan hint), exit 128 + its number, while the manifest keeps how
    #: the capture ended; None: none came
    stopped_once_over: signal.Signals | None = None

    @property
    def dry_run(self) -> bool:
        return self.rig.loaded.config.backend != "hardware"

    @property
    def steps_done_before(self) -> int:
        """Images verified on disk before this run (a resumed session's)."""
        return len(self.folder.done)

    @property
    def total_steps(self) -> int:
        """The session's steps: the schedule's, or an adaptive session's maximum."""
        return len(self.schedule) if self.source is None else self.source.total

    @property
    def steps_to_do(self) -> int:
        return self.total_steps - self.steps_done_before

    @property
    def teardown_ran(self) -> bool:
        """Whether the controller's teardown took the rig in this run (it hands the run's end
        to :meth:`SessionFolder.finish` whatever happens, so :attr:`SessionFolder.run_end` is
        set).

        Why one place: :meth:`close` makes the devices safe in the teardown's stead when it
        did not run, and ``run`` tells such a stop from a stop during the capture by the same
        fact; each had read ``run_end`` on its own."""
        return self.folder.run_end is not None

    def take_close_failures(self) -> list[str]:
        """What :meth:`close` could not make safe, handed over once (emptied as it is taken).

        Why: the command says them beside the stop that led to the close; the ``finally``
        that closes the rig a second time round must not say them again (the command had
        emptied this list itself)."""
        failures, self.close_failures = self.close_failures, []
        return failures

    def close(self) -> None:
        """Release the rig and the session's lock; once (a second call does nothing).

        Where the controller's teardown never ran (a stop after the capture's ``with`` began,
        before the controller's ``try``: :attr:`teardown_ran` False), its device part is done
        here first, before the rig's resources go: the lights' all-off where their link is
        open (a dome held open after metering), then the camera's and the lights' close,
        signals held; what failed is kept in :attr:`close_failures`.

        Why: the rig's close releases only what ``build_rig`` opened (an emulator, its pty),
        trusting the controller to have made the devices safe: a SIGTERM as the capture
        checked the free space left the emulated dome's held port open, its all-off unsent."""
        from rti_rig.core.deferred_signals import signals_deferred
        from rti_rig.runtime.lighting import attempt_all, port_close_failures
        from rti_rig.runtime.session import unlock_session

        if self.closed:
            return
        self.closed = True
        rig = self.rig
        try:
            with signals_deferred():
                try:
                    if not self.teardown_ran:
                        done: list[str] = []
                        if rig.lighting.link_open:
                            done += rig.lighting.safe(emergency=True)
                        done += attempt_all(
                            [
                                ("camera close", rig.camera.close),
                                ("lights close", rig.lighting.close),
                            ]
                        )
                        # a port that did not close cleanly was said as it happened, never
                        # raised: kept as the controller's teardown keeps it (it had been said
                        # to the user and in no record of the run)
                        done += port_close_failures(rig.lighting)
                        self.close_failures += done
                        if self.cut_by is not None:
                            # a stop cut the run's end before the controller recorded it: said
                            # on disk as a stop, not left as a kill leaves it. After the devices
                            # are safe: the manifest's fsync (seconds behind a slow card's
                            # pending images) had kept a lamp or an LED lit while it ran
                            self.close_recorded = self.folder.record_cut_end(self.cut_by, done)
                finally:
                    # every resource closed whatever the record did, each failure kept for the
                    # command to say, never raised: it had replaced the session's own error (an
                    # emulator's close after a servo's overload: "unexpected OSError", the
                    # overload unsaid)
                    self.close_failures += rig.close()
        finally:
            try:  # a reshoot stopped before its capture began: the images it set aside back
                self.folder.put_back_now()
            except Exception as exc:  # never in place of why the run stopped
                self.close_failures.append(f"put back the images set aside: {exc}")
            finally:
                unlock_session(self.folder.root)  # a resume's lock, also for a run never started

    def __enter__(self) -> OpenedSession:
        return self

    def __exit__(self, exc_type: object, exc: object, tb: object) -> None:
        from rti_rig.runtime.controller import EmergencyStop, FinishReason

        if isinstance(exc, EmergencyStop):
            self.cut_by = str(FinishReason.EMERGENCY_STOP)
        elif isinstance(exc, KeyboardInterrupt):
            self.cut_by = str(FinishReason.INTERRUPTED)
        self.close()


def check_max_saturated(max_saturated: float) -> None:
    if not 0.0 <= max_saturated < 1.0:
        raise RtiRigError(
            f"--max-saturated {max_saturated:g}: give a fraction of pixels in [0, 1), "
            "e.g. 0.001 for 0.1 %"
        )


def default_lights(loaded, geometry) -> int:  # type: ignore[no-untyped-def]
    """The light count a run uses without ``--lights``: every LED of a dome (or its
    ``default_lights``), the arm's ``default_lights``."""
    from rti_rig.core.rig_geometry import DomeGeometry

    cfg = loaded.config
    if isinstance(geometry, DomeGeometry):
        assert cfg.dome is not None
        return int(cfg.dome.default_lights or geometry.count)
    assert cfg.arm is not None
    return int(cfg.arm.default_lights)


class RigChangedError(RtiRigError):
    """A resume was asked on a rig whose images would not match the session's."""


def check_light_count(n: int, asked: str | None = None, way_out: str = "") -> None:
    """Refuse a light count no session can run, before any layout is built, on every rig
    (the planner names a dome's own limit, its LED count).

    ``asked`` says where ``n`` came from when no ``--lights`` gave it (a plan's lines, every
    image of a recorded acquisition), ``way_out`` what to do then. Why: a dense acquisition
    of 1100 images replayed without ``--lights`` had been told "--lights 1100: at most 1000",
    of an option never given, and not how to run it at all."""
    from rti_rig.core.lp_format import MAX_LIGHTS

    said = asked or f"--lights {n}"
    if n < 1:
        from rti_rig.app.usecases.fit_outlook import fit_needs

        raise RtiRigError(f"{said}: give at least 1 light (1 or 2 make a test shot; {fit_needs()})")
    if n > MAX_LIGHTS:
        raise RtiRigError(
            f"{said}: at most {MAX_LIGHTS} lights per session (the most an .lp file may "
            "list for readers such as relight)" + (f"; {way_out}" if way_out else "")
        )


def too_few_to_fit(n: int, schedule: LightSchedule | None = None) -> Note | None:
    """What `rti-rig fit` will not make of a session of ``n`` lights (:func:`fit_outlook`):
    accepted (a test shot of one or two lights is a use), but said before the rig moves, not
    only by the QA or the fit afterwards (``--lights 3`` had been silent, its verdict "good",
    and plain ``fit`` then failed).

    ``schedule``: the session's lights, where known. Lights that cannot determine a normal
    (captured with ``--allow-no-normals``) get no note here: their own note has said what the
    fit makes of them, from the same rules (a second note had promised them a normal map)."""
    from rti_rig.app.usecases.fit_outlook import fit_outlook

    if schedule is not None:
        import numpy as np

        from rti_rig.app.normals_determined import undetermined_normals

        lights = np.array([s.direction for s in schedule.steps], dtype=np.float64)
        if undetermined_normals(lights) is not None:
            return None
    said = fit_outlook(n)
    return None if said is None else Note(said, "warning")


def checked_rig(  # type: ignore[no-untyped-def]
    loaded, schedule: LightSchedule, shot: frozenset[int] = frozenset()
) -> Rig:
    """The rig, opened, with ``schedule`` checked against it before anything moves.

    ``shot``: a resume's steps already taken (0-based), not checked: history, shot on the rig
    as it was (:func:`~rti_rig.runtime.controller.validate_schedule`).

    The rig is closed (lights off, arm stopped) if the check fails, whatever the exception.
    """
    from rti_rig.app.compose import build_rig

    _check_timed_window(loaded, schedule, shot)  # before the port opens
    rig = build_rig(loaded)
    try:
        validate_schedule(rig, schedule, shot)
    except BaseException:
        rig.close_said()  # its failures said, never in place of the error raised
        raise
    return rig


def _check_timed_window(  # type: ignore[no-untyped-def]
    loaded, schedule: LightSchedule, shot: frozenset[int] = frozenset()
) -> None:
    """Refuse a plan's own exposures that a timed firmware's on-window cannot hold (the config's
    exposure_s is checked when the config loads); ``shot``, a resume's steps taken, aside."""
    from rti_rig.app.config import timed_exposure_limit
    from rti_rig.core.errors import ScheduleError

    limit = timed_exposure_limit(loaded)
    if limit is None:
        return
    over = [
        f"step {i + 1}: exposure {step.exposure_s:g} s"
        for i, step in enumerate(schedule.steps)
        if i not in shot
        and step.exposure_s is not None
        and step.exposure_s > limit.max_exposure_s + 1e-9
    ]
    if over:
        raise ScheduleError(
            f"{len(over)} step(s) expose longer than the {limit.max_exposure_s:.3g} s that fit: "
            f"{limit.window_said()}, and each capture (settle + exposure + readout + transfer) "
            f"must end while its LED is lit; nothing has moved: {'; '.join(over[:5])}"
            f"{' ...' if len(over) > 5 else ''}"
        )


def _check_steps_fit_lit(  # type: ignore[no-untyped-def]
    loaded, schedule: LightSchedule, done: frozenset[int] = frozenset()
) -> None:
    """Refuse the steps' own exposures (a metered session's, resumed) whose shot cannot end
    while its LED is lit, ``[dome.serial.thermal] max_on_s``, before the port opens.

    Why: the config's exposure_s is checked when it loads, the steps' were not. A session
    metered at 0.084 s and resumed after max_on_s was lowered to 1.17 s opened the dome, lit
    LED 21 and stopped at the thermal guard ("LED 21 stayed on 1.186 s, beyond max_on_s =
    1.17 s; the firmware watchdog switched it off"), then said to resume, which did the same.
    """
    from rti_rig.app.config import lit_per_shot, shot_said
    from rti_rig.core.errors import ScheduleError

    dome = loaded.config.dome
    serial = dome.serial if dome is not None else None
    if serial is None:
        return
    max_on = serial.thermal.max_on_s
    fixed, _ = lit_per_shot(loaded)
    over = [
        (i, step)
        for i, step in enumerate(schedule.steps)
        if i not in done and step.exposure_s is not None and fixed + step.exposure_s > max_on + 1e-9
    ]
    if not over:
        return
    i, step = over[0]
    # a dome's LED by its number and direction, as every word names it
    led = f" ({led_fields(step.led, step.direction, step.label)})" if step.led is not None else ""
    _, said = shot_said(loaded, "its exposure_s", round(step.exposure_s or 0.0, 6))
    need = math.ceil((fixed + max(s.exposure_s or 0.0 for _, s in over)) * 100) / 100
    steps = ", ".join(str(j + 1) for j, _ in over[:10]) + (" ..." if len(over) > 10 else "")
    raise ScheduleError(
        f"{len(over)} step(s) to shoot expose too long for an LED that may stay lit at most "
        f"[dome.serial.thermal] max_on_s = {max_on:g} s ({shown_path(loaded.path)}): step "
        f"{i + 1}{led}, {said}, would run into the thermal limit (step(s) {steps}); nothing has "
        "moved. A step's exposure_s is the schedule's own (fixed when the session began, by "
        "--auto-exposure), which the session's images share: raise max_on_s to at least "
        f"{need:g} s if the LEDs allow it, or shorten the [timing] keys"
    )


def fix_exposure(
    rig: Rig, schedule: LightSchedule, max_saturated: float, on_note: NoteSink = _ignore
) -> LightSchedule:
    """Meter the session's exposure with the camera driver layer's test series.

    On a timed firmware (RTIPy) the metering may choose no exposure longer than the LED's
    self-timed window leaves room for: the camera's ``max_exposure_s`` is lowered to it, with
    a note (a longer exposure would be refused at its capture on the dome). And each test shot
    is taken under its own lighting (the policy's ``shot_per_lighting``): a window holds one
    capture, not a series (about 1.1 s per shot on the shipped configs against RTIPy's 2 s),
    and the later shots of a series under one lighting had been dark.

    On a dome whose LEDs were never evened out (:func:`_light_outputs_unknown`) the light
    nearest the zenith need not be the brightest: metered there alone, 7 of the 48 images of
    the emulated card dome clipped 56–100 %. There up to ``PROBE_LIGHTS`` of the highest-ranked
    planned lights are checked, at one test shot each at least, with a note saying so and what
    it costs before the lights come on."""
    from rti_rig.core.devices import ShutterSpeedCamera
    from rti_rig.drivers.cameras.exposure import meter_exposure, recheck_exposure
    from rti_rig.drivers.cameras.settings import ExposureRule
    from rti_rig.runtime.exposure_policy import (
        PROBE_LIGHTS,
        Recheck,
        exposure_steps,
        fix_session_exposure,
        metering_start,
        metering_steps,
        representable_s,
    )

    cam = rig.camera_config
    longest = cam.max_exposure_s
    limit = _timed_limit(rig)
    if limit is not None:
        own = (
            "each test shot is taken under a window of its own (its LED lit again for it): "
            "a window holds one capture, not a series"
        )
        if limit.max_exposure_s < longest:
            longest = max(limit.max_exposure_s, cam.min_exposure_s)
            on_note(
                Note(
                    f"Metering chooses no exposure longer than {longest:.3g} s (not the "
                    f"camera's max_exposure_s = {cam.max_exposure_s:g} s): "
                    f"{limit.window_said()}, and each capture (settle + exposure + readout + "
                    "transfer) must end while its LED is lit. For longer exposures raise "
                    f"dome.serial.protocol.light_on_s. And {own}"
                )
            )
        else:
            on_note(Note(f"Metering: {limit.window_said()}, so {own}"))
    # an LED may stay lit max_on_s at a time (the dome's thermal guard), and a shot (settle,
    # exposure, readout) must end within it: metering of a dark object had chosen the camera's
    # max_exposure_s (30 s on the shipped DSLR example) and shot it with the LED lit 30 s
    # against max_on_s = 8 s (no watchdog on that firmware), the session then refused
    lit_cap = _lit_exposure_cap(rig)
    if lit_cap is not None and lit_cap < longest:
        longest = max(lit_cap, cam.min_exposure_s)
    else:
        lit_cap = None
    within = metering_range(rig)
    rule = ExposureRule(
        max_saturated_fraction=max_saturated,
        headroom=1.25,  # other planned lights may be a little brighter than the metered one
        min_exposure_s=within[0][0],
        max_exposure_s=within[1][0],
    )

    #: what the connected camera bounds the exposure by, where it is shorter than the rule's
    camera_cap: list[tuple[float, str]] = []
    #: the shortest exposure the camera takes, where it is longer than the rule's
    camera_floor: list[tuple[float, str]] = []

    def camera_rule(camera) -> ExposureRule:  # type: ignore[no-untyped-def]
        # the camera is connected by now: its own range (a UVC camera's frame period, its
        # [camera.device] min_exposure_s) is known, which the config's [camera] range is not
        update: dict[str, float] = {}
        shortest = getattr(camera, "shortest_exposure_s", None)
        low = shortest() if shortest is not None else None
        if low is not None and low[0] > rule.min_exposure_s * (1 + 1e-9):
            # a device minimum above [camera]'s: a bright object had been metered down to a
            # test shot the camera refuses ("outside the configured range"), stopping the run
            camera_floor[:] = [low]
            update["min_exposure_s"] = low[0]
        bound = getattr(camera, "longest_exposure_s", None)
        found = bound() if bound is not None else None
        if found is not None and found[0] < rule.max_exposure_s:
            # kept as the longest exposure the camera takes exactly (whole exposure_unit_s):
            # at 30 fps 1/30 s is 333 units, 0.0333 s, which the warning's check never reached
            camera_cap[:] = [(representable_s(camera, found[0]), found[1])]
            update["max_exposure_s"] = found[0]
        if not update:
            return rule
        low_s = update.get("min_exposure_s", rule.min_exposure_s)
        high_s = max(update.get("max_exposure_s", rule.max_exposure_s), low_s)
        return rule.model_copy(update={"min_exposure_s": low_s, "max_exposure_s": high_s})

    def shutter_speeds() -> list[float] | None:
        # a camera with its own list of exposures (a DSLR's shutter speeds) is metered on it:
        # asked of the rig's camera, which the metering's camera wraps, by its declared
        # capability (core.devices), where getattr had probed the wrapper by name
        camera = rig.camera
        return camera.available_exposures_s() if isinstance(camera, ShutterSpeedCamera) else None

    # a camera taking exposures in steps (a UVC camera's exposure_unit_s) is asked for those
    def meter(camera, start_s: float):  # type: ignore[no-untyped-def]
        ruled = camera_rule(camera)
        if not isinstance(rig.camera, ShutterSpeedCamera):
            # a start moved into the camera's range is said (it had been refused above it)
            moved = metering_start(camera, cam.exposure_s, within)[1]
            if moved is not None:
                on_note(Note(moved))
        return meter_exposure(
            camera,
            ruled,
            # [camera] exposure_s is only where the metering starts, decided once, inside both
            # ranges and in the camera's units (metering_start): clamped again here it had
            # left the camera's units (0.00125 s on a 0.0001 s camera, judged 0.0012 s)
            start_s,
            shutter_speeds(),
            quantise=exposure_steps(camera),
        )

    def recheck(camera, exposure_s: float) -> Recheck:  # type: ignore[no-untyped-def]
        choice, tested = recheck_exposure(
            camera,
            camera_rule(camera),
            exposure_s,
            shutter_speeds(),
            quantise=exposure_steps(camera),
        )
        return Recheck(tested, choice)

    unknown = _light_outputs_unknown(rig)
    probes = min(PROBE_LIGHTS, len(metering_steps(schedule, PROBE_LIGHTS))) if unknown else 1
    if probes > 1:
        on_note(Note(_probes_said(rig, unknown, probes, limit)))
    try:
        fixed = fix_session_exposure(
            rig,
            schedule,
            meter,
            recheck if probes > 1 else None,
            probes,
            shot_per_lighting=limit is not None,
            within=within,
            # a dome's lost port, reopened while metering, said as the run says it
            say=lambda text: on_note(Note(text)),
        )
    except (Exception, KeyboardInterrupt, EmergencyStop) as exc:
        # what metering's teardown established about the lights travels with the error, the
        # stop (Ctrl-C, SIGTERM) or a fault no part of rti-rig named (the user had been told
        # only the error, and of a camera driver's TypeError "check the rig's lights" of a
        # dome whose all-off metering had sent and seen acknowledged); a state that cannot be
        # told leaves the fault to be said as it is
        from rti_rig.app.usecases.safe_state import carry_lights_state, lights_state
        from rti_rig.runtime.exposure_policy import teardown_failures_of
        from rti_rig.runtime.lighting import unsafe_failures

        # (a port that did not close cleanly is no doubt about the lights: the all-off says)
        failures = unsafe_failures(teardown_failures_of(exc))
        with contextlib.suppress(Exception):  # never said in place of the fault raised
            carry_lights_state(exc, lights_state(rig, bool(failures)))
        raise
    chosen = fixed.provenance["exposure"]
    where = ""
    if probes > 1:
        at = chosen["metered_at_step"] - 1
        step = schedule.steps[at]
        which = (
            f" ({led_fields(step.led, step.direction, step.label)})" if step.led is not None else ""
        )
        metered = len(chosen["lights_metered_at_steps"])
        where = (
            f" at {image_names(len(schedule))[at]}'s light{which}, the brightest of the "
            f"{metered} metered, after {chosen['metering_shots']} test shots"
        )
    on_note(Note(f"Exposure fixed at {chosen['exposure_s']:.4g} s{where} ({chosen['reason']})"))
    if strays := chosen.get("metering_strays"):
        on_note(Note(_metering_strays_said(strays)))
    floored = camera_floor and chosen["exposure_s"] <= camera_floor[0][0] * (1 + 1e-6)
    if floored and not chosen.get("satisfied", False):  # bound: it wanted shorter
        measured = chosen.get("measured_saturated_fraction")
        saturated = (
            f"its test shot there saturated {measured:.2%} of pixels (limit {max_saturated:.2%})"
            if measured is not None
            else "the images may be saturated"
        )
        on_note(
            Note(
                f"The exposure, {chosen['exposure_s']:.4g} s, is the shortest the camera "
                f"{rig.camera.name} can take ({camera_floor[0][1]}), not the "
                f"{cam.min_exposure_s:g} s [camera] min_exposure_s allows: the metering could "
                f"go no shorter, and {saturated}. Lower the camera's gain or dim the light",
                level="warning",
            )
        )
    if camera_cap and chosen["exposure_s"] >= camera_cap[0][0] * (1 - 1e-6):
        bound = camera_cap[0][1]
        on_note(
            Note(
                f"The exposure, {chosen['exposure_s']:.4g} s, is the longest the camera "
                f"{rig.camera.name} can take, not the {longest:.3g} s the config allows "
                f"([camera] max_exposure_s, the LED's lit time): {bound}. The images may be "
                "dark; raise the gain or the light",
                level="warning",
            )
        )
    elif lit_cap is not None and chosen["exposure_s"] >= _next_shorter_s(rig, longest) - 1e-9:
        serial = rig.loaded.config.dome.serial  # type: ignore[attr-defined]
        less = (
            "timing.settle_s, readout_s, transfer_s and light_switch_s: this camera holds its "
            "LED lit until its frame is in"
            if _held_after_s(rig)
            else "timing.settle_s and timing.readout_s"
        )
        on_note(
            Note(
                f"The exposure, {chosen['exposure_s']:.4g} s, is the longest the metering "
                f"could choose: each shot must end while its LED is lit, which leaves "
                f"{longest:.3g} s ([dome.serial.thermal] max_on_s = "
                f"{serial.thermal.max_on_s:g} s, less {less}), "
                f"not the camera's max_exposure_s = {cam.max_exposure_s:g} s; the images may "
                "be dark. Raise max_on_s if the LEDs allow it, or the ISO or aperture",
                level="warning",
            )
        )
    return fixed


def metering_range(rig: Rig) -> tuple[tuple[float, str], tuple[float, str]]:
    """The range ``run --auto-exposure`` meters within before the camera is connected, each
    end with the phrase naming its key: ``[camera] min_exposure_s`` … ``max_exposure_s``, the
    longest lowered to what a timed firmware's window or an LED's ``max_on_s`` allows a shot.

    Why one place: the metering's rule, its start (:func:`~rti_rig.runtime.exposure_policy.
    metering_start`) and ``rti-rig check --auto-exposure``, which judges that start, keep to
    the same range."""
    cam = rig.camera_config
    low = (cam.min_exposure_s, f"[camera] min_exposure_s = {cam.min_exposure_s:g} s")
    high = (cam.max_exposure_s, f"[camera] max_exposure_s = {cam.max_exposure_s:g} s")
    limit = _timed_limit(rig)
    if limit is not None and limit.max_exposure_s < high[0]:
        longest = max(limit.max_exposure_s, cam.min_exposure_s)
        high = (longest, f"{longest:.3g} s ({limit.window_said()})")
    lit_cap = _lit_exposure_cap(rig)
    if lit_cap is not None and lit_cap < high[0]:
        longest = max(lit_cap, cam.min_exposure_s)
        high = (
            longest,
            f"{longest:.3g} s, the longest shot an LED lit at most max_on_s allows after "
            "timing.settle_s and before timing.readout_s",
        )
    return low, high


def _lit_exposure_cap(rig: Rig) -> float | None:
    """The longest exposure a shot can have under an LED lit at most ``max_on_s`` (less the
    settle before and the readout after it, and for a camera that holds its LED lit until its
    frame is in the transfer and the all-off's own time), or None when the light has no time
    limit.

    Why: metering a dry run's simulated camera on a dome with max_on_s = 2 s (LEDs dim) chose
    the exposure that left settle and readout only, whose test shot then held its LED through
    the transfer too, and stopped at the thermal guard before the session began ("LED 41
    stayed on 2.691 s, beyond max_on_s = 2 s"). Asked of the lighting by name (the Lighting
    protocol's): a ``getattr`` had answered "no limit" for a renamed method."""
    limit = rig.lighting.lit_limit_s()
    if limit is None:
        return None
    return limit - rig.timing.settle_s - rig.timing.readout_s - _held_after_s(rig)


def _metering_strays_said(strays: list[dict[str, Any]]) -> str:
    """What the run says of pictures the camera delivered besides the metering's test shots.

    Why: a picture a body took behind a busy answer during ``--auto-exposure`` is no session
    image (a moment and a light rti-rig did not choose), but it is a picture of the object:
    it had vanished with the metering's private download folder, and from the card, unsaid."""
    n = len(strays)
    where = {"not kept": "not kept", "on the camera's card": "left on the camera's card"}
    names = ", ".join(f"{s['camera_file']} ({where.get(s['kept'], s['kept'])})" for s in strays)
    lost = any(s["kept"] == "not kept" for s in strays)
    return (
        f"Metering: the camera delivered {n} picture{'s' if n != 1 else ''} besides its test "
        f"shots, taken while it answered busy: {names}. A metering shot is no session image, "
        "and such a picture was taken at a moment rti-rig did not choose, under a light it "
        "cannot vouch for"
        + (
            "; a RAM capture keeps no copy once the metering ends (capture_target = 'Memory "
            "card' leaves such a picture on the card)"
            if lost
            else ""
        )
    )


def _held_after_s(rig: Rig) -> float:
    """How long past its readout a shot holds its LED lit: nothing for a camera that says when
    its exposure is over (an ``ExposingCamera``: the LED goes off then, the readout its
    margin), else the transfer and the all-off's own time (``timing.light_switch_s``), as
    :func:`rti_rig.app.config.lit_per_shot` counts it."""
    from rti_rig.core.devices import ExposingCamera

    if isinstance(rig.camera, ExposingCamera):
        return 0.0
    return rig.timing.transfer_s + rig.timing.light_switch_s


def _next_shorter_s(rig: Rig, longest: float) -> float:
    """The longest shutter speed the camera offers at or under ``longest`` (``longest`` for a
    camera without a list): the metering chose the cap when it chose that one."""
    from rti_rig.core.devices import ShutterSpeedCamera

    camera = rig.camera
    offered = camera.available_exposures_s() if isinstance(camera, ShutterSpeedCamera) else []
    speeds = [t for t in offered if t <= longest + 1e-9]
    return max(speeds) if speeds else longest


def _light_outputs_unknown(rig: Rig) -> str:
    """Why the lights' outputs may differ from one another (empty if they may not): a dome
    that is not simulated, with no light calibration applied. A simulated dome's LEDs are
    equal, a calibrated one's evened out (``intensity_correction``), an arm has one lamp."""
    from rti_rig.app.config import LoadedRig

    loaded = rig.loaded
    if not isinstance(loaded, LoadedRig):
        return ""
    config = loaded.config
    if config.kind != "dome" or config.backend == "simulated" or config.dome is None:
        return ""
    serial = config.dome.serial
    if serial is not None and not serial.can_dim:
        # the link's declared fact, as calibrate-lights and the config loader read it: a
        # correction on an on/off firmware is not applied, so it evens nothing out, and
        # calibrate-lights (which it had been sent to) refuses such a dome
        return (
            "This dome cannot be evened out with rti-rig calibrate-lights "
            f"({serial.dimming_refusal()}): its LEDs may differ by tens of percent, so the "
            "light nearest the zenith need not be the brightest"
        )
    if serial is not None and serial.intensity_correction is not None:
        from rti_rig.app.config import calibration_coverage

        coverage = calibration_coverage(loaded)
        if coverage is None or coverage[0] == coverage[1]:
            return ""
        measured, count = coverage
        return (
            f"This dome's light calibration measured {measured} of its {count} LEDs (the "
            "others were assumed to give the median light; calibrate a card shot under every "
            "LED to even them out): they may differ by tens of percent, so the light nearest "
            "the zenith need not be the brightest"
        )
    return (
        "This dome has no light calibration applied (rti-rig calibrate-lights): its LEDs may "
        "differ by tens of percent, so the light nearest the zenith need not be the brightest"
    )


def _probes_said(rig: Rig, why: str, probes: int, limit) -> str:  # type: ignore[no-untyped-def]
    """The note that metering checks more lights, and what that costs: the user waits for
    shots they did not ask for, so how many and how long is said before the lights come on
    (a shot's time from the rig's [timing], as the session's estimate takes it)."""
    timing = rig.loaded.config.timing
    shot_s = timing.settle_s + timing.readout_s + timing.transfer_s
    window = (
        f"; each test shot also waits out an LED window of its own, {limit.window_s:g} s"
        if limit is not None
        else ""
    )
    return (
        f"{why}. Metering checks the {probes} planned lights a level object receives most "
        f"from: {probes - 1} more test shots than at one light, more where one is brighter "
        f"(each about {shot_s:.2g} s + the exposure: settle + readout + transfer{window})"
    )


def _timed_limit(rig: Rig):  # type: ignore[no-untyped-def]
    from rti_rig.app.config import LoadedRig, timed_exposure_limit

    return timed_exposure_limit(rig.loaded) if isinstance(rig.loaded, LoadedRig) else None


def check_disk_holds(  # type: ignore[no-untyped-def]
    loaded, root: Path, steps: int, frames: tuple[int, int] | None = None
) -> None:
    """Refuse a session whose images the disk under ``root`` cannot hold, before the rig opens
    (``frames``: the frame size its camera was seen to deliver, counted instead of the
    config's, :func:`~rti_rig.runtime.session.recorded_frame_size`).

    Why: the controller checks this too, but only as the capture begins: a full disk had been
    refused after the rig opened and below a drawn "capturing 0/48" progress bar, as if the
    capture had started. The controller's own check stays (the disk may fill meanwhile)."""
    from rti_rig.app.disk_estimate import bytes_per_image, size_from_frame

    per = bytes_per_image(loaded) if frames is None else size_from_frame(loaded)(*frames)[2]
    check_free_space(root, steps, per)


def _check_disk_holds_rest(loaded, folder: SessionFolder, root: Path) -> None:  # type: ignore[no-untyped-def]
    """Refuse a resume whose remaining images the disk cannot hold, in a resume's words.

    Why: the refusal said "free space or choose another --out", and ``run --resume S --out X``
    is refused ("drop --out"); nor did it say that the images taken are kept or how to go on,
    which the same disk refusal had said when it came after the rig opened. The caller adds
    the command to continue with (it knows the options the resume was given)."""
    from rti_rig.runtime.session import (
        LP_NAME,
        megabytes_said,
        recorded_frame_size,
        steps_to_hold,
    )

    done, total = len(folder.done), folder.total_steps
    header = folder.manifest.get("adaptive")
    if header:  # as the controller will count them
        from rti_rig.app.usecases.adaptive import images_sure

        sure = images_sure(header)
    else:
        sure = total
    cam = loaded.config.camera
    frames = recorded_frame_size(folder.manifest, cam.width, cam.height)
    try:  # at the size its camera was seen to deliver, where the config's was wrong
        check_disk_holds(loaded, root, steps_to_hold(total, done, sure), frames)
    except NoSpaceError as exc:
        if done:
            listed = f", listed in {LP_NAME}" if folder.lp_listing()[0] else ""
            kept = f"The {done} image(s) already taken are kept{listed}"
        else:
            kept = "It holds no verified image yet"
        still = (
            "still to shoot"
            if sure >= total
            else "it is still sure to take (its --until-error stop may come at any light after "
            "them; each is checked for room as it comes)"
        )
        need_mb, free_mb = megabytes_said(exc.need, exc.free)
        raise NoSpaceError(
            f"not enough free disk space to go on with {shown_path(root)}: the {exc.steps} "
            f"image(s) {still} need about {need_mb} on the disk holding {exc.where}, "
            f"{free_mb} free; free at least {math.ceil(exc.shortfall / 1e6)} MB "
            f"there. {kept}",
            exc.where,
            exc.steps,
            exc.need,
            exc.free,
        ) from None


def _open_new(
    loaded,  # type: ignore[no-untyped-def]
    schedule: LightSchedule,
    out_dir: Path,
    auto_exposure: bool,
    max_saturated: float,
    on_note: NoteSink,
) -> OpenedSession:
    """Check the folder, open and check the rig, meter if asked, make the folder.

    The folder is checked first, so nothing lights or moves for a session that could not be
    written; the rig is closed if anything after opening it fails, whatever the exception.
    """
    from rti_rig.app.rig_identity import rig_identity

    SessionFolder.check_new(out_dir)
    check_disk_holds(loaded, out_dir, len(schedule))
    if auto_exposure:
        refuse_unmeterable_rig(loaded)
    identity = rig_identity(loaded)
    _check_steps_fit_lit(loaded, schedule)
    rig = checked_rig(loaded, schedule)
    try:
        if auto_exposure:
            schedule = fix_exposure(rig, schedule, max_saturated, on_note)
        folder = SessionFolder.create(out_dir, len(schedule))
        folder.rig_identity = identity
    except BaseException:
        rig.close_said()  # its failures said, never in place of the error raised
        raise
    return OpenedSession(rig, schedule, folder, Path(out_dir))


def refuse_unmeterable_rig(loaded) -> None:  # type: ignore[no-untyped-def]
    """``--auto-exposure`` on a rig whose exposure metering cannot change: a replayed
    acquisition, or a camera rti-rig does not set the exposure of
    (:func:`refuse_unmeterable_camera`). Asked by a planned run, and first by an adaptive one,
    whose own refusal advises metering with a planned run: on these rigs that advice led to
    the refusal below."""
    if loaded.config.backend == "replay":
        # the recorded images come back whatever the exposure: metering them would "fix" an
        # exposure that changes nothing (a claim nothing established)
        raise ConfigError(
            loaded.path,
            None,
            "--auto-exposure cannot meter a replayed acquisition: its camera returns the "
            "recorded images whatever the exposure; drop --auto-exposure",
        )
    refuse_unmeterable_camera(loaded)


def refuse_unmeterable_camera(loaded) -> None:  # type: ignore[no-untyped-def]
    """``--auto-exposure`` on a camera that does not set its exposure is refused before the
    rig opens.

    Why: a watched folder only receives what the camera (set by hand or by its own program)
    shot. Metering asked it for test exposures it could not take, fired the camera for them,
    and stopped at the second with "set the camera to manual at the session exposure", an
    exposure the metering was still looking for.
    """
    from rti_rig.app.config import camera_device_settings
    from rti_rig.drivers.cameras.kinds import camera_kind

    if loaded.config.camera.device is None:
        return
    kind = camera_kind(getattr(camera_device_settings(loaded), "kind", None))
    if kind is not None and not kind.sets_exposure:
        raise ConfigError(
            loaded.path,
            "camera.device.kind",
            f"--auto-exposure cannot meter a '{kind.name}' camera: rti-rig does not set its "
            "exposure (the camera or its own program does), so it cannot take test shots at "
            "other exposures. Drop --auto-exposure, set the camera's shutter by hand and "
            "[camera] exposure_s to the same value",
        )


#: What ``--plan`` takes, said where it is given no ``.lp``.
PLAN_WANTED = (
    "--plan takes a plan, the .lp light list (a count line, then 'name x y z' per image) that "
    "rti-rig plan writes"
)


def _refuse_rig_config_as_plan(
    plan: Path, rig_config: Path, out_dir: Path, geometry: object
) -> None:
    """Refuse a rig config given as ``--plan``, saying that it is one, what ``--plan`` takes
    and the commands that make and run a plan.

    Why: it had been told "this is a TOML file (a rig config?), not an .lp", a guess that left
    the user to work out that a plan is another file and where one comes from. Told by its
    content (a TOML table with a rig's ``kind``), not its name alone; any other file is left to
    the .lp reader, which says what it is. The commands name the run's own ``--out`` (nothing
    was written to it) and a real count: ``--out SESSION`` and ``--lights N`` had been printed,
    which pasted as printed ran into a folder named SESSION or were refused, and the fixed
    ``--lights 12`` that replaced it was refused on a dome of fewer LEDs
    (:func:`~rti_rig.core.rig_geometry.hint_light_count`); the plan file is one that does not
    exist yet (``plan`` refuses an existing one without ``--force``)."""
    import tomllib

    from rti_rig.core.rig_geometry import hint_light_count

    if plan.suffix.lower() != ".toml" or not plan.is_file():
        return
    try:
        data = tomllib.loads(plan.read_bytes().decode("utf-8-sig"))
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError):
        return  # the .lp reader says what the file is
    if data.get("kind") not in ("dome", "arm"):
        return
    name = f" ({data['name']})" if isinstance(data.get("name"), str) and data["name"] else ""
    rig, out = shell_word(str(rig_config)), shell_word(str(out_dir))
    plan_lp = shell_word(str(free_name(Path("plan.lp"))))
    raise RtiRigError(
        f"--plan {shown_path(plan)} is a rig config{name}, not a plan: --plan takes a plan file, "
        "the .lp light list (a count line, then 'name x y z' per image) that rti-rig plan writes; "
        f"make one with: rti-rig plan --rig {rig} --out {plan_lp}, then run it with: rti-rig "
        f"run {rig} --plan {plan_lp} --out {out} (or run a homogeneous layout without a plan: "
        f"rti-rig run {rig} --lights {hint_light_count(geometry)} --out {out})"
    )


def _replan_command(req: NewSessionRequest, geometry: object, lights: int) -> str:
    """The commands that plan ``lights`` lights for ``req``'s rig and run them (a free .lp
    beside, shell words), for a plan whose lights are not this rig's; no fewer than ``plan``
    plans, and of a dome no more than it has LEDs. Said with the preview left out: the plan's
    own may have had one, which the user adds."""
    from rti_rig.core.fit_minimums import NORMAL_MIN_LIGHTS
    from rti_rig.core.rig_geometry import DomeGeometry

    lights = max(lights, NORMAL_MIN_LIGHTS)  # the fewest plan plans
    if isinstance(geometry, DomeGeometry):
        lights = min(lights, len(geometry.directions))
    rig, out = shell_word(str(req.rig_config)), shell_word(str(req.out_dir))
    plan_lp = shell_word(str(free_name(Path("plan.lp"))))
    return (
        f"rti-rig plan --rig {rig} --lights {lights} --out {plan_lp} (add its preview, if the "
        f"plan had one), then rti-rig run {rig} --plan {plan_lp} --out {out}"
    )


def _refuse_plan_outside_band(req: NewSessionRequest, entries: Any, schedule: Any) -> None:
    """Refuse a ``--plan`` whose lights leave the band ``--min/--max-elevation-deg`` given
    with it, naming them by their lines.

    Why: the band was ignored with a plan, so ``--plan P --max-elevation-deg 30`` fired P's
    lights at 40° (a gilded object's highlights in the lens, the very thing a ceiling is for),
    exit 0, and recorded no band. The plan's own lights are what fires; the band checks them."""
    from rti_rig.core.geometry import az_el_from_direction

    low, high = req.min_elevation_deg, req.max_elevation_deg
    if low == 0.0 and high == 90.0:
        return
    outside = []
    for entry, step in zip(entries, schedule.steps, strict=True):
        el = float(az_el_from_direction(step.direction)[1])
        # to within an .lp's six decimals (a light on the edge, written so, moves ~3e-5°)
        if not in_band(el, low, high):
            line = f"line {entry.line}" if entry.line is not None else entry.name
            outside.append(f"{line} ({entry.name}) at {el:.1f}°")
    if not outside:
        return
    band = band_options((low, high)).strip()
    more = f" and {len(outside) - 5} more" if len(outside) > 5 else ""
    raise RtiRigError(
        f"--plan {shown_path(req.plan)}: {len(outside)} of its {len(entries)} lights lie outside "
        f"{band} ({', '.join(outside[:5])}{more}); nothing was lit. Plan within the band "
        f"(rti-rig plan … {band} --out PLAN.lp, then run --plan PLAN.lp), or run this plan "
        "without the band"
    )


def _in_band(geometry: DomeGeometry, low: float, high: float) -> int:
    """How many of a dome's LEDs lie from ``low`` to ``high`` degrees of elevation."""
    from rti_rig.core.geometry import az_el_from_direction

    _, el = az_el_from_direction(geometry.directions)
    return int(in_band(el, low, high).sum())


def new_session_schedule(  # type: ignore[no-untyped-def]
    req: NewSessionRequest, loaded, on_note: NoteSink = _ignore
) -> LightSchedule:
    """The schedule a new session runs: the plan's, or a homogeneous layout, with what it was
    asked for recorded in its provenance (:func:`_asked_for`)."""
    from rti_rig.app.compose import arm_order_for
    from rti_rig.app.config import rig_geometry
    from rti_rig.app.normals_determined import band_advice
    from rti_rig.core.lp_format import MAX_LIGHTS, read_lp
    from rti_rig.core.rig_geometry import ArmGeometry
    from rti_rig.planner.from_lp import schedule_from_lp
    from rti_rig.planner.make_plan import check_elevation_band
    from rti_rig.planner.uniform import arm_band_note, plan_uniform

    geometry = rig_geometry(loaded)
    if req.plan is not None:
        if req.lights is not None:
            raise RtiRigError("give either --plan or --lights, not both")
        _refuse_rig_config_as_plan(
            Path(req.plan), Path(req.rig_config), Path(req.out_dir), geometry
        )
        if not Path(req.plan).exists():  # "nosuch.lp: cannot read" had not said which option
            raise RtiRigError(
                f"--plan {shown_path(req.plan)}: no such file: give the .lp that "
                "'rti-rig plan … --out PLAN.lp' wrote (or drop --plan for the rig's own layout)"
            )
        plan_notes: list[str] = []
        entries = read_lp(req.plan, upper_hemisphere=True, notes=plan_notes, wanted=PLAN_WANTED)
        for note in plan_notes:
            on_note(Note(note, "warning"))
        check_light_count(
            len(entries),
            f"--plan {req.plan} lists {len(entries)} lights",
            f"split it into plans of at most {MAX_LIGHTS} lights, each run into its own --out",
        )
        schedule = schedule_from_lp(
            entries, geometry, str(req.plan), replan=_replan_command(req, geometry, len(entries))
        )
        _refuse_plan_outside_band(req, entries, schedule)
        _check_determined(
            req,
            schedule,
            f"lights of --plan {req.plan}",
            "plan them with rti-rig plan (it refuses such lights) or give a plan with lights "
            "at several elevations and azimuths",
            on_note,
        )
        return _asked_for(schedule, req)
    check_elevation_band(req.min_elevation_deg, req.max_elevation_deg)
    n = req.lights if req.lights is not None else default_lights(loaded, geometry)
    if req.lights is None and isinstance(geometry, DomeGeometry):
        # a band without --lights: every LED in it (or the config's default_lights, if fewer).
        # "asked for 48 lights but the dome has only 24 LEDs between 0° and 30°" had refused
        # a ceiling alone, the planning guide's advice for gilding, of a count never given
        inside = _in_band(geometry, req.min_elevation_deg, req.max_elevation_deg)
        if not inside:  # said of the band asked, not of a count never given
            from rti_rig.core.geometry import az_el_from_direction
            from rti_rig.planner.uniform import band_text, count_in_band_text

            lo, hi = req.min_elevation_deg, req.max_elevation_deg
            el = az_el_from_direction(geometry.directions)[1]
            replay = loaded.config.backend == "replay"  # its "LEDs" are images
            has = count_in_band_text(
                0,
                band_text(lo, hi),
                el,
                *(("image", "its images' lights") if replay else ()),
            )
            rig = f"the acquisition {shown_path(loaded.path)}" if replay else "the dome"
            widen = " / ".join(
                [f"--min-elevation-deg {lo:g}"] * (lo != 0.0)
                + [f"--max-elevation-deg {hi:g}"] * (hi != 90.0)
            )
            raise RtiRigError(f"{rig} has {has}; widen {widen}")
        n = min(n, inside)
    if req.lights is not None:
        check_light_count(n)
    else:
        every = (
            f"every image of the acquisition {shown_path(loaded.path)}"
            if loaded.config.backend == "replay"
            else f"the rig's default, from {shown_path(loaded.path)}"
        )
        check_light_count(
            n,
            f"{n} lights ({every})",
            f"give --lights with a count of at most {MAX_LIGHTS} to run that many spread over "
            f"the directions (e.g. --lights {MAX_LIGHTS})",
        )
    if loaded.config.backend == "replay":  # its "LEDs" are images, in the band or not
        # (with --min/--max-elevation-deg the planner's refusal had said "the dome has only
        # 8 LEDs at or above 50° elevation" of an acquisition's images)
        from rti_rig.core.geometry import az_el_from_direction
        from rti_rig.planner.uniform import band_text, count_in_band_text

        lo, hi = req.min_elevation_deg, req.max_elevation_deg
        _, el = az_el_from_direction(geometry.directions)
        inside = _in_band(geometry, lo, hi)
        if n > inside:
            band = band_text(lo, hi)
            fewer = [f"use --lights {inside} or fewer"] if inside else []
            if band:
                fewer.append("widen --min-elevation-deg / --max-elevation-deg")
            asked = f"--lights {n}" if req.lights is not None else f"{n} lights (every image)"
            has = count_in_band_text(inside, band, el, "image", "its images' lights")
            raise RtiRigError(
                f"{asked}: the acquisition {shown_path(loaded.path)} has {has}; "
                + " or ".join(fewer)
            )
    schedule = plan_uniform(
        geometry, n, req.min_elevation_deg, arm_order_for(loaded), req.max_elevation_deg
    )
    if isinstance(geometry, ArmGeometry):  # a band beyond the arm's reach, cut: said once
        cut = arm_band_note(
            geometry,
            req.min_elevation_deg,
            req.max_elevation_deg,
            min_given=req.min_elevation_given,
            max_given=req.max_elevation_given,
        )
        if cut is not None:
            on_note(Note(cut, "warning"))
    _check_determined(
        req,
        schedule,
        "lights asked for with --lights"
        if req.lights is not None
        else "lights run takes by default",
        band_advice(req.min_elevation_deg, req.max_elevation_deg),
        on_note,
    )
    return _asked_for(schedule, req)


def _asked_for(schedule: LightSchedule, req: NewSessionRequest) -> LightSchedule:
    """``schedule`` whose provenance records what the session was asked for beyond its
    layout: ``--plan`` as an absolute path (``plan_file``) and ``--allow-no-normals``.

    Why: a refused replay resume prints the command that starts a new session with the
    session's options (:func:`~rti_rig.app.usecases.replay_advice.new_session_command`). The
    plan had been recorded as typed, so a relative ``--plan`` ran only from the folder the
    session was started in; ``--allow-no-normals`` was not recorded at all, so the command
    was refused the very lights the session had been asked to capture."""
    provenance = {**schedule.provenance, "allow_no_normals": req.allow_no_normals}
    if req.plan is not None:
        provenance["plan_file"] = str(Path(req.plan).resolve())
    return replace(schedule, provenance=provenance)


def _check_determined(
    req: NewSessionRequest, schedule: LightSchedule, what: str, advice: str, on_note: NoteSink
) -> None:
    """Refuse, before the rig is opened, lights that cannot determine a normal, unless
    ``--allow-no-normals`` asks for them: then a warning, printed and kept in the manifest.

    Why the way through: a deliberate ``run --plan`` at one azimuth (raking-light
    documentation) had no way past the refusal. The warning says what ``rti-rig fit`` will
    make of them: relighting files that are ridge-regularised guesses along the missing
    direction, and no normal maps.
    """
    import numpy as np

    from rti_rig.app.normals_determined import (
        CAPTURED_WITHOUT_NORMALS,
        refuse_undetermined,
        undetermined_normals,
    )
    from rti_rig.app.usecases.fit_outlook import fit_without_normals

    lights = np.array([s.direction for s in schedule.steps], dtype=np.float64)
    if not req.allow_no_normals:
        refuse_undetermined(
            lights,
            what,
            f"{advice}; or, to capture them all the same (raking-light documentation, no "
            "normal maps wanted), add --allow-no-normals",
            "nothing was lit or moved",
        )
        return
    reason = undetermined_normals(lights, what)
    if reason is not None:
        on_note(
            Note(
                f"{reason}; {CAPTURED_WITHOUT_NORMALS}: {fit_without_normals(len(lights))}",
                "warning",
            )
        )


def _metering_options(req: NewSessionRequest, loaded) -> str:  # type: ignore[no-untyped-def]
    """The lights of the planned run an adaptive session is advised to meter with: 6 (fewer
    where a dome's band holds fewer) in the session's band. Why: the advice had been `--lights
    6` over every elevation, which meters under lights the session will never fire and fires
    them (above a gilded object's 45° ceiling, the highlight the band keeps out)."""
    from rti_rig.app.config import rig_geometry
    from rti_rig.core.rig_geometry import DomeGeometry
    from rti_rig.planner.uniform import band_run_options

    lo, hi = req.min_elevation_deg, req.max_elevation_deg
    lights = 6
    geometry = rig_geometry(loaded)
    if isinstance(geometry, DomeGeometry):  # as the planner bands its LEDs
        lights = max(1, min(lights, _in_band(geometry, lo, hi)))
    return band_run_options(lights, lo, hi)


def _minimum_below_start(min_lights: int | None, source) -> Note | None:  # type: ignore[no-untyped-def]
    """What a ``--min-lights`` at or below the starting lights means: nothing, said before
    anything lights, with the smallest minimum that binds.

    Why: the stop is first judged once the starting lights are in, so ``--min-lights 3`` (or
    4, the start) was accepted and silently held nothing; a user who asked for a floor was
    not told the session's own start already was one, nor what value would change anything."""
    start = len(source.plan.start)
    if min_lights is None or min_lights > start:
        return None
    most = source.plan.max_lights
    binds = (
        f"the smallest --min-lights that holds its stop is {start + 1} (a PTM needs 6 lights, "
        "an HSH fit.rti 5)"
        if start < most
        else f"this session's maximum is {most} lights: it shoots them all"
    )
    return Note(
        f"--min-lights {min_lights} holds nothing: an adaptive session shoots its {start} "
        f"starting lights before its stop is first judged, so it never stops below {start}; "
        f"{binds}",
        "warning",
    )


def _open_adaptive(req: NewSessionRequest, loaded) -> OpenedSession:  # type: ignore[no-untyped-def]
    """A new adaptive session: the starting layout, the step source and the folder."""
    from rti_rig.app.rig_identity import rig_identity
    from rti_rig.app.usecases.adaptive import open_adaptive_session
    from rti_rig.planner.adaptive import START_LIGHTS
    from rti_rig.planner.make_plan import check_elevation_band

    # --plan with it is refused by check_option_pairs, before the config is read
    # every light of the session is chosen in the band (it had been refused: the adaptive
    # loop chose among every light the rig can run)
    check_elevation_band(req.min_elevation_deg, req.max_elevation_deg)
    if req.auto_exposure:
        refuse_unmeterable_rig(loaded)  # no planned run meters these either: say so first
        # the metering run's --out a folder not there yet beside the session's ('--out TEST'
        # pasted was refused where a TEST of an earlier metering run was left non-empty)
        metering = free_folder_beside(Path(req.out_dir), "metering")
        raise RtiRigError(
            f"{req.adaptive_option} cannot meter the exposure: its lights are chosen as the images "
            "arrive, so there is no brightest planned light to meter at. Meter once with a "
            f"planned run ({run_words(Path(req.rig_config), metering)} "
            f"{_metering_options(req, loaded)} --auto-exposure prints 'Exposure fixed at T s'), "
            "set camera.exposure_s = T in the rig config, then run this command again without "
            "--auto-exposure"
        )
    if req.lights is not None and req.lights > START_LIGHTS:
        # fewer are refused with the adaptive range (open_adaptive_session): "give at least 1
        # light" had been said of --lights 0, and then 1 refused for the range
        check_light_count(req.lights)
    identity = rig_identity(loaded)

    def check_room(sure: int, most: int) -> None:
        """The images it is sure to take, as the controller counts them; the rest, image by
        image. Asked before the rig is built, as a planned run's (it had come after)."""
        try:
            check_disk_holds(loaded, req.out_dir, sure)
        except NoSpaceError as exc:
            if sure >= most:
                raise
            raise NoSpaceError(
                f"{exc} (the {exc.steps} are the lights it is sure to take; it may take up "
                f"to {most}, each checked for room as it comes)",
                exc.where,
                exc.steps,
                exc.need,
                exc.free,
            ) from None

    rig, schedule, folder, source = open_adaptive_session(
        loaded,
        req.out_dir,
        req.lights,
        req.until_error_deg,
        req.objective or "normals",
        req.min_lights,
        (req.min_elevation_deg, req.max_elevation_deg),
        check_room=check_room,
    )
    folder.rig_identity = identity
    return OpenedSession(rig, schedule, folder, Path(req.out_dir), source=source)


def check_option_pairs(req: NewSessionRequest) -> None:
    """Refuse ``req``'s options on their own, before any file is read: each value, and the
    options that do not go together.

    Why here, in one place: a resume refused as another request advises the new session that
    would shoot it, and that command is asked the same questions first, so that what it
    advises is never refused in turn (it had advised ``--adaptive --lights 12 --min-lights 6``,
    which run refuses: --min-lights goes with --until-error)."""
    from rti_rig.app.usecases.adaptive import check_min_lights, check_until_error
    from rti_rig.planner.make_plan import check_elevation_band

    check_max_saturated(req.max_saturated)
    check_until_error(req.until_error_deg)
    check_elevation_band(req.min_elevation_deg, req.max_elevation_deg)
    check_min_lights(
        req.min_lights,
        req.lights,
        req.until_error_deg,
        run_words(req.rig_config, req.out_dir),
        (req.min_elevation_deg, req.max_elevation_deg),
    )
    if req.plan is not None and req.is_adaptive:
        raise RtiRigError(f"{req.adaptive_option} chooses its own lights: drop --plan")
    if req.plan is not None and req.lights is not None:
        raise RtiRigError("give either --plan or --lights, not both")
    if req.objective is not None and not req.is_adaptive:
        raise RtiRigError(
            f"--objective {req.objective} goes with --adaptive (it says what the adaptive "
            "design is chosen for); a planned layout's objective is chosen with `rti-rig plan "
            "--objective`, then run with --plan"
        )
    if req.is_adaptive and req.allow_no_normals:
        raise RtiRigError(
            "--allow-no-normals goes with --plan or --lights: an adaptive session chooses its "
            "lights itself; drop --allow-no-normals"
        )


def open_new_session(req: NewSessionRequest, on_note: NoteSink = _ignore) -> OpenedSession:
    """Check a new session's request, open and check the rig, and prepare its folder."""
    from rti_rig.app.config import load_rig_config

    check_option_pairs(req)
    loaded = load_rig_config(req.rig_config)
    for note in loaded.notes:
        on_note(Note(note, "warning"))
    from rti_rig.app.flash_sync import check_new_session

    check_new_session(req, loaded)  # a camera-triggered dome runs its own sequence only
    if req.is_adaptive:
        opened = _open_adaptive(req, loaded)
        opened.folder.input_notes = list(loaded.notes)
        # a fixed count (--adaptive --lights N): what the fit will make of it, once the
        # request has passed its refusals; an --until-error stop is said when it happens
        fixed = req.lights if req.until_error_deg is None else None
        if fixed is not None and (few := too_few_to_fit(fixed)) is not None:
            on_note(few)
        if (idle := _minimum_below_start(req.min_lights, opened.source)) is not None:
            on_note(idle)
        return opened
    plan_notes: list[Note] = []

    def keep_note(note: Note) -> None:  # the plan file's notes: printed and recorded
        plan_notes.append(note)
        on_note(note)

    schedule = new_session_schedule(req, loaded, keep_note)
    # said before the rig opens, not recorded among the inputs' notes: not about the inputs
    if (few := too_few_to_fit(len(schedule), schedule)) is not None:
        on_note(few)
    opened = _open_new(loaded, schedule, req.out_dir, req.auto_exposure, req.max_saturated, on_note)
    opened.folder.input_notes = [*loaded.notes, *(n.text for n in plan_notes)]
    return opened


def _real_size_as_recorded(  # type: ignore[no-untyped-def]
    manifest: dict[str, Any],
    recorded: dict[str, Any] | None,
    identity: dict[str, Any],
    loaded,
    root: Path | None = None,
) -> dict[str, Any]:
    """``identity`` with the session's recorded camera size where the config now says the
    size its camera was seen to deliver (``rig.frame_size``, recorded by the run that found
    the config's size wrong; for a session begun before that record, the size of its first
    image in ``root``): the same images, the config corrected as that run advised.

    Why: the run says to set camera.width and camera.height, and a resume with them set was
    refused as another picture ("camera size: 64×64 → 256×256"), though the camera's images
    were that size all along. A session whose manifest predates ``rig.frame_size`` had been
    told the same by its run, and was still refused."""
    from rti_rig.app.disk_estimate import size_from_frame
    from rti_rig.runtime.session import FRAME_SIZE_KEY

    seen = (manifest.get("rig") or {}).get(FRAME_SIZE_KEY)
    if not recorded or recorded.get("camera_size") in (None, identity.get("camera_size")):
        return identity
    if seen is None and root is not None:  # a session from before the record: its images
        frames: Any = _first_image_size(root)
        config: Any = [int(v) for v in str(recorded["camera_size"]).split("×") if v.isdigit()]
    elif isinstance(seen, dict):
        config, frames = seen.get("config"), seen.get("frames")
    else:
        return identity
    if not (isinstance(config, list) and isinstance(frames, list) and len(frames) == 2):
        return identity
    if recorded["camera_size"] != "×".join(str(v) for v in config):
        return identity
    width, height, _ = size_from_frame(loaded)(int(frames[0]), int(frames[1]))
    if identity.get("camera_size") != f"{width}×{height}":
        return identity
    return {**identity, "camera_size": recorded["camera_size"]}


def _first_image_size(root: Path) -> list[int] | None:
    """[width, height] of the session's first journaled linear TIFF, from its header; None
    when it has none or the header cannot be read (the resume then checks as before)."""
    from rti_rig.core.image_files import header_layout
    from rti_rig.runtime.session import scan_journal

    try:
        records = scan_journal(root).records
        name = records[0].get("linear_image") if records else None
        layout = header_layout(root / str(name)) if name else None
    except (OSError, RtiRigError):  # a journal the reopen will judge: checked as before
        return None
    return None if layout is None else [layout[1], layout[0]]


def _recorded_images_other(recorded: dict[str, Any], identity: dict[str, Any]) -> bool:
    """Whether the recorded images' digest says other files than the session began with
    (False where the session began before that digest was recorded: not known).

    Why on the digests: a resume had decided by matching :func:`~rti_rig.app.rig_identity.
    identity_differences`' printed label ("recorded images: changed"), which a rewording
    would have silently turned off."""
    return recorded.get("recorded_images") not in (None, identity.get("recorded_images"))


def _changed_recorded_files(recorded: dict[str, Any], identity: dict[str, Any]) -> str:
    """`` (image70.jpg differs from the one recorded)``: the files of a replayed acquisition
    whose checksum differs from the session's record, or that are gone or new; "" where the
    session recorded no per-file checksums (begun before they were).

    Why: a resume refused "one was edited, replaced or re-exported since" without naming it,
    though the manifest holds each file's SHA-256: among hundreds of images the user could
    not tell which one to put back."""
    before, now = recorded.get("recorded_files"), identity.get("recorded_files")
    if not isinstance(before, dict) or not isinstance(now, dict):
        return ""

    def sha(stamp: Any) -> Any:
        return stamp[3] if isinstance(stamp, list) and len(stamp) > 3 else None

    changed = [n for n in before if sha(before[n]) != sha(now.get(n))]
    changed += [n for n in now if n not in before]
    if not changed:
        return ""
    more = f" and {len(changed) - 5} more" if len(changed) > 5 else ""
    which = ", ".join(changed[:5]) + more
    differs = "differs" if len(changed) == 1 else "differ"
    return f" ({which} {differs} from the one{'s' if len(changed) > 1 else ''} recorded)"


def _same_files_listed_otherwise(recorded: dict[str, Any], identity: dict[str, Any]) -> bool:
    """Whether a replayed acquisition's files are all the ones recorded, each with its
    recorded checksum, although the digest of the images in their `.lp` order differs: the
    `.lp`'s lines were reordered or paired with other lights (False where the session recorded
    no per-file checksums)."""
    before, now = recorded.get("recorded_files"), identity.get("recorded_files")
    if not isinstance(before, dict) or not isinstance(now, dict) or set(before) != set(now):
        return False
    return not _changed_recorded_files(recorded, identity)


def check_resume_rig(  # type: ignore[no-untyped-def]
    manifest: dict[str, Any],
    loaded,
    config_path: Path,
    accept_change: bool,
    on_note: NoteSink,
    session_dir: Path | str = "DIR",
) -> tuple[dict[str, Any], list[str]]:
    """The rig's identity, checked against the session's; the differences the user accepted.

    Refuses (:class:`RigChangedError`, listing what differs) unless ``accept_change``; what
    no flag accepts (another kind of rig, another picture) is refused even then. Every
    difference is named in the one refusal (:func:`_rig_refusal`), not the first found.
    """
    from rti_rig.app.rig_identity import (
        IMAGE_KEYS,
        identity_differences,
        rig_identity,
        same_rig,
    )

    recorded = (manifest.get("rig") or {}).get("identity")
    root = Path(session_dir)
    identity = _real_size_as_recorded(
        manifest, recorded, rig_identity(loaded), loaded, root if root.is_dir() else None
    )
    if recorded is None:  # a session from before identities were recorded
        if loaded.sha256 != (manifest.get("rig") or {}).get("config_sha256"):
            on_note(
                Note(
                    f"{_config_differs(config_path, manifest)}; the remaining steps are checked "
                    "against it before anything moves.",
                    "warning",
                )
            )
        return identity, []
    diffs = identity_differences(recorded, identity)
    image_diffs = identity_differences(  # the same comparison, on the image keys alone
        {k: recorded[k] for k in IMAGE_KEYS if k in recorded},
        {k: identity.get(k) for k in IMAGE_KEYS if k in recorded},
    )
    images_other = _recorded_images_other(recorded, identity)
    only_images_other = (
        images_other
        and identity.get("recorded_images") is not None
        and all(
            recorded[k] == identity.get(k)
            for k in IMAGE_KEYS
            if k in recorded and k != "recorded_images"
        )
    )
    last = (manifest.get("rig") or {}).get("config_path")
    another_file = not last or not _same_file(Path(config_path), Path(str(last)))
    if only_images_other and another_file and _other_lights(recorded, identity):
        # its lights too: another acquisition, not an edited image of this one (it had been
        # said "one was edited", and the new session advised with a --lights it lacks)
        raise RigChangedError(
            _another_acquisition(config_path, recorded, identity, manifest, session_dir)
        )
    if only_images_other and _same_files_listed_otherwise(recorded, identity):
        # every recorded file as it was: the .lp's lines were reordered or repaired (it had
        # been blamed on an image "edited, replaced or re-exported", none named)
        raise RigChangedError(
            f"{shown_path(config_path)} lists the same recorded files as when this session "
            "began, each as it was, but not in the same order or not with the same lights: "
            "the .lp was edited since. The session's images were paired with its lights by "
            "their lines, so a resume cannot go on with them. Put the .lp back as it was (from "
            "a backup copy) to continue (rti-rig run --resume "
            f"{shell_word(str(session_dir))}), or start a new session from the acquisition as "
            "it is now ("
            + new_session_command(config_path, manifest, session_dir, most=_light_count(identity))
            + ")"
        )
    if only_images_other:
        # a replayed acquisition is a rig whose camera returns its files: they are its images
        raise RigChangedError(
            f"the images of {shown_path(config_path)} are not the ones this session began with "
            "(one was edited, replaced or re-exported since)"
            + _changed_recorded_files(recorded, identity)
            + ": the session's first images and the "
            "ones a resume would take would come from two different acquisitions. Put the original "
            f"files back to continue (rti-rig run --resume {shell_word(str(session_dir))}), "
            "or start a new session from the acquisition as it is now ("
            + new_session_command(config_path, manifest, session_dir, most=_light_count(identity))
            + ")"
        )
    replay = recorded.get("backend") == identity.get("backend") == "replay"
    if replay and images_other:
        # other recorded files, and of another size or kind: no config to set back
        raise RigChangedError(
            _replay_images_changed(config_path, image_diffs, manifest, session_dir)
        )
    if image_diffs and replay and "recorded_images" not in recorded:
        # a session begun before the images' digest was recorded: same files or not, unknown
        raise RigChangedError(
            _replay_images_unknown(config_path, image_diffs, manifest, session_dir)
        )
    if image_diffs and replay:  # the same recorded files, read otherwise
        raise RigChangedError(
            _replay_read_otherwise(config_path, image_diffs, manifest, session_dir)
        )
    other_kind = recorded.get("kind") != identity.get("kind")
    # never accepted: another kind of rig, another backend (accepted, a dry run's rendered
    # images went on with the real dome's photographs, or a replay's, in one session), or
    # another picture (accepted, a new exposure had gone into the fit as a brighter light:
    # normals 5.5° off on average, with a "good" verdict; nothing downstream corrects for it).
    # The rest is refused unless accepted.
    other_backend = recorded.get("backend") != identity.get("backend")
    if other_kind or other_backend or image_diffs or (diffs and not accept_change):
        raise RigChangedError(
            _rig_refusal(
                config_path, loaded, manifest, session_dir, recorded, identity, diffs, image_diffs
            )
        )
    if diffs:
        # recorded in the manifest when the session goes on: a resume refused after this (a
        # remaining step the changed rig cannot run, an adaptive step it would decide
        # otherwise) records nothing. A resume says it only once those are checked
        # (open_resumed_session): it had said "rig change accepted" and then refused
        on_note(
            Note(
                "rig change accepted (recorded in the manifest once the session goes on): "
                + "; ".join(diffs),
                "warning",
            )
        )
    elif loaded.sha256 != (manifest.get("rig") or {}).get("config_sha256"):
        on_note(
            Note(
                f"{_config_differs(config_path, manifest)}, in nothing the images depend on "
                "(kind, lights, camera, exposure, decoding are the same).",
                "warning",
            )
        )
    if not diffs:  # the same rig: its positions as the session recorded them (rounding aside)
        identity = same_rig(recorded, identity)
    return identity, diffs


def _other_lights(recorded: dict[str, Any], identity: dict[str, Any]) -> bool:
    """Whether a replayed acquisition's lights differ from the session's: their count, or
    their directions (:func:`~rti_rig.app.rig_identity.moved_lights`: beyond rounding)."""
    from rti_rig.app.rig_identity import moved_lights

    if recorded.get("lights") != identity.get("lights"):
        return True
    before, now = recorded.get("light_directions"), identity.get("light_directions")
    if before is None or now is None:  # a session from before the directions were recorded
        return recorded.get("light_positions") != identity.get("light_positions")
    return bool(moved_lights(before, now))


def _light_count(identity: dict[str, Any]) -> int | None:
    """A dome's LED count, from the directions its identity records (None: none recorded)."""
    directions = identity.get("light_directions")
    return len(directions) if isinstance(directions, list) else None


def _another_acquisition(
    config_path: Path,
    recorded: dict[str, Any],
    identity: dict[str, Any],
    manifest: dict[str, Any],
    session_dir: Path | str,
) -> str:
    """Why a resume on another recorded acquisition than the session's is refused, and the
    two ways on: the session's own .lp, or a new session from this one (its counts within
    this acquisition's lights)."""
    last = (manifest.get("rig") or {}).get("config_path")
    count, before = _light_count(identity), _light_count(recorded)
    which = (
        f"{count} lights, the session's {before} lights"
        if count != before
        else f"{count} lights as the session's, at other directions"
    )
    own = (f", {shown_path(last)}" if last else "") + (
        f": rti-rig run --resume {shell_word(str(session_dir))}"
    )
    return (
        f"{shown_path(config_path)} is another acquisition than the one this session began "
        f"with: its lights and images differ ({which}): a resume would mix two acquisitions in "
        f"one session. Continue it on its own acquisition{own}; or start a new session from "
        "this one (" + new_session_command(config_path, manifest, session_dir, most=count) + ")"
    )


#: How many differences make a config given in place of the session's own another rig, not
#: a change to this one (with its kind or backend, which always do). One or two is the shape
#: of a deliberate change copied into a new file (a re-measured ``.lp``, a new controller
#: board); three or more (rig_configs/emulated_dome.toml against a session of
#: simulated_dome.toml: backend, all 48 LEDs, firmware profile, camera size, scene) is another
#: rig, which no setting set back and no --accept-rig-change makes this session's.
ANOTHER_RIG_DIFFERENCES = 3


def _rig_refusal(  # type: ignore[no-untyped-def]
    config_path: Path,
    loaded,
    manifest: dict[str, Any],
    session_dir: Path | str,
    recorded: dict[str, Any],
    identity: dict[str, Any],
    diffs: list[str],
    image_diffs: list[str],
) -> str:
    """Why a resume on ``config_path`` is refused: every difference from the rig the session
    began on, in one message, which of them no ``--accept-rig-change`` takes, and the way out
    (another rig: its own config, or a new session; else set back, or accept the rest).

    Why: what the images are (:data:`~rti_rig.app.rig_identity.IMAGE_KEYS`) and the kind of
    rig were checked, and refused, one before the other and before the rest, since no flag
    accepts them. The refusal named only those: a session of simulated_dome.toml resumed on
    emulated_dome.toml was told "camera size: 512×512 → 256×256 … set it back to continue",
    and, with the size matched, the backend, all 48 LEDs moved, the firmware profile and the
    scene. The user fixed one thing, ran again and was told the next, and "set it back" was
    the wrong advice for a whole other rig. The checks and what they refuse are unchanged;
    only the telling is collected."""
    other_kind = recorded.get("kind") != identity.get("kind")
    last = (manifest.get("rig") or {}).get("config_path")
    own_file = bool(last) and _same_file(Path(config_path), Path(last))
    other_rig = (
        other_kind
        or recorded.get("backend") != identity.get("backend")
        or (not own_file and len(diffs) >= ANOTHER_RIG_DIFFERENCES)
    )
    resume = f"rti-rig run --resume {shell_word(str(session_dir))}"
    listed = "; ".join(diffs)
    if other_rig:
        text = (
            f"{shown_path(config_path)} describes another rig than the one this session began "
            f"on ({len(diffs)} difference{'s' if len(diffs) != 1 else ''}: {listed})"
        )
    else:
        text = f"{shown_path(config_path)} does not describe the rig this session began on"
        text += f" ({listed})"
    text += ": its images would not match the ones already taken. "
    refused = []
    if other_kind:
        refused.append(
            f"it is a rig of kind '{identity.get('kind')}', and this session was begun on "
            f"one of kind '{recorded.get('kind')}': a session cannot change kind of rig"
        )
    elif recorded.get("backend") != identity.get("backend"):
        refused.append(
            f"its backend is '{identity.get('backend')}', and this session was begun on "
            f"'{recorded.get('backend')}': one session's images come from one backend (a dry "
            "run's rendered images, a real camera's, a replayed acquisition's are not one set)"
        )
    if image_diffs:
        labels = ", ".join(d.split(":", 1)[0] for d in image_diffs)
        refused.append(
            f"{labels} change{'' if len(image_diffs) > 1 else 's'} what "
            "this session's images are (another exposure or gain reads as a brighter or darker "
            "light, another size or decoding as another picture, another simulated scene as "
            "another object), and fit, relight and "
            "RTIBuilder take a session's images as one set"
        )
    if refused:
        said = "; ".join(refused)
        text += (
            said[0].upper()
            + said[1:]
            + ": that cannot be accepted into this session, even with --accept-rig-change. "
        )
    # its counts within the lights this rig has (the session's --lights 12 had been advised
    # for a dome of 10 LEDs, and refused when pasted)
    new = new_session_command(config_path, manifest, session_dir, most=_light_count(identity))
    if other_rig:
        back = (
            _back_to_own_config(config_path, manifest, session_dir)
            if own_file or not last
            else (
                f"Resume with the session's own config, {last} (recorded in "
                f"{Path(session_dir) / 'manifest.json'} under rig.config_path): {resume}"
            )
        )
        return text + (
            f"{back}; or shoot a new session on this rig: {new}. (--accept-rig-change is for "
            "a deliberate change to this session's rig, a repaired LED, re-measured light "
            "positions, a new controller board; not for another rig)"
        )
    back = _read_file_changed(loaded, manifest) or _back_to_own_config(
        config_path, manifest, session_dir
    )
    if refused:
        rest = len(diffs) - len(image_diffs)
        return text + (
            f"{back}, or start a new session with the new settings ({new})"
            + (
                f". The other difference{'s' if rest > 1 else ''}, if deliberate, "
                "--accept-rig-change records once the images' settings are as the session began"
                if rest > 0
                else ""
            )
        )
    return text + (
        f"{back}, or, if the change is deliberate (a repaired LED, recalibrated light "
        "positions, a new controller board), add --accept-rig-change to record it"
        + _renumbered_caveat(recorded, identity)
    )


def _renumbered_caveat(recorded: dict[str, Any], identity: dict[str, Any]) -> str:
    """What ``--accept-rig-change`` can do for a dome whose number of LEDs changed: go on only
    where the steps still to shoot name LEDs that stand where they did.

    Why: the refusal advised the flag alone, and with it the resume was then refused for
    every step whose LED an LED added or taken out before it had renumbered."""
    before, now = recorded.get("lights"), identity.get("lights")
    if recorded.get("kind") != "dome" or not before or not now or before == now:
        return ""
    return (
        f" (the dome had {before} and has {now}: an LED added or taken out changes the number "
        "of every LED after it, and the session's steps name their LEDs by number, so with "
        "--accept-rig-change it goes on only if each step still to shoot names an LED that "
        "stands where it did; each that does not is named)"
    )


def _replay_images_changed(
    config_path: Path, image_diffs: list[str], manifest: dict[str, Any], session_dir: Path | str
) -> str:
    """Why a replay session whose recorded images changed, and with them what they are (their
    size, decoding), cannot go on, and the command that starts a new one (no final stop).

    Why: such a resume (the acquisition re-exported at another size) was told that the .lp
    "changes what this session's images are … set it back to continue (rti-rig run --resume
    DIR with the session's own config)": the .lp is the session's own, untouched, and there is
    no setting to set back; it is the images that changed."""
    return (
        f"the images of {shown_path(config_path)} are not the ones this session began with, and "
        "are other images now (" + "; ".join(image_diffs) + "): replaced or re-exported since. A "
        "replay's camera takes its size and settings from the recorded images themselves, "
        "and a session's images are one set for fit, relight and RTIBuilder, so this session "
        "cannot be continued on them (not even with --accept-rig-change; only the original "
        "files, put back, would let it resume). Start a new session from the acquisition as "
        "it is now (" + new_session_command(config_path, manifest, session_dir) + ")"
    )


def _replay_images_unknown(
    config_path: Path, image_diffs: list[str], manifest: dict[str, Any], session_dir: Path | str
) -> str:
    """Why a replay session begun before its images' digest was recorded, whose images now
    read otherwise, cannot go on, and the command that starts a new one (no final stop).

    Why: such a session (before 2026-11-29) cannot tell the same files read otherwise from
    files re-exported at another size since; it had been told they were "the same recorded
    images" (:func:`_replay_read_otherwise`), which nothing established."""
    return (
        f"the images of {shown_path(config_path)} now read otherwise than this session's ("
        + "; ".join(image_diffs)
        + "): re-exported since, or the same files read otherwise (an rti-rig before "
        "2026-11-30 replayed a TIFF whose thumbnail comes first at the thumbnail's size); "
        "this session began before rti-rig recorded its acquisition's images, so which "
        "cannot be told. A replay's camera takes its size and settings from the recorded "
        "images themselves, so nothing can be set back, and images taken now would not "
        "match the ones already taken. This session cannot be continued: start a new "
        "session from the acquisition as it is now, with the options it began with ("
        + new_session_command(config_path, manifest, session_dir)
        + ")"
    )


def _replay_read_otherwise(
    config_path: Path, image_diffs: list[str], manifest: dict[str, Any], session_dir: Path | str
) -> str:
    """Why a replay session whose recorded images are unchanged cannot go on, and the command
    that starts a new one (a sentence, no final stop).

    Why: a replay rig's camera size (and exposure, gain, decoding) is its recorded images' own,
    which no config sets. A session begun by an rti-rig that replayed a TIFF whose thumbnail
    comes first at the thumbnail's size (before 2026-11-30) recorded 16×12 images of a 64×48
    acquisition; its resume was told to "set it back to continue", which nothing can."""
    return (
        f"{shown_path(config_path)} replays the same recorded images this session began with, but "
        "they are now read as other images (" + "; ".join(image_diffs) + "): a replay's camera "
        "takes its size and settings from the recorded images themselves, so nothing can be "
        "set back, and images taken now would not match the ones already taken. (An rti-rig "
        "before 2026-11-30 replayed a TIFF whose thumbnail comes first at the thumbnail's "
        "size.) This session cannot be continued: start a new session from the acquisition "
        "with the options it began with ("
        + new_session_command(config_path, manifest, session_dir)
        + ")"
    )


def _read_file_changed(loaded, manifest: dict[str, Any]) -> str | None:  # type: ignore[no-untyped-def]
    """What to set back when the config is byte for byte the one the session last ran with
    (with its intensity correction file) and the change is in the light calibration ``.lp``
    it reads (a sentence, no final stop); None otherwise.

    Why: a dome re-measured since (a new ``lp_file``) had been told that its config was
    "edited since the session began: set it back … (recorded … under rig.config)", about a
    file nobody had touched and whose recorded copy holds no position."""
    if loaded.sha256 != (manifest.get("rig") or {}).get("config_sha256"):
        return None
    dome = loaded.config.dome
    if dome is None or dome.layout != "lp" or not dome.lp_file:
        return None
    lp = (loaded.folder / dome.lp_file).resolve()
    return (
        f"The config itself is as the session began; the light calibration it reads, {lp}, is "
        "not: put the .lp the session began with back to continue"
    )


def _back_to_own_config(
    config_path: Path, manifest: dict[str, Any], session_dir: Path | str
) -> str:
    """How to get back to the rig the session began on (a sentence, no final stop).

    Why: the advice was always "Resume with the session's own config (rti-rig run --resume
    DIR)", also when the file refused *was* the session's own, edited in place since (an arm's
    keep-out cone widened between two runs): that command loads the same edited file and is
    refused again. Then the file must be set back, and the manifest holds what it said."""
    last = (manifest.get("rig") or {}).get("config_path")
    if last and _same_file(Path(config_path), Path(last)):
        where = Path(session_dir) / "manifest.json"
        return (
            "It is this session's own config, edited since the session began: set it back "
            f"to continue (the config the session began with is recorded in {where}, under "
            "rig.config)"
        )
    return (
        "Resume with the session's own config (rti-rig run --resume "
        f"{shell_word(str(session_dir))})"
    )


def _config_differs(config_path: Path, manifest: dict[str, Any]) -> str:
    """How ``config_path`` came to differ from the config the session began with.

    Why: a resume given another file than the session's (``rti-rig run OTHER.toml --resume
    DIR``, a second dome's config, a copy) had been told that this file "has been edited since
    the session began": a claim about a file nobody had touched, which sends the user looking
    for an edit instead of at the choice of config. The file the session last ran with is named.
    """
    last = (manifest.get("rig") or {}).get("config_path")
    if last and not _same_file(Path(config_path), Path(last)):
        return (
            f"{shown_path(config_path)} is not the rig config this session last ran with ({last}), "
            "and differs from the one it began with"
        )
    return f"{shown_path(config_path)} has been edited since the session began"


def _same_file(a: Path, b: Path) -> bool:
    """Whether ``a`` and ``b`` name one file (the recorded one may be gone: then by path)."""
    try:
        return a.samefile(b)
    except OSError:
        return a.resolve() == b.resolve()


def rebuild_finished_session(req: ResumeRequest) -> list[str] | None:
    """``--rebuild-journal`` of a session that completed: its journal rebuilt from what proves
    each image (:func:`~rti_rig.runtime.session.rebuild_finished_journal`), no rig opened,
    since nothing is left to capture; returns what was done. None when the request is no such
    rebuild (the session did not complete, or no rebuild was asked): the resume goes on.

    Why not through :func:`open_resumed_session`: a completed session's resume is refused (and
    a camera-triggered dome's, or a rig config moved since, could not even open), and a lost
    journal of a finished session had no way back at all."""
    from rti_rig.runtime.session import read_manifest, rebuild_finished_journal

    if not req.rebuild_journal or req.reshoot_lost or req.reshoot:
        return None
    manifest = read_manifest(req.session_dir)
    if (manifest.get("runner") or {}).get("finish_reason") != "completed":
        return None
    if req.start is not None:
        # no rig is read here to compare them with (the session's own or not): refused, as
        # before they could be given again with --resume (they had gone unchecked, unsaid)
        raise RtiRigError(
            f"{shown_path(req.session_dir)}: --rebuild-journal of a session that completed opens "
            f"no rig and shoots nothing, so {', '.join(req.start.given)} would change nothing "
            "(nothing in the folder was changed): drop "
            + ("it" if len(req.start.given) == 1 else "them")
        )
    return rebuild_finished_journal(Path(req.session_dir))


def _lost_said(session_dir: Path, reshoot: bool) -> str:
    """:func:`_say_if_complete`, or with ``reshoot`` (``--reshoot-lost``, ``--reshoot``) the
    images lost alone: an intact session is then no success to end on (the reshoot asked for
    is refused). Why: ``--reshoot-lost`` on a camera-triggered session with image_007 deleted
    had said "nothing to resume", not which image was lost, which fit named."""
    if not reshoot:
        return _say_if_complete(session_dir)
    from rti_rig.runtime.session import CompleteJournalNotWhole, SessionComplete

    try:
        return _say_if_complete(session_dir)
    except (SessionComplete, CompleteJournalNotWhole):
        return ""


def _say_if_complete(session_dir: Path) -> str:
    """Raise :class:`~rti_rig.runtime.session.SessionComplete` if the completed session in
    ``session_dir`` has every image as captured (exit 0, the next step named), as any other
    complete session's resume does; return otherwise (the caller refuses it) what its resume's
    refusal says of the images missing or changed since capture ("" when it names none).

    Why: a complete, intact camera-triggered session's resume had been exit 2 while every
    other kind's was exit 0 with ``rti-rig fit`` named; nothing flash-specific differs once
    nothing is to be shot (a lab's script runs the same ``--resume`` line either way). The
    check reads and changes nothing more than another session's resume: the completed branch
    of :func:`~rti_rig.runtime.session.prepare_resume` only reads, then raises. The images
    lost are named in its words (their advice already what this dome can do: put them back,
    or shoot again into a new folder): the refusal had said only "nothing to resume"."""
    from rti_rig.runtime.session import (
        CompleteJournalNotWhole,
        ImagesLostSinceCapture,
        SessionComplete,
        SessionError,
        prepare_resume,
    )

    try:
        prepare_resume(session_dir)
    except (SessionComplete, CompleteJournalNotWhole):
        raise  # the journal's rebuild is said as any other session's
    except ImagesLostSinceCapture as exc:
        return exc.note  # the flash refusal says them, then why it cannot reshoot
    except SessionError:
        return ""  # unchecked, say: the flash refusal says why it cannot reshoot
    raise RtiRigError(
        f"{shown_path(session_dir)}: a completed session's resume went on"
    )  # pragma: no cover


def reshoot_steps(manifest: dict[str, Any], named: Sequence[str], root: Path) -> tuple[int, ...]:
    """The steps (0-based) of the images ``--reshoot`` names (``image_006``, ``image_006.jpg``,
    several in one word with commas), refused by name before anything is opened or moved: a
    name the session has no image of, a session that did not complete (its resume reshoots
    what it cannot verify anyway), or an adaptive one (each light after an image was chosen
    from it: the image reshot, they would no longer be what its evidence chose).

    Why: the QA verdict names an intact image "misfired, no light" or "wrong light" and says
    reshoot, and no command did (``--reshoot-lost`` reshoots only images lost or changed
    since capture: it said "nothing to reshoot" of these)."""
    from rti_rig.runtime.session import image_names, planned_steps

    words = [w.strip() for given in named for w in given.split(",") if w.strip()]
    if named and not words:
        # --reshoot "" (a script's variable unset) had resumed as if it were not given
        raise RtiRigError(
            f"--reshoot {shell_word(named[0])}: name the images to reshoot, as the QA verdict "
            "names them (image_006, or several: image_006,image_010); nothing was changed"
        )
    if not words:
        return ()
    runner = manifest.get("runner") or {}
    total = planned_steps(manifest)
    names = image_names(total)
    if runner.get("finish_reason") != "completed":
        raise RtiRigError(
            f"{shown_path(root)}: --reshoot is for a session that completed; this one did not, "
            "and its resume shoots the rest first (nothing in the folder was changed): continue "
            f"it with rti-rig run --resume {shell_word(str(root))}, then reshoot"
        )
    if (manifest.get("rig") or {}).get("backend") == "replay":
        raise RtiRigError(
            f"{shown_path(root)}: --reshoot cannot help a replayed acquisition: its images are "
            "the recording's, and a reshoot gives the same image again (nothing in the folder "
            "was changed); mend the acquisition itself"
        )
    if "adaptive" in manifest:
        raise RtiRigError(
            f"{shown_path(root)}: --reshoot cannot reshoot an image of an adaptive session: "
            "each light after it was chosen from it, and with the image reshot they would no "
            "longer be what the session's evidence chose (nothing in the folder was changed); "
            "shoot a new session for the object (its verdict says why the image is bad)"
        )
    steps: list[int] = []
    unknown: list[str] = []
    for word in words:
        stem = word if word in names else Path(word).stem  # image_006 or image_006.jpg
        if stem in names:
            if names.index(stem) not in steps:
                steps.append(names.index(stem))
        else:
            unknown.append(word)
    if unknown:
        raise RtiRigError(
            f"--reshoot {', '.join(unknown)}: {shown_path(root)} has no image of that name; "
            f"give its images as the verdict names them, {names[0]} to {names[-1]} (several "
            "with commas: --reshoot image_006,image_009)"
        )
    return tuple(sorted(steps))


def open_resumed_session(req: ResumeRequest, on_note: NoteSink = _ignore) -> OpenedSession:
    """Check the rig against the session, verify and repair the session on disk, open the
    rig and check the remaining steps on it.

    The rig is checked from the manifest alone (nothing in the folder changes if it is
    refused); only then is the journal repaired and anything unverified set aside.
    """
    from rti_rig.app.config import load_rig_config
    from rti_rig.runtime.session import read_manifest

    check_max_saturated(req.max_saturated)
    manifest = read_manifest(req.session_dir)
    if req.reshoot and req.rebuild_journal:
        raise RtiRigError(
            f"{shown_path(req.session_dir)}: --rebuild-journal and --reshoot go one at a time "
            "(nothing in the folder was changed): rebuild the journal first (rti-rig run --resume "
            f"{shell_word(str(req.session_dir))} --rebuild-journal), then reshoot"
        )
    also_reshoot = reshoot_steps(manifest, req.reshoot, Path(req.session_dir))
    if req.objective is not None or "adaptive" in manifest:
        from rti_rig.app.usecases.adaptive import check_resume_objective

        check_resume_objective(manifest, Path(req.session_dir), req.objective)
    rig_entry = manifest.get("rig") or {}
    if req.rig_config is None and not rig_entry.get("config_path"):
        raise RtiRigError(
            f"{shown_path(req.session_dir)}: the manifest does not say which rig config it was "
            "shot with; give it: rti-rig run RIG.toml --resume "
            f"{shell_word(str(req.session_dir))} (RIG.toml: that config's path)"
        )
    config_path = req.rig_config or Path(rig_entry["config_path"])
    if req.rig_config is None and not config_path.is_file():
        plain = not (req.reshoot_lost or req.reshoot or req.rebuild_journal)
        if plain and (manifest.get("runner") or {}).get("finish_reason") == "completed":
            # a complete, intact session needs no rig to be said so (exit 0, `fit` named): a
            # resume of one whose config had since moved had been refused for the config
            # (QA, 2026-12-06); one with images lost or changed goes on to the refusal below
            # (its reshoot needs the rig)
            _say_if_complete(Path(req.session_dir))
        # a replay rig is an acquisition's .lp, moved with its images: ask for that, not a TOML
        replay = config_path.suffix.lower() == ".lp"
        what = "recorded acquisition it replayed" if replay else "rig config it was shot with"
        resume = f"--resume {shell_word(str(req.session_dir))}"
        if replay:
            # the path it was, from the manifest, as shell words: "ACQ/dirs.lp" was a
            # template the user had to fill in (and, pasted, named a folder that never was)
            give = (
                f"put it back there (its images beside it): rti-rig run "
                f"{shell_word(str(config_path))} {resume}, or give the path it has now in "
                "its place"
            )
        else:
            give = f"give it: rti-rig run RIG.toml {resume}"
        raise RtiRigError(
            f"{shown_path(req.session_dir)}: the {what}, {shown_path(config_path)}, is not there "
            f"any more (moved or renamed?); {give} (the session's manifest keeps a copy of the "
            "rig it began with, and a resume checks the rig against it)"
        )
    loaded = load_rig_config(config_path)
    for note in loaded.notes:
        on_note(Note(note, "warning"))
    from rti_rig.app.flash_sync import flash_sync_of, refuse_options

    runner = manifest.get("runner") or {}
    again = free_folder_beside(Path(req.session_dir), "again")  # the one a new run would take
    if flash_sync_of(loaded) is not None and runner.get("finish_reason") == "completed":
        # a finished session had been told only that a camera-triggered dome cannot resume
        # (so the user looked for what had interrupted it): it is complete, and says so
        lost = _lost_said(Path(req.session_dir), bool(req.reshoot_lost or req.reshoot))
        done = (
            f"{shown_path(req.session_dir)}: this session already completed all "
            f"{runner.get('steps_planned', len(manifest.get('steps') or []))} steps; nothing "
            "to resume"
        )
        if lost:  # named, with what this dome can do (nothing in the folder was changed)
            raise RtiRigError(done + lost)
        raise RtiRigError(
            done + " (a camera-triggered dome cannot reshoot single images either: to shoot "
            "again, long-press the dome's start button, then rti-rig run "
            f"{shell_word(str(config_path))} --out {shell_word(str(again))})"
        )
    refuse_options(loaded, again, **{"--resume": True})
    _refuse_image_sequence_resume(loaded, Path(req.session_dir))
    # the rig first: another rig given with the session's own options is refused as another
    # rig (its layout compared with the session's had been blamed on the options, with the
    # advice to give those very options); its notes (an accepted change) said only once the
    # options are found the session's own
    rig_notes: list[Note] = []
    identity, diffs = check_resume_rig(
        manifest, loaded, config_path, req.accept_rig_change, rig_notes.append, req.session_dir
    )
    if req.start is not None:  # the session's own options given again, or refused
        from rti_rig.app.usecases.resume_request import check_same_start

        check_same_start(req.start, manifest, loaded, Path(req.session_dir))
    if "adaptive" in manifest and not diffs:  # on an arm whose times changed: before a word
        from rti_rig.app.usecases.adaptive import refuse_other_times

        refuse_other_times(manifest, loaded, Path(req.session_dir))
    # a change accepted is said once the steps still to shoot are found to run on the rig as
    # changed (_opened_resume): "rig change accepted" had been followed by a refusal of them
    accepted = rig_notes if diffs else []
    for note in [] if diffs else rig_notes:
        on_note(note)
    check_done = None
    if "adaptive" in manifest:
        from rti_rig.app.usecases.adaptive import refuse_broken_run
        from rti_rig.runtime.session import planned_steps

        check_done = refuse_broken_run(Path(req.session_dir), planned_steps(manifest))
    folder = SessionFolder.reopen(
        req.session_dir,
        check_done,
        req.reshoot_lost or bool(also_reshoot),
        req.rebuild_journal,
        also_reshoot,
    )
    try:
        return _opened_resume(req, loaded, folder, identity, diffs, on_note, accepted)
    except BaseException:
        # the folder's lock (taken by the reopen) goes with the run that did not start: a
        # process that stays (a test, a program calling this) had kept every other one out
        from rti_rig.runtime.session import unlock_session

        try:
            folder.put_back_now()  # a reshoot that never shot leaves no hole
        except Exception as exc:  # said, never in place of why the resume did not open
            on_note(Note(f"the images set aside could not be put back: {exc}", "warning"))
        finally:
            unlock_session(folder.root)
        if folder.put_back is not None:
            on_note(Note(put_back_said(folder.put_back), "warning"))
        raise


def put_back_said(back: Any) -> str:
    """What a reshoot that never shot says of what it put back (a
    :class:`~rti_rig.runtime.session.PutBack`): those as captured, and those that were not
    (``--reshoot-lost``'s, put back as they were found)."""
    parts = []
    if back.as_captured:
        parts.append(f"{', '.join(back.as_captured)} put back as captured")
    if back.not_as_captured:
        parts.append(
            f"{', '.join(back.not_as_captured)} put back as found (still missing or changed "
            "since capture)"
        )
    return (
        f"Nothing was reshot: {'; '.join(parts)}, and lights.lp lists every image again: the "
        "session's images are as they were before this resume."
    )


def _refuse_image_sequence_resume(loaded: Any, root: Path) -> None:
    """Refuse, before the folder is touched, to resume a session with images whose camera is
    an image sequence (:func:`rti_rig.runtime.session.image_sequence_restarts`)."""
    from rti_rig.runtime.session import holds_no_image, image_sequence_restarts

    again = shell_word(str(free_folder_beside(Path(root), "again")))  # shoot again into it
    why = image_sequence_restarts(loaded.config.camera.device, shell_word(str(loaded.path)), again)
    if why is None or holds_no_image(root):
        return  # nothing shot yet: the sequence's first file is the first image's
    raise RtiRigError(
        f"{shown_path(root)}: this session cannot be resumed (nothing was changed): {why}"
    )


def _opened_resume(  # type: ignore[no-untyped-def]
    req, loaded, folder, identity, diffs, on_note, accepted=()
):
    folder.rig_identity = identity
    folder.rig_change = diffs or None
    folder.input_notes = list(loaded.notes)  # recorded in this run's entry of the manifest
    schedule = LightSchedule.from_dict(folder.manifest["schedule"])
    done = len(folder.done)
    resume = folder.resume
    recovered = resume.recovered if resume else []
    # where they went, said: the folder of this resume, not recovered/ at large (which may hold
    # earlier resumes' too); with --reshoot-lost they are the files of the images to shoot
    # again, which had been called "unverified" though their checksums may well match
    where = ", ".join(sorted({"/".join(Path(p).parts[:2]) for p in recovered}))
    # the rejected journal lines and a lights.lp written again are set aside there too, but
    # they are not files of the images to reshoot (they had been counted as such)
    images = [p for p in recovered if Path(p).suffix.lower() not in (".txt", ".lp")]
    moved = (
        f", {len(images)} file(s) of the images to reshoot set aside in {where}/ (never deleted)"
        if req.reshoot_lost or req.reshoot
        else f", {len(images)} unverified file(s) moved to {where}/"
        if images
        else f" (what it set aside is in {where}/)"
    )
    on_note(
        Note(
            f"Resuming {shown_path(req.session_dir)}: {done} of {folder.total_steps} images "
            "verified on disk" + (moved if recovered else "")
        )
    )
    for note in resume.journal_repair if resume else []:
        # a record written back from its step's record file is kept, not set aside
        aside = ": set aside in recovered/, not appended onto" if note.set_aside else ""
        on_note(Note(f"{note.text}{aside}", "warning"))
    for line in resume.journal_rebuild if resume else []:
        on_note(Note(line, "warning"))
    if resume is not None and resume.edited_lp is not None:
        from rti_rig.runtime.session import edited_lp_note

        on_note(Note(edited_lp_note(folder.root, resume.edited_lp), "warning"))
    earlier = resume.set_aside_before if resume else []
    if earlier:
        shown = ", ".join(earlier[:8]) + (" …" if len(earlier) > 8 else "")
        on_note(
            Note(
                f"{len(earlier)} image(s) an earlier resume set aside to reshoot ({shown}, as "
                "captured, never deleted): shot again now, with the object where it was"
            )
        )
    lost = resume.lost_since_capture if resume else []
    if lost:
        # in the verdict's words, with what this resume does about them: it had said only "N
        # unverified file(s) moved", of a RAW a raw editor had written into, say
        shown = "; ".join(lost[:8]) + (" …" if len(lost) > 8 else "")
        aside = f"what is left of them set aside in {where}/ (never deleted), " if where else ""
        on_note(
            Note(
                f"{len(lost)} image(s) lost since capture ({shown}): what was captured is no "
                f"longer there; {aside}shot again now, with the object where it was",
                "warning",
            )
        )
    # the steps still to shoot, at their own exposures, before the port opens
    _check_steps_fit_lit(loaded, schedule, frozenset(folder.done))
    _check_disk_holds_rest(loaded, folder, Path(req.session_dir))
    # the steps still to shoot only: the ones shot are history (a change accepted that left
    # only those out of reach had refused the resume). An adaptive session's recorded layout
    # is not checked here: its start is placed again on the rig as it is now, and what is
    # left of that is checked once its step source is built, below (the layout recorded had
    # refused a light the resume would not take)
    adaptive = "adaptive" in folder.manifest
    shot = frozenset(folder.done)
    leds_now = _leds_numbered_alike(loaded, folder, identity) if diffs else None
    if leds_now is not None and not adaptive:
        # a fixed plan's LEDs still to shoot, from where they are now (re-measured)
        schedule = _start_as_placed(schedule, _lit_from(leds_now, schedule), shot, folder)
    try:
        rig = checked_rig(loaded, schedule, frozenset(range(len(schedule))) if adaptive else shot)
    except ScheduleError as exc:
        raise _refused_on_changed_rig(exc, diffs, loaded, req, folder, identity) from None
    source = None
    if adaptive:
        from rti_rig.app.usecases.adaptive import resume_adaptive_source

        try:
            source = resume_adaptive_source(rig, folder, req.objective)
            schedule = _start_as_placed(schedule, source.start_schedule(), shot, folder)
            # the start's lights still to shoot; each light chosen after it is checked
            # before it moves (run_session)
            validate_schedule(rig, schedule, shot)
        except ScheduleError as exc:
            rig.close_said()
            raise _refused_on_changed_rig(exc, diffs, loaded, req, folder, identity) from None
        except BaseException:
            rig.close_said()  # its failures said, never in place of the error raised
            raise
    for note in accepted:  # the steps still to shoot run on the rig as changed
        on_note(note)
    if diffs and shot:
        _say_shot_beyond(rig, schedule, folder, shot, on_note, leds_now)
    return OpenedSession(
        rig, schedule, folder, Path(req.session_dir), resumed=True, source=source, request=req
    )


def _leds_numbered_alike(  # type: ignore[no-untyped-def]
    loaded, folder, identity: dict[str, Any]
) -> DomeGeometry | None:
    """The LEDs of a dome resumed on a change accepted, when they are numbered as the session
    began (as many of them: ``lights`` of its recorded identity), so that an LED's index is
    the same light, moved perhaps (re-measured); None for an arm, or for a dome with another
    number of LEDs.

    Why the number: an LED taken out of a ring numbers every later one otherwise, and a step
    moved to whatever light now has its index would fire another LED than the one planned or
    shot. Such a dome's steps are checked as recorded instead: an LED gone is refused by its
    number, one now elsewhere as "planned direction is … from LED N's calibrated direction"."""
    from rti_rig.app.config import rig_geometry

    geometry = rig_geometry(loaded)
    recorded = (folder.manifest.get("rig") or {}).get("identity") or {}
    if not isinstance(geometry, DomeGeometry) or recorded.get("lights") != identity.get("lights"):
        return None
    return geometry


def _lit_from(leds: DomeGeometry, schedule: LightSchedule) -> LightSchedule:
    """``schedule`` with each step lighting its LED from where ``leds`` has it now (a step
    whose LED is not one of them kept, for the check to refuse by its number)."""
    steps = tuple(
        replace(step, direction=tuple(float(x) for x in leds.directions[step.led]))
        if step.led is not None and step.led < leds.count
        else step
        for step in schedule.steps
    )
    return LightSchedule(steps, method=schedule.method, provenance=schedule.provenance)


def _start_as_placed(  # type: ignore[no-untyped-def]
    recorded: LightSchedule, placed: LightSchedule, shot: frozenset[int], folder
) -> LightSchedule:
    """An adaptive session's starting layout as this resume shoots it: its steps shot as
    recorded, the rest as the rig as it is now places them (``placed``). Where that differs
    from the layout recorded (an accepted rig change), the manifest's ``schedule`` is made this
    one and the one recorded is kept in the run (``schedule_before_rig_change``). A fixed
    dome plan resumed on re-measured LEDs is placed so too, each step on its own LED
    (:func:`_lit_from`).

    Why: after a change of reach the manifest still gave a start light at 53.3° that never
    fired, while lights.lp and the journal said 36.2°; a tool reading the manifest's schedule
    (or the next resume's check of the steps shot) read a light that was not the session's."""
    steps = tuple(
        recorded.steps[i] if i in shot else placed.steps[i] for i in range(len(placed.steps))
    )
    now = LightSchedule(steps, method=recorded.method, provenance=recorded.provenance)
    if now.to_dict() != folder.manifest["schedule"]:
        folder.schedule_before_change = folder.manifest["schedule"]
        folder.manifest["schedule"] = now.to_dict()
    return now


def _refused_on_changed_rig(  # type: ignore[no-untyped-def]
    exc: ScheduleError,
    diffs: list[str],
    loaded,
    req: ResumeRequest,
    folder: Any = None,
    identity: dict[str, Any] | None = None,
) -> ScheduleError:
    """The refusal of a resume whose steps still to shoot cannot run: with an accepted change
    (an arm's reach narrowed) that leaves the session's own lights out of reach, what to do
    too (the list alone had said what, not what to do). Said as steps that cannot run, not
    "out of its reach": the refusal may be a narrower camera's exposure range or a timed
    firmware's window, a change as accepted.

    ``folder``, ``identity``: the session and the rig as it is now; a dome whose number of
    LEDs changed since the session began has its steps' LEDs said as renumbered. Why: each
    was said "the plan was made for another dome layout", of a session whose plan was made
    for this very dome as it began, and no plan was given; the LED added or taken out had
    shifted the number of every LED after it."""
    if not diffs:
        return exc
    session = Path(req.session_dir)
    again = free_folder_beside(session, "again")
    problems, renumbered = str(exc), ""
    recorded = ((folder.manifest.get("rig") or {}).get("identity") or {}) if folder else {}
    before, now = recorded.get("lights"), (identity or {}).get("lights")
    if before and now and before != now and ANOTHER_LAYOUT in problems:
        problems = problems.replace(ANOTHER_LAYOUT, "renumbered or moved since this session began")
        renumbered = (
            f"This dome has {now} and had {before} when the session began: an LED added or "
            "taken out changes the number of every LED after it, and the session's steps name "
            "their LEDs by number: the LED each of these names stands elsewhere than planned. "
        )
    return ScheduleError(
        f"{problems}\n{renumbered}The rig change accepted ({'; '.join(diffs)}) leaves these "
        f"steps of {shown_path(session)} unable to run on it: to finish the session, set "
        f"{shown_path(loaded.path)} back as it began (its copy is in "
        f"{shown_path(session / 'manifest.json')}, under rig.config) and resume; or shoot "
        f"a new session on the rig as it is: {run_words(loaded.path, again)}"
    )


def _say_shot_beyond(  # type: ignore[no-untyped-def]
    rig,
    schedule: LightSchedule,
    folder,
    shot: frozenset[int],
    on_note: NoteSink,
    leds_now: DomeGeometry | None = None,
) -> None:
    """Say, and record in this run's manifest entry, the images already shot that the rig as
    changed could not take (an arm's reach narrowed, an LED taken out): kept, as shot on the
    rig as it was; ``lights.lp`` lists the lights that fired for them. ``leds_now``: a dome's
    LEDs numbered as the session began (:func:`_leds_numbered_alike`), each still there,
    re-measured or not: its LEDs can all be lit again.

    Why: the resume had refused such a session whole; going on, the images kept beside ones
    the rig could no longer take must be told as what they are, not left to look like the
    changed rig's work. Why ``leds_now``: an image shot under an LED since re-measured had
    been said (and recorded) as one the rig could not take, "the plan was made for another
    dome layout"."""
    from rti_rig.runtime.controller import schedule_problems

    as_shot = _as_shot(schedule, folder)
    if leds_now is not None:
        as_shot = _lit_from(leds_now, as_shot)
    beyond = schedule_problems(rig, as_shot, sorted(shot))
    if not beyond:
        return
    folder.shot_beyond_change = beyond
    shown = "; ".join(beyond[:5]) + (f"; ... and {len(beyond) - 5} more" if len(beyond) > 5 else "")
    on_note(
        Note(
            f"{len(beyond)} image(s) already shot could not be taken on the rig as changed "
            f"({shown}): they are kept, shot on the rig as it was (its config in "
            f"{shown_path(folder.root / 'manifest.json')}, under rig.config; lights.lp lists "
            "the lights that fired for them); only the steps still to shoot were checked "
            "against the change (recorded in the manifest's run as shot_before_rig_change)",
            "warning",
        )
    )


def _as_shot(schedule: LightSchedule, folder) -> LightSchedule:  # type: ignore[no-untyped-def]
    """The session's steps as they were shot, to check against a changed rig: the schedule's,
    and past an adaptive session's starting layout the lights it chose, as its records keep
    them (its schedule holds no step beyond the start)."""
    done = folder.done  # an adaptive session's: steps 0..n-1, none missing (refuse_broken_run)
    if len(done) <= len(schedule):
        return schedule
    chosen = (
        LightStep(tuple(done[i].planned_direction), led=done[i].led)
        for i in range(len(schedule), len(done))
    )
    return LightSchedule((*schedule.steps, *chosen), method=schedule.method)


def open_preview_session(req: PreviewRequest, on_note: NoteSink = _ignore) -> OpenedSession:
    """A one-image session under the preview light (the planner's input)."""
    from rti_rig.app.config import load_rig_config, rig_geometry
    from rti_rig.planner.make_plan import check_elevation_band
    from rti_rig.planner.preview_shot import preview_schedule, refuse_unplannable_band

    check_max_saturated(req.max_saturated)
    check_elevation_band(req.min_elevation_deg, req.max_elevation_deg)
    loaded = load_rig_config(req.rig_config)
    refuse_unplannable_band(rig_geometry(loaded), (req.min_elevation_deg, req.max_elevation_deg))
    from rti_rig.app.flash_sync import refuse_options

    refuse_options(loaded, req.out_dir, preview=True)  # nothing was written to it
    # the folder before the light: a note on which LED stands in for the light asked had been
    # printed above the refusal of an --out that is not empty or lies in a session
    SessionFolder.check_new(req.out_dir)
    schedule, notes = preview_schedule(
        rig_geometry(loaded),
        req.light_az_el_deg,
        (req.min_elevation_deg, req.max_elevation_deg),
        shot_as=f"{image_names(1)[0]}.jpg",  # the file its one step writes
    )
    for note in notes:
        on_note(Note(note, "warning"))
    opened = _open_new(loaded, schedule, req.out_dir, req.auto_exposure, req.max_saturated, on_note)
    opened.list_card = False
    # a camera that advises how to shoot a lost image again (a DSLR whose download the disk
    # refused) says to run the preview again, the command its user typed. Not that no resume
    # continues a preview: 'rti-rig run --resume' does (a one-image session), and it had
    # been said that none does
    if hasattr(opened.rig.camera, "shoot_again"):
        opened.rig.camera.shoot_again = "run the same 'rti-rig preview' again"
    return opened


def run_opened_session(
    opened: OpenedSession,
    cancel: CancelToken | None = None,
    on_event: Callable[[Event], None] | None = None,
) -> SessionResult:
    """Run an opened session to its end (or cancel / error); the rig is closed afterwards.

    The controller's guarantees hold: devices are put in their safe state and the session's
    `.lp` and manifest are written from what is on disk, whatever happens.
    """
    with opened:
        result = run_session(
            opened.rig,
            opened.schedule,
            opened.folder,
            cancel=cancel,
            on_event=on_event,
            source=opened.source,
            list_card=opened.list_card,
        )
    if opened.source is not None and result.finish_reason is FinishReason.COMPLETED:
        # the adaptive run's outcome (lights used, final estimate, why it stopped), concluded
        # before the session completed and recorded by the controller in the same write
        opened.extra["adaptive_result"] = opened.source.conclude()
    return result
