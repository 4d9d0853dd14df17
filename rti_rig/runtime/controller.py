"""The controller: validate a schedule against the rig, run it step by step, always tear down.

Policy lives here, not in drivers: nothing moves until the whole schedule has been checked;
between steps the run can be cancelled; lights go off after every capture; and whatever happens
(success, cancel, device error, Ctrl-C) the ``finally`` block puts every device in its safe state
and writes the session's `.lp` and manifest from the images already on disk.
"""

from __future__ import annotations

import signal
import time
from collections.abc import Callable, Iterable
from contextlib import AbstractContextManager, nullcontext
from dataclasses import dataclass
from enum import StrEnum
from typing import TYPE_CHECKING, Any, Protocol

from rti_rig.core.deferred_signals import as_received, signals_deferred, stop_words
from rti_rig.core.devices import (
    BusyAwareCamera,
    CardListingCamera,
    ExposingCamera,
    ExposureRefusingCamera,
    Frame,
    FramePacedCamera,
)
from rti_rig.core.dome_link import DomeLedError, DomeLinkError
from rti_rig.core.errors import CameraBusyError, CaptureError, DeviceError, ScheduleError
from rti_rig.core.lp_format import MAX_LIGHTS
from rti_rig.core.rig_geometry import hint_light_count, led_fields
from rti_rig.core.schedule import LightSchedule, LightStep
from rti_rig.core.shell_words import shown_path
from rti_rig.runtime.lighting import ArmLighting, Lighting, port_close_failures
from rti_rig.runtime.rig import Rig
from rti_rig.runtime.session import (
    FRAME_SIZE_KEY,
    NoSpaceError,
    SessionFolder,
    SessionWriteError,
    SourceReadError,
    StepRecord,
    check_free_space,
    estimated_bytes_per_image,
    recorded_frame_size,
    steps_to_hold,
)
from rti_rig.runtime.teardown_repeats import failed_as_before

if TYPE_CHECKING:
    from rti_rig.runtime.arm_check import ArmSelfTestReport


class FinishReason(StrEnum):
    COMPLETED = "completed"
    CANCELLED = "cancelled"
    ERROR = "error"
    INTERRUPTED = "interrupted"
    EMERGENCY_STOP = "emergency-stop"
    #: a session file could not be written (no space, read-only, I/O error)
    WRITE_FAILED = "write-failed"
    #: the disk could not hold the next image (checked before each one)
    NO_SPACE = "no-space"


def run_state(reason: FinishReason) -> str:
    """The manifest's ``runner.state`` for a run that recorded its end with ``reason``:
    ``finished`` for a run that completed its plan, ``stopped`` for one that ended before it
    (a stop, an error, a full disk), as :meth:`SessionFolder.record_cut_end` says of a run
    whose end a stop cut short.

    Why: every recorded end had read ``finished``, a SIGTERM mid-capture too, while the same
    SIGTERM a moment later (cutting the end record short) read ``stopped``: one stop, two
    states, and a ``finished`` of a session with most of its images still to take."""
    return "finished" if reason is FinishReason.COMPLETED else "stopped"


class EmergencyStop(BaseException):
    """Raised (e.g. from a SIGTERM handler) to abandon the current step at once.

    A BaseException so that no ``except Exception`` in a driver swallows it; the controller's
    ``finally`` still puts every device in its safe state.

    :attr:`signum` is the signal that stopped, as the handler received it: a command's exit
    code is decided on it (128 + its number); ``str()`` is the words said to the user
    (:func:`stop_words`, or ``words`` where the handler names it otherwise: "second Ctrl-C").
    Why typed: the exit code had been decided by comparing those words with "SIGTERM".
    """

    #: The report of an arm's self-test this stop cut short (set by
    #: :func:`~rti_rig.runtime.arm_check.arm_self_test`: its teardown's failures, where it
    #: left the arm), None otherwise. Declared: ``check`` had read it with ``getattr``.
    self_test_report: ArmSelfTestReport | None = None
    #: What metering's teardown established of the lights, where this stop ended metering
    #: (as :attr:`~rti_rig.core.errors.RtiRigError.lights_state`), None otherwise.
    lights_state: str | None = None

    def __init__(self, signum: signal.Signals, words: str | None = None) -> None:
        self.signum = as_received(signum)  # a hang-up answered as a SIGTERM is a SIGHUP
        super().__init__(words or stop_words(self.signum))


class CancelToken:
    """Run control set from another thread or a signal handler, acted on between steps.

    ``cancel`` ends the session after the current step; ``pause`` holds the run between steps,
    with the lights off, until ``resume`` (or ``cancel``).

    Plain flags, no lock: a Python signal handler runs in the main thread between two of its
    bytecodes, possibly while that thread holds a ``threading.Event``'s lock inside
    :meth:`wait_while_paused`; an ``Event.set`` in the handler then waited for that lock for
    ever, and a SIGTERM sent with the SIGUSR1 that resumed was never acted on (a paused run
    stopped only on two Ctrl-C).
    """

    def __init__(self) -> None:
        self._cancelled = False
        self._paused = False
        self._capture_over = False

    def capture_over(self) -> None:
        """Set by the controller as it leaves its capture loop for the teardown (whatever
        ended it): a Ctrl-C from now on has no image left to stop after.

        Why: the teardown holds Ctrl-C and delivers it once done, and the CLI then said
        "Stopping after this image" of a session whose images were all in and whose arm was
        already left or parked."""
        self._capture_over = True

    @property
    def over(self) -> bool:
        """Whether the capture has ended (see :meth:`capture_over`)."""
        return self._capture_over

    def cancel(self) -> None:
        self._cancelled = True
        self._paused = False

    def pause(self) -> None:
        self._paused = True

    def resume(self) -> None:
        self._paused = False

    @property
    def cancelled(self) -> bool:
        return self._cancelled

    @property
    def paused(self) -> bool:
        return self._paused

    def wait_while_paused(self, poll_s: float = 0.05) -> None:
        """Block (in real time: a pause waits for a person) until resumed or cancelled.

        Sleeps, holding nothing a signal handler or another thread needs."""
        while self._paused and not self._cancelled:
            time.sleep(poll_s)


class StepAbandoned(Exception):
    """The run was cancelled (Ctrl-C) while a busy camera was awaited with the step's light
    off: the step is left untaken, to be shot by a resume, rather than lit again for it.

    Why: the cancel is acted on between steps, and that wait (the camera's next try, then any
    cool-down the dome's duty limit asks, up to a minute) ended with the light lit again and
    the shot taken before the run stopped; a user who pressed Ctrl-C waited for a shot they
    had asked not to take."""


#: How often a wait in the dark looks at the cancel (seconds of the rig's clock).
DARK_POLL_S = 0.1


@dataclass(frozen=True)
class Paused:
    index: int
    total: int


@dataclass(frozen=True)
class StepStarted:
    index: int
    total: int
    step: LightStep


@dataclass(frozen=True)
class StepCompleted:
    index: int
    total: int
    record: StepRecord


@dataclass(frozen=True)
class SessionResult:
    finish_reason: FinishReason
    records: tuple[StepRecord, ...]
    rig_time_s: float
    wall_time_s: float
    error: str | None
    teardown_failures: tuple[str, ...]
    #: What the rig's end-of-run check says (e.g. whether a flash-stepped dome's order held).
    notes: tuple[str, ...] = ()


@dataclass(frozen=True)
class LightOffForCamera:
    """The step's light was switched off because the camera is still busy and its next try
    would come after the light's ``max_on_s``; it is lit again after ``wait_s`` (the
    camera's next try) and ``cool_s`` (the cool-down the dome's duty limit asks)."""

    index: int
    total: int
    led: int | None
    lit_s: float
    #: what the all-off established ("acknowledged", "sent-no-ack"…; None: not known)
    off: str | None
    wait_s: float
    #: how long the light must cool after that wait before its duty limit lets it light
    cool_s: float
    #: how long the light may stay lit (the dome's ``max_on_s``, or a timed firmware's
    #: shorter window)
    max_on_s: float
    #: what sets that limit, as a message names it ("max_on_s = 8 s", or the timed
    #: firmware's window: RTIPy's LED goes dark by itself after ``light_on_s``)
    limit: str = ""


@dataclass(frozen=True)
class DeviceSays:
    """A device's word on what it is doing, said as it happens: a DSLR listing its card before
    the first step (which may take minutes on a full card, had been silent), a dome reopening
    its lost port and the outcome (printed raw as log records before)."""

    device: str
    text: str


@dataclass(frozen=True)
class Preparing:
    """What the run is doing before its first step, as each part begins: ``phase`` is
    ``"lights"`` (the dome's port, the arm's connect and baud scan), ``"camera"`` (its
    connect), ``"card"`` (a card camera listing its card) or ``"ready"`` (all connected, the
    first step next).

    Why: a first Ctrl-C there stops before any image, and the CLI says what it waits for;
    it had said "the rig is being connected" during the camera's connect, a card's listing
    (minutes on a full card) and a pause before the first step alike."""

    phase: str


Event = StepStarted | StepCompleted | Paused | LightOffForCamera | DeviceSays | Preparing


class StepSource(Protocol):
    """Steps decided as the session goes (adaptive acquisition), instead of a fixed schedule.

    The controller keeps every guarantee of a fixed schedule (checks before a light moves,
    lights off after each capture, teardown, journal) and asks the source, before step
    ``index``, what to do: a step and the evidence of that decision (journaled with the step),
    or ``None`` to end the session there. After each capture the source sees the frame.
    Decisions must depend only on the frames seen (in index order), so that ``--resume``, which
    shows the source the frames already on disk, continues the session deterministically.
    """

    @property
    def total(self) -> int:
        """The most steps the session may take (the session folder is sized for it)."""
        ...

    @property
    def sure_total(self) -> int:
        """The steps the session is sure to take (``total`` when they are known): the disk is
        asked to hold these before the capture starts, the rest image by image."""
        ...

    def header(self) -> dict[str, Any]:
        """What the manifest records of the source (its settings), under ``adaptive``."""
        ...

    def next_step(self, index: int) -> tuple[LightStep, dict[str, Any]] | None: ...

    def observe(self, index: int, frame: Frame, record: StepRecord) -> None: ...

    def conclude(self) -> dict[str, Any]:
        """How the source ended (for an adaptive session: lights used, final estimate, why it
        stopped), asked once its last step is done and *before* the session counts as
        completed: it is recorded under ``adaptive.result`` in the same manifest write that
        says so. Computed afterwards, a stop during it (the estimate takes a fraction of a
        second) had left a session marked completed without its result, which no resume
        could add."""
        ...


def step_exposure(rig: Rig, step: LightStep) -> float:
    return step.exposure_s if step.exposure_s is not None else rig.camera_config.exposure_s


def shoot_lit(rig: Rig, exposure_s: float) -> Frame:
    """Capture one frame under the light that is on, and switch the light off.

    A camera that can say when its exposure is over (an :class:`ExposingCamera`: a DSLR that
    downloads and decodes, a tethered file still on its way) has the light switched off then,
    not after the image is in hand: seconds less of light on the object per image, and no shot
    lost to ``max_on_s`` while a file crossed a slow link. The frame is collected after that.
    """
    camera = rig.camera
    if not isinstance(camera, ExposingCamera):
        frame = camera.capture(exposure_s)
        rig.lighting.off()
        return frame
    return _finish_shot(rig, camera.expose(exposure_s))


def _finish_shot(rig: Rig, ended: float | None) -> Frame:
    """Light off once the exposure that ``expose`` fired has ended, then collect its frame."""
    camera: Any = rig.camera
    if ended is None:  # the camera cannot tell: the light stays on until the image is in
        frame = camera.collect()
        rig.lighting.off()
        return frame
    wait = ended - rig.clock.now()
    if wait > 0:
        rig.clock.sleep(wait)
    rig.lighting.off()
    return camera.collect()


def shoot_step(
    rig: Rig,
    step: LightStep,
    exposure_s: float,
    lit_at: float,
    on_dark: Callable[[dict[str, Any]], None] | None = None,
    cancelled: Callable[[], bool] | None = None,
) -> tuple[Frame, list[dict[str, Any]]]:
    """Capture the image of ``step``, lit at ``lit_at`` and settled, and switch its light off;
    return the frame and the times its light was switched off and lit again meanwhile.

    A camera that answers busy (a DSLR writing its previous shot to a slow card) is awaited
    with the light lit only as long as the light may stay lit (the dome's ``max_on_s``, or a
    timed firmware's shorter window, RTIPy's ``light_on_s``, after which its LED is dark
    whatever the host does; less the exposure and ``timing.readout_s``, from ``lit_at``).
    Past that the light is switched off (thermal duty first; a timed firmware is left to
    switch it off), the camera is awaited in the dark for its next try, and the same light is
    lit again (on RTIPy a new timed command) and settled before the camera is asked again:
    the image is always the one taken under the lit light, since the camera is only ever
    fired with it lit, and its light goes off only once the exposure is over or the camera
    has refused the shot. The whole wait is bounded by the camera's own retry settings
    (``busy_retries`` and its back-off); a camera still busy then stops the session, which
    ``--resume`` continues. The dome's thermal guard may add a cool-down before a relight.
    Until 2026-11-29 a camera busy longer than ``max_on_s`` stopped the session, with advice
    (raise ``busy_retries``) that then ran into the thermal limit.

    ``on_dark`` is told each time the light goes off (how long it was lit, what the all-off
    established, how long the camera is awaited), before that wait. ``cancelled`` is asked
    through each wait in the dark: once it says so the step is abandoned with its light off
    (:class:`StepAbandoned`), never lit again for it.
    """
    camera = rig.camera
    if lit_limit_s(rig) is None or not isinstance(camera, BusyAwareCamera):
        return shoot_lit(rig, exposure_s), []
    ended, relit = fire_lit(rig, step, exposure_s, lit_at, on_dark, cancelled)
    return _finish_shot(rig, ended), relit


def lit_limit_s(rig: Rig) -> float | None:
    """How long the rig's light may stay lit at a time (a dome's ``max_on_s``), or None
    (:meth:`rti_rig.runtime.lighting.Lighting.lit_limit_s`, which every lighting answers)."""
    return rig.lighting.lit_limit_s()


def lit_limit_said(rig: Rig) -> str:
    """What sets :func:`lit_limit_s`, as a message names it (``max_on_s = 8 s``)."""
    return rig.lighting.lit_limit_said()


def check_capture_fits_lit(rig: Rig, exposures_s: Iterable[float], before: str) -> None:
    """Refuse, before anything is lit, a camera whose capture holds its light lit longer than
    the light may stay lit (a dome's ``max_on_s``), once the camera is connected.

    Why: the config's check (``rti_rig.app.config.lit_per_shot``) counts settle + exposure +
    readout + transfer + the all-off; a UVC camera (a :class:`FramePacedCamera`) reads the
    frames it drains and the one it keeps with the LED lit, which only the connected camera
    can count (its frame rate and queue). A 5 fps camera whose driver refused the one-buffer
    request passed the check and stopped at the first image with the object lit ("LED 0 stayed
    on 1.555 s, beyond max_on_s = 1 s; raise max_on_s or shorten settle and exposure"). The
    step's lit time is the config's sum with the exposure replaced by the frames read.
    ``before`` says what was not done ("nothing was lit").
    """
    camera = rig.camera
    limit = lit_limit_s(rig)
    exposures = list(exposures_s)
    _check_capture_lit_time(rig, camera, limit, exposures, before)
    # a UVC camera exposes at most a frame period however long it is asked (its exposure
    # reads back as set), and only whole exposure units: refused here too, with no lit-time
    # limit, before anything lights (the longest first: the frame period is its to fail)
    if isinstance(camera, ExposureRefusingCamera):  # declared, where getattr had probed
        for exposure in sorted(set(exposures), reverse=True):
            camera.refuse_exposure(exposure, before)


def _check_capture_lit_time(
    rig: Rig, camera: object, limit: float | None, exposures: list[float], before: str
) -> None:
    """The lit-time half of :func:`check_capture_fits_lit`."""
    if limit is None or not exposures or not isinstance(camera, FramePacedCamera):
        return
    exposure = max(exposures)  # a frame period is at least the exposure: the longest is worst
    counted = camera.capture_time_s(exposure)
    if counted is None:
        return
    capture_s, said = counted
    t = rig.timing
    transfer, switch = float(t.transfer_s), float(t.light_switch_s)  # declared: TimingConfig
    total = t.settle_s + capture_s + t.readout_s + transfer + switch
    if total <= limit + 1e-9:
        return
    where = rig.loaded.path
    raise DeviceError(
        camera.name,
        f"a capture at {exposure:g} s reads {said} with its LED lit, so each step's LED stays "
        f"lit timing.settle_s {t.settle_s:g} + {capture_s:.3g} s + timing.readout_s "
        f"{t.readout_s:g} + timing.transfer_s {transfer:g} + timing.light_switch_s {switch:g} "
        f"= {total:.3g} s, beyond {lit_limit_said(rig)}"
        f"{f' ({shown_path(where)})' if where else ''}: every capture would stop at the thermal "
        f"limit with the object lit; {before}. Give the camera a higher frame rate, let its driver "
        "queue fewer buffers (buffer_size in [camera.device]; drain_frames if the sensor latches a "
        "new exposure at once), or raise max_on_s if the LEDs allow it",
        "check lit time",
    )


def fire_lit(
    rig: Rig,
    step: LightStep,
    exposure_s: float,
    lit_at: float,
    on_dark: Callable[[dict[str, Any]], None] | None = None,
    cancelled: Callable[[], bool] | None = None,
) -> tuple[float | None, list[dict[str, Any]]]:
    """Fire a :class:`BusyAwareCamera` under ``step``'s light, lit at ``lit_at`` and settled,
    by :func:`shoot_step`'s rules; the light is left lit. Returns when the exposure ended (as
    ``expose`` does) and the relights; raises :class:`StepAbandoned`, the light off, when
    ``cancelled`` says so during a wait in the dark."""
    camera = rig.camera
    assert isinstance(camera, BusyAwareCamera)
    limit = lit_limit_s(rig)
    clock = rig.clock
    relit: list[dict[str, Any]] = []
    while True:
        fire_by = None if limit is None else lit_at + limit - exposure_s - rig.timing.readout_s
        try:
            return camera.expose_within(exposure_s, fire_by), relit
        except CameraBusyError as busy:
            off_at = clock.now()
            rig.lighting.off()  # raises, stopping the session, if the dome did not take it
            off_said = rig.lighting.off_said()
            if on_dark is not None:
                after = clock.now() + busy.retry_in_s
                cool_s = rig.lighting.cool_down_s(step, after)
                on_dark(
                    {
                        "lit_s": off_at - lit_at,
                        "off": off_said,
                        "wait_s": busy.retry_in_s,
                        "cool_s": cool_s,
                        "max_on_s": limit,
                        "limit": lit_limit_said(rig),
                    }
                )
            _wait_dark(rig, clock.now() + busy.retry_in_s, cancelled)
            # the cool-down the thermal guard would wait in ``set``, waited here where a
            # cancel is seen (it may be a minute)
            _wait_dark(rig, clock.now() + rig.lighting.cool_down_s(step, clock.now()), cancelled)
            rig.lighting.set(step)  # the thermal guard may let the LED cool first
            relit.append(
                {
                    # how long the light had been lit, and how long it was dark
                    "lit_s": off_at - lit_at,
                    "off": off_said,
                    "dark_s": clock.now() - off_at,
                    "camera_busy_tries": busy.tries,
                    "camera_wait_s": busy.retry_in_s,
                }
            )
            lit_at = clock.now()
            clock.sleep(rig.timing.settle_s)


def _wait_dark(rig: Rig, until: float, cancelled: Callable[[], bool] | None) -> None:
    """Wait on the rig's clock until ``until``, the light off; raise :class:`StepAbandoned` as
    soon as ``cancelled`` says so (looked at every :data:`DARK_POLL_S`)."""
    clock = rig.clock
    while True:
        if cancelled is not None and cancelled():
            raise StepAbandoned("cancelled while the camera was awaited with the light off")
        left = until - clock.now()
        if left <= 0:
            return
        clock.sleep(left if cancelled is None else min(left, DARK_POLL_S))


def validate_schedule(
    rig: Rig, schedule: LightSchedule, shot: frozenset[int] = frozenset()
) -> None:
    """Raise :class:`ScheduleError` listing every step the rig cannot run, before anything moves.

    ``shot``: the steps (0-based) a resumed session has already taken, not checked. Why: they
    are history, shot on the rig as it was; a rig change accepted on resume (an arm's reach
    narrowed, an LED taken out) that left only those out of reach had refused the resume of
    steps it could all run."""
    if len(schedule) == 0:
        raise ScheduleError("the schedule has no steps")
    if len(schedule) > MAX_LIGHTS:
        raise ScheduleError(
            f"{len(schedule)} steps: `.lp` readers accept at most {MAX_LIGHTS} images per session"
        )
    problems = schedule_problems(rig, schedule, [i for i in range(len(schedule)) if i not in shot])
    if problems:
        shown = "\n  ".join(problems[:10])
        more = f"\n  ... and {len(problems) - 10} more" if len(problems) > 10 else ""
        raise ScheduleError(
            f"the schedule cannot run on rig '{rig.name}' "
            f"({len(problems)} problem(s)); nothing has moved:\n  {shown}{more}"
        )


def schedule_problems(rig: Rig, schedule: LightSchedule, steps: Iterable[int]) -> list[str]:
    """What stops each of ``steps`` (0-based) of ``schedule`` running on ``rig``, one line a
    step ("step 4 (LED 7 …): …"); empty if all can run."""
    cam = rig.camera_config
    problems = []
    for i in steps:
        step = schedule.steps[i]
        reason = rig.lighting.problem(step)
        exp = step_exposure(rig, step)
        if reason is None and not cam.min_exposure_s <= exp <= cam.max_exposure_s:
            reason = f"exposure {exp} s outside [{cam.min_exposure_s}, {cam.max_exposure_s}] s"
        if reason:
            problems.append(f"step {i + 1}{_step_named(step)}: {reason}")
    return problems


def _step_named(step: LightStep) -> str:
    """How a refused step is named to the user: a dome's LED by its number and where it lights
    from, as the preview's note and ``check`` name it. The step's ``label`` is the dome's
    machine-readable name for the LED (``led_036``, kept in the manifest), and the refusal had
    read "step 1 (led_036): ..." beside a note that said "LED 36 (az 112.5°, el 55.0°)"; a
    name the user gave (a dome ``.lp``'s image name) is still said beside the number."""
    if step.led is None:
        return f" ({step.label})" if step.label else ""
    return f" ({led_fields(step.led, step.direction, step.label)})"


def frame_layout(frame: Frame) -> tuple[int, int, bool]:
    """(height, width, colour) of a frame, as :func:`rti_rig.core.image_files.header_layout`
    reads them from a session's linear TIFF."""
    px = frame.pixels
    return int(px.shape[0]), int(px.shape[1]), px.ndim == 3 and px.shape[2] >= 3


def _refuse_other_layout(
    rig: Rig,
    folder: SessionFolder,
    index: int,
    frame: Frame,
    got: tuple[int, int, bool],
    layout: tuple[int, int, bool],
) -> None:
    """Stop on a frame whose size or colour differs from the session's images, keeping it.

    A session's images are one set for every fit, relight and RTIBuilder (a resume with another
    camera size is refused for that reason); such a frame had been written into the session as
    if nothing were wrong, the run said complete, and only the QA verdict ("images differ in
    shape") then told of a session that no tool could use."""

    def said(lay: tuple[int, int, bool], by: str = "×") -> str:
        return f"{lay[1]}{by}{lay[0]} {'colour' if lay[2] else 'grey'}"

    # a TIFF's description is ASCII
    why = (
        f"not image {index + 1} of the session: {said(got, 'x')}, the session's are "
        f"{said(layout, 'x')}"
    )
    # as paths that paste from anywhere: relative to the session they had named no file from
    # the folder the user ran rti-rig in
    tiff, *originals = (shown_path(folder.root / p) for p in folder.set_aside(index, frame, why))
    camera_files = f", the camera's own file(s) as {', '.join(originals)}" if originals else ""
    raise CaptureError(
        rig.camera.name,
        f"image {index + 1} came back {said(got)}, but this session's images are "
        f"{said(layout)}: the camera's image size or format changed during the session (a "
        "setting changed on the camera, another camera's file in a watched folder). It is not "
        f"part of the session (kept as {tiff}{camera_files}); set the camera back, then "
        "continue the session",
        "capture",
    )


#: How far (a fraction of the pixels) the camera's real frames may differ from ``[camera]``'s
#: width x height before the config's size is said to be wrong and the disk checked again.
SIZE_TOLERANCE = 0.05


def _checked_real_size(
    rig: Rig,
    folder: SessionFolder,
    got: tuple[int, int, bool],
    per_image: int,
    left: int,
    emit: Callable[[Event], None],
) -> int:
    """The bound on one image's files for the rest of the run, from the first real frame
    (``got``: height, width, colour): where it is not the ``[camera]`` width x height (beyond
    :data:`SIZE_TOLERANCE`), says once a session that the config's size is wrong, naming the
    keys, records the real size in the manifest (``rig.frame_size``), and checks the disk
    again for the ``left`` images still to take at the real size (raising
    :class:`~rti_rig.runtime.session.NoSpaceError`, with the images kept, if it cannot hold
    them).

    Why: ``[camera] width``/``height`` default to 512 x 512 and nothing compared them with a
    real camera's frames, so the start-up check counted a 24 MP camera's images as 0.26 MP
    and let a session start that the disk could not hold. Said once a session: each resume
    had said it again, as if newly found; a resume counts the disk at the recorded real size
    from its start, and takes the config corrected to it (the recorded size is the session's
    own: :func:`rti_rig.app.usecases.session.check_resume_rig`)."""
    if rig.size_from_frame is None:
        return per_image
    cam = rig.camera_config
    width, height, real = rig.size_from_frame(got[1], got[0])
    said = cam.width * cam.height
    if abs(width * height - said) <= SIZE_TOLERANCE * said:
        return per_image
    if recorded_frame_size(folder.manifest, cam.width, cam.height) != (got[1], got[0]):
        emit(
            DeviceSays(
                rig.camera.name,
                f"The camera delivers {got[1]} x {got[0]} px images, but camera.width x "
                f"camera.height in {shown_path(rig.loaded.path)} say {cam.width} x "
                f"{cam.height} px: set camera.width = {width} and camera.height = {height} "
                "there (the real size is recorded in the session's manifest: a --resume "
                "takes either). The disk was checked for images of the config's size; the "
                f"{left} image(s) left are checked again at the real size",
            )
        )
        folder.manifest.setdefault("rig", {})[FRAME_SIZE_KEY] = {
            "frames": [got[1], got[0]],
            "config": [cam.width, cam.height],
        }
    if left:
        check_free_space(folder.root, left, real, holds_images=True)
    return real


def led_error_record(exc: BaseException) -> dict[str, Any] | None:
    """An error about one LED as data for the manifest's ``runner.led_error``: the LED, and the
    link's fault and firmware code beneath it (``None`` for any other error).

    Why: what a stopped session is told to do next depends on *why* the LED stopped it (a dead
    LED meets a resume again, a board reboot or a cooled LED does not), and a later command
    (``calibrate-lights`` on a card session) must decide it from the record, not by reading
    the error's words."""
    if not isinstance(exc, DomeLedError):
        return None
    cause = exc.__cause__
    link = cause if isinstance(cause, DomeLinkError) else None
    return {
        "led": exc.led,
        "fault": None if link is None else str(link.fault),
        "code": None if link is None else link.code,
    }


def _arm_end(lighting: object) -> dict[str, Any]:
    """The manifest's ``arm_end``: where an arm's teardown left it, as read back
    (:class:`rti_rig.runtime.arm_end.ArmEnd`); nothing for a dome, or an arm not gone safe.
    Asked of an :class:`ArmLighting` by name (it had been ``getattr(lighting, "end")``, which
    a renamed attribute would have silently answered "no record")."""
    end = lighting.end if isinstance(lighting, ArmLighting) else None
    return {} if end is None else {"arm_end": end.to_dict()}


def _dome_reconnections(lighting: Lighting) -> dict[str, Any]:
    """The manifest's ``dome_reconnections``: each reopening of a dome's lost port in this run
    (during which command, what was lost, the attempts, the outcome), the detail of what the
    user was told in a line as it happened; nothing when none was reopened."""
    found = lighting.reconnections()
    return {"dome_reconnections": found} if found else {}


def _resends(lighting: Lighting) -> tuple[dict[str, Any], str | None]:
    """The manifest's ``dome_resent`` / ``arm_resent`` (each command sent again after a fault
    and then answered) and the line that counts them for the user; nothing when none was."""
    return lighting.resends()


def _teardown_failure(label: str, exc: Exception, earlier: list[str]) -> str:
    """``label: what failed``, or a pointer to the earlier failure it repeats word for word.

    Why: a device's ``close`` retries its own safe state (an arm stops again), so one servo
    fault was printed in full for the stop and again for the close, a paragraph each."""
    text = str(exc)
    for failure in earlier:
        first, _, said = failure.partition(": ")
        if said == text:
            return failed_as_before(label, first)
    return f"{label}: {text}"


class _Entered:
    """A context manager already entered (its ``__enter__`` called): the ``with`` that takes
    it only exits it."""

    def __init__(self, entered: AbstractContextManager[Any]) -> None:
        self._entered = entered

    def __enter__(self) -> None:
        return None

    def __exit__(self, *exc_info: Any) -> bool | None:
        return self._entered.__exit__(*exc_info)


def _teardown_held(cancel: CancelToken) -> tuple[_Entered, BaseException | None]:
    """The teardown's hold on SIGINT/SIGTERM, entered, after ``cancel.capture_over()``; and
    the stop (an exception) a signal handler raised before the hold was set, or None.

    Why: the teardown is :func:`run_session`'s ``finally``, and Python runs a signal handler
    between any two bytecodes of the main thread. A stop whose handler raises (the CLI's
    SIGTERM, hang-up or second Ctrl-C: EmergencyStop; an unhandled Ctrl-C: KeyboardInterrupt)
    landing after the capture's last step or its break, before the hold was set, left the
    ``finally`` at once: no all-off sent, nothing closed, no end in the manifest (it read as
    a run still under way). Caught here, the hold set all the same, it is raised once the
    teardown is done, the manifest naming it, as a stop in the last step is. Once the hold's
    handlers are in place a signal is only held: nothing raises between here and the
    ``with`` that exits it.

    The tries are bounded (:data:`_HOLD_TRIES`): an exception that recurs on every try (not a
    stop but a fault in setting the hold) had spun here for ever, the devices never made safe;
    after the last the teardown runs unheld, the first exception raised at its end. A second
    stop caught here is added to the first's notes (it had been dropped without a trace)."""
    caught: list[BaseException] = []
    for _ in range(_HOLD_TRIES):
        try:
            cancel.capture_over()
            hold = signals_deferred()
            hold.__enter__()
            return _Entered(hold), _first_noted(caught)
        except BaseException as exc:  # a stop's handler, as the hold was being set: again
            caught.append(exc)
    # never held: the teardown runs all the same (a stop now leaves it, as before the hold)
    return _Entered(nullcontext()), _first_noted(caught)


#: How many times :func:`_teardown_held` tries to set the teardown's hold: each stop a user
#: can send (Ctrl-C, a second Ctrl-C, SIGTERM, a hang-up) may land in one try, with room over.
_HOLD_TRIES = 8


def _first_noted(caught: list[BaseException]) -> BaseException | None:
    """The first exception caught, each later one in its notes (as a hold's own delivery
    notes the stops it delivered after the first); None if none was. Only the first can be
    raised, and it names the run's end; the rest are kept for a traceback or a log."""
    if not caught:
        return None
    first = caught[0]
    for later in caught[1:]:
        if later is not first:
            first.add_note(
                f"also raised as the teardown's hold was being set: {type(later).__name__}: {later}"
            )
    return first


def _stop_recorded_as(exc: BaseException) -> tuple[FinishReason, str]:
    """The manifest's end and error for a stop that raised as the capture ended, before the
    teardown's hold (:func:`_teardown_held`), as the capture's own ``except`` clauses record
    one raised within it."""
    if isinstance(exc, KeyboardInterrupt):
        return FinishReason.INTERRUPTED, "interrupted by the user (Ctrl-C)"
    if isinstance(exc, EmergencyStop):
        return FinishReason.EMERGENCY_STOP, f"emergency stop: {exc}"
    return FinishReason.ERROR, f"{type(exc).__name__}: {exc}"


def run_session(
    rig: Rig,
    schedule: LightSchedule,
    folder: SessionFolder,
    *,
    cancel: CancelToken | None = None,
    on_event: Callable[[Event], None] | None = None,
    source: StepSource | None = None,
    list_card: bool = True,
) -> SessionResult:
    """Run ``schedule`` on ``rig`` into ``folder``; see the module docstring for the guarantees.

    ``list_card``: whether a card camera lists its card before the first shot (not for a
    preview's one image).

    With ``source`` the steps are the source's decisions, step by step (adaptive acquisition);
    ``schedule`` is then the starting layout recorded in the manifest, checked where the
    session is opened (each step the source decides is checked before it moves).
    """
    # a resume's steps already shot are not checked again (an accepted rig change may have
    # left them out of its reach). An adaptive run's steps are its source's decisions, each
    # checked before it moves, below; its starting layout is checked where the session is
    # opened (a resume's as placed again on the rig as it is, its lights shot left aside)
    skip = frozenset(folder.done) if source is None else frozenset(range(len(schedule)))
    validate_schedule(rig, schedule, skip)
    total = len(schedule) if source is None else source.total
    if folder.total_steps != total:
        raise ScheduleError("session folder was sized for another schedule")
    done = folder.done
    todo = [i for i in range(total) if i not in done]
    cam = rig.camera_config
    per_image = rig.bytes_per_image or estimated_bytes_per_image(cam.width, cam.height)
    seen = recorded_frame_size(folder.manifest, cam.width, cam.height)
    if seen is not None and rig.size_from_frame is not None:  # a resume: its camera's real size
        per_image = rig.size_from_frame(*seen)[2]
    sure = total if source is None else source.sure_total  # declared by StepSource
    check_free_space(
        folder.root, steps_to_hold(total, len(done), sure), per_image, holds_images=bool(done)
    )
    cancel = cancel or CancelToken()
    emit = on_event or (lambda _e: None)
    clock = rig.clock
    header = {
        "rig": {
            "name": rig.name,
            "kind": rig.loaded.config.kind,
            "backend": rig.loaded.config.backend,
            "config_path": rig.loaded.path,
            "config_sha256": rig.loaded.sha256,
            "config": rig.loaded.raw,
            # what a hint read from the manifest alone (a finished preview's plan command)
            # may ask for: the runtime cannot load the rig's geometry there, and plan's default
            # 12 was refused on a dome of 8 LEDs
            "plan_lights": hint_light_count(getattr(rig, "geometry", None)),
        },
        "schedule": schedule.to_dict(),
        **({"adaptive": source.header()} if source is not None else {}),
    }
    records: list[StepRecord] = []
    end_notes: list[str] = []
    layout = folder.image_layout()  # the session's image size, once it has an image
    size_checked = False  # the first frame of this run compared with [camera]'s size
    reason = FinishReason.ERROR
    error: str | None = None
    led_error: dict[str, Any] | None = None
    teardown: list[str] = []
    #: the source's conclusion (``StepSource.conclude``), once it has one
    concluded: dict[str, Any] | None = None
    rig_t0, wall_t0 = clock.now(), time.perf_counter()
    try:
        rig.bind_session(folder.root)
        # a lost port's reopening is said as the product speaks, between the bar's redraws
        rig.lighting.listen(lambda text: emit(DeviceSays(rig.lighting.name, text)))
        emit(Preparing("lights"))
        rig.lighting.connect()
        emit(Preparing("camera"))
        rig.camera.connect()
        rig.lighting.off()
        # a card camera lists its card, to tell a picture taken before the first shot (only
        # a capture session does: `check` and `preview` never wait for it)
        if list_card and isinstance(rig.camera, CardListingCamera):
            name = str(rig.camera.name)
            emit(Preparing("card"))
            rig.camera.list_card(lambda text: emit(DeviceSays(name, text)))
        emit(Preparing("ready"))
        planned = [
            *(step_exposure(rig, schedule.steps[i]) for i in todo if source is None),
            *((cam.exposure_s, *(s.exposure_s or 0.0 for s in schedule.steps)) if source else ()),
        ]
        check_capture_fits_lit(rig, planned, "nothing was lit or written")
        # only now, with the rig known to answer, is anything written to disk
        folder.begin(header)
        for i in todo:
            if cancel.paused:
                emit(Paused(i, total))
                cancel.wait_while_paused()
            if cancel.cancelled and source is None:
                reason = FinishReason.CANCELLED
                break
            decision: dict[str, Any] | None = None
            if source is None:
                step = schedule.steps[i]
            else:
                # asked even after a stop was asked for: a source whose session is done (an
                # --until-error target met by the image just taken) completes it. Whether a
                # Ctrl-C on that image ended it "cancelled" (exit 130, resume advised) or
                # complete (exit 0) had hung on whether it landed before or during this
                # decision; and one landing during it had let the next light fire
                decided = source.next_step(i)
                if decided is None:  # the source says the session is done
                    concluded = source.conclude()
                    reason = FinishReason.COMPLETED
                    break
                if cancel.cancelled:  # not a light more once a stop was asked for
                    reason = FinishReason.CANCELLED
                    break
                step, decision = decided
                validate_schedule(rig, LightSchedule((step,)))  # before this light moves
            check_free_space(folder.root, 1, per_image, holds_images=folder.images_kept > 0)
            emit(StepStarted(i, total, step))
            t_start = clock.now()
            actual = rig.lighting.set(step)
            t_lit = clock.now()
            clock.sleep(rig.timing.settle_s)
            t_settled = clock.now()
            try:
                frame, relit = shoot_step(
                    rig,
                    step,
                    step_exposure(rig, step),
                    t_lit,
                    lambda dark, i=i, led=step.led: emit(LightOffForCamera(i, total, led, **dark)),
                    lambda: cancel.cancelled,
                )
            except StepAbandoned:
                # the light is off and nothing of this step was recorded: the resume takes it
                end_notes.append(
                    f"image {i + 1} was not taken: the run was cancelled while its camera was "
                    "still busy and awaited with its light off, so its light was not lit again "
                    "for it; a resume takes it first"
                )
                reason = FinishReason.CANCELLED
                break
            t_captured = clock.now()
            # an arm whose servo faulted (or that moved) during the exposure: the image is not
            # kept under the direction read before it; the error stops the run, a resume
            # retakes this step
            rig.lighting.check_held()
            got = frame_layout(frame)
            if layout is not None and got != layout:
                _refuse_other_layout(rig, folder, i, frame, got, layout)
            if rig.capture_check is not None:  # may keep the image aside and stop the session
                rig.capture_check(i, frame, actual, folder.root)
            fields = {
                "planned_direction": step.direction,
                "actual_direction": actual.direction,
                "led": actual.led,
                "rig_start_s": t_start - rig_t0,
                "light_s": t_lit - t_start,
                "settle_s": t_settled - t_lit,
                "capture_s": t_captured - t_settled,
                **({"decision": decision} if decision is not None else {}),
                **({"relit": relit} if relit else {}),
            }
            # the lights are off; an emergency stop raised between the files' rename and the
            # journal line left an image on disk that lights.lp did not list: the commit of a
            # captured image is finished first (a fraction of a second), then the stop acts.
            # The record is counted inside the hold too: a stop that acted before the count
            # left the manifest's steps_done_this_run one short of the images this run wrote
            with signals_deferred():
                late: SessionWriteError | None = None
                try:
                    record = folder.write_step(i, frame, fields)
                except SessionWriteError as exc:
                    # its journal line or lights.lp failed after its record file, the commit:
                    # the step is kept, and had gone uncounted (progress 2/8, the manifest's
                    # steps_done_this_run 2, "3 image(s) kept")
                    if exc.committed is None:
                        raise
                    record, late = exc.committed, exc
                records.append(record)
                # said inside the hold too: a stop acting before it left the progress bar one
                # short of the images kept ("4/10", then "5 image(s) in the session")
                emit(StepCompleted(i, total, record))
                if late is not None:
                    raise late
            if source is not None:
                source.observe(i, frame, record)
            layout = layout or got
            if not size_checked:  # once a run: its first frame is the camera's real size
                size_checked = True
                left = steps_to_hold(total, len(done) + len(records), sure)
                per_image = _checked_real_size(rig, folder, got, per_image, left, emit)
        else:
            if source is not None:  # run to its maximum: never asked for the step past it
                concluded = source.conclude()
            if rig.end_check is not None:  # e.g. a camera-triggered dome's proof frame
                last = schedule.steps[-1] if source is None else None
                exposure = cam.exposure_s if last is None else step_exposure(rig, last)

                end_notes = list(rig.end_check(lambda e=exposure: shoot_lit(rig, e), folder.root))
            reason = FinishReason.COMPLETED
    except KeyboardInterrupt:
        reason, error = FinishReason.INTERRUPTED, "interrupted by the user (Ctrl-C)"
        raise
    except EmergencyStop as exc:
        reason, error = FinishReason.EMERGENCY_STOP, f"emergency stop: {exc}"
        raise
    except NoSpaceError as exc:
        reason, error = FinishReason.NO_SPACE, str(exc)
        raise
    except SourceReadError as exc:  # a camera file unreadable, not the session's write
        reason, error = FinishReason.ERROR, str(exc)
        raise
    except SessionWriteError as exc:
        reason, error = FinishReason.WRITE_FAILED, str(exc)
        raise
    except Exception as exc:
        reason, error = FinishReason.ERROR, f"{type(exc).__name__}: {exc}"
        led_error = led_error_record(exc)
        raise
    finally:
        hold, stopped = _teardown_held(cancel)
        if stopped is not None and reason in (FinishReason.COMPLETED, FinishReason.CANCELLED):
            reason, error = _stop_recorded_as(stopped)  # held now: nothing raises between
        with hold:
            # (a dome's safe() marks the teardown first: a reopening now is for its all-off)
            teardown += rig.lighting.safe(emergency=reason is FinishReason.EMERGENCY_STOP)
            for label, close in (
                ("camera close", rig.camera.close),
                ("light close", rig.lighting.close),
            ):
                try:
                    close()
                except Exception as exc:  # keep tearing down whatever fails
                    teardown.append(_teardown_failure(label, exc, teardown))
            # a port that did not close cleanly is said as it happens, never raised: recorded
            # here too (it had been in no record of the run)
            teardown += port_close_failures(rig.lighting)
            rig_time = clock.now() - rig_t0
            wall_time = time.perf_counter() - wall_t0
            resent, resends_said = _resends(rig.lighting)
            try:
                folder.finish(
                    records,
                    runner={
                        "state": run_state(reason),
                        "finish_reason": str(reason),
                        "error": error,
                        "teardown_failures": teardown,
                        "steps_planned": total,
                        "steps_done_this_run": len(records),
                        **({"end_check": end_notes} if rig.end_check is not None else {}),
                        **_arm_end(rig.lighting),
                        **_dome_reconnections(rig.lighting),
                        **resent,
                        **({"led_error": led_error} if led_error is not None else {}),
                    },
                    timing={"rig_time_s": rig_time, "wall_time_s": wall_time},
                    source_result=concluded if reason is FinishReason.COMPLETED else None,
                )
            except SessionWriteError as exc:
                if error is None:  # nothing else went wrong: this is the session's failure
                    raise
                teardown.append(f"session record: {exc}")  # the first failure is the story
            if resends_said is not None:
                emit(DeviceSays(rig.lighting.name, resends_said))
        if stopped is not None:
            raise stopped
    return SessionResult(
        reason, tuple(records), rig_time, wall_time, error, tuple(teardown), tuple(end_notes)
    )
