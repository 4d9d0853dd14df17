"""Use case: measure each LED of a dome from a card session and write its intensity correction.

What ``rti-rig calibrate-lights`` does, without the command line: the card session (a level
matte white card shot under every LED with ``rti-rig run``) gives each LED's own light
(:mod:`rti_rig.app.light_calibration`); the correction that evens the dome out is written as a
TOML file for ``[dome.serial] intensity_correction_file``. Nothing is measured before every
input and the output are checked, and a card session's own calibration file is never replaced.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from rti_rig.app.config import LoadedRig, load_rig_config, rig_geometry
from rti_rig.app.light_calibration import (
    MAX_CARD_SPREAD_DEG,
    CardSession,
    CardStoppedAtLedError,
    LightCalibration,
    calibrate_dome,
    calibration_toml,
    card_spread_deg,
    read_card_session,
    refuse_other_rig,
    step_direction,
)
from rti_rig.app.output_files import check_output_file, rig_inputs
from rti_rig.app.usecases.run_options import run_words
from rti_rig.core.errors import RtiRigError
from rti_rig.core.out_folders import file_beside, free_folder_beside, free_name
from rti_rig.core.rig_geometry import ArmGeometry, DomeGeometry
from rti_rig.core.shell_words import shell_word, shown_path
from rti_rig.drivers.led_dome.settings import DIMMING_LINK, IMAGE_GAINS_REMEDY
from rti_rig.reconstruct.light_gains import DeadLightError


@dataclass(frozen=True)
class CalibrateRequest:
    card_session: Path
    rig_config: Path
    #: None: CARD_SESSION/light_calibration.toml (never replaced).
    out_file: Path | None = None
    #: The card's unit normal (up out of the card, towards the camera).
    card_normal: tuple[float, float, float] = (0.0, 0.0, 1.0)
    min_elevation_deg: float = 5.0
    force: bool = False
    #: Skip the check that the images are of a flat card (see ``MAX_CARD_SPREAD_DEG``).
    not_flat_ok: bool = False

    @property
    def target(self) -> Path:
        return self.out_file or self.card_session / "light_calibration.toml"


@dataclass(frozen=True)
class CalibrationWritten:
    calibration: LightCalibration
    card: CardSession
    loaded: LoadedRig
    geometry: DomeGeometry | ArmGeometry
    target: Path
    #: What the user should know of how the card session was read (LEDs re-measured since).
    notes: tuple[str, ...] = ()


def _check_dome_can_dim(req: CalibrateRequest, loaded: LoadedRig) -> None:
    serial = loaded.config.dome.serial if loaded.config.dome else None
    if serial is None:
        # why it has none, said as it is: an arm's or a camera-triggered dome's had been told
        # "the simulated backend's are exact", true only of a simulated dome
        rig = f"{shown_path(req.rig_config)}: rig '{loaded.config.name}'"
        if loaded.config.kind != "dome":
            raise RtiRigError(
                f"{rig} is an arm: calibrate-lights evens out the LEDs of a dome driven over a "
                "serial link ([dome.serial]); an arm's lamp is one light, with nothing to even out"
            )
        if loaded.config.backend == "simulated":
            why = "a simulated dome's LEDs are exact, with nothing to even out"
        else:
            why = "only a dome driven over a serial link can dim its LEDs"
        raise RtiRigError(f"{rig} has no [dome.serial]: {why}")

    # the link's declared fact, not its codec's: every firmware profile had been given a binary
    # codec that "carries a level", and an on/off sketch's correction was written and then
    # silently not applied
    why = serial.dimming_refusal()
    if why is not None:
        raise RtiRigError(
            f"{shown_path(req.rig_config)}: {why}, so a light correction could not be applied to "
            f"it. A correction needs {DIMMING_LINK}; on this dome, divide the gains out of the "
            f"images instead ({IMAGE_GAINS_REMEDY})"
        )


def _dead_led_advice(
    req: CalibrateRequest, card: CardSession, geometry: DomeGeometry, exc: DeadLightError
) -> str:
    """A dark card image named as the LED and session image it is, with what can be done.

    Why: the refusal said "light 20 gives 0.000 of the median light's signal ...; check that
    light and drop its image": "light 20" is the 21st image of the session (image_021, the one
    the QA verdict calls misfired), not an LED number, and a card session with an image
    removed is refused as not as captured. A card shot under every other LED (a ``--plan`` of
    the session's own lights.lp without that line) is what calibrates the rest."""
    led = int(card.leds[exc.light])
    image = card.image_of.get(led, f"image {exc.light + 1}")
    # its number and direction, the image to open beside them
    said = geometry.led_fields(led) if 0 <= led < geometry.count else f"LED {led}"
    number, _, rest = f"{said}, ".partition(", ")
    session_lp = shell_word(str(Path(req.card_session) / "lights.lp"))
    return (
        f"{shown_path(req.card_session)}: {number} ({rest}session image {image}) gave "
        f"{exc.gain:.3f} of the median LED's light: a dead LED (or a black frame), which no "
        "correction can even out. Check that LED and its wiring, then shoot the card again; to "
        "calibrate the other LEDs meanwhile, shoot the card under all but it: copy "
        f"{session_lp} without the line of {image} (the count on its first line one less) "
        f"{_shoot_and_calibrate(req, f'without-led-{led}')}"
    )


def _shoot_and_calibrate(req: CalibrateRequest, tag: str) -> str:
    """The end of a dead LED's advice: the plan's name, the card session that shoots it and
    the calibration of that session, in real names beside the card session that do not exist
    yet (``tag`` in each). Why: ``as PLAN.lp … --out NEW_CARD and calibrate NEW_CARD`` had
    been said, which pasted made a folder named NEW_CARD, and no calibrate command."""
    card = Path(req.card_session)
    plan = shell_word(str(free_name(card.with_name(f"{card.name}-{tag}.lp"))))
    new_card = shell_word(str(free_folder_beside(card, tag)))
    rig = shell_word(str(req.rig_config))
    return (
        f"as {plan}, run rti-rig run {rig} --plan {plan} --out {new_card} and calibrate that "
        f"with rti-rig calibrate-lights {new_card} --rig {rig}"
    )


def calibrate_words(
    req: CalibrateRequest, out_file: Path | None = None, *, not_flat_ok: bool = False
) -> str:
    """``rti-rig calibrate-lights CARD --rig RIG`` with the request's own options (``out_file``
    for its ``--out`` where given), each a shell word: the command a refusal advises, pasteable.

    Why: the refusals said "give --out" and "give --not-flat-ok", and the user had to rebuild
    the command, the --card-normal and --min-elevation-deg they had typed included."""
    words = [
        "rti-rig calibrate-lights",
        shell_word(str(req.card_session)),
        "--rig",
        shell_word(str(req.rig_config)),
    ]
    out = out_file or req.out_file
    if out is not None:
        words += ["--out", shell_word(str(out))]
    if tuple(req.card_normal) != (0.0, 0.0, 1.0):
        words += ["--card-normal", ",".join(f"{c:.6g}" for c in req.card_normal)]
    if req.min_elevation_deg != CalibrateRequest.min_elevation_deg:
        words += ["--min-elevation-deg", f"{req.min_elevation_deg:g}"]
    if req.force and out_file is None:
        words.append("--force")
    if req.not_flat_ok or not_flat_ok:
        words.append("--not-flat-ok")
    return " ".join(words)


def _without_led(req: CalibrateRequest, loaded: LoadedRig, which: str, led: int | None) -> str:
    """How to calibrate the other LEDs while ``which`` LED waits for repair: a card session of
    a plan that leaves it out (an LED not in a card session is assumed at the median)."""
    dome = loaded.config.dome
    lp = (
        f"{shell_word(str(loaded.folder / dome.lp_file))} (the rig's LED .lp)"
        if dome is not None and dome.lp_file
        else "a list of every LED's direction (x y z, as rti-rig plan writes them)"
    )
    return (
        f"Repair {which} or its wiring and shoot the card again; to calibrate the other LEDs "
        f"meanwhile, copy {lp} without the line of {which} (the count on its first line one "
        f"less) {_shoot_and_calibrate(req, 'others' if led is None else f'without-led-{led}')}"
    )


#: The identity keys that say which LED a number is: the correction is a list by LED number.
LED_KEYS = ("lights", "light_positions", "light_directions", "dome_firmware")


def _refuse_other_leds(req: CalibrateRequest, loaded: LoadedRig) -> str | None:
    """Refuse a card session shot on another rig, or while the rig's LEDs were others than
    ``--rig`` gives now;
    the note to say where they are the same LEDs re-measured, else None.

    Why: the correction is written per LED number and only the rig's name was compared. A
    config of the same name whose ``.lp`` lists the LEDs in another order (or another count,
    or another controller board, which may number them otherwise) had its LED 18 (led_42.jpg)
    given the correction measured under the card session's LED 18 (led_18.jpg), with no word.
    A session recorded before identities were is not asked (as a resume does not ask it).
    Decided from the manifest alone, before any card image is read: a card of other LEDs
    had every image read first, and one with images missing was refused for those instead.
    LEDs that moved only as a re-measured ``.lp`` moves them (each still nearest its own
    recorded position) are the same LEDs: they had been refused as "others", though the
    correction by LED number holds for them (:func:`_same_leds_re_measured`)."""
    from rti_rig.app.rig_identity import identity_differences, rig_identity
    from rti_rig.runtime.session import read_manifest

    manifest = read_manifest(req.card_session)
    rig = manifest.get("rig") or {}
    if not isinstance(rig, dict):
        return None  # a manifest that says no rig: refused where the card session is read
    # another rig's card, refused before a calibration already beside it (told to write that
    # elsewhere first, the user had learnt only then that no file of this card fits this rig)
    refuse_other_rig(Path(req.card_session), rig, loaded.config.name)
    recorded = rig.get("identity")
    if not isinstance(recorded, dict):
        return None
    now = rig_identity(loaded)
    diffs = identity_differences(
        {k: recorded[k] for k in LED_KEYS if k in recorded},
        {k: now.get(k) for k in LED_KEYS if k in recorded},
    )
    if not diffs:
        return None
    if _same_leds_re_measured(recorded, now, manifest.get("steps")):
        seen = (
            ""
            if isinstance(recorded.get("light_directions"), list)
            else " (as its steps record them: its rig identity holds a digest of them alone)"
        )
        return (
            f"{shown_path(req.card_session)} recorded the dome's LEDs elsewhere than "
            f"{shown_path(req.rig_config)} places them now ({'; '.join(diffs)}), each still "
            f"nearest its own recorded position{seen}: taken as the same LEDs re-measured (the "
            "correction is by LED number, and the card is read at the positions it recorded)"
        )
    raise RtiRigError(
        f"{shown_path(req.card_session)} was shot when the dome's LEDs were others than "
        f"{shown_path(req.rig_config)} gives now ({'; '.join(diffs)}): the correction is a list by "
        "LED number, so it would dim other LEDs than the ones the card measured. Calibrate "
        "with the rig config the card was shot with, or shoot the card again on the rig "
        "as it is now"
    )


def _same_leds_re_measured(recorded: dict[str, Any], now: dict[str, Any], steps: Any) -> bool:
    """True where only the LEDs' positions differ, and each LED's position now is nearer its
    own recorded position than any other LED's (and its recorded position nearer its own
    position now than any other's): a finer ``.lp`` of the same LEDs, not LEDs listed in
    another order (which puts an LED nearest another's recorded position).

    A session recorded when the identity held a digest of the positions alone is compared at
    the positions its steps record for the LEDs it lit: it had been refused as "others" for
    any re-measure, though the card is read at those positions, and a session recorded before
    identities at all is not asked."""
    from rti_rig.app.rig_identity import identity_differences

    others = [k for k in LED_KEYS if k in recorded and k not in _POSITION_KEYS]
    if identity_differences({k: recorded[k] for k in others}, {k: now.get(k) for k in others}):
        return False
    before, after = _recorded_directions(recorded, steps), now.get("light_directions")
    if before is None or not isinstance(after, list) or any(i >= len(after) for i in before):
        return False
    leds = sorted(before)
    was = _unit([before[i] for i in leds])
    is_now = _unit(after)
    nearest_recorded = np.argmax(is_now[leds] @ was.T, axis=1)
    nearest_now = np.argmax(was @ is_now.T, axis=1)
    return bool(
        np.array_equal(nearest_recorded, np.arange(len(leds)))
        and np.array_equal(nearest_now, np.asarray(leds))
    )


def _recorded_directions(recorded: dict[str, Any], steps: Any) -> dict[int, Any] | None:
    """Each LED's recorded position by LED number: the identity's ``light_directions``, or
    for a session recorded with a digest of them alone, where its steps say each LED it lit
    was; None where they cannot be told (a step without an LED or a direction)."""
    listed = recorded.get("light_directions")
    if "light_directions" in recorded:
        return dict(enumerate(listed)) if isinstance(listed, list) and listed else None
    if not isinstance(steps, list) or not steps:
        return None
    out: dict[int, Any] = {}
    for step in steps:
        led = step.get("led") if isinstance(step, dict) else None
        if isinstance(led, bool) or not isinstance(led, int) or led < 0:
            return None
        direction = step_direction(step)
        if direction is None:
            return None
        out[led] = direction
    return out


def _unit(directions: Any) -> np.ndarray:
    vectors = np.asarray(directions, dtype=float)
    return vectors / np.linalg.norm(vectors, axis=1, keepdims=True)


#: The identity keys that hold the LEDs' positions (compared as positions when both are held).
_POSITION_KEYS = ("light_positions", "light_directions")


def calibrate_lights(req: CalibrateRequest) -> CalibrationWritten:
    """Check, measure, and write the calibration file; returns what was measured."""
    loaded = load_rig_config(req.rig_config)
    _check_dome_can_dim(req, loaded)
    geometry = rig_geometry(loaded)
    # from the manifest, before any image is read: a card of other LEDs had every image read
    # (and a card with images missing was refused for them) before the refusal that mattered
    same_leds = _refuse_other_leds(req, loaded)
    # the output too, before any image is read: a session calibrated already had every image
    # read (minutes for a real dome's 48 full-size TIFFs) before the refusal
    target = req.target
    if req.out_file is None and target.exists():
        elsewhere = file_beside(req.card_session, "-light_calibration.toml")
        raise RtiRigError(
            f"{shown_path(target)} exists: this card session was calibrated already (its file is "
            "never replaced, even with --force, which replaces only a file named by --out); to "
            f"write the calibration elsewhere: {calibrate_words(req, out_file=elsewhere)}"
        )
    check_output_file(target, req.force, rig_inputs(req.rig_config, loaded))
    try:
        card = read_card_session(req.card_session, rig_name=loaded.config.name)
    except CardStoppedAtLedError as exc:
        which = (
            geometry.led_said(exc.led)
            if isinstance(geometry, DomeGeometry)
            and exc.led is not None
            and 0 <= exc.led < geometry.count
            else "that LED"
        )
        raise RtiRigError(f"{exc}. {_without_led(req, loaded, which, exc.led)}") from None
    spread = 0.0 if req.not_flat_ok else card_spread_deg(card)
    if spread > MAX_CARD_SPREAD_DEG:
        # an object's session had been "calibrated" into a correction the user was told to
        # install: its relief read as the LEDs' differences
        raise RtiRigError(
            f"{shown_path(req.card_session)}: these images are not of a flat card: their fitted "
            f"normals spread {spread:.0f}° (90th percentile from their mean; a level card gives "
            f"about 1°, the limit is {MAX_CARD_SPREAD_DEG:g}°), so what differs between them is "
            "the object's relief, not the LEDs. Shoot a level matte white card under every LED "
            f"({run_words(req.rig_config, free_folder_beside(req.card_session, 'card'))}); if this "
            f"is one (a card large for its dome): {calibrate_words(req, not_flat_ok=True)}"
        )
    try:
        cal = calibrate_dome(
            card,
            geometry.count,
            card_normal=req.card_normal,
            min_elevation_deg=req.min_elevation_deg,
        )
    except DeadLightError as exc:
        raise RtiRigError(_dead_led_advice(req, card, geometry, exc)) from None
    text = calibration_toml(cal, loaded.config.name, req.card_session.resolve(), geometry)
    # atomically: a write cut off (a full disk, a Ctrl-C) had left a partial file under the
    # name, and a card session's own light_calibration.toml is never replaced, so every later
    # calibrate-lights of the session was refused as "calibrated already"
    tmp = target.with_name(f".{target.name}.tmp")
    try:
        tmp.write_text(text, encoding="utf-8")
        tmp.replace(target)
    except OSError as exc:
        raise RtiRigError(
            f"cannot write {shown_path(target)}: {exc.strerror or exc}; nothing was written there"
        ) from None
    finally:
        tmp.unlink(missing_ok=True)
    notes = () if same_leds is None else (same_leds,)
    return CalibrationWritten(cal, card, loaded, geometry, target, notes)
