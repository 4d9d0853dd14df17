"""Rig configuration: one TOML file per rig, validated before anything is built.

A bad config is reported with the file, the dotted key and what is wrong, e.g.
``rig.toml: key 'dome.rings[2].count': Input should be greater than 0 (got -4)``.
The config describes *what* the rig is (light layout, camera, timing, limits) and which backend
drives it; building devices from it happens in :mod:`rti_rig.app.compose` (the composition root).
"""

from __future__ import annotations

import contextlib
import hashlib
import math
import os
import tomllib
from importlib import resources
from pathlib import Path
from typing import Any, Literal, NamedTuple

import numpy as np
from numpy.typing import NDArray
from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    ValidationError,
    ValidationInfo,
    field_validator,
    model_validator,
)

from rti_rig.app.flash_sync import FlashSyncSettings, SyncFaultConfig
from rti_rig.core.errors import ConfigError, LpFormatError
from rti_rig.core.exposure_range import Bound, shared_range
from rti_rig.core.geometry import az_el_from_direction, direction_from_az_el, fibonacci_cap
from rti_rig.core.image_files import looks_like_image
from rti_rig.core.lp_format import (
    acquisition_lp_files,
    directions_of,
    lights_said,
    lp_files_in,
    lp_name_from,
    read_lp,
)
from rti_rig.core.rig_geometry import (
    COINCIDENT_LED_DEG,
    ArmGeometry,
    DomeGeometry,
    coincident_leds,
    default_led_name,
)
from rti_rig.core.shell_words import shell_word, shown_path
from rti_rig.core.validation_text import error_text as _error_text
from rti_rig.core.validation_text import key_of as _key_of
from rti_rig.core.validation_text import table_keys
from rti_rig.drivers.dynamixel.settings import ArmSettings
from rti_rig.drivers.led_dome.settings import (
    DIMMING_LINK,
    IMAGE_GAINS_REMEDY,
    DomeSerialSettings,
    ProtocolKeyError,
)


class KeyValueError(ValueError):
    """A value refused by a table's own check that compares keys (``exposure_s`` against
    ``max_exposure_s``): ``key``, the table's key to blame, and ``text``, what is wrong.

    Why: such a check runs on the whole table, so pydantic placed its error at the table, and
    ``exposure_s = 1e9`` was said as "line 19: key 'camera'", the ``[camera]`` line, not the
    key's own (as :class:`ProtocolKeyError` does for ``[dome.serial.protocol]``)."""

    def __init__(self, key: str, text: str) -> None:
        self.key = key
        self.text = text
        super().__init__(f"{key}: {text}")


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class Ring(_Strict):
    """One ring of LEDs at a fixed elevation, evenly spaced in azimuth."""

    elevation_deg: float = Field(ge=0, le=90)
    count: int = Field(gt=0, le=1000)
    azimuth_offset_deg: float = 0.0


class DomeConfig(_Strict):
    """Where a dome's LEDs are: rings, an even (Fibonacci) spread, or a calibrated `.lp` file."""

    layout: Literal["rings", "fibonacci", "lp"] = "rings"
    rings: list[Ring] = Field(default_factory=list)
    count: int | None = Field(default=None, gt=0, le=1000)
    min_elevation_deg: float = Field(default=10.0, ge=0, lt=90)
    lp_file: str | None = None
    default_lights: int | None = Field(default=None, gt=0, le=1000)
    serial: DomeSerialSettings | None = None
    #: The camera's flash signal steps the dome (docs/domes.md); the host only shoots.
    flash_sync: FlashSyncSettings | None = None

    @field_validator("lp_file")
    @classmethod
    def _home_expanded(cls, lp_file: str | None) -> str | None:
        """``~/domes/dome.lp`` names the user's home, as the camera's ``folder`` does: it had
        been looked for as a folder named ``~`` beside the config."""
        return None if lp_file is None else os.path.expanduser(lp_file)

    @model_validator(mode="after")
    def _layout_has_its_keys(self) -> DomeConfig:
        if self.flash_sync is not None and self.serial is not None:
            raise ValueError(
                "a camera-triggered dome ([dome.flash_sync]) has no serial link: remove "
                "[dome.serial] (or [dome.flash_sync] if the host drives the dome)"
            )
        if self.layout == "rings" and not self.rings:
            raise ValueError("layout 'rings' needs at least one [[dome.rings]] table")
        if self.layout == "fibonacci" and self.count is None:
            raise ValueError("layout 'fibonacci' needs key 'count' (number of LEDs)")
        if self.layout == "lp" and not self.lp_file:
            raise ValueError("layout 'lp' needs key 'lp_file' (path relative to the config)")
        # a key another layout reads is refused, not ignored: an lp_file naming a file that
        # does not exist passed a check, and the dome ran rings the user did not describe
        unused = [
            f"{key} (read only with layout = {layout!r})"
            for key, layout, given in (
                ("rings", "rings", bool(self.rings)),
                ("count", "fibonacci", self.count is not None),
                ("lp_file", "lp", self.lp_file is not None),
            )
            if given and self.layout != layout
        ]
        if unused:
            raise ValueError(
                f"layout is {self.layout!r}, so {' and '.join(unused)} would be ignored: "
                "remove it, or change the layout"
            )
        return self


class ArmConfig(_Strict):
    """Reach, safety limits and motion of an arm that carries one lamp.

    A simulated arm uses the limits and motion below. An emulated or hardware arm is described
    by its servos under ``[arm.dynamixel]`` (docs/protocols/dynamixel-arm.md): its reach,
    keep-out cone and parking pose then come from there.
    """

    min_elevation_deg: float = Field(default=5.0, ge=0, lt=90)
    max_elevation_deg: float = Field(default=80.0, gt=0, le=90)
    keep_out_half_angle_deg: float = Field(default=8.0, ge=0, lt=90)
    speed_deg_s: float = Field(default=90.0, gt=0)
    acceleration_deg_s2: float = Field(default=180.0, gt=0)
    resolution_deg: float = Field(default=360.0 / 4096, gt=0)
    park_azimuth_deg: float = 0.0
    park_elevation_deg: float = 45.0
    default_lights: int = Field(default=24, gt=0, le=1000)
    park_after_session: bool = True
    park_on_emergency_stop: bool = False
    dynamixel: ArmSettings | None = None
    #: emulated backend: "pty" runs the real SDK and pyserial on a pseudo-terminal.
    transport: Literal["pty", "inprocess"] = "pty"

    @field_validator("park_elevation_deg")
    @classmethod
    def _park_clear_of_the_camera(cls, park: float, info: ValidationInfo) -> float:
        """A simulated arm parked at 89° (inside the keep-out cone around the camera) had
        passed check and parked there, where the Dynamixel arm's settings refuse such a pose.
        A park above the band's ceiling but clear of the cone is left alone: a ceiling
        lowered for one object (``max_elevation_deg = 30``) need not move the park. (A
        Dynamixel arm parks where ``[arm.dynamixel]`` says, checked there.)"""
        cone = info.data.get("keep_out_half_angle_deg")
        top = None if cone is None else 90.0 - cone
        if park < 0.0 or (top is not None and park > top + 1e-9):
            where = "below the object's plane" if park < 0.0 else "inside the keep-out cone"
            raise ValueError(
                f"{park:g} is {where}: the lamp would park "
                + ("under the object" if park < 0.0 else "in the camera's way")
                + f"; give a park pose from 0 to {top if top is not None else 90:g} degrees"
                + " (90 minus keep_out_half_angle_deg)"
            )
        return park

    @model_validator(mode="after")
    def _limits_consistent(self) -> ArmConfig:
        if self.max_elevation_deg <= self.min_elevation_deg:
            raise KeyValueError(
                "max_elevation_deg",
                f"{self.max_elevation_deg:g} must be above min_elevation_deg "
                f"{self.min_elevation_deg:g}",
            )
        if self.max_elevation_deg > 90.0 - self.keep_out_half_angle_deg + 1e-9:
            raise KeyValueError(
                "max_elevation_deg",
                f"{self.max_elevation_deg:g} reaches into the keep-out cone around the camera: "
                f"keep it at most {90.0 - self.keep_out_half_angle_deg:g}",
            )
        return self


class CameraConfig(_Strict):
    """The camera's fixed settings for a session.

    ``device`` is the real camera's driver table (``kind = "opencv" | "gphoto2" |
    "folder_watch"``, see docs/cameras.md); a simulated or emulated rig renders its images.
    ``signal_noise``: noise in this rig's images that grows in proportion to the signal, as a
    fraction, for the planner (``rti-rig plan`` uses it unless ``--signal-noise`` is given):
    0.05 for 8-bit JPEGs on a dome whose LED intensities are not calibrated
    (docs/research/planner.md),
    0 (the default) when the noise is additive and shot noise only, as on the simulated rigs.
    """

    width: int = Field(default=512, gt=0, le=20000)
    height: int = Field(default=512, gt=0, le=20000)
    exposure_s: float = Field(default=0.05, gt=0)
    gain: float = Field(default=1.0, gt=0)
    min_exposure_s: float = Field(default=1e-4, gt=0)
    max_exposure_s: float = Field(default=30.0, gt=0)
    device: dict[str, Any] | None = None
    signal_noise: float = Field(default=0.0, ge=0.0, lt=1.0)

    @model_validator(mode="after")
    def _exposure_in_range(self) -> CameraConfig:
        if self.min_exposure_s > self.max_exposure_s:
            raise KeyValueError(
                "min_exposure_s",
                f"{self.min_exposure_s:g} is above max_exposure_s "
                f"{self.max_exposure_s:g}: the limits are the wrong way round",
            )
        if not self.min_exposure_s <= self.exposure_s <= self.max_exposure_s:
            raise KeyValueError(
                "exposure_s",
                f"{self.exposure_s:g} s is outside min_exposure_s {self.min_exposure_s:g} to "
                f"max_exposure_s {self.max_exposure_s:g}: give an exposure within them (or "
                "widen them)",
            )
        return self


class TimingConfig(_Strict):
    """How long the real rig takes for each part of a step (seconds; at most
    ten minutes each: ``settle_s = 1e6`` had been accepted, a real session would
    have waited eleven days per image, and a dry run reported it without a word)."""

    light_switch_s: float = Field(default=0.02, ge=0, le=600)
    settle_s: float = Field(default=0.1, ge=0, le=600)
    readout_s: float = Field(default=0.3, ge=0, le=600)
    transfer_s: float = Field(default=0.7, ge=0, le=600)


class SceneConfig(_Strict):
    """What the simulated camera looks at (simulated and emulated backends).

    ``name``: ``relief`` (a simple Lambertian test scene) or a scene of the library in
    docs/simulator.md (painting, tablet, coin, tilted, industrial, flat).
    """

    @model_validator(mode="after")
    def _known_scene(self) -> SceneConfig:
        from rti_rig.simulator.scenes import SCENE_NAMES

        if self.name not in ("relief", *SCENE_NAMES):
            raise ValueError(
                f"unknown scene {self.name!r}; choose relief, {', '.join(SCENE_NAMES)}"
            )
        if self.name == "relief" and self.light_distance_mm is not None:
            # the relief is rendered under directional lights only: a lamp distance given for
            # it was silently dropped, and the dry run claimed point lamps it never rendered
            raise ValueError(
                "light_distance_mm has no effect on the relief scene, which is lit by "
                "directional lights only: remove light_distance_mm, or choose a library scene "
                f"for point lamps ({', '.join(SCENE_NAMES)})"
            )
        return self

    name: str = "relief"
    seed: int = Field(default=0, ge=0)
    noise: bool = True
    #: None: directional lights; else point lamps at this distance (dome radius, arm reach).
    light_distance_mm: float | None = Field(default=None, gt=0)
    raw: bool = False  # deliver frames through a DNG and the rawpy decode path, as a DSLR would


class LampsConfig(_Strict):
    """Where the lamps are relative to what the camera sees (``[lamps]``, optional).

    ``distance_mm``: the lamps' distance from the object's centre (a dome's radius, an arm's
    reach); ``field_width_mm``: the width of the object field the frame spans. Given, the
    adaptive stop's estimate renders the lamps as point lamps at that distance (each pixel lit
    from its own direction and distance, which a fit reading one direction per light gets
    wrong); not given, it assumes distant lamps and says so. Hardware rigs only: a simulated
    or emulated scene with ``light_distance_mm`` gives both itself, and a replayed
    acquisition's ``.lp`` has no config to give them in (docs/adaptive.md, "Lamps near the
    object").
    """

    distance_mm: float = Field(gt=0)
    field_width_mm: float = Field(gt=0)


class EmulatorFault(_Strict):
    """One byte-level fault of the emulated dome firmware, at its n-th command (1-based), or
    of the emulated servo bus, at its n-th instruction packet (:data:`ARM_FAULT_KINDS`): a
    status packet lost or damaged, or a servo's own hardware error
    (:data:`ARM_HARDWARE_FAULTS`, raised on ``servo_id`` as that packet arrives)."""

    at_command: int = Field(gt=0)
    kind: Literal[
        "drop_reply",
        "garble_reply",
        "garble_command",
        "delay_reply",
        "disconnect",
        "reset",
        "reset_after_reply",
        "blank_line_before_reply",
        "overload",
        "overheating",
        "input_voltage",
        "electrical_shock",
        "power_lost",
    ]
    delay_s: float = Field(default=1.0, ge=0, le=60)
    #: The servo a hardware error (``overload`` …) is raised on; arm faults only.
    servo_id: int | None = Field(default=None, ge=0, le=252)


#: The ``[[emulator.faults]]`` kinds the emulated servo bus rehearses: a status packet lost or
#: damaged on the wire (the servos' faults of their own, overload and the like, are the
#: emulator's hardware errors).
ARM_FAULT_KINDS = (
    "drop_reply",
    "garble_reply",
    "delay_reply",
    "overload",
    "overheating",
    "input_voltage",
    "electrical_shock",
    "power_lost",  # from the at_command-th packet on, no servo answers (the chain's supply)
)

#: The ``[[emulator.faults]]`` kinds that are a servo's own hardware error (a bit of its
#: Hardware Error Status (70), ROBOTIS e-manual), raised on ``servo_id``: the servo sets the
#: Alert bit of every status packet and, for the faults its Shutdown (63) selects, switches
#: its torque off (the arm sags) until a reboot. Without them a servo's overload could not be
#: rehearsed through ``run`` or ``check`` at all.
ARM_HARDWARE_FAULTS = ("overload", "overheating", "input_voltage", "electrical_shock")


class EmulatorConfig(_Strict):
    """Faults and flaws of the emulated devices in an ``emulated`` dry run (to rehearse them).

    ``led_power`` / ``led_power_spread`` make the emulated dome's LEDs uneven, as real domes'
    are (one measured dome: 19–37 % darker to 18–23 % brighter than its median LED), so that a
    light calibration (``rti-rig calibrate-lights``) can be rehearsed: either each LED's output
    relative to nominal, in LED index order, or the RMS of the natural log of the output, drawn
    per LED from ``scene.seed``.
    """

    dead_leds: list[int] = Field(default_factory=list)
    reports_dead_leds: bool = True
    faults: list[EmulatorFault] = Field(default_factory=list)
    led_power: list[float] | None = None
    led_power_spread: float = Field(default=0.0, ge=0.0, le=1.0)
    #: Where the emulated dome's LEDs really are: an ``.lp`` (line i = LED i, relative to the
    #: config's folder). Why: a new dome is shot with a stand-in layout (``fibonacci`` with its
    #: LED count) until ``rti-rig lights-from-sphere`` measures its directions; rehearsing that
    #: needs LEDs that are not where the config says. The camera renders the light from here;
    #: the rig, its schedule and its session's lights.lp keep the config's directions.
    led_directions_file: str | None = None
    #: Flash pulses lost or bounced at chosen exposures (a camera-triggered dome).
    sync_faults: list[SyncFaultConfig] = Field(default_factory=list)

    @model_validator(mode="after")
    def _one_power_model(self) -> EmulatorConfig:
        if self.led_power is not None:
            if self.led_power_spread:
                raise ValueError(
                    "give either led_power (each LED's output) or led_power_spread, not both"
                )
            for i, p in enumerate(self.led_power):
                if not (np.isfinite(p) and 0.05 <= p <= 5.0):
                    raise ValueError(
                        f"led_power[{i}] is {p}: an LED's output relative to nominal must be "
                        "in [0.05, 5] (use dead_leds for an LED that gives no light)"
                    )
        return self

    def led_powers(self, count: int, seed: int) -> NDArray[np.float64]:
        """Each emulated LED's output relative to nominal (all 1 unless configured)."""
        if self.led_power is not None:
            return np.asarray(self.led_power, dtype=np.float64)
        rng = np.random.default_rng([seed, 0x1ED])
        return np.exp(self.led_power_spread * rng.standard_normal(count))


class RigConfig(_Strict):
    """A whole rig: what it is, how it is driven, its camera and its timing.

    ``backend``: ``simulated`` (simulated devices, virtual time), ``emulated`` (the real
    drivers, pyserial or dynamixel-sdk, talking to device emulators on pseudo-terminals; the
    camera renders what the emulated devices really did) or ``hardware``.
    """

    name: str = Field(min_length=1)
    kind: Literal["dome", "arm"]
    backend: Literal["simulated", "emulated", "hardware", "replay"] = "simulated"
    description: str = ""
    dome: DomeConfig | None = None
    arm: ArmConfig | None = None
    camera: CameraConfig = CameraConfig()
    timing: TimingConfig = TimingConfig()
    scene: SceneConfig = SceneConfig()
    emulator: EmulatorConfig = EmulatorConfig()
    lamps: LampsConfig | None = None

    def _refuse_real_port_when_emulated(self) -> None:
        """Refuse a real port in an emulated dry run's config, naming the key.

        The dry run serves its own emulator (the dome's firmware, the arm's servos) and
        replaces the port: a config copied from a shipped emulated one with the device's real
        port set, as its header said to, ran a whole check against the emulator ("PASS") and
        never opened the port, so the device on it was never reached."""
        if self.backend != "emulated":
            return
        if self.kind == "dome" and self.dome is not None and self.dome.serial is not None:
            key, port, device = "[dome.serial]", self.dome.serial.port, "the dome"
        elif self.kind == "arm" and self.arm is not None and self.arm.dynamixel is not None:
            key, port, device = "[arm.dynamixel]", self.arm.dynamixel.port, "the arm's servos"
        else:
            return
        if port != "emulated":
            raise ValueError(
                f"{key} port = {port!r} with backend = 'emulated': an emulated dry run serves "
                f"its own emulator of {device} and never opens that port, so {device} on it "
                "would not be reached; to drive it, set backend = 'hardware' (with a "
                "[camera.device]); for the dry run, set port = 'emulated'"
            )

    def _real_unevenness(self) -> str:
        """What becomes of a real dome's uneven LEDs on this config's link, as the tail of the
        ``[emulator] led_power`` refusal (empty where there is no serial link to speak of).

        Why: the refusal had said the real driver applies the correction that evens them out,
        untrue for an on/off firmware (nab-rti-v1 and the other described ones), which cannot
        dim: its LEDs' unevenness stays in the images. Judged by the link's own
        :meth:`~rti_rig.drivers.led_dome.settings.DomeSerialSettings.dimming_refusal`."""
        serial = self.dome.serial if self.kind == "dome" and self.dome is not None else None
        if serial is None:
            return ""
        why = serial.dimming_refusal()
        if why is None:
            return " (the real driver applies the intensity correction that evens them out)"
        return (
            f" (on this rig {why}, so its LEDs' unevenness stays in the images; divide the "
            f"light gains out of them instead: {IMAGE_GAINS_REMEDY})"
        )

    def _dome_fault_has_a_link(self, i: int, kind: str) -> None:
        """Refuse a dome's command fault where no firmware emulator receives commands.

        Why: the faults are keyed by the n-th command the firmware emulator on the serial link
        receives; the camera-stepped cceh/rti dome has no link (its emulator is stepped by the
        flash signal) and a simulated dome has no firmware, so a rehearsed reset or lost reply
        was ignored and ``check`` said PASS: nothing had been rehearsed."""
        dome = self.dome
        if dome is None or (dome.serial is not None and self.backend == "emulated"):
            return
        if dome.flash_sync is not None:
            # on a hardware rig the sync faults are refused too: advise them only where they run
            rehearse = (
                "Rehearse its faults as [[emulator.sync_faults]] (at_image = N, kind = "
                "'missed_pulse', 'double_step' or 'power_cycle'), or remove this one"
                if self.backend == "emulated"
                else f"Nothing is rehearsed on backend = '{self.backend}': remove it"
            )
            raise ValueError(
                f"emulator.faults[{i}]: {kind} is a fault of a serial link's reply or "
                f"command, and this dome ({dome.flash_sync.firmware}) has none: the camera's "
                f"flash signal steps it. {rehearse}"
            )
        raise ValueError(
            f"emulator.faults[{i}]: {kind} is rehearsed by an emulated dome's firmware on its "
            "serial link (backend = 'emulated' with a [dome.serial]), and this rig is not one; "
            "remove the fault, or rehearse it on the emulated dome rti-rig ships, "
            f"{shell_word(shipped_config_path('emulated_dome.toml'))} (copy it, with the "
            f"{shell_word(shipped_config_path('example_dome_48.lp'))} its lp_file names, into "
            "one folder and add the fault to the copy)"
        )

    def _sync_faults_have_a_flash_dome(self) -> None:
        """Refuse flash-pulse faults on a rig whose camera steps no dome.

        Why: only the emulated camera-triggered dome's camera reads them; on a serial dome
        ``[[emulator.sync_faults]]`` were ignored and ``check`` said PASS, nothing rehearsed."""
        if not self.emulator.sync_faults:
            return
        dome = self.dome
        if dome is not None and dome.flash_sync is not None and self.backend == "emulated":
            return
        fault = f"emulator.sync_faults[0]: {self.emulator.sync_faults[0].kind}"
        if dome is not None and dome.flash_sync is not None:
            # a real camera-triggered dome: its camera does step it, nothing emulates the pulse
            raise ValueError(
                f"{fault} is rehearsed by the emulated camera-triggered dome (backend = "
                f"'emulated'), and this rig's backend is '{self.backend}': nothing emulates "
                "its flash pulses; remove it"
            )
        if dome is None:
            raise ValueError(
                f"{fault} is a flash pulse of a camera-triggered dome ([dome.flash_sync], "
                "backend = 'emulated'), and an arm has none; remove it"
            )
        raise ValueError(
            f"{fault} is a flash pulse of a camera-triggered dome ([dome.flash_sync], backend = "
            "'emulated'), and no camera steps this rig's lights; rehearse a serial dome's "
            "faults as [[emulator.faults]] (at_command = N, kind = 'reset', 'drop_reply', …), "
            "or remove it"
        )

    def _arm_faults_are_replies(self) -> None:
        """Refuse, naming the key, an arm's fault the emulated servos cannot rehearse.

        Why: the faults were the dome firmware's alone, and an arm config's were ignored: a
        rehearsal of a lost status packet ran a clean check ("PASS") and rehearsed nothing."""
        if self.kind != "arm":
            for i, fault in enumerate(self.emulator.faults):
                # power_lost too: the dome's firmware emulator has no such fault, and it had
                # reached the user as a traceback ("'power_lost' is not a valid FaultKind")
                chain = fault.kind == "power_lost"
                if fault.kind in ARM_HARDWARE_FAULTS or chain or fault.servo_id is not None:
                    whose = "the servo chain's" if chain else "a servo's"
                    raise ValueError(
                        f"emulator.faults[{i}]: {fault.kind}"
                        f"{' with servo_id' if fault.servo_id is not None else ''} is "
                        f"{whose} fault, rehearsed on an emulated arm; a dome's firmware "
                        "rehearses drop_reply, garble_reply, garble_command, delay_reply, "
                        "disconnect, reset, reset_after_reply and blank_line_before_reply"
                    )
                self._dome_fault_has_a_link(i, fault.kind)
                serial = self.dome.serial if self.dome is not None else None
                if fault.kind == "blank_line_before_reply" and (
                    serial is None or serial.profile not in ("default", "framed")
                ):
                    # a CR LF is two acknowledgement bytes on the binary link, and a
                    # described firmware's board has no such fault: refused, not ignored
                    raise ValueError(
                        f"emulator.faults[{i}]: blank_line_before_reply is a stray CR LF "
                        "before a reply of a line profile's firmware; set [dome.serial] "
                        "profile to 'default' or 'framed', or remove the fault"
                    )
            return
        if not self.emulator.faults:
            return
        for i, fault in enumerate(self.emulator.faults):
            if self.backend != "emulated" or self.arm is None or self.arm.dynamixel is None:
                raise ValueError(
                    f"emulator.faults[{i}]: faults are rehearsed on emulated servos only "
                    "(backend = 'emulated' with an [arm.dynamixel] table); remove them here"
                )
            if fault.kind not in ARM_FAULT_KINDS:
                raise ValueError(
                    f"emulator.faults[{i}].kind = {fault.kind!r}: the emulated servo bus "
                    f"rehearses {', '.join(ARM_FAULT_KINDS[:3])} (the status packet of "
                    "the at_command-th instruction packet the servos receive, lost, "
                    "damaged, or delay_s late, as on a slow USB-serial adapter), "
                    "power_lost (from that packet on no servo answers: the chain's supply "
                    "lost) and "
                    f"{', '.join(ARM_HARDWARE_FAULTS)} (a servo's hardware "
                    "error, on servo_id, as that packet arrives)"
                )
            ids = [j.servo_id for j in (self.arm.dynamixel.azimuth, self.arm.dynamixel.elevation)]
            if fault.kind in ARM_HARDWARE_FAULTS and fault.servo_id not in ids:
                raise ValueError(
                    f"emulator.faults[{i}].servo_id = {fault.servo_id}: a {fault.kind} is "
                    "raised on one of the arm's servos; set servo_id to "
                    + " or ".join(str(i) for i in ids)
                )
            if fault.kind not in ARM_HARDWARE_FAULTS and fault.servo_id is not None:
                what = (
                    "silences every servo of the chain"  # its supply, not one servo's
                    if fault.kind == "power_lost"
                    else "loses the status packet of whichever servo answers"
                )
                raise ValueError(
                    f"emulator.faults[{i}].servo_id: a {fault.kind} {what}; remove servo_id"
                )

    @model_validator(mode="after")
    def _kind_has_its_table(self) -> RigConfig:
        if self.kind == "dome" and self.dome is None:
            raise ValueError("kind 'dome' needs a [dome] table")
        if self.kind == "arm" and self.arm is None:
            raise ValueError("kind 'arm' needs an [arm] table")
        if self.kind == "dome" and self.arm is not None:
            raise ValueError(
                "kind 'dome' reads no [arm] table: remove it (or set kind = 'arm' for an arm)"
            )
        if self.kind == "arm" and self.dome is not None:
            raise ValueError(
                "kind 'arm' reads no [dome] table: remove it (or set kind = 'dome' for a dome)"
            )
        devices = [
            name
            for name, present in (
                ("[dome.serial]", self.dome is not None and self.dome.serial is not None),
                ("[arm.dynamixel]", self.arm is not None and self.arm.dynamixel is not None),
                ("[camera.device]", self.camera.device is not None),
            )
            if present
        ]
        if "backend" not in self.model_fields_set and devices:
            # a missing line must not turn a hardware session into a simulated one unnoticed
            raise ValueError(
                f"backend is not set, but {' and '.join(devices)} describe real devices: "
                "add backend = 'hardware' to drive them (or 'emulated' / 'simulated' for a "
                "dry run)"
            )
        if self.backend == "replay" and (self.kind != "dome" or self.dome.layout != "lp"):  # type: ignore[union-attr]
            raise ValueError(
                "backend 'replay' replays a recorded acquisition: it needs kind = 'dome' with "
                "layout = 'lp' and lp_file naming the acquisition's .lp (images beside it)"
            )
        driven = self.backend in ("emulated", "hardware")
        flash_sync = self.kind == "dome" and self.dome.flash_sync is not None  # type: ignore[union-attr]
        if driven and self.kind == "dome" and self.dome.serial is None and not flash_sync:  # type: ignore[union-attr]
            raise ValueError(
                f"backend '{self.backend}' drives the dome over serial: add a [dome.serial] "
                "table (port, profile; see docs/protocols/led-dome.md)"
            )
        self._refuse_real_port_when_emulated()
        if self.backend != "simulated" and self.kind == "arm" and self.arm.dynamixel is None:  # type: ignore[union-attr]
            raise ValueError(
                f"backend '{self.backend}' drives the arm's servos: add an [arm.dynamixel] "
                "table (see docs/protocols/dynamixel-arm.md)"
            )
        emu = self.emulator
        if (emu.led_power is not None or emu.led_power_spread) and (
            self.backend != "emulated" or self.kind != "dome"
        ):
            raise ValueError(
                "emulator.led_power / led_power_spread make an emulated dome's LEDs uneven: "
                f"they need kind = 'dome' and backend = 'emulated'{self._real_unevenness()}"
            )
        if emu.led_directions_file is not None and (
            self.backend != "emulated" or self.kind != "dome"
        ):
            raise ValueError(
                "emulator.led_directions_file puts an emulated dome's LEDs elsewhere than the "
                "config says: it needs kind = 'dome' and backend = 'emulated'"
            )
        self._arm_faults_are_replies()
        self._sync_faults_have_a_flash_dome()
        if self.lamps is not None and self.backend in ("simulated", "emulated"):
            # the estimate would render lamps the rendered images do not have
            raise ValueError(
                f"[lamps] describes a hardware rig's lamps; "
                f"the lamps of a rig with backend '{self.backend}' come from its [scene] "
                "(light_distance_mm, over the scene's own field): remove the [lamps] table, "
                "or set [scene] light_distance_mm"
            )
        if self.backend in ("simulated", "emulated"):
            from rti_rig.simulator.scenes import MIN_SIZE_PX

            # the relief's normals need two pixels a side (central differences); the library
            # scenes MIN_SIZE_PX. A smaller frame failed at the first capture, the relief's with
            # an unexplained numpy ValueError after the session folder was made
            least = 2 if self.scene.name == "relief" else MIN_SIZE_PX
            if min(self.camera.width, self.camera.height) < least:
                raise ValueError(
                    f"camera.width x camera.height = {self.camera.width} x "
                    f"{self.camera.height} px is too small for the simulated scene "
                    f"'{self.scene.name}': it needs at least {least} x {least} px"
                )
        if (
            self.scene.raw
            and self.backend != "hardware"
            and (self.camera.width % 2 or self.camera.height % 2)
        ):
            # refused here, not at the first capture: the mosaic encoder raised an unexplained
            # ValueError once the session had started
            raise ValueError(
                "scene.raw = true delivers each frame through a 2x2 Bayer mosaic (a DNG), which "
                f"needs an even camera width and height; got {self.camera.width} x "
                f"{self.camera.height}: make both even, as a real sensor's are"
            )
        if self.backend == "hardware" and self.camera.device is None:
            raise ValueError(
                "backend 'hardware' needs a [camera.device] table naming the camera driver "
                "(kind = 'opencv', 'gphoto2' or 'folder_watch'; see docs/cameras.md)"
            )
        return self


class LoadedRig(BaseModel):
    """A validated config together with where it came from (for errors and the manifest)."""

    model_config = ConfigDict(frozen=True, arbitrary_types_allowed=True)

    config: RigConfig
    path: str
    sha256: str  # of the config file, and of its light calibration file if it names one
    raw: dict[str, Any]  # the parsed TOML (a correction file's values filled in)
    #: what was tolerated while reading it (an .lp's clamped horizon light, its wrong count
    #: line), each naming the file and line: shown to the user and kept in the manifest
    notes: tuple[str, ...] = ()

    @property
    def folder(self) -> Path:
        return Path(self.path).parent


def quoted_value(raw: Any, value: Any, loc: tuple[Any, ...] = ()) -> tuple[str, str, Any] | None:
    """(key, text, value) of the first value the TOML gave as a string that validation turned
    into a number or a truth value (``exposure_s = "0.05"``, ``checksum = "false"``), else None.

    Why: pydantic's lax mode converts such strings silently, but TOML has numbers and booleans
    of its own, so quotes around one are a slip (often a line copied from elsewhere or written
    by a script), and the reverse slip — a number where a camera wants its own text, ``iso =
    100`` — is refused already. The walk compares the file's tree with the validated one, so it
    needs no list of numeric keys and reaches every table and array."""
    if isinstance(raw, str):
        return (_key_of(loc), raw, value) if _reads_as(raw, value) else None
    if isinstance(raw, dict):
        for k, sub_raw in raw.items():
            if isinstance(value, BaseModel) and k in type(value).model_fields:
                sub = getattr(value, k)
            elif isinstance(value, dict) and k in value:
                sub = value[k]
            else:
                continue
            hit = quoted_value(sub_raw, sub, (*loc, k))
            if hit is not None:
                return hit
    elif isinstance(raw, list) and isinstance(value, list | tuple) and len(raw) == len(value):
        for i, (sub_raw, sub) in enumerate(zip(raw, value, strict=True)):
            hit = quoted_value(sub_raw, sub, (*loc, i))
            if hit is not None:
                return hit
    return None


#: the texts pydantic's lax mode reads as a truth value
_TRUTH_WORDS = frozenset(["true", "false", "yes", "no", "on", "off", "t", "f", "y", "n", "1", "0"])


def _reads_as(text: str, value: Any) -> bool:
    """Whether ``text`` is ``value`` written in quotes: a truth value's word, or the number
    itself. A value that came from elsewhere (``[dome.serial] baudrate`` is the protocol's, so a
    ``protocol.baudrate = "fast"`` beside it met a number) is no quoted number: saying "write it
    without the quotes" of 'fast' was untrue."""
    if isinstance(value, bool):
        return text.strip().lower() in _TRUTH_WORDS
    if isinstance(value, int | float):
        try:
            return float(text) == float(value)
        except ValueError:
            return False
    return False


def refuse_quoted_value(path: str | Path, raw: Any, value: Any, loc: tuple[Any, ...] = ()) -> None:
    """Raise a :class:`ConfigError` naming the key :func:`quoted_value` finds, if any."""
    hit = quoted_value(raw, value, loc)
    if hit is None:
        return
    key, text, got = hit
    kind = "true or false" if isinstance(got, bool) else "a number"
    raise ConfigError(
        path, key, f"{text!r} is text in quotes, not {kind}: write it without the quotes"
    )


def _problem(err: Any) -> tuple[str | None, str]:
    """(key, text) of one error of the rig config. A refused ``[dome.serial.protocol]`` key is
    raised inside ``[dome.serial]``'s own check, so pydantic places it at ``dome.serial``; it is
    named in full here (``dome.serial.protocol.bogus_key``), as every other table's key is."""
    cause = err.get("ctx", {}).get("error")
    if isinstance(cause, ProtocolKeyError):
        return _key_of((*err["loc"], "protocol", *cause.loc)), cause.text
    if isinstance(cause, KeyValueError):
        return _key_of((*err["loc"], cause.key)), cause.text
    known = table_keys(RigConfig, err["loc"]) if err["type"] == "extra_forbidden" else ()
    return _key_of(err["loc"]) or None, _error_text(err, known, RigConfig)


def parse_rig_config(data: dict[str, Any], path: str) -> RigConfig:
    """Validate parsed TOML; the first problem becomes a :class:`ConfigError`, and so does a
    number or truth value written in quotes (:func:`quoted_value`)."""
    try:
        config = RigConfig.model_validate(data)
    except ValidationError as exc:
        problems = []
        for err in exc.errors():
            problems.append(_problem(err))
        key, msg = problems[0]
        if len(problems) > 1:
            rest = "; ".join(f"'{k}': {m}" if k else m for k, m in problems[1:])
            msg += f" — and also {rest}"
        raise ConfigError(path, key, msg) from None
    refuse_quoted_value(path, data, config)
    serial = config.dome.serial if config.dome is not None else None
    if serial is not None and serial.protocol:
        raw = data.get("dome", {}).get("serial", {}).get("protocol", {})
        try:
            spec = serial.protocol_spec()
        except (ValueError, ValidationError):
            spec = None  # refused by name elsewhere (the settings' own check)
        if spec is not None:
            refuse_quoted_value(path, raw, spec, ("dome", "serial", "protocol"))
    return config


#: Format tag of a light calibration file (``rti-rig calibrate-lights``).
CALIBRATION_FORMAT = "rti-rig-light-calibration/1"

#: What ``dome.lp_file`` names, said where it names no ``.lp``.
DOME_LP_WANTED = (
    "dome.lp_file names the dome's .lp light list (a count line, then 'name x y z' per LED, "
    "in the order of the LEDs)"
)


#: The key under which a loaded rig's raw ``[dome.serial]`` (and so a session's manifest)
#: records which LEDs its calibration file measured (the others were assumed median).
MEASURED_KEY = "intensity_correction_measured"


def measured_leds(data: dict[str, Any], count: int) -> list[bool] | None:
    """The ``measured`` flags of a calibration file's ``data`` (one per LED), or None if it has
    none of that length (an older or hand-made file): what is not said is not claimed."""
    measured = data.get("measured")
    if not isinstance(measured, list) or len(measured) != count:
        return None
    if not all(isinstance(m, bool) for m in measured):
        return None
    return list(measured)


#: What a text file refused by :func:`_config_text` is not, and what to give instead.
class _TextFileKind(NamedTuple):
    not_a: str
    give: str
    #: name the .lp files beside an image given (a rig: an acquisition's .lp replays it)
    lps_beside: bool = False


#: A light calibration file, as ``[dome.serial] intensity_correction_file`` names one.
_CALIBRATION_FILE = _TextFileKind(
    "a light calibration file",
    "give the light_calibration.toml that rti-rig calibrate-lights wrote",
)


def read_calibration_file(path: Path) -> tuple[dict[str, Any], bytes]:
    """A light calibration file's parsed TOML and its bytes, from one read.

    Read as tolerantly as a rig config (:func:`_config_text`: UTF-8 with or without a BOM,
    UTF-16 with one), an image or other binary file refused as such. Why: it had been read as
    UTF-8 alone, so a file saved again by Notepad as "Unicode" was told Python's decoder's
    words ("not valid TOML: 'utf-8' codec can't decode byte 0xff"), and an image given for it
    the same; and it was read three times (values, measured flags, checksum).

    Raises ``ValueError`` with what is wrong (the config loader names the file and key)."""
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise ValueError(f"cannot read {shown_path(path)}: {exc.strerror or exc}") from None
    try:
        return tomllib.loads(_config_text(path, raw, _CALIBRATION_FILE)), raw
    except ConfigError as exc:  # an image, a binary file, another encoding: said as such
        raise ValueError(str(exc)) from None
    except tomllib.TOMLDecodeError as exc:
        raise ValueError(f"{shown_path(path)} is not valid TOML: {exc}") from None


def correction_factors(data: dict[str, Any], path: Path, rig_name: str) -> list[float]:
    """The ``intensity_correction`` list of calibration file ``path`` (its parsed ``data``),
    checked against the rig.

    Raises ``ValueError`` with what is wrong (the config loader names the file and key).
    """
    if data.get("format") != CALIBRATION_FORMAT:
        raise ValueError(
            f"{shown_path(path)} is not an rti-rig light calibration (format "
            f"{CALIBRATION_FORMAT!r})"
        )
    if data.get("rig") != rig_name:
        raise ValueError(
            f"{shown_path(path)} calibrates the dome '{data.get('rig')}', not '{rig_name}'; "
            "calibrate this dome (rti-rig calibrate-lights)"
        )
    corr = data.get("intensity_correction")
    if not isinstance(corr, list) or not corr:
        raise ValueError(
            f"{shown_path(path)}: intensity_correction must be a list of factors, one per LED"
        )
    for i, v in enumerate(corr):
        ok = isinstance(v, int | float) and not isinstance(v, bool)
        if not (ok and math.isfinite(v) and 0 < v <= 1):
            raise ValueError(
                f"{shown_path(path)}: intensity_correction[{i}] is {v!r}; factors must be numbers "
                "in (0, 1] (calibrate again with rti-rig calibrate-lights)"
            )
    return [float(v) for v in corr]


def calibration_coverage(loaded: LoadedRig) -> tuple[int, int] | None:
    """(LEDs measured, LEDs) of the light calibration file the rig config names, or None when
    it names none or the file does not say (a correction typed into the config).

    Why: a card session of 12 of a dome's 48 LEDs gives a correction that assumes the other 36
    median; they are not evened out, and metering at one light, as on a dome evened out, had
    clipped 5 of 48 images of a matte card 67–100 %.
    """
    dome = loaded.raw.get("dome")
    serial = dome.get("serial") if isinstance(dome, dict) else None
    measured = serial.get(MEASURED_KEY) if isinstance(serial, dict) else None
    if not isinstance(measured, list):
        return None
    return sum(bool(m) for m in measured), len(measured)


def _with_correction_file(
    data: dict[str, Any], path: Path
) -> tuple[dict[str, Any], dict[str, Any], bytes]:
    """(to record, to validate, the file's bytes): ``data`` with ``[dome.serial]
    intensity_correction_file`` read into ``intensity_correction``.

    The record keeps the file's name beside its values, so a session's manifest says both what
    was applied and where it came from; the settings model sees only the values. The path is
    relative to the config's real folder (as ``lp_file`` is).
    """
    dome = data.get("dome")
    serial = dome.get("serial") if isinstance(dome, dict) else None
    if not isinstance(serial, dict) or "intensity_correction_file" not in serial:
        return data, data, b""
    key = "dome.serial.intensity_correction_file"
    name = serial["intensity_correction_file"]
    if "intensity_correction" in serial:
        raise ConfigError(
            path, key, "give intensity_correction or intensity_correction_file, not both"
        )
    if not isinstance(name, str) or not name:
        raise ConfigError(path, key, "must be the path of a calibration file (a string)")
    file = (path.resolve().parent / name).resolve()
    try:
        calibration, raw = read_calibration_file(file)
        values = correction_factors(calibration, file, str(data.get("name")))
    except ValueError as exc:
        _refuse_undimmable_first(path, data, serial)
        raise ConfigError(path, key, str(exc)) from None
    recorded = {**serial, "intensity_correction": values}
    measured = measured_leds(calibration, len(values))
    if measured is not None:  # which LEDs it evens out, for metering and the QA verdict
        recorded[MEASURED_KEY] = measured
    settings = {
        k: v for k, v in recorded.items() if k not in ("intensity_correction_file", MEASURED_KEY)
    }
    return (
        {**data, "dome": {**dome, "serial": recorded}},  # type: ignore[dict-item]
        {**data, "dome": {**dome, "serial": settings}},  # type: ignore[dict-item]
        raw,
    )


def _refuse_undimmable_first(path: Path, data: dict[str, Any], serial: dict[str, Any]) -> None:
    """Refuse a correction file on a link that cannot dim, before what is wrong with the file.

    Why: a nab-rti-v1 config given another dome's calibration had been told to "calibrate this
    dome (rti-rig calibrate-lights)", which refuses a dome that cannot dim: the refusal that
    holds whatever the file says (remove the key) comes first. A ``[dome.serial]`` that does not
    validate is left to the config's own refusal of it."""
    given = {k: v for k, v in serial.items() if k != "intensity_correction_file"}
    try:
        settings = DomeSerialSettings.model_validate(given)
    except ValueError:  # pydantic's ValidationError among them
        return
    _check_dome_can_dim(path, data, settings)


def _with_led_map_path(data: dict[str, Any], folder: Path) -> dict[str, Any]:
    """``[dome.serial] led_map_file`` relative to the config's folder, like ``lp_file``."""
    dome = data.get("dome")
    serial = dome.get("serial") if isinstance(dome, dict) else None
    name = serial.get("led_map_file") if isinstance(serial, dict) else None
    if not isinstance(name, str) or Path(name).is_absolute():
        return data
    resolved = {**serial, "led_map_file": str((folder / name).resolve())}  # type: ignore[dict-item]
    return {**data, "dome": {**dome, "serial": resolved}}  # type: ignore[dict-item]


def _with_watched_folder_path(data: dict[str, Any], folder: Path) -> dict[str, Any]:
    """A watched-folder camera's relative ``folder`` read relative to the config's folder,
    as ``lp_file`` and ``led_map_file`` are (``~`` is the user's home, as before).

    Why: it had been read relative to the folder the command was typed in, so ``check``
    passed from the config's folder and failed from another, and a resume typed elsewhere
    would have watched another folder than the session's."""
    camera = data.get("camera")
    device = camera.get("device") if isinstance(camera, dict) else None
    if not isinstance(device, dict) or device.get("kind") != "folder_watch":
        return data
    name = device.get("folder")
    if not isinstance(name, str) or Path(name).is_absolute() or name.startswith("~"):
        return data
    resolved = {**device, "folder": str((folder / name).resolve())}
    return {**data, "camera": {**camera, "device": resolved}}  # type: ignore[dict-item]


def _watched_folder_note(
    data: dict[str, Any], settings: dict[str, Any], path: Path
) -> tuple[str, ...]:
    """A note naming the folder a relative watched ``folder`` is read as (the config's, since
    2026-12-05; it had been the folder the command was typed in), where that is not the
    folder of the same name here: a config written for the old rule is told which it watches."""
    given = ((data.get("camera") or {}).get("device") or {}).get("folder")
    used = ((settings.get("camera") or {}).get("device") or {}).get("folder")
    if not isinstance(given, str) or given == used or used is None:
        return ()
    if Path(used) == (Path.cwd() / given).resolve():
        return ()
    return (
        f"{shown_path(path)}: camera.device.folder = {given!r} is read relative to the rig "
        f"config's folder: {used} (not {given!r} in the folder the command runs in)",
    )


#: A rig config, as ``run``, ``check`` and ``plan --rig`` read one (or an acquisition's .lp).
_RIG_FILE = _TextFileKind(
    "a rig config or an .lp",
    "give the rig config (.toml), or the .lp of a recorded acquisition that lists its images",
    lps_beside=True,
)


def _config_text(path: Path, raw: bytes, kind: _TextFileKind = _RIG_FILE) -> str:
    """The text of rig config ``path`` (its bytes ``raw``), or of another TOML file it names
    (``kind``: what the file should be, and what to give): UTF-8, with or without a BOM, or
    UTF-16 with one (Notepad's "Unicode"); else a :class:`ConfigError` saying what the file is
    and what to give.

    Why: an image given as the rig (``run ACQ/image01.jpg``), any other binary file, or a
    config saved in a Windows ANSI encoding had been told Python's decoder's words, "not valid
    TOML: 'utf-8' codec can't decode byte 0xff in position 0", which say neither what the file
    is nor what to do (``run``, ``check`` and ``plan --rig`` read a rig here)."""
    import codecs

    if looks_like_image(raw):
        image = _image_kind(path, raw)
        lps = _lps_beside(path) if kind.lps_beside else []
        beside = f" ({path.parent} holds {', '.join(lps)}: give that)" if lps else ""
        raise ConfigError(path, None, f"this is {image}, not {kind.not_a}: {kind.give}{beside}")
    if raw.startswith((codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE)):
        with contextlib.suppress(UnicodeDecodeError):
            return raw.decode("utf-16")
    head = raw[:4096]
    controls = sum(1 for b in head if b < 0x20 and b not in b"\t\n\r\f")
    if b"\x00" in head or controls > len(head) // 20:
        raise ConfigError(
            path,
            None,
            f"this is a binary file (not text), so not {kind.not_a}: {kind.give}",
        )
    try:
        return raw.decode("utf-8-sig")  # a BOM (Notepad) is no error
    except UnicodeDecodeError as exc:
        line = raw[: exc.start].count(b"\n") + 1
        raise ConfigError(
            path,
            None,
            f"line {line}: byte 0x{raw[exc.start]:02x} is not UTF-8 text (the file was saved in "
            "another encoding, such as a Windows ANSI one): save it again as UTF-8 (in Notepad: "
            "Save As, Encoding UTF-8)",
        ) from None


def _image_kind(path: Path, raw: bytes) -> str:
    """What kind of image ``raw`` (the start of ``path``) is, for a refusal: "an image (JPEG)"."""
    from rti_rig.core.image_files import JPEG_MAGIC, PNG_MAGIC, is_camera_raw

    if is_camera_raw(path):
        return "a camera RAW image"
    kind = "JPEG" if raw.startswith(JPEG_MAGIC) else "PNG" if raw.startswith(PNG_MAGIC) else "TIFF"
    return f"an image ({kind})"


def _lps_beside(path: Path) -> list[str]:
    """The ``.lp`` files beside ``path`` (at most three), by their path as given."""
    try:
        return [str(path.parent / p.name) for p in lp_files_in(path.parent)][:3]
    except OSError:
        return []


def _lps_in_folder_said(folder: Path) -> str:
    """What to say of the ``.lp`` files of a folder given as the rig: its own, or an
    RTIBuilder project's in ``assembly-files/`` (the project folder, or its ``jpeg-exports``,
    given), the one to give as a word that pastes.

    Why: an RTIBuilder project folder had been told only "is a folder", its .lp one folder
    down not named."""
    tomls = sorted(folder.glob("*.toml")) if folder.is_dir() else []
    lps = acquisition_lp_files(folder)
    if tomls and not any(_images_beside(p) for p in lps):
        # a folder of rig configs (rig_configs/): its configs named, not an LED-position .lp
        # beside them, which had been advised as "a recorded acquisition" and then failed
        # with every image missing
        more = " ..." if len(tomls) > 4 else ""
        names = ", ".join(shell_word(p) for p in tomls[:4])
        return f" (this folder holds the rig config(s) {names}{more}: give one)"
    if not lps:
        return ""
    more = " ..." if len(lps) > 3 else ""
    own = lps[0].parent == folder
    if len(lps) > 1:
        # each as a word that pastes: the user gives one of them in the folder's place
        names = ", ".join(shell_word(p) for p in lps[:3])
        where = "this folder holds" if own else "the RTIBuilder project's assembly-files holds"
        return f" ({where} {names}{more}: give the one that lists this acquisition's images)"
    names = lp_name_from(folder, lps[0])
    where = "this folder holds" if own else "the RTIBuilder project's light list is"
    return f" ({where} {names}: give {shell_word(lps[0])})"


def _images_beside(lp: Path) -> bool:
    """Whether the first image ``lp`` lists is there: an acquisition's, not an LED-position
    file's (whose names are labels of no file)."""
    from rti_rig.core.lp_format import image_path, read_lp

    try:
        entries = read_lp(lp)
    except Exception:
        return False
    try:
        return bool(entries) and image_path(lp.parent, entries[0].name).is_file()
    except OSError:  # a name no file here can have (too long): not found, as one missing
        return False


def rtibuilder_project_lp(folder: Path) -> Path | None:
    """The one ``.lp`` an RTIBuilder project folder (or its ``jpeg-exports``) holds in
    ``assembly-files/``, to replay in the folder's place; None for any other folder (one with
    ``.lp`` files of its own, a session folder among them, is still refused: which of its
    files is the acquisition is the user's to say). Several in ``assembly-files/``: refused,
    each named as a word to paste.

    Why: a conservator holds the project folder and expects `run PROJECT` to replay it as
    `run PROJECT/assembly-files/X.lp` does; it had been refused, naming the .lp to give."""
    folder = Path(folder)
    if not folder.is_dir() or lp_files_in(folder):
        return None
    lps = acquisition_lp_files(folder)
    if len(lps) > 1:
        raise ConfigError(
            folder,
            None,
            f"is an RTIBuilder project whose assembly-files holds {len(lps)} light lists, "
            "so which acquisition to replay is not known; give the one that lists its images: "
            + " or ".join(shell_word(p) for p in lps),
        )
    return lps[0] if lps else None


def project_lp_note(folder: Path, lp: Path, doing: str = "replaying") -> str:
    """What is said (and kept among the rig's notes in the manifest) of a project folder given
    as the rig: the ``.lp`` taken in its place, by its full path, and what is ``doing`` with it
    (``replaying`` for a run, ``checking`` for check, ``planning on`` for plan --rig).

    Why the verb: check, which replays nothing, had said "replaying its light list"."""
    return (
        f"{shown_path(folder)} is an RTIBuilder project: {doing} its light list "
        f"{lp_name_from(folder, lp)} ({shell_word(lp)})"
    )


def _not_toml_hint(raw: bytes) -> str:
    """What a text file that is no TOML was given as a rig instead, where that can be told: an
    acquisition's light list saved under another suffix (``lights.txt``), which a rig is read
    as only when it ends in ``.lp``. It had been told only the TOML parser's complaint
    ("Expected '=' after a key")."""
    with contextlib.suppress(LpFormatError):
        from rti_rig.core.lp_format import parse_lp

        text = raw.decode("utf-8-sig", errors="replace")
        if len(parse_lp(text)) >= 1:
            return (
                "; it reads as an .lp light list: a recorded acquisition is replayed from a "
                "file named *.lp (rename or copy it to end in .lp)"
            )
    return ""


def load_rig_config(path: Path | str, project_doing: str = "replaying") -> LoadedRig:
    """Read and validate a rig config TOML file (or an acquisition's `.lp`: a replay rig;
    ``project_doing``: what the command does with an RTIBuilder project's .lp, for its note,
    :func:`project_lp_note`)."""
    path = Path(path)
    if path.suffix.lower() == ".lp":
        return load_replay_rig(path)
    project_lp = rtibuilder_project_lp(path)
    if project_lp is not None:
        loaded = load_replay_rig(project_lp)  # its path, in the manifest, is the .lp replayed
        note = project_lp_note(path, project_lp, project_doing)
        return loaded.model_copy(update={"notes": (note, *loaded.notes)})
    if path.is_dir():  # an acquisition's folder, given for its .lp: say which file to give
        raise ConfigError(
            path,
            None,
            "is a folder: give a rig config (.toml) or a recorded acquisition's .lp"
            + _lps_in_folder_said(path),
        )
    try:
        raw_bytes = path.read_bytes()
    except OSError as exc:
        raise ConfigError(path, None, f"cannot read the file: {exc.strerror or exc}") from None
    try:
        data = tomllib.loads(_config_text(path, raw_bytes))
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(path, None, f"not valid TOML: {exc}{_not_toml_hint(raw_bytes)}") from None
    data, settings, correction_bytes = _with_correction_file(data, path)
    settings = _with_led_map_path(settings, path.parent)
    settings = _with_watched_folder_path(settings, path.parent)
    config = parse_rig_config(settings, str(path))
    if config.backend == "replay":
        # the form a session's manifest records a replay rig in, not one to write by hand:
        # such a file had been read with its images looked for beside the TOML, none checked
        # before the run, and the first capture blamed "its drive unplugged"
        lp_file = config.dome.lp_file if config.dome is not None else None
        acq = shell_word(str((path.parent / lp_file).resolve())) if lp_file else "ACQ/dirs.lp"
        raise ConfigError(
            path,
            "backend",
            "'replay' is the rig rti-rig makes of a recorded acquisition's .lp, not one a "
            f"config describes: give the .lp itself as the rig (rti-rig run {acq} --out "
            f"SESSION, rti-rig check {acq}); a session begun from this file continues with "
            f"rti-rig run {acq} --resume SESSION",
        )
    serial_cfg = config.dome.serial if config.dome is not None else None
    if serial_cfg is not None and serial_cfg.led_map_file is not None:  # refuse a bad map now
        from rti_rig.drivers.led_dome.factory import protocol_for
        from rti_rig.drivers.led_dome.protocol_spec import MissingSection

        try:
            protocol_for(serial_cfg)
        except MissingSection as exc:  # the config's section name, not the map file, is wrong
            raise ConfigError(path, "dome.serial.led_map_section", str(exc)) from None
    loaded = LoadedRig(
        config=config,
        path=str(path.resolve()),
        # a new calibration file changes the rig as much as an edit of the config does
        sha256=hashlib.sha256(raw_bytes + correction_bytes).hexdigest(),
        raw=data,
        notes=_watched_folder_note(data, settings, path),
    )
    try:
        return _checked(loaded, path, data)
    except ConfigError as exc:
        if exc.path != loaded.path:
            raise
        # said with the config's path as the user gave it, as every other refusal of it is (a
        # [camera.device] or dome.lp_file slip had printed the resolved, absolute path)
        raise ConfigError(path, exc.key, exc.message) from None


def _checked(loaded: LoadedRig, path: Path, data: dict[str, Any]) -> LoadedRig:
    """The checks of a loaded config that need it whole (its LEDs, its camera's settings)."""
    config = loaded.config
    if config.kind == "dome":
        notes: list[str] = []
        dirs, _ = dome_led_directions(loaded, notes)  # fail now, not when the session starts
        loaded = loaded.model_copy(update={"notes": (*loaded.notes, *notes)})
        serial = config.dome.serial if config.dome else None
        if serial is not None and serial.is_described:
            # a firmware that reports nothing: its LED count and on-window are the config's
            # own, so a mismatch is found now, naming the key, not after the port opened
            _check_firmware_led_count(loaded, len(dirs))
            limit = timed_exposure_limit(loaded)
            if limit is not None and config.camera.exposure_s > limit.max_exposure_s + 1e-9:
                raise ConfigError(path, "camera.exposure_s", limit.refusal(config.camera))
        if serial is not None and serial.intensity_correction is not None:
            _check_dome_can_dim(path, data, serial)
        if serial is not None:
            _check_exposure_fits_lit(loaded, serial)
        if serial is not None and (problem := serial.check_led_count(len(dirs))):
            key = "dome.serial.expected_led_count"
            if problem.startswith("intensity_correction"):
                used_file = "intensity_correction_file" in data["dome"]["serial"]
                key = "dome.serial.intensity_correction" + ("_file" if used_file else "")
            else:
                # where the count comes from, and which of the two to change (it had said
                # "… but 48 LEDs given", given by what left unsaid)
                dome = config.dome
                given = (
                    f"dome.lp_file ({dome.lp_file}) lists {len(dirs)}"
                    if dome is not None and dome.layout == "lp"
                    else f"the dome's layout gives {len(dirs)}"
                )
                problem = (
                    f"expected_led_count = {serial.expected_led_count}, but {given} LEDs: set "
                    f"expected_led_count = {len(dirs)} if the dome has {len(dirs)} LEDs, else "
                    "give the lights of this dome (a dome's .lp lists one line per LED, in the "
                    "firmware's numbering)"
                )
            raise ConfigError(path, key, problem)
        from rti_rig.app.flash_sync import check_exposure

        check_exposure(loaded)
        power = config.emulator.led_power
        if power is not None and len(power) != len(dirs):
            raise ConfigError(
                path,
                "emulator.led_power",
                f"{len(power)} values for {len(dirs)} LEDs: give one per LED, in LED order",
            )
        if config.emulator.led_directions_file is not None:
            emulated_led_directions(loaded, len(dirs))  # refused now, not at the first image
        # an LED index the dome has not had been ignored without a word: the rehearsal then
        # had no dead LED at all, and its check and fit "found" none
        outside = sorted({i for i in config.emulator.dead_leds if not 0 <= i < len(dirs)})
        if outside:
            raise ConfigError(
                path,
                "emulator.dead_leds",
                f"{', '.join(map(str, outside))} not among this dome's {len(dirs)} LEDs: give "
                f"LED indices from 0 to {len(dirs) - 1}",
            )
        if (
            config.backend == "emulated"
            and serial is not None
            and not serial.is_described
            and serial.senses_led_current
            and not config.emulator.reports_dead_leds
        ):
            # the emulated board measures no LED current but the config says the board does:
            # its check had called a dead LED "passed" (the protocol cannot tell the two)
            raise ConfigError(
                path,
                "emulator.reports_dead_leds",
                "false rehearses a board that measures no LED current, but "
                "dome.serial.senses_led_current is true (the default), so a check would call "
                "a dead LED 'passed': set senses_led_current = false under [dome.serial], as "
                "for the real board without current sensing",
            )
    if config.camera.device is not None and config.backend != "hardware":
        # a dry run renders its images (the camera a simulated, emulated or replayed rig has):
        # a real camera's table would be ignored without a word
        raise ConfigError(
            path,
            "camera.device",
            f"backend = '{config.backend}' renders its own images and does not drive a real "
            "camera, so this table would be ignored: to shoot with that camera set backend = "
            "'hardware'; for a dry run remove [camera.device]",
        )
    if config.camera.device is not None:
        cam = camera_device_settings(loaded)
        _check_exposure_ranges(loaded, path, cam)
        if getattr(cam, "trigger", "none") == "dome_shutter" and config.kind != "dome":
            raise ConfigError(
                path,
                "camera.device.trigger",
                "'dome_shutter' needs a dome (its camera-release line fires the camera); on an "
                "arm rig let the camera fire itself (trigger = 'none')",
            )
        _check_dome_has_shutter(path, config, cam)
        # a busy DSLR is no note (it had been one until 2026-11-29): the controller switches
        # the LED off while a busy camera is awaited past max_on_s, and lights it again
        for note in (_untriggered_wait_note(loaded, cam), _resume_check_note(loaded, cam)):
            if note:
                loaded = loaded.model_copy(update={"notes": (*loaded.notes, note)})
    return loaded


def _check_dome_has_shutter(path: Path, config: Any, cam: Any) -> None:
    """Refuse ``trigger = 'dome_shutter'`` on a dome whose firmware has no shutter command.

    Why: ``check`` passed such a rig, and ``run`` stopped at its first image, the dome lit,
    with "this firmware has no shutter command"."""
    serial = config.dome.serial if config.dome is not None else None
    if getattr(cam, "trigger", "none") != "dome_shutter" or serial is None:
        return
    if not serial.is_described:  # rti-rig's own protocols have a shutter verb
        return
    from rti_rig.drivers.led_dome.factory import protocol_for

    try:
        spec = protocol_for(serial)
    except Exception:  # the dome's own refusal is said where its settings are checked
        return
    if spec.shutter is None:
        raise ConfigError(
            path,
            "camera.device.trigger",
            f"'dome_shutter' needs a dome firmware with a shutter command, and "
            f"profile '{serial.profile}' has none: let the camera fire itself (trigger = "
            "'none', the camera on an interval timer or tethered), or give the profile a "
            "shutter command ([dome.serial.protocol], docs/domes.md)",
        )


def _check_dome_can_dim(path: Path, data: dict[str, Any], serial: Any) -> None:
    """Refuse an intensity correction for a link that cannot dim an LED, naming the key, the
    file and the firmware.

    Why: an on/off firmware (nab-rti-v1 and every other described one) lit each corrected LED
    at full light; ``check`` said PASS, the images were those of no correction, and metering
    took the dome for evened out (one light, not the planned six), which can over-expose."""
    why = serial.dimming_refusal()
    if why is None:
        return
    given = data["dome"]["serial"]
    if "intensity_correction_file" in given:
        key = "dome.serial.intensity_correction_file"
        what = f"the correction in {given['intensity_correction_file']!r}"
    else:
        key, what = "dome.serial.intensity_correction", "this correction"
    raise ConfigError(
        path,
        key,
        f"{why}, so {what} would be ignored (every LED lit at full light). Remove the key; "
        f"a correction needs {DIMMING_LINK}. To even out this dome's images instead, divide "
        f"the light gains out of them ({IMAGE_GAINS_REMEDY})",
    )


def _check_exposure_ranges(loaded: LoadedRig, path: Path, cam: object) -> None:
    """Refuse a ``[camera]`` exposure range that shares no exposure with the range the camera
    of ``[camera.device]`` takes (``min_exposure_s`` … ``max_exposure_s`` there, its defaults
    where not given), naming both keys.

    Why: the two tables were compared only once the camera connected (the metering's start,
    :func:`rti_rig.runtime.exposure_policy.metering_start`, or the camera's own refusal of
    the first exposure), so ``rti-rig check`` opened the dome's port and the camera for a
    config no shot can come from: every exposure is kept inside ``[camera]``'s range, and the
    camera refuses any outside its own. Said in the connect-time check's words, and judged by
    the same function (:func:`rti_rig.core.exposure_range.shared_range`). The frame period and
    the exposure units, known only once connected, are left to that check."""
    low = getattr(cam, "min_exposure_s", None)
    high = getattr(cam, "max_exposure_s", None)
    if low is None or high is None:  # a camera whose range the config does not give
        return
    given = loaded.config.camera.device or {}
    camera = loaded.config.camera

    def device(key: str, value: float) -> Bound:
        default = "" if key in given else " (its default)"
        return value, f"{key} = {value:g} s in [camera.device]{default}"

    shortest = (camera.min_exposure_s, f"[camera] min_exposure_s = {camera.min_exposure_s:g} s")
    longest = (camera.max_exposure_s, f"[camera] max_exposure_s = {camera.max_exposure_s:g} s")
    shared = shared_range(
        (shortest, longest), (device("min_exposure_s", low), device("max_exposure_s", high))
    )
    if not shared.empty:
        return
    assert shared.floor is not None and shared.cap is not None  # what empty means
    # the ranges are each the right way round, so an empty share has one end of [camera]'s:
    # its shortest above the device's longest, or its longest below the device's shortest
    key = "camera.min_exposure_s" if shared.floor is shortest else "camera.max_exposure_s"
    raise ConfigError(
        path,
        key,
        f"no exposure the camera takes lies between {shared.floor[1]} and {shared.cap[1]}: "
        "the camera refuses "
        "any exposure outside [camera.device]'s range, and every exposure (exposure_s, and "
        "what run --auto-exposure meters) is kept inside [camera]'s; lower the first or raise "
        "the second",
    )


def lit_per_shot(rig: LoadedRig) -> tuple[float, bool]:
    """(seconds an LED stays lit for one shot besides its exposure, whether that counts the
    transfer).

    The settle before the exposure and the readout after it always; and the transfer and the
    all-off's time too for a camera that cannot say when its exposure is over (a dry run's
    simulated camera, an OpenCV camera): the LED goes off only once its frame is in hand.
    Without the transfer the check below had passed a dry-run config whose every capture
    overran max_on_s ("LED 0 stayed on 1.153 s, beyond max_on_s = 0.46 s"), found after the
    dome was opened and lit."""
    from rti_rig.drivers.cameras.kinds import camera_kind

    t = rig.config.timing
    kind = camera_kind((rig.config.camera.device or {}).get("kind"))
    held = kind is None or not kind.says_exposure_end  # a dry run's simulated camera: held
    # held: the LED goes off only with the all-off sent after the frame, which takes its own
    # time (timing.light_switch_s); a camera that says when its exposure is over has the
    # readout after it as margin
    after = t.transfer_s + t.light_switch_s if held else 0.0
    return t.settle_s + t.readout_s + after, held


def shot_said(rig: LoadedRig, exposure_key: str, exposure_s: float) -> tuple[float, str]:
    """(seconds an LED stays lit for a shot of ``exposure_s``, the sum said with its keys:
    ``timing.settle_s 0.2 + camera.exposure_s 2 + timing.readout_s 0.5 = 2.7 s``)."""
    t = rig.config.timing
    fixed, held = lit_per_shot(rig)
    total = fixed + exposure_s
    text = (
        f"timing.settle_s {t.settle_s:g} + {exposure_key} {exposure_s:g} + timing.readout_s "
        f"{t.readout_s:g}"
    )
    if held:
        text += (
            f" + timing.transfer_s {t.transfer_s:g} + timing.light_switch_s "
            f"{t.light_switch_s:g} (this camera cannot say when its exposure is over, so its "
            "LED stays lit until the frame is in and the all-off is through)"
        )
    return total, f"{text} = {total:.3g} s"


def _check_exposure_fits_lit(rig: LoadedRig, serial: Any) -> None:
    """Refuse a ``[camera] exposure_s`` whose shot cannot end while its LED is lit.

    An LED may stay lit ``[dome.serial.thermal] max_on_s`` at a time, and a shot takes the
    settle before it and the camera's readout after it (:func:`lit_per_shot`): with more, every
    capture overran the thermal limit and the session stopped at its first image with the LED
    lit all along ("LED 0 stayed on 2.2 s, beyond max_on_s = 2 s"), after the dome had been
    opened and lit.
    """
    cam = rig.config.camera
    max_on = serial.thermal.max_on_s
    fixed, _ = lit_per_shot(rig)
    room = max_on - fixed
    if cam.exposure_s <= room + 1e-9:
        return
    _, said = shot_said(rig, "camera.exposure_s", cam.exposure_s)
    shorten = (
        f"shorten exposure_s to at most {room:.3g} s (or raise the ISO or open the aperture)"
        if room >= cam.min_exposure_s
        else "shorten the [timing] keys and the exposure"
    )
    raise ConfigError(
        rig.path,
        "camera.exposure_s",
        f"{cam.exposure_s:g} s does not fit: an LED may stay lit at most "
        f"[dome.serial.thermal] max_on_s = {max_on:g} s, and each shot ({said}) must end while "
        f"its LED is lit; every capture would stop the session at the thermal limit. Either "
        f"{shorten}, or raise max_on_s if the LEDs allow it",
    )


def _untriggered_wait_note(rig: LoadedRig, cam: Any) -> str:
    """Said when a dome's LED may have to stay lit longer than it is allowed while a camera
    fired by someone else is awaited ("" otherwise).

    With ``trigger = 'none'`` nothing tells rti-rig when the camera fires, so the LED stays on
    until the file comes (with ``'dome_shutter'`` it goes off after the exposure). A file later
    than ``max_on_s`` then stops the session at the thermal limit, with advice about settle and
    exposure that does not name the wait.
    """
    serial = rig.config.dome.serial if rig.config.dome is not None else None
    if serial is None or getattr(cam, "kind", None) != "folder_watch" or cam.trigger != "none":
        return ""
    lit_for = serial.thermal.max_on_s - rig.config.timing.settle_s
    if cam.timeout_s <= lit_for:
        return ""
    return (
        f"{shown_path(rig.path)}: camera.device.timeout_s = {cam.timeout_s:g} s is longer than an "
        f"LED may stay lit ([dome.serial.thermal] max_on_s = {serial.thermal.max_on_s:g} s, less "
        f"settle_s): with trigger = 'none' the LED stays on until the file comes, so a file "
        f"later than {lit_for:g} s stops the session at the thermal limit. Lower timeout_s, or "
        "let the dome fire the camera (trigger = 'dome_shutter': its LED goes off after the "
        "exposure, and the file may take timeout_s)"
    )


def _resume_check_note(rig: LoadedRig, cam: Any) -> str:
    """Said when a dome-fired folder-watch camera's ``timeout_s`` is too short for its
    capture-time check to tell a stopped run's late file from a quick resume's own ("" if not).

    A resume's first file is refused only when it was shot more than the check's allowance
    (the 1 s of EXIF times, ``shutter_lag_s`` and the pulses' trigger times, at least the
    shutter pulse) before the resume connected, and its shot is itself known only to within
    that allowance; the file the stopped run waited for was shot ``timeout_s`` before the
    stop. So it is surely caught only when ``timeout_s`` is over twice the allowance. The docs
    had said such a file is always caught: with a shorter wait a quick resume may take it as
    the resumed light's image.
    """
    serial = rig.config.dome.serial if rig.config.dome is not None else None
    if getattr(cam, "kind", None) != "folder_watch" or cam.trigger != "dome_shutter":
        return ""
    from rti_rig.drivers.cameras.folder_watch import CAPTURE_TIME_RESOLUTION_S

    pulse_s = 0.0 if serial is None else serial.shutter_pulse_ms / 1000
    allowance = CAPTURE_TIME_RESOLUTION_S + cam.shutter_lag_s + 2 * pulse_s
    if cam.timeout_s > 2 * allowance:
        return ""
    return (
        f"{shown_path(rig.path)}: camera.device.timeout_s = {cam.timeout_s:g} s is not over twice "
        f"the allowance of the capture-time check ({allowance:g} s: 1 s of EXIF times, "
        f"camera.device.shutter_lag_s = {cam.shutter_lag_s:g} s and two shutter pulses): a "
        "late file of a run stopped at timeout_s and quickly resumed may not be told from the "
        f"resumed light's own and be taken as its image. Raise timeout_s over "
        f"{2 * allowance:g} s (a RAW over Wi-Fi may need 15 s), or wait that long before "
        "resuming"
    )


def _layout_said(dome: DomeConfig, count: int) -> str:
    """The [dome] layout as the user wrote it, e.g. ``layout 'fibonacci' (count = 12)``."""
    if dome.layout == "fibonacci":
        return f"layout 'fibonacci' (count = {dome.count})"
    if dome.layout == "lp":
        return f"layout 'lp' ({dome.lp_file} lists {count})"
    return f"layout 'rings' ({' + '.join(str(r.count) for r in dome.rings)} = {count})"


def _check_firmware_led_count(rig: LoadedRig, count: int) -> None:
    """Refuse a firmware profile's LED count that the firmware cannot drive or that differs from
    the [dome] layout's, naming where the count came from (the firmwares report none)."""
    from rti_rig.drivers.led_dome.dome_profiles import max_led_count
    from rti_rig.drivers.led_dome.factory import protocol_for

    dome = rig.config.dome
    assert dome is not None and dome.serial is not None
    serial = dome.serial
    n = protocol_for(serial).led_count
    if serial.led_map_file is not None:
        key = "dome.serial.led_map_file"
        section = f", section '{serial.led_map_section}'" if serial.led_map_section else ""
        given = f"the LED map{section} has {n} rows (one per LED)"
        fix = f"give the map one row per LED of the layout ({count})"
    elif "led_count" in (serial.protocol or {}):
        key = "dome.serial.protocol.led_count"
        given = f"led_count = {n}"
        fix = f"set led_count = {count}"
    else:
        key = "dome.serial.protocol.led_count"
        given = f"not set, so the {serial.profile} profile's {n} applies"
        fix = f"add led_count = {count} under [dome.serial.protocol]"
    most = max_led_count(serial.profile)
    if most is not None and n > most:
        raise ConfigError(
            rig.path,
            key,
            f"{given}, but the {serial.profile} firmware drives at most {most} LEDs: give the "
            f"number of LEDs wired (at most {most}), as many as the [dome] layout lists",
        )
    if n != count:
        raise ConfigError(
            rig.path,
            key,
            f"{given} but [dome] {_layout_said(dome, count)} gives {count} lights: {fix} (the "
            "LEDs wired, in the layout's order), or change the layout. The firmware reports no "
            "count: this number is the rig config's own",
        )


class TimedExposureLimit(BaseModel):
    """The longest exposure a timed firmware's self-timed on-window leaves room for.

    The window (``light_on_s`` sent as whole seconds) starts as the firmware's reply to the
    light command starts (RTIPy prints it, then lights the LED); the capture must end inside
    it: the all-off after each capture refuses an image whose LED went dark first
    (``ScriptedDomeDriver._wait_window``), and a camera's capture ends after the reply is all
    heard (``reply_s``), the settle, the exposure, the readout and the transfer.
    """

    model_config = ConfigDict(frozen=True)

    firmware: str
    light_on_s: float
    light_on_from_profile: bool
    window_s: int
    margin_s: float
    settle_s: float
    readout_s: float
    transfer_s: float
    #: From the LED lighting to its light command's reply all heard, when the capture begins:
    #: the reply on the wire plus the port's latency (RTIPy prints it, then lights the LED:
    #: :func:`rti_rig.drivers.led_dome.scripted.timed_reply_s`).
    reply_s: float = 0.0

    @property
    def max_exposure_s(self) -> float:
        return (
            self.window_s
            + self.margin_s
            - self.reply_s
            - self.settle_s
            - self.readout_s
            - self.transfer_s
        )

    def window_said(self) -> str:
        where = (
            f"the {self.firmware} profile's light_on_s = {self.light_on_s:g}"
            if self.light_on_from_profile
            else f"dome.serial.protocol.light_on_s = {self.light_on_s:g}"
        )
        whole = "" if self.light_on_s == self.window_s else f", sent as {self.window_s} whole s"
        return (
            f"the {self.firmware} firmware lights each LED for {self.window_s} s ({where}{whole}) "
            "and then switches it off by itself"
        )

    def refusal(self, cam: CameraConfig) -> str:
        total = self.reply_s + self.settle_s + cam.exposure_s + self.readout_s + self.transfer_s
        need = math.ceil(total - self.margin_s - 1e-9)
        room = self.max_exposure_s
        fixed = self.reply_s + self.settle_s + self.readout_s + self.transfer_s
        shorten = (
            f"shorten exposure_s to at most {room:.3g} s"
            if room >= cam.min_exposure_s
            else f"shorten the exposure and the timings (settle, readout and transfer alone take "
            f"{fixed:.3g} s of the {self.window_s} s window)"
        )
        return (
            f"{cam.exposure_s:g} s does not fit: {self.window_said()}, and each capture must end "
            f"while its LED is lit (the firmware's reply {self.reply_s:.3f} s, heard after "
            f"the LED lights, + timing.settle_s {self.settle_s:g} + camera.exposure_s "
            f"{cam.exposure_s:g} + timing.readout_s {self.readout_s:g} + timing.transfer_s "
            f"{self.transfer_s:g} = {total:.3g} s from the LED lighting to the end of the "
            f"capture); on the dome every capture would be refused. Raise "
            f"dome.serial.protocol.light_on_s to {need} (whole seconds) or more, or {shorten}"
        )


def timed_exposure_limit(rig: LoadedRig) -> TimedExposureLimit | None:
    """The exposure limit a timed firmware's on-window sets (RTIPy), or None (no such limit)."""
    from rti_rig.drivers.led_dome.factory import protocol_for
    from rti_rig.drivers.led_dome.scripted import TIMED_MARGIN_S, timed_reply_s

    cfg = rig.config
    serial = cfg.dome.serial if cfg.dome is not None else None
    if serial is None or not serial.is_described:
        return None
    spec = protocol_for(serial)
    if spec.window_s is None or spec.light_on_s is None:
        return None
    t = cfg.timing
    return TimedExposureLimit(
        firmware=spec.name,
        light_on_s=spec.light_on_s,
        light_on_from_profile="light_on_s" not in (serial.protocol or {}),
        window_s=spec.window_s,
        margin_s=TIMED_MARGIN_S,
        settle_s=t.settle_s,
        readout_s=t.readout_s,
        transfer_s=t.transfer_s,
        reply_s=timed_reply_s(spec),
    )


def camera_device_settings(rig: LoadedRig):  # type: ignore[no-untyped-def]
    """The validated driver settings of the rig's real camera (``[camera.device]``)."""
    from rti_rig.drivers.cameras.kinds import camera_kind
    from rti_rig.drivers.cameras.settings import parse_camera_settings

    raw = rig.config.camera.device or {}
    try:
        settings = parse_camera_settings(raw)
    except ValidationError as exc:
        err = exc.errors()[0]  # said as every other table's (parse_rig_config)
        kind = camera_kind(raw.get("kind"))
        known = table_keys(kind.settings, err["loc"]) if kind is not None else []
        model = kind.settings if kind is not None else None
        said = _other_kinds_key(err, raw.get("kind")) or _error_text(
            err, known, model, ("camera", "device")
        )
        raise ConfigError(rig.path, _key_of(("camera", "device", *err["loc"])), said) from None
    refuse_quoted_value(rig.path, raw, settings, ("camera", "device"))
    return settings


def _other_kinds_key(err: Any, kind: object) -> str:
    """What to say of a ``[camera.device]`` key spelt right for another camera kind ("" for
    any other error). Why: ``decode`` under an ``opencv`` camera was told "unknown key …; did
    you mean 'device'?", sending the user after a typo that was not one."""
    from rti_rig.drivers.cameras.kinds import camera_kind, camera_kind_names

    loc = err.get("loc") or ()
    if err.get("type") != "extra_forbidden" or len(loc) != 1:
        return ""
    key = str(loc[0])
    others = [
        name
        for name in camera_kind_names()
        if name != kind and key in (camera_kind(name).settings.model_fields)
    ]
    if not others:
        return ""
    which = " or ".join(f"'{name}'" for name in others)
    return (
        f"'{key}' is a key of a {which} camera, and this one is kind '{kind}': remove it, or "
        "set the kind of camera it is"
    )


def default_config_path() -> Path:
    """The embedded simulated dome config shipped with the package."""
    return shipped_config_path("simulated_dome.toml")


def shipped_config_path(name: str) -> Path:
    """Where the rig config ``name`` shipped with the package is, installed or in a checkout.

    Why: a hint that named ``rig_configs/emulated_dome.toml`` named a path only a checkout's
    root has; an installed user pasting it was told there is no such file."""
    return Path(str(resources.files("rti_rig.rig_configs").joinpath(name)))


def _ring_directions(rings: list[Ring]) -> NDArray[np.float64]:
    dirs = []
    for ring in rings:
        az = ring.azimuth_offset_deg + 360.0 * np.arange(ring.count) / ring.count
        dirs.append(direction_from_az_el(az, np.full(ring.count, ring.elevation_deg)))
    return np.concatenate(dirs, axis=0)


def emulated_led_directions(rig: LoadedRig, count: int) -> NDArray[np.float64] | None:
    """The directions ``[emulator] led_directions_file`` gives the emulated dome's ``count``
    LEDs (LED index order), None where it is not set; a file that cannot be read or lists
    another number of lights is refused with the key."""
    name = rig.config.emulator.led_directions_file
    if name is None:
        return None
    key = "emulator.led_directions_file"
    path = (rig.folder / name).resolve()
    try:
        entries = read_lp(path, upper_hemisphere=True)
    except LpFormatError as exc:
        raise ConfigError(rig.path, key, str(exc)) from None
    if len(entries) != count:
        raise ConfigError(
            rig.path,
            key,
            f"{shown_path(path)} lists {len(entries)} lights for the dome's {count} LEDs: give "
            "one line per LED, in LED order",
        )
    return directions_of(entries)


def dome_led_directions(
    rig: LoadedRig, notes: list[str] | None = None
) -> tuple[NDArray[np.float64], list[str]]:
    """The dome's calibrated LED directions (N, 3) and their names, in LED index order.

    What a calibration `.lp` needed tolerated is appended to ``notes``."""
    dome = rig.config.dome
    if dome is None:
        raise ConfigError(rig.path, "kind", "this rig is not a dome")
    if dome.layout == "rings":
        dirs = _ring_directions(dome.rings)
    elif dome.layout == "fibonacci":
        assert dome.count is not None
        dirs = fibonacci_cap(dome.count, dome.min_elevation_deg)
    else:
        assert dome.lp_file is not None
        lp_path = (rig.folder / dome.lp_file).resolve()
        if not lp_path.exists():
            raise ConfigError(
                rig.path,
                "dome.lp_file",
                f"file {shown_path(lp_path)} does not exist (paths are relative to the config "
                "file's folder)",
            )
        try:
            entries = read_lp(lp_path, upper_hemisphere=True, notes=notes, wanted=DOME_LP_WANTED)
        except LpFormatError as exc:
            raise ConfigError(rig.path, "dome.lp_file", str(exc)) from None
        dirs = np.array([e.direction for e in entries])
        pair = coincident_leds(dirs)
        if pair is not None:
            i, j = pair
            raise ConfigError(
                rig.path,
                "dome.lp_file",
                f"{shown_path(lp_path)}: {lights_said(entries, (i, j))} give the same "
                "direction; a dome's calibration lists each LED "
                "once (an acquisition's .lp may repeat a light: remove the repeats)",
            )
        return dirs, [e.name for e in entries]  # read_lp refused lights below the plane
    if len(dirs) > 1000:
        raise ConfigError(rig.path, "dome", f"{len(dirs)} LEDs: at most 1000 are supported")
    _check_hemisphere(rig, dirs)
    pair = coincident_leds(dirs)
    if pair is not None:
        az, el = (float(v) for v in az_el_from_direction(dirs[pair[0]]))
        raise ConfigError(
            rig.path,
            f"dome.{dome.layout}",
            f"{_led_name(dome, pair[0])} and {_led_name(dome, pair[1])} both point at azimuth "
            f"{az:.1f}°, elevation {el:.1f}°: two LEDs cannot share a direction (a ring at 90° "
            "elevation holds one LED; rings at one elevation need different azimuth offsets)",
        )
    return dirs, [default_led_name(i) for i in range(len(dirs))]


def _led_name(dome: DomeConfig, i: int) -> str:
    """LED ``i`` as the user wrote it: ``LED i (rings[r], its k-th)`` for rings."""
    if dome.layout != "rings":
        return f"LED {i}"
    k = i
    for r, ring in enumerate(dome.rings):
        if k < ring.count:
            return f"LED {i} (rings[{r}], LED {k + 1} of {ring.count})"
        k -= ring.count
    return f"LED {i}"


def _check_hemisphere(rig: LoadedRig, dirs: NDArray[np.float64]) -> None:
    below = np.flatnonzero(dirs[:, 2] < -1e-9)
    if below.size:
        raise ConfigError(
            rig.path,
            "dome",
            f"LED(s) {below.tolist()} point below the object plane (z < 0): check the layout",
        )


def rig_geometry(rig: LoadedRig) -> DomeGeometry | ArmGeometry:
    """Where this rig can put light, for the planner and for validation."""
    cfg = rig.config
    if cfg.kind == "dome":
        dirs, names = dome_led_directions(rig)
        return DomeGeometry(dirs, tuple(names))
    arm = cfg.arm
    assert arm is not None
    if arm.dynamixel is not None and cfg.backend != "simulated":
        dxl = arm.dynamixel
        cone_top = 90.0 - dxl.keep_out_half_angle_deg
        return ArmGeometry(
            min_elevation_deg=max(0.0, dxl.elevation.min_deg),
            max_elevation_deg=min(dxl.elevation.max_deg, cone_top),
            keep_out_half_angle_deg=dxl.keep_out_half_angle_deg,
            park_azimuth_deg=dxl.park_azimuth_deg,
            park_elevation_deg=dxl.park_elevation_deg,
            min_azimuth_deg=max(-180.0, dxl.azimuth.min_deg),
            max_azimuth_deg=min(180.0, dxl.azimuth.max_deg),
            configured_max_elevation_deg=(
                dxl.elevation.max_deg if dxl.elevation.max_deg > cone_top else None
            ),
        )
    return ArmGeometry(
        min_elevation_deg=arm.min_elevation_deg,
        max_elevation_deg=arm.max_elevation_deg,
        keep_out_half_angle_deg=arm.keep_out_half_angle_deg,
        park_azimuth_deg=arm.park_azimuth_deg,
        park_elevation_deg=arm.park_elevation_deg,
    )


def converted_by_replay(path: Path) -> bool:
    """Whether a replay converts ``path`` to linear sRGB by the space it says (the replay's
    rule: a colour file, :func:`needs_conversion`), read from its headers alone."""
    from rti_rig.core.image_files import header_bit_depth, header_layout
    from rti_rig.drivers.cameras.colour_convert import needs_conversion
    from rti_rig.drivers.cameras.file_colour import file_colour

    layout, bits = header_layout(path), header_bit_depth(path)
    if layout is None or not layout[2] or bits is None:
        return False
    # a TIFF of 10, 12 or 14 bits a sample is decoded to uint16, as a 16-bit one is
    return needs_conversion(file_colour(path), np.dtype(np.uint16 if bits > 8 else np.uint8))


def load_replay_rig(lp_path: Path | str) -> LoadedRig:
    """A recorded acquisition as a rig: a dome with exactly the `.lp`'s lights (backend
    ``replay``) whose camera returns the image recorded beside the `.lp` for the light fired.

    Every image is checked to exist before anything runs, and the first one is read for the
    camera's size; the rig's identity (``sha256``) is that of the `.lp` file. The timing is the
    default dome's (about 1 s a light), so a replayed session reports what a real dome would
    take.
    """
    from rti_rig.core.acquisition_images import (
        AcquisitionImagesError,
        check_acquisition_images,
        mixed_depth_note,
    )
    from rti_rig.core.image_files import png_alpha_note
    from rti_rig.runtime.session import refuse_if_in_use

    lp_path = Path(lp_path).resolve()
    # a session's lights.lp while its run still captures (it grows, its next image may be
    # half written): refused as check, fit and export-lp refuse it; run, plan --rig and
    # bench had read the images so far as a whole acquisition, in silence
    refuse_if_in_use(lp_path.parent, "use it as a recorded acquisition")
    try:
        raw_bytes = lp_path.read_bytes()
    except OSError as exc:
        raise LpFormatError(lp_path, None, f"cannot read: {exc.strerror or exc}") from None
    notes: list[str] = []
    entries = read_lp(lp_path, upper_hemisphere=True, notes=notes)
    pair = coincident_leds([e.direction for e in entries])
    if pair is not None:
        # said before the images are read, in a replay's words: the dome check below had
        # said "key 'dome.lp_file'" (a key of a config the user never wrote) and "a dome's
        # calibration lists each LED once"
        i, j = pair
        refused = ConfigError(
            lp_path,
            None,
            f"{lights_said(entries, (i, j))} share one "
            f"direction (within {COINCIDENT_LED_DEG}°): a replay fires the acquisition's "
            "lights by direction, each once; remove one of the two lines (its image is then "
            "left out) to replay the others",
        )
        refused.reader_notes = tuple(notes)  # type: ignore[attr-defined]
        raise refused
    # every image found, whole, readable, of one size and kind, before anything runs (shared
    # with bench tradeoff --from, which reads the same acquisitions)
    try:
        found = check_acquisition_images(
            lp_path,
            entries,
            lead="as a rig, an .lp is a recorded acquisition, replayed from the images it lists: ",
        )
    except AcquisitionImagesError as exc:
        exc.reader_notes = tuple(notes)  # said with the refusal (run) or the failed check
        raise
    # their readers drop a PNG's alpha: said once, among the rig's notes (run, check)
    notes.extend(png_alpha_note([e.name for e in entries], found.paths))
    width, height = found.width, found.height
    names = [e.name for e in entries]
    mixed = mixed_depth_note(lp_path, names, found.paths, "replayed")
    if mixed:
        # a file the replay converts by the space it says is read by neither of the note's
        # two guesses (fit leaves it out of its note too): a 16-bit sRGB PNG among JPEGs had
        # been said "taken as linear" where the replay undoes its curve. Headers are read
        # again only where there is a mix
        kept = [i for i, p in enumerate(found.paths) if not converted_by_replay(p)]
        mixed = mixed_depth_note(
            lp_path, [names[i] for i in kept], [found.paths[i] for i in kept], "replayed"
        )
    if mixed:
        notes.append(mixed)
    data: dict[str, Any] = {
        "name": f"replay of {lp_path.parent.name}/{lp_path.name}",
        "kind": "dome",
        "backend": "replay",
        "description": "a recorded acquisition replayed (rti-rig run ACQ/dirs.lp)",
        "dome": {"layout": "lp", "lp_file": str(lp_path)},
        "camera": {"width": width, "height": height},
    }
    config = parse_rig_config(data, str(lp_path))
    loaded = LoadedRig(
        config=config,
        path=str(lp_path),
        sha256=hashlib.sha256(raw_bytes).hexdigest(),
        raw=data,
        notes=tuple(notes),
    )
    dome_led_directions(loaded)  # the coincident-light check, as for any dome
    return loaded
