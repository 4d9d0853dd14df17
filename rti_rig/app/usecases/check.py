"""Use case: self-test a rig before a session (``rti-rig check``).

A dome lights each LED in turn and reports what answered; an arm visits poses spanning its band,
checking where it really got to, flashes its lamp at each and parks (if its config says so).
Then the camera is opened, takes one test shot if it is a tethered stills camera (its RAW
decoded), and is released. The rig is closed — lights off, arm stopped — whatever
happens.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from rti_rig.app.compose import build_rig
from rti_rig.app.config import load_rig_config
from rti_rig.app.usecases.safe_state import lights_state, software_lamp
from rti_rig.core.acquisition_images import AcquisitionImagesError
from rti_rig.core.devices import (
    ConnectNotingCamera,
    ExposureJudgingCamera,
    ShutterSpeedCamera,
    TrialShotCamera,
)
from rti_rig.core.errors import DeviceError, RtiRigError
from rti_rig.core.rig_geometry import ArmGeometry
from rti_rig.core.shell_words import shell_word, shown_path
from rti_rig.runtime.arm_check import ArmSelfTestReport, arm_self_test
from rti_rig.runtime.controller import EmergencyStop
from rti_rig.runtime.dome_policy import self_test
from rti_rig.runtime.lighting import ArmLighting, DomeLighting
from rti_rig.runtime.session import refuse_if_in_use


class CheckStopped(Exception):
    """The check was stopped (SIGTERM, Ctrl-C) part-way; the rig was torn down first."""

    def __init__(
        self,
        stop: EmergencyStop,
        lights: str,
        teardown_failures: tuple[str, ...] = (),
        walk: tuple[str, ...] = (),
        todo: str | None = None,
    ) -> None:
        super().__init__(f"check stopped ({stop}): {lights}")
        #: the words said of the stop, and the signal it came from (the exit code's)
        self.why, self.signum = str(stop), stop.signum
        #: what is known about the lights after the teardown (never "off" unless established)
        self.lights = lights
        #: what the teardown could not do (an arm's lamp off, stop), to be said first
        self.teardown_failures = teardown_failures
        #: what an arm's walk had verified before the stop (its poses, as the report's table)
        self.walk = walk
        #: the command that parks an arm the stop left unparked, as a sentence; None when
        #: there is none to give (parked, never connected, or park_after_session off)
        self.todo = todo


@dataclass(frozen=True)
class CheckRequest:
    rig_config: Path
    #: LED drive level for a dome's walk, in (0, 1]; None: not given (:data:`DEFAULT_INTENSITY`)
    intensity: float | None = None
    #: check the rig for ``run --auto-exposure``: ``[camera] exposure_s`` is then only the
    #: metering's start, judged as the metering takes it (see :func:`_exposure_problem`)
    auto_exposure: bool = False


#: what a check stopped while its arm rig was being built may say of the arm: no byte was sent
ARM_NOT_REACHED = "nothing was sent to the arm: the check stopped before connecting it"

#: the LED drive level of a dome's walk when ``--intensity`` is not given
DEFAULT_INTENSITY = 0.2


def check_rig(
    req: CheckRequest,
    on_start: Callable[[], None] | None = None,
    on_note: Callable[[str], None] | None = None,
) -> Any:
    """The self-test report (``.lines()``, ``.ok``) of the rig ``req.rig_config`` describes.

    ``on_note`` is told, as it happens, what the user should know while the walk goes on (a
    dome's lost port being reopened, and the outcome), which the report then sums up.

    ``on_start`` is called once the config and the options are known to be usable, before
    anything is opened. Why: the command said "Checking … (Ctrl-C stops the check at once)…"
    and then refused ``--intensity 0.5`` on an on/off firmware's dome: validate, then
    announce."""
    intensity = DEFAULT_INTENSITY if req.intensity is None else req.intensity
    if not 0.0 < intensity <= 1.0:
        raise RtiRigError(
            f"--intensity {intensity:g}: give the LED drive level as a fraction in (0, 1]"
        )
    if req.rig_config.suffix.lower() == ".lp":
        # a session's lights.lp as a replay: refused while a run still captures into it, as
        # export-lp, fit and plan refuse it (its images and lights.lp change as it goes, and
        # the check had passed the images present so far)
        refuse_if_in_use(req.rig_config.parent, "check its images")
    try:
        # an RTIBuilder project's .lp is checked, not replayed: its note says so
        loaded = load_rig_config(req.rig_config, project_doing="checking")
    except AcquisitionImagesError as exc:
        if req.auto_exposure:  # refused on any replay: a usage error, said as before
            raise
        # what this check is for: the images of a recorded acquisition, each problem said
        if on_start is not None:
            on_start()
        return FailedReplayCheck(Path(exc.path).name, exc.problems, exc.reader_notes)
    if req.intensity is not None:
        _refuse_undimmable(loaded, req.intensity)
    if req.auto_exposure:
        # what run --auto-exposure refuses before the rig opens, refused here as there
        from rti_rig.app.flash_sync import refuse_options
        from rti_rig.app.usecases.session import refuse_unmeterable_rig

        refuse_unmeterable_rig(loaded)
        refuse_options(loaded, Path("session"), **{"--auto-exposure": True})
    if on_start is not None:
        on_start()
    if loaded.config.backend == "replay":
        repeated = repeated_files(Path(loaded.path))
        if repeated:
            return FailedReplayCheck(Path(loaded.path).name, repeated, tuple(loaded.notes))
        return ReplayCheck.of(loaded)
    if loaded.config.dome is not None and loaded.config.dome.flash_sync is not None:
        from rti_rig.app.flash_sync import flash_sync_check

        return flash_sync_check(loaded)
    try:
        built = build_rig(loaded)
    except EmergencyStop as exc:
        if loaded.config.arm is None:
            raise  # a dome's port may have been opened (a board that boots lit): said as before
        # the stop came while the rig was being built, before the arm's connect sent its
        # first byte: "check the rig's lights" had been said of an arm, nothing of the arm
        raise CheckStopped(exc, ARM_NOT_REACHED) from None
    with built as rig:
        try:
            if isinstance(rig.lighting, DomeLighting):
                rig.lighting.listen(on_note)
                lights = self_test(rig.lighting.source, rig.clock, intensity=intensity)
                lights.rig_config = shell_word(str(req.rig_config))  # for its advice's commands
                camera = camera_line(rig, auto_exposure=req.auto_exposure, test_shot=True)
                return WithCamera(lights, camera, config_note_lines(loaded))
            if isinstance(rig.lighting, ArmLighting) and isinstance(rig.geometry, ArmGeometry):
                rig.lighting.listen(on_note)
                lights = arm_self_test(
                    rig.lighting.carrier,
                    rig.geometry,
                    rig.clock,
                    park=rig.lighting.park_after_session,
                )
                # the status packets lost and asked again, counted once (each had been a raw
                # log record on stderr)
                resent = rig.lighting.resends()[1]
                notes = (*config_note_lines(loaded), *_lamp_notes(rig), *filter(None, [resent]))
                camera = camera_line(rig, auto_exposure=req.auto_exposure, test_shot=True)
                return WithCamera(lights, camera, notes)
        except EmergencyStop as exc:
            # the self-test's own teardown (all-off; lamp off, stop) has run on the way out
            report = exc.self_test_report  # declared on the stop (it had been a getattr)
            failures = tuple(str(f) for f in report.teardown_failures) if report else ()
            # where the self-test's teardown left the arm, as read back (a stopped check
            # had said "lamp off and stop were requested" and nothing of the arm)
            # and which of its lamp-off and stop failed: a failed lamp-off had been said
            # "lamp off and stop were requested", the lamp perhaps still lit
            lights = lights_state(
                rig,
                bool(failures),
                end=report.end if report else None,
                not_sent=report.not_sent if report else None,
                unheld=report.unheld if report else None,
            )
            walk = tuple(report.stopped_lines()) if report else ()
            raise CheckStopped(
                exc, lights, failures, walk, _park_todo(report, req.rig_config)
            ) from None
        raise RtiRigError(f"{shown_path(req.rig_config)}: no self-test for this kind of lighting")


def _park_todo(report: ArmSelfTestReport | None, rig_config: Path) -> str | None:
    """How to park an arm a stopped check left unparked: ``rti-rig check CONFIG --park-only``,
    its config as shell words (a pasteable command, as ``run``'s end gives), which parks and
    moves nothing else; after a stop that did not hold every joint, once the arm is made safe.

    Why: a check stopped by Ctrl-C said where the arm was left and no way to park it; then it
    advised the check again, which walks every pose before it parks. None where there is
    nothing to give: the arm parked, never connected (nothing moved), or
    ``park_after_session`` is off (the check would not park it either)."""
    from rti_rig.runtime.lighting import park_check

    if report is None or report.end is None or not report.park_wanted:
        return None
    if report.end.outcome == "parked":
        return None
    check = park_check(str(rig_config))
    if not report.stopped:
        return (
            "Once the arm is safe (the lines above say how), park it with "
            f"{check} (it moves to the park pose, nothing else)"
        )
    return f"To park it: {check} (it moves to the park pose, nothing else)"


def _refuse_undimmable(loaded: Any, intensity: float) -> None:
    """``--intensity`` given for a rig whose check cannot light anything at that level is
    refused, as ``--auto-exposure`` is
    (:func:`~rti_rig.app.usecases.session.refuse_unmeterable_rig`): a usage error that names
    the option, says why, and says to drop it.

    Why: ``check ACQ/dirs.lp --intensity 0.5`` passed without a word, as if the level had been
    used; so did an arm (its lamp is switched on or off, never dimmed), a camera-triggered
    dome (rti-rig lights none of its LEDs) and an on/off serial firmware (its LEDs were lit
    fully on): a PASS that implied a walk at the level asked for. An on/off firmware's
    ``--intensity 1`` is the full drive it lights each LED at, so it is used, not refused (it
    had been refused as "not at the level asked for", which it is)."""
    from rti_rig.core.errors import ConfigError

    why = _undimmable_reason(loaded, intensity)
    if why is None:
        return
    raise ConfigError(
        loaded.path,
        None,
        f"--intensity {intensity:g} cannot be used on {why}; drop --intensity",
    )


def _undimmable_reason(loaded: Any, intensity: float) -> str | None:
    """What about this rig leaves the check no LED to light at level ``intensity``, or None."""
    config = loaded.config
    if config.backend == "replay":
        return (
            "a replayed acquisition: it has no LEDs to dim (its images were recorded at the "
            "light they had)"
        )
    if config.arm is not None:
        return (
            "an arm: its lamp is only switched on and off (its brightness is the lamp's own), "
            "so the check's lamp flashes cannot be dimmed"
        )
    dome = config.dome
    if dome is None:
        return None
    if dome.flash_sync is not None:
        return (
            f"a camera-triggered dome ({dome.flash_sync.firmware}): its firmware lights its "
            "LEDs with the camera's flash pulse, and rti-rig lights none of them, so no LED "
            "can be checked at any level"
        )
    serial = dome.serial
    refusal = None if serial is None else serial.dimming_refusal()
    if refusal is not None and intensity < 1.0:  # fully on is the level 1 asks for
        return (
            f"this dome: {refusal}, so the check would light each LED fully on, not at the "
            "level asked for (--intensity 1 is that full drive)"
        )
    return None


@dataclass(frozen=True)
class RebootReport:
    """What ``check --reboot-faulted`` established, servo by servo (``.lines()``, ``.ok``)."""

    outcomes: tuple[Any, ...]
    rig_config: Path

    @property
    def ok(self) -> bool:
        return all(o.cleared for o in self.outcomes)

    def lines(self) -> list[str]:
        out = [o.sentence() for o in self.outcomes]
        if not any(o.rebooted for o in self.outcomes):
            out.append("nothing rebooted; no torque was switched on or off")
        else:
            out.append(
                "no torque was switched on: the rebooted joints are limp until a check or run "
                f"connects the arm (rti-rig check {self.rig_config} next, with the arm clear)"
            )
        out.append("RESULT: " + ("PASS" if self.ok else "FAIL"))
        return out


def reboot_faulted(rig_config: Path, on_start: Callable[[], None] | None = None) -> RebootReport:
    """Reboot the arm's servos whose Hardware Error Status is set (torque off), and read their
    status back: nothing moves, and no torque is switched on (see
    ``DynamixelArm.reboot_faulted``). Refused on a rig that has no Dynamixel arm.

    ``on_start`` is called once the config is known to have one, before its port is opened.
    Why: the command said "Looking for faulted servos on ACQ/dirs.lp's arm" of a dome or a
    replay rig before refusing it as having no arm."""
    loaded = load_rig_config(rig_config)
    if loaded.config.arm is None or loaded.config.backend not in ("emulated", "hardware"):
        raise RtiRigError(
            f"{shown_path(rig_config)}: --reboot-faulted reboots a Dynamixel arm's faulted servos; "
            "this rig config has none (a dome, a simulated or a replay rig)"
        )
    if on_start is not None:
        on_start()
    from rti_rig.drivers.dynamixel.arm import DynamixelArm

    with build_rig(loaded) as rig:
        # asked of the type: a getattr had answered "none" for a misspelt name as for an arm
        # that has no Dynamixel servos
        carrier = rig.lighting.carrier if isinstance(rig.lighting, ArmLighting) else None
        if not isinstance(carrier, DynamixelArm):
            raise RtiRigError(
                f"{shown_path(rig_config)}: --reboot-faulted needs an arm on Dynamixel servos; "
                "this rig's arm has none"
            )
        return RebootReport(tuple(carrier.reboot_faulted()), rig_config)


def config_note_lines(loaded: Any) -> tuple[str, ...]:
    """What loading the rig config tolerated or warns of (a calibration `.lp` light clamped to
    the horizon, a count line that disagrees, a watched folder's wait longer than an LED may
    stay lit), as the check's ``note:`` lines.

    Why: ``run`` and ``plan`` print these notes, and ``check`` — the step before a dome's first
    session — had dropped them, passing a config whose calibration file it had had to mend."""
    return tuple(f"note: {n}" for n in loaded.notes)


def _lamp_notes(rig) -> tuple[str, ...]:  # type: ignore[no-untyped-def]
    """What the arm check says of a lamp it cannot switch: a real arm's lamp whose switch is
    outside the servo bus (``lamp = "software"``, the default). The check is said to flash the
    lamp at each pose, and a user watching a lamp that never lit was told nothing of why."""
    if not software_lamp(rig.lighting) or rig.loaded.config.backend != "hardware":
        return ()
    return (
        'lamp: not switched by rti-rig (lamp = "software" in [arm.dynamixel]: its switch is '
        "outside the servo bus), so no flash reached it at any pose; set lamp = "
        '"servo_led" and lamp_servo_id if it hangs on a servo\'s LED output',
    )


def camera_line(  # type: ignore[no-untyped-def]
    rig, why_no_image: str = "", *, auto_exposure: bool = False, test_shot: bool = False
) -> tuple[str, bool]:
    """Open and release the rig's camera, taking no image (after a lights' walk the lights are
    off; on a camera-triggered dome a shot would step it: ``why_no_image``): the line to print
    and whether it connected. A check had passed a rig whose camera then failed the session's
    first capture (gphoto2 not installed, no camera found). ``auto_exposure``: the exposure is
    judged as ``run --auto-exposure`` takes it (:func:`_exposure_problem`).

    What the camera could not establish at connect (``connect_notes``: a gphoto2 image format
    whose name does not tell whether it gives a RAW) is said after the line: left unsaid, a
    check passed what the first shot might refuse.

    ``test_shot`` (the walk is over, nothing is stepped by a shot): a camera that can take a
    test shot (``test_shot``, a tethered DSLR) takes one and decodes its RAW, once its
    exposure is known to be one it takes. Why: a body whose RAW the installed LibRaw cannot
    read passed the check and was refused at the session's first shot, its LED lit."""
    shot: str | None = None
    failed: RtiRigError | None = None
    try:
        rig.camera.connect()
        problem = _exposure_problem(rig, auto_exposure)
        # declared capabilities (core.devices), where getattr had probed by name
        if test_shot and problem is None and isinstance(rig.camera, TrialShotCamera):
            try:
                shot = str(rig.camera.test_shot())
            except RtiRigError as exc:
                failed = exc
        # read once, after the shot: what it established (a RAW given) is no longer said to be
        # unknown; what a failed shot left unknown or undone (a format it never reached, a
        # shutter speed it could not put back) is said beside its error (it had been left out,
        # the body left at the shot's speed without a word)
        camera = rig.camera
        said = tuple(camera.connect_notes()) if isinstance(camera, ConnectNotingCamera) else ()
        if failed is not None:
            left = "".join(f"; note: {n}" for n in said)
            return (
                f"camera: {rig.camera.name} connected, but FAILED its test shot: {failed}{left}",
                False,
            )
    except RtiRigError as exc:
        return f"camera: FAILED to connect: {exc}", False
    finally:
        rig.camera.close()
    why = f": {why_no_image}" if why_no_image else ""
    unsure = "".join(f"; note: {n}" for n in said)
    if shot is not None:
        return f"camera: {rig.camera.name} connected ({shot}){unsure}", True
    if problem is not None:
        return (
            f"camera: {rig.camera.name} connected (no image taken{why}), but FAILED: "
            f"{problem}{unsure}",
            False,
        )
    return f"camera: {rig.camera.name} connected (no image taken{why}){unsure}", True


def _exposure_problem(rig, auto_exposure: bool = False) -> str | None:  # type: ignore[no-untyped-def]
    """Why the config's ``[camera] exposure_s`` cannot be shot on the connected camera, if its
    driver can tell (a DSLR offers a fixed list of shutter speeds): such a session failed at
    its first capture, its light already on, after a check that had passed.

    With ``auto_exposure`` it is judged as ``run --auto-exposure`` takes it, only as the
    metering's start (:func:`_metering_start_s`). Without, a refusal that run --auto-exposure
    would not make says so: the check had refused an exposure_s (off a UVC camera's units)
    that the run the user meant to start took, naming neither the flag nor why."""
    if not isinstance(rig.camera, ExposureJudgingCamera):
        return None
    judge = rig.camera.exposure_problem
    exposure = float(rig.camera_config.exposure_s)
    try:
        start = _metering_start_s(rig, exposure)
    except DeviceError as exc:
        # no start inside both ranges: run --auto-exposure refuses it before anything lights
        if auto_exposure:
            return str(exc)
        start = None
    if auto_exposure:
        said = judge(start) if start is not None else None
        return None if said is None else str(said)
    said = judge(exposure)
    if said is None:
        return None
    if start is None or judge(start) is None:
        begins = (
            "at the shutter speed the camera offers nearest it"
            if start is None
            else f"at {start:g} s, which the camera takes"
        )
        said = (
            f"{said}. run --auto-exposure would take exposure_s only as its metering's start "
            f"({begins}): rti-rig check --auto-exposure checks the rig for that"
        )
    return str(said)


def _metering_start_s(rig, exposure_s: float) -> float | None:  # type: ignore[no-untyped-def]
    """Where ``run --auto-exposure`` starts metering from ``[camera] exposure_s``
    (:func:`~rti_rig.runtime.exposure_policy.metering_start_s`, within the run's own
    :func:`~rti_rig.app.usecases.session.metering_range`, so the check judges the start the
    run takes); None on a camera offering its own list of speeds (a DSLR), whose metering
    starts at the one nearest it. Raises DeviceError when no start fits both ranges."""
    from rti_rig.app.usecases.session import metering_range
    from rti_rig.runtime.exposure_policy import metering_start_s

    if isinstance(rig.camera, ShutterSpeedCamera):
        return None
    return metering_start_s(rig.camera, exposure_s, metering_range(rig))


@dataclass(frozen=True)
class WithCamera:
    """A lights self-test report with the camera's line before its result: a camera that does
    not connect fails the check."""

    lights: Any
    camera: tuple[str, bool]
    #: lines said after the lights' own (what the check could not do with them)
    notes: tuple[str, ...] = ()

    @property
    def ok(self) -> bool:
        return bool(self.lights.ok) and self.camera[1]

    def lines(self) -> list[str]:
        *body, result = self.lights.lines()
        return [
            *body,
            *self.notes,
            self.camera[0],
            result if self.camera[1] else "RESULT: FAIL",
        ]


@dataclass(frozen=True)
class ReplayCheck:
    """``check`` of a recorded acquisition (``rti-rig check ACQ/dirs.lp``): what loading it as a
    rig verified, its images, and nothing more.

    Why: the replay rig's "LEDs" are images, so the dome walk had reported "unknown firmware,
    18 LEDs … passed: 18 … round trip median 0.00 ms … PASS" — a light test of lights that do
    not exist. What can be checked of an acquisition is checked when it loads (every image
    listed present beside the .lp, no damaged JPEG, every image readable, one size and one
    kind), so a load that succeeds is the pass, said as such."""

    count: int
    width: int
    height: int
    lp_name: str
    notes: tuple[str, ...]
    #: where the images were found: "beside it", or the folders, relative to the .lp's
    where: str = "beside it"

    @classmethod
    def of(cls, loaded: Any) -> ReplayCheck:
        from rti_rig.app.config import dome_led_directions
        from rti_rig.core.lp_format import image_paths, read_lp

        cam = loaded.config.camera
        lp = Path(loaded.path)
        # said as found: an RTIBuilder project's images are in ../jpeg-exports, a name may
        # hold a folder; "each present beside it" had been said of those too
        folders = sorted({p.parent for p in image_paths(lp, read_lp(lp, upper_hemisphere=True))})
        where = "beside it"
        if folders != [lp.parent]:
            shown = [os.path.relpath(f, lp.parent) for f in folders[:3]]
            more = " ..." if len(folders) > 3 else ""
            where = f"in {', '.join(shown)}{more} (from the .lp's folder)"
        return cls(
            count=len(dome_led_directions(loaded)[0]),
            width=int(cam.width),
            height=int(cam.height),
            lp_name=lp.name,
            notes=tuple(loaded.notes),
            where=where,
        )

    @property
    def ok(self) -> bool:
        return True

    def lines(self) -> list[str]:
        return [
            "replay rig: a recorded acquisition, no device to light, move or open",
            f"images: {self.count} listed in {self.lp_name}, each present {self.where}, "
            # "of one kind" had been read as one bit depth, a line before a note that the
            # images mix 8-bit and 16-bit ones: it meant colour against grey, said so
            f"undamaged and readable, all {self.width}x{self.height}, all colour or all grey",
            *config_note_lines(self),
            "RESULT: PASS",
        ]


def repeated_files(lp: Path) -> tuple[str, ...]:
    """Each image of the acquisition ``lp`` that is, byte for byte, the file of an earlier
    line: what to do about it.

    Why: a frame delivered twice (a camera that missed its trigger) or a file copied over
    another passed the check ("RESULT: PASS"): two photographs are never equal to the last
    bit, so such a file is the picture of another light."""
    from rti_rig.core.lp_format import image_paths, read_lp
    from rti_rig.runtime.session import file_sha256

    first: dict[str, Path] = {}
    said = []
    for path in image_paths(lp, read_lp(lp, upper_hemisphere=True)):
        digest = file_sha256(path)
        if digest is None:
            continue
        if digest in first:
            said.append(
                f"{path.name} is the same file as {first[digest].name}, byte for byte, though "
                "another light is listed for it (a frame delivered twice, or a file copied "
                f"over): put its own light's picture in its place, or remove its line from "
                f"{lp.name}"
            )
        else:
            first[digest] = path
    return tuple(said)


@dataclass(frozen=True)
class FailedReplayCheck:
    """``check`` of a recorded acquisition whose images fail what :class:`ReplayCheck` checks
    (missing, damaged, unreadable, of another size or kind): each problem, then RESULT: FAIL.

    Why: ``check --help`` names these as what it checks of an `.lp`, and a failed check ends
    "RESULT: FAIL" with exit 1; an image deleted or resized had been said as a usage error
    ("error: …", exit 2), as if the command had been mistyped."""

    lp_name: str
    problems: tuple[str, ...]
    #: what the tolerant reader noted of the `.lp` (a passing check says them too): the user
    #: mending the images had learnt of a count line that disagrees only on the next check
    notes: tuple[str, ...] = ()

    @property
    def ok(self) -> bool:
        return False

    def lines(self) -> list[str]:
        return [
            "replay rig: a recorded acquisition, no device to light, move or open",
            *(f"images of {self.lp_name}: FAILED: {p}" for p in self.problems),
            *config_note_lines(self),
            "RESULT: FAIL",
        ]
