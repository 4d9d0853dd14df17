"""Evening out a dome's LEDs: a per-LED intensity correction measured from a card session.

Why in the dome and not in the fit: relight, RTIBuilder and every PTM/HSH/photometric-stereo
fitter read only the images and the ``.lp``, and assume all lights are equally strong. Real
domes' LEDs are not (one measured dome: 19–37 % darker to 18–23 % brighter than its median LED,
docs/reconstruction.md "Light gains"), and a dim light tilts every normal it helps to fit. The
dome driver can dim each LED by a factor (``[dome.serial] intensity_correction``, PWM level ×
factor), so a correction measured once makes every later session's images equal-light for
every tool.

The measurement: shoot a level matte white card under every LED (``rti-rig run``), then
:func:`read_card_session` and :func:`calibrate_dome`. The card's images give each light's gain
(:func:`rti_rig.reconstruct.estimate_light_gains`). An image is ∝ p · d where p is the LED's
own output and d the drive it was given (the correction in force × the step's intensity, as the
quantised PWM level it became), so p = gain / d, and the new correction p_min / p makes every
LED give the weakest one's light. Evening out costs light (an image needs p_median / p_min
times the exposure it needed under the median LED), which is reported.
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from dataclasses import dataclass, field
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from rti_rig.app.config import CALIBRATION_FORMAT as FORMAT
from rti_rig.app.dead_led import dead_led_recorded
from rti_rig.app.usecases.run_options import run_words
from rti_rig.core.errors import SessionError
from rti_rig.core.image_files import read_linear_tiff
from rti_rig.core.out_folders import free_folder_beside
from rti_rig.core.rig_geometry import DomeGeometry
from rti_rig.core.shell_words import shell_word, shown_path
from rti_rig.core.toml_strings import toml_basic_string
from rti_rig.planner.topography import downsample
from rti_rig.reconstruct import ReconstructionError, estimate_light_gains
from rti_rig.runtime.session import (
    JOURNAL,
    MANIFEST,
    image_names,
    read_manifest,
    scan_journal,
    verified_steps,
)

#: Card images are area-averaged to at most this many pixels on their long side: the gains are
#: medians over the card, so full resolution only costs memory (72 × 24 MP would be 7 GB).
WORK_SIZE = 512
#: A card image with more saturated pixels than this is refused (its gain would be clipped).
MAX_SATURATED = 0.01
#: A card session whose photometric-stereo normals spread more than this (degrees, 90th
#: percentile of their angle to the mean normal) is not of a flat card: refused. Measured:
#: the emulated dome's card session 1.3°, its coin scene (6 LEDs) 35°; a real card's would
#: rise with the lights' change of direction across it (near LEDs, a large card), hence the
#: room left.
MAX_CARD_SPREAD_DEG = 10.0


@dataclass(frozen=True)
class CardSession:
    """The card images of one dome session, each with the LED that lit it and how hard."""

    root: Path
    rig_name: str
    images: NDArray[np.float32]  # (n, h, w) grey, linear, downsampled
    directions: NDArray[np.float64]  # (n, 3) the directions that actually ran
    leds: NDArray[np.intp]  # (n,) LED index of each image
    drive: NDArray[np.float64]  # (n,) PWM level / max level × exposure / longest exposure
    correction: tuple[float, ...] | None  # the dome's intensity_correction when it was shot
    #: LED index → the session's image of it (``image_019.jpg``): what a user opens to look
    image_of: dict[int, str] = field(default_factory=dict)


@dataclass(frozen=True)
class LightCalibration:
    """A dome's per-LED correction, and the evidence for it.

    ``output`` each LED's light at full drive relative to the median measured LED (assumed
    where not measured, see :func:`calibrate_dome`); ``measured`` which LEDs the card session
    measured; ``correction`` the new factors in (0, 1] (the weakest LED at 1); ``previous``
    the factors the card was shot with;
    ``shot_spread`` the RMS of the natural log of the measured lights' gains as shot (the
    unevenness the card session itself had: after a good correction, a re-shot card shows the
    residual here).
    """

    output: NDArray[np.float64]
    measured: NDArray[np.bool_]
    correction: NDArray[np.float64]
    previous: NDArray[np.float64]
    shot_spread: float

    @property
    def evened_light(self) -> float:
        """The light every LED gives once evened out, relative to the median LED's (≤ 1)."""
        return float(self.output.min() / np.median(self.output[self.measured]))

    @property
    def stops_lost(self) -> float:
        """Exposure an evened-out image needs beyond one lit by the median LED, in stops."""
        return float(-math.log2(self.evened_light))


#: How a run records an error about one LED (``DomeLedError``) as its finish ``error``.
LED_ERROR = "DomeLedError: "


class CardStoppedAtLedError(SessionError):
    """The card session stopped at an error about one LED (a dead one, say), which a resume or
    a new card session meets again: the caller adds how to shoot the card without it. ``led``
    is the LED of the first step not captured (the one it stopped at), None if not known."""

    def __init__(self, message: str, led: int | None) -> None:
        super().__init__(message)
        self.led = led


def _stopped_dead(runner: dict[str, Any], error: str, led: int | None) -> bool:
    """Whether a card session stopped at dead LED ``led``: from the run's typed record
    (``runner.led_error``, :func:`dead_led_recorded`), the same fact ``run`` advises from;
    a manifest written before that record is judged by :func:`_refused`."""
    if "led_error" in runner:
        return led is not None and dead_led_recorded(runner) == led
    return _refused(error, led)


def _refused(error: str, led: int | None) -> bool:
    """Whether a run's recorded LED error is the board refusing that LED (a dead one, sensed by
    its current), which a resume meets again: for manifests without ``runner.led_error``.

    Why: the other errors about one LED pass: a board that rebooted while the LED was lit (its
    power supply or USB cable) or an LED left on past ``max_on_s`` stop the run too, which says
    to resume, and a card session stopped by them had been told to repair the LED and shoot the
    card without it. The dome driver words a refusal "LED <n> refused: <the firmware's
    reason>"."""
    return led is not None and f"LED {led} refused: " in error


def _serial_table(manifest: dict[str, Any]) -> dict[str, Any]:
    config = (manifest.get("rig") or {}).get("config") or {}
    return (config.get("dome") or {}).get("serial") or {}


def read_card_session(root: Path | str, rig_name: str | None = None) -> CardSession:
    """Load a finished dome session of a calibration card (its linear images, downsampled).

    Raises :class:`SessionError` naming the session and image for what cannot calibrate: not a
    dome session, a session shot without a serial dome (the simulated backend), one that did
    not finish, or whose runs were shot with different configs or calibrations, an LED shot
    twice or outside the dome, a missing image, an image with too many saturated pixels, or a
    manifest that does not say what it should. With ``rig_name``, a session shot on another
    rig is refused before any image is read.
    """
    root = Path(root)
    manifest = read_manifest(root)
    try:
        return _read_card_session(root, manifest, rig_name)
    except (KeyError, IndexError, TypeError, ValueError, AttributeError) as exc:
        raise SessionError(
            f"{shown_path(root)}/manifest.json does not describe a card session rti-rig can read "
            f"({type(exc).__name__}: {exc}); shoot the card again with 'rti-rig run'"
        ) from None


def _card_again(root: Path, rig: dict[str, Any]) -> str:
    """The command that shoots the card again under every LED: the session's own rig config
    (its manifest's ``config_path``) into a folder not there yet beside it.

    Why: "rti-rig run RIG --out CARD_SESSION" had been printed, which pasted ran a rig file
    named RIG. A manifest naming no config leaves the config to the user, said as such."""
    again = free_folder_beside(root, "again")
    config = rig.get("config_path")
    if not isinstance(config, str) or not config:
        return f"rti-rig run with the dome's rig config and --out {shell_word(str(again))}"
    return run_words(Path(config), again)


def refuse_other_rig(root: Path, rig: dict[str, Any], rig_name: str | None) -> None:
    """Refuse card session ``root`` (its manifest's ``rig``) if shot on another rig than
    ``rig_name``.

    Why public: ``calibrate-lights`` asks it from the manifest it reads before anything else,
    ahead of its refusal of a calibration file already beside the card. A card calibrated
    already, given another rig's config, had been sent to write its file elsewhere
    (``--out``), and only then told that the card is another rig's."""
    if rig_name is not None and rig.get("name") != rig_name:
        # the name is what tells two domes of one model apart (the same LEDs, positions and
        # firmware): a card is one dome's. A renamed config had been left with no way on
        raise SessionError(
            f"{shown_path(root)} was shot on rig '{rig.get('name')}', not '{rig_name}': calibrate "
            "a dome from its own card session (each dome's LEDs differ, even on two domes of "
            f"one model); if '{rig_name}' is that same dome renamed, give its config's name "
            f"back, name = {toml_basic_string(str(rig.get('name')))}, to calibrate it"
        )


def _read_card_session(root: Path, manifest: dict[str, Any], rig_name: str | None) -> CardSession:
    rig = manifest["rig"]
    refuse_other_rig(root, rig, rig_name)
    steps = manifest.get("steps") or []
    if rig.get("kind") != "dome":
        raise SessionError(
            f"{shown_path(root)}: a session of the {rig.get('kind')!r} rig '{rig.get('name')}'; "
            "light calibration is for domes (an arm carries one lamp, which every image shares)"
        )
    serial = _serial_table(manifest)
    if not serial:
        raise SessionError(
            f"{shown_path(root)}: shot on rig '{rig.get('name')}' without a [dome.serial] table "
            f"(backend {rig.get('backend')!r}): only a serial dome can dim its LEDs; shoot the "
            "card on the hardware (or emulated) rig"
        )
    planned = manifest["schedule"]["steps"]
    finish = (manifest.get("runner") or {}).get("finish_reason")
    if finish != "completed" or len(steps) != len(planned):
        # counted from the journal: the manifest lists a run's steps only once it finishes, so
        # a killed card session had been said to hold "0 of 48 images" with 20 on disk
        done = {r["index"] for r in scan_journal(root, image_names(len(planned))).records}
        taken = len(done)
        runner = manifest.get("runner") or {}
        error = str(runner.get("error") or "")
        stopped = next((k for k in range(len(planned)) if k not in done), None)
        led = None if stopped is None else planned[stopped].get("led")
        if not isinstance(led, int) or isinstance(led, bool):
            led = None
        if finish == "error" and error.startswith(LED_ERROR) and _stopped_dead(runner, error, led):
            # a resume lights the same LED first, and a new card session lights it too: "continue
            # it with --resume, or shoot the card again" led back to the same stop
            raise CardStoppedAtLedError(
                f"{shown_path(root)}: the card session stopped at an LED after "
                f"{max(taken, len(steps))} of {len(planned)} images "
                f"({error.removeprefix(LED_ERROR)}); a resume, or the card shot again, lights "
                "that LED again",
                led,
            )
        raise SessionError(
            f"{shown_path(root)}: the card session did not finish "
            f"({finish or 'no finish recorded'}, {max(taken, len(steps))} of {len(planned)} "
            "images): continue it with rti-rig run "
            f"--resume {shell_word(str(root))}, or shoot the card again"
        )
    shot_with = {run.get("config_sha256") for run in manifest.get("runs") or []}
    shot_with.discard(None)
    if len(shot_with | {rig.get("config_sha256")}) > 1:
        raise SessionError(
            f"{shown_path(root)}: the card session was resumed with a changed rig config or light "
            "calibration, so its images were not all shot with the same LED correction; shoot "
            "the card again"
        )
    if len(steps) < 4:
        raise SessionError(
            f"{shown_path(root)}: {len(steps)} image(s); shoot the card under every LED of the "
            f"dome (with no --lights): {_card_again(root, rig)}"
        )
    directions = _step_directions(root, steps)
    refuse_unverified(root, steps, len(planned))
    correction = serial.get("intensity_correction")
    max_level = int(serial.get("max_level", 255))
    exposures = np.array([float(s["exposure_s"]) for s in steps])
    _refuse_saturated(root, manifest, steps, exposures)
    images, drive, leds, names = [], [], [], []
    image_of: dict[int, str] = {}
    seen: dict[int, str] = {}
    for s, exposure in zip(steps, exposures, strict=True):
        led, name = s["led"], s["linear_image"]
        if isinstance(led, bool) or not isinstance(led, int) or led < 0:
            raise SessionError(
                f"{shown_path(root)}: step {s['index'] + 1} ({name}) records LED {led!r}"
            )
        if led in seen:
            raise SessionError(
                f"{shown_path(root)}: LED {led} lit both {seen[led]} and {name}; a card session "
                "shoots each LED once"
            )
        seen[led] = name
        path = root / name
        try:
            pixels = read_linear_tiff(path)
        except (OSError, ValueError) as exc:
            raise SessionError(f"{shown_path(path)} (LED {led}) cannot be read: {exc}") from None
        images.append(_work_image(pixels))
        intensity = float(planned[s["index"]].get("intensity", 1.0))
        factor = 1.0 if correction is None or led >= len(correction) else float(correction[led])
        level = max(round(intensity * factor * max_level), 1) / max_level
        # what reached the sensor is ∝ PWM level × exposure time
        drive.append(level * exposure / exposures.max())
        leds.append(led)
        names.append(name)
        image_of[led] = str(s.get("image") or name)
    return CardSession(
        root=root,
        rig_name=str(rig.get("name")),
        images=np.stack(images),
        directions=directions,
        leds=np.array(leds, dtype=np.intp),
        drive=np.array(drive),
        correction=None if correction is None else tuple(float(v) for v in correction),
        image_of=image_of,
    )


def step_direction(step: Any) -> NDArray[np.float64] | None:
    """The direction a card session's step records as lit (its ``actual_direction``), or None
    where it records none that is a direction (missing, not three finite numbers, or zero).

    Why one reader: the card is read at these directions (:func:`_step_directions`), and
    calibrate-lights compares an older session's LEDs at them
    (:mod:`rti_rig.app.usecases.calibrate`); each had its own test of what counts as one."""
    try:
        direction = np.asarray(step.get("actual_direction"), dtype=np.float64)
    except (AttributeError, TypeError, ValueError):
        return None
    if direction.shape != (3,) or not np.all(np.isfinite(direction)) or not direction.any():
        return None
    return direction


def _step_directions(root: Path, steps: list[dict[str, Any]]) -> NDArray[np.float64]:
    """The direction each step of the card session records as lit, refused by step when one
    records none, before any image is read.

    Why: the card is read at the positions its steps recorded, and a step without one (a
    manifest edited or damaged outside rti-rig) was refused as "does not describe a card
    session (KeyError: 'actual_direction')", after every image had been read, naming neither
    the step nor its image."""
    out = []
    for k, step in enumerate(steps):
        direction = step.get("actual_direction")
        light = step_direction(step)
        if light is None:
            index = step.get("index")
            which = f"step {index + 1}" if isinstance(index, int) else f"step {k + 1}"
            image = step.get("image") or step.get("linear_image") or "its image"
            what = "no light" if direction is None else f"the light {direction!r}, not a direction"
            raise SessionError(
                f"{shown_path(root)}/{MANIFEST}: {which} ({image}, LED {step.get('led')!r}) "
                f"records {what} ('actual_direction' is "
                f"{'missing' if direction is None else 'unreadable'}), so the direction that lit "
                f"it is not known and the card cannot be read at it: restore {MANIFEST} from a "
                "backup copy of the folder, or shoot the card again with rti-rig run"
            )
        out.append(light)
    return np.array(out, dtype=np.float64)


def _refuse_saturated(
    root: Path, manifest: dict[str, Any], steps: list[dict[str, Any]], exposures: np.ndarray
) -> None:
    """Refuse a card session with clipped images, naming every one and an exposure to try.

    The advice had been "rti-rig run --auto-exposure meters one", also for a session that
    --auto-exposure had metered: it meters at the nominally brightest LEDs (one, or up to six on
    an uncalibrated dome), and on a card (every pixel at one level) under an uncalibrated dome a
    brighter LED clipped the whole frame."""
    clipped = [s for s in steps if float(s.get("saturated_fraction") or 0.0) > MAX_SATURATED]
    if not clipped:
        return
    worst = max(clipped, key=lambda s: float(s["saturated_fraction"]))
    listed = ", ".join(f"{s['linear_image']} (LED {s['led']})" for s in clipped[:5]) + (
        f" and {len(clipped) - 5} more" if len(clipped) > 5 else ""
    )
    exposure = float(exposures.min())
    provenance = (manifest.get("schedule") or {}).get("provenance") or {}
    metered = provenance.get("exposure")
    why = ""
    if isinstance(metered, dict):
        # a session --auto-exposure metered at several LEDs (an uncalibrated dome's, since it
        # recorded lights_metered_at_steps) had been said to be metered "at one LED"
        lights = metered.get("lights_metered_at_steps")
        count = len(lights) if isinstance(lights, list) and lights else 1
        at = "one LED" if count == 1 else f"{count} LEDs"
        other = "a brighter one" if count == 1 else "a brighter one it did not meter at"
        why = (
            f"--auto-exposure metered this session at {at}, and an uncalibrated dome's LEDs "
            f"differ by tens of percent, so {other} clipped the card: "
        )
    raise SessionError(
        f"{shown_path(root)}/{worst['linear_image']} (LED {worst['led']}): "
        f"{100 * float(worst['saturated_fraction']):.1f} % of its pixels are saturated "
        f"({len(clipped)} of {len(steps)} images clipped over {100 * MAX_SATURATED:g} %: "
        f"{listed}); {why}shoot the card again with a shorter fixed exposure, e.g. "
        f"exposure_s = {exposure / 2:.4g} under [camera] in the rig config (half the "
        f"session's {exposure:.4g} s), without --auto-exposure"
    )


def refuse_unverified(
    root: Path,
    steps: list[dict[str, Any]],
    total: int,
    what: str = "card",
    instead: str = "shoot the card again",
    harm: str = "a calibration measured from them would misjudge those LEDs, or all of them",
) -> None:
    """Refuse a card (or sphere: ``what``) session whose linear TIFFs are not as captured
    (checked against the journal's checksums), saying what to do ``instead`` of restoring
    them: one halved TIFF had read as a dome "0.37 of the median", and the correction written
    from it would have dimmed every other LED; two sphere images swapped had given two LEDs
    directions 30° off, written into the dome's .lp without a word."""
    scan = scan_journal(root, image_names(total))
    verified = verified_steps(root, scan.records, only="linear_image")
    recorded = {rec["index"] for rec in scan.records}
    bad = []
    for s in steps:
        if s["index"] in verified:
            continue
        name = s["linear_image"]
        if not (root / name).is_file():
            bad.append(f"{name} (LED {s['led']}) missing")
        elif s["index"] in recorded:
            bad.append(f"{name} (LED {s['led']}) changed since capture")
        else:
            bad.append(f"{name} (LED {s['led']}) has no readable record in {JOURNAL}")
    if bad:
        shown = "; ".join(bad[:6]) + (f"; and {len(bad) - 6} more" if len(bad) > 6 else "")
        raise SessionError(
            f"{shown_path(root)}: {len(bad)} {what} image(s) not as captured ({shown}): "
            f"{harm}; restore the originals from a backup copy of the folder, or {instead}"
        )


def card_spread_deg(card: CardSession) -> float:
    """How far the card session's images are from a flat card's: the 90th percentile of the
    angle between each pixel's least-squares photometric-stereo normal and their mean. A level
    card gives about a degree; an object's relief, tens (the coin scene of the emulated dome:
    35°), and its "gains" would be its relief's, not the LEDs'."""
    from rti_rig.reconstruct import fit_photometric_stereo

    ps = fit_photometric_stereo(card.images, card.directions, robust=False)
    normals = ps.normals[ps.valid].astype(np.float64)
    if len(normals) == 0:
        return float("inf")
    mean = normals.mean(axis=0)
    mean /= max(float(np.linalg.norm(mean)), 1e-12)
    angles = np.degrees(np.arccos(np.clip(normals @ mean, -1.0, 1.0)))
    return float(np.percentile(angles, 90))


def _work_image(pixels: NDArray[Any]) -> NDArray[np.float32]:
    """Grey linear float32, area-averaged so its long side is at most :data:`WORK_SIZE`."""
    small = downsample(pixels, WORK_SIZE)
    return (small.mean(axis=2) if small.ndim == 3 else small).astype(np.float32)


#: The fewest measured LEDs the gain estimate takes (:func:`estimate_light_gains`).
MIN_MEASURED_LEDS = 4


def _check_enough_above(
    card: CardSession, card_normal: Sequence[float], min_elevation_deg: float
) -> None:
    """Refuse, naming ``--min-elevation-deg``, a floor that leaves too few LEDs to measure.

    Why: the gain estimate's own refusal ("only 0 lights light the card at shading >= 0.985:
    need 4; is the card's normal right?") pointed at the card's normal when the floor the user
    gave was the cause."""
    normal = np.asarray(card_normal, dtype=np.float64)
    normal = normal / np.linalg.norm(normal)
    above = np.degrees(np.arcsin(np.clip(card.directions @ normal, -1.0, 1.0)))
    usable = int((above >= min_elevation_deg - 1e-9).sum())
    if usable < MIN_MEASURED_LEDS:
        raise ReconstructionError(
            f"{shown_path(card.root)}: only {usable} of its {len(above)} LEDs are at or above "
            f"--min-elevation-deg {min_elevation_deg:g} above the card (the highest at "
            f"{float(above.max()):.1f}°), and measuring needs at least {MIN_MEASURED_LEDS}: "
            "lower --min-elevation-deg (default 5)"
        )


def calibrate_dome(
    card: CardSession,
    led_count: int,
    *,
    card_normal: Sequence[float] = (0.0, 0.0, 1.0),
    min_elevation_deg: float = 5.0,
) -> LightCalibration:
    """The correction that evens out a dome of ``led_count`` LEDs, from its card session.

    LEDs lower than ``min_elevation_deg`` above the card, or not in the session, are not
    measured: they are assumed to give, under the correction in force when the card was shot,
    the median measured LED's light under it (so an earlier calibration of them is kept). Raises
    :class:`ReconstructionError` (from the gain estimate) for a dead LED, a card too dark to
    measure or images that do not pair with their lights, and :class:`SessionError` for an LED
    index outside the dome.
    """
    outside = (card.leds < 0) | (card.leds >= led_count)
    if outside.any():
        bad = int(card.leds[outside][0])
        raise SessionError(
            f"{shown_path(card.root)}: LED {bad} is outside a dome of {led_count} LEDs; was the "
            "card shot on another rig?"
        )
    if not 0.0 < min_elevation_deg < 90.0:
        raise ReconstructionError(f"min_elevation_deg must be in (0, 90), got {min_elevation_deg}")
    _check_enough_above(card, card_normal, min_elevation_deg)
    gains = estimate_light_gains(
        card.images,
        card.directions,
        target_normal=card_normal,
        min_shading=math.sin(math.radians(min_elevation_deg)),
    )
    previous = np.ones(led_count) if card.correction is None else np.array(card.correction)
    if len(previous) != led_count:
        raise SessionError(
            f"{shown_path(card.root)}: shot with {len(previous)} correction factors, but the dome "
            f"has {led_count} LEDs; was the card shot on another rig?"
        )
    est = gains.estimated
    power = gains.gains / card.drive  # each measured LED's own output, up to a common scale
    power = power / np.exp(np.median(np.log(power[est])))
    measured = np.zeros(led_count, dtype=bool)
    measured[card.leds[est]] = True
    output = np.empty(led_count)
    output[card.leds[est]] = power[est]
    # an LED not measured is assumed to give, under the correction in force, the median
    # measured LED's light under it (with no correction: the median LED's light)
    evened = float(np.median(output[measured] * previous[measured]))
    output[~measured] = evened / previous[~measured]
    correction = output.min() / output
    log_gains = np.log(gains.gains[est])
    return LightCalibration(
        output=output,
        measured=measured,
        correction=correction,
        previous=previous,
        shot_spread=float(np.sqrt(np.mean((log_gains - np.median(log_gains)) ** 2))),
    )


def evened_sentence(cal: LightCalibration, digits: int) -> str:
    """What the correction evens out, as the report and the file's comment say it.

    Why "every measured LED" on a partial card session: an LED the card did not shoot is only
    assumed at the median (or at the figure of the correction in force), so its correction
    dims it by a guess. "Every LED gives 0.74 of the median" was said from a 12-LED card
    session of a dome whose unmeasured LED 38 then still gave 1.17 (the full card shot under
    that correction spread 16 % RMS)."""
    light = f"{cal.evened_light:.{digits}f} of the median LED's light"
    stops = f"({cal.stops_lost:.2f} stop(s) more exposure)"
    if cal.measured.all():
        return f"Evened out, every LED gives {light} {stops}"
    unmeasured = int((~cal.measured).sum())
    # one is the common case (a card shot under all but a dead LED, as its refusal advises):
    # it had been said as "the 1 not measured are dimmed by a guess of their light"
    they = (
        "is dimmed by a guess of its light, so it stays as uneven as it was"
        if unmeasured == 1
        else "are dimmed by a guess of their light, so they stay as uneven as they were"
    )
    return (
        f"Evened out, every measured LED gives {light} {stops}; the {unmeasured} not "
        f"measured {they}"
    )


def calibration_toml(
    cal: LightCalibration, rig_name: str, session: Path, dome: DomeGeometry
) -> str:
    """The calibration file: the correction list plus the evidence, as commented TOML.

    ``dome`` names the weakest LED in the comments, by its number and direction.
    """
    created = datetime.now(UTC).isoformat(timespec="seconds")
    weakest = int(np.argmin(cal.output))

    def listing(items: list[str]) -> str:
        rows = (", ".join(items[i : i + 8]) for i in range(0, len(items), 8))
        return "[\n" + "".join(f"  {r},\n" for r in rows) + "]"

    def floats(values: NDArray[np.float64]) -> str:
        return listing([f"{v:.4f}" for v in values])

    lines = [
        f"# Light calibration of dome '{rig_name}' from the card session "
        f"{toml_basic_string(_as_text(session))}.",
        "# Use it from the rig config, under [dome.serial]:",
        '#   intensity_correction_file = "<path of this file, relative to the config>"',
        "# then shoot the card again and calibrate that session: its spread is what is left.",
        f"# Measured {int(cal.measured.sum())} of {len(cal.output)} LEDs; the unmeasured ones "
        "are assumed to give the median LED's light under the correction in force.",
        f"# Spread of the lights as shot (RMS of ln gain): {cal.shot_spread:.3f}; weakest "
        f"{dome.led_said(weakest)} at "
        f"{cal.output[weakest]:.3f} of the median.",
        f"# {evened_sentence(cal, 3)}.",
        f'format = "{FORMAT}"',
        f"rig = {toml_basic_string(rig_name)}",
        f"session = {toml_basic_string(_as_text(session))}",
        f'created = "{created}"',
        f"measured = {listing(['true' if m else 'false' for m in cal.measured])}",
        "# each LED's output at full drive relative to the median measured LED, LED order",
        f"relative_output = {floats(cal.output)}",
        "# PWM factor per LED, LED order (the dome driver multiplies each level by it)",
        f"intensity_correction = {floats(cal.correction)}",
        "",
    ]
    return "\n".join(lines)


def _as_text(path: Path) -> str:
    """``path`` as text a TOML file (UTF-8) can hold: a byte of its name that is not UTF-8 is
    written ``\\xHH``, as Python shows it.

    Why: a card session in a folder whose name is not UTF-8 ended calibrate-lights with a
    traceback (UnicodeEncodeError) as the file was written, after the whole measurement; its
    name is only a record here (nothing reads it back as a path)."""
    return os.fsencode(path).decode("utf-8", "backslashreplace")
