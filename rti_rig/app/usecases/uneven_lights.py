"""A bright image that an uncalibrated dome's own LED explains is no reason to reshoot it.

Why: the QA verdict judges each image against a fit of the others, and called an image
"1.6× brighter than the other images predict" — advice: reshoot — also where the image was
exactly what its LED gives. A real dome's LEDs differ by tens of percent, and a reshoot under the
same LED gives the same image. Where the session's gains scatter light to light as uneven LEDs
make them (:data:`rti_rig.reconstruct.qa.LIGHT_SCATTER_MIN`), the bright image lies within that
scatter (:data:`~rti_rig.reconstruct.qa.LIGHT_SCATTER_Z`) and the dome can be evened out but
was not (a serial dome with no ``intensity_correction`` applied), the verdict points to
``rti-rig calibrate-lights`` instead. A dome whose firmware cannot dim an LED (an on/off
sketch such as nab-rti-v1: :func:`~rti_rig.drivers.led_dome.settings.dimming_refusal_of`, the
answer ``calibrate-lights`` itself refuses by) is no different in its images, but the verdict
says so and points to dividing a card's gains out of them instead of to a command that refuses
it. Anywhere else — a calibrated dome, an arm (one lamp), an
object no rendering explains (gloss), an image far brighter than the scatter — the reshoot
stands: a stray flash or a wrong exposure is a fault of that image.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from rti_rig.app.config import MEASURED_KEY
from rti_rig.core.shell_words import shell_word
from rti_rig.drivers.led_dome.settings import (
    DomeSerialSettings,
    FramedOptions,
    dimming_refusal_of,
)
from rti_rig.reconstruct.qa import BRIGHTER, QAReport


def uncalibrated_serial_dome(manifest: dict[str, Any]) -> bool:
    """True if the session was shot on a dome driven over a serial link (a recorded
    ``[dome.serial]`` table: its LEDs are real, so they differ) with no light calibration
    applied (no ``intensity_correction``, which a calibration file is read into)."""
    serial = _dome_serial(manifest)
    if serial is None:
        return False
    return "intensity_correction" not in serial and "intensity_correction_file" not in serial


def recorded_dimming_refusal(manifest: dict[str, Any]) -> str | None:
    """Why the session's recorded dome link cannot dim an LED (naming its firmware), or None
    where it can or the session has no ``[dome.serial]``.

    Read from the recorded table as the loaded settings are read (the same
    :func:`dimming_refusal_of`), not by building the settings: an older session's table may
    hold keys this version refuses or files no longer there. The table is the config as
    written, so a key it leaves out is the settings' default, read from their model
    (``profile``, ``[dome.serial.framed] send_level``) rather than restated. A profile name
    this version does not know (one since renamed) is said as such and taken for one that
    cannot dim: this rti-rig cannot drive it, so ``calibrate-lights`` could not load that
    config and is no command to advise."""
    serial = _dome_serial(manifest)
    if serial is None:
        return None
    profile = str(serial.get("profile", DomeSerialSettings.model_fields["profile"].default))
    framed = serial.get("framed")
    unsaid: bool = FramedOptions.model_fields["send_level"].default
    send_level = framed.get("send_level", unsaid) if isinstance(framed, dict) else unsaid
    try:
        return dimming_refusal_of(profile, bool(send_level))
    except KeyError:
        return (
            f"the recorded profile {profile!r} is no profile this rti-rig can drive, so it "
            "cannot dim its LEDs"
        )


def card_commands(manifest: dict[str, Any], session: Path | None) -> str:
    """How to even the dome out, as commands that paste: a card session shot under every LED
    on the rig config the session recorded, beside the session, then ``calibrate-lights`` on
    it (docs/guide.md, section 6).

    Why: the verdict named ``rti-rig calibrate-lights`` alone, which pasted is refused for its
    missing card session and ``--rig``; the config and the folder are known here. A session
    that recorded no config path (an older one) is told the shape of the commands instead."""
    config = str((manifest.get("rig") or {}).get("config_path") or "")
    guide = "docs/guide.md, section 6"
    if not config:
        return (
            "a level matte white card shot under every LED with rti-rig run on this dome's rig "
            f"config, then rti-rig calibrate-lights on that session with --rig and the config; "
            f"{guide}"
        )
    card = shell_word(session.parent / f"{session.name}-card") if session else "sessions/card"
    rig = shell_word(config)
    this = (
        f"; if this session is such a card: rti-rig calibrate-lights {shell_word(session)} "
        f"--rig {rig}"
        if session
        else ""
    )
    return (
        f"a level matte white card filling the frame, shot under every LED: rti-rig run {rig} "
        f"--out {card}, then rti-rig calibrate-lights {card} --rig {rig}{this}; {guide}"
    )


def unmeasured_leds(manifest: dict[str, Any]) -> frozenset[int]:
    """The LEDs the session's light calibration did not measure (assumed to give the median
    light, so not evened out): a card shot under only some LEDs. Empty where the calibration
    measured every LED, or does not say (a correction typed into the config)."""
    serial = _dome_serial(manifest) or {}
    measured = serial.get(MEASURED_KEY)
    if not isinstance(measured, list):
        return frozenset()
    return frozenset(i for i, m in enumerate(measured) if not m)


def _dome_serial(manifest: dict[str, Any]) -> dict[str, Any] | None:
    """The recorded ``[dome.serial]`` table of the session's rig, if it is such a dome."""
    rig = manifest.get("rig") or {}
    if rig.get("kind") != "dome":
        return None
    config = rig.get("config") or {}
    serial = (config.get("dome") or {}).get("serial")
    return serial if isinstance(serial, dict) and serial else None


def with_uneven_lights(
    qa: QAReport, manifest: dict[str, Any], session: Path | None = None
) -> QAReport:
    """``qa`` with its bright images that the dome's uneven LEDs explain taken off the reshoot
    list, and the verdict pointing to what evens them out (unchanged where
    the session's rig or evidence does not allow it: see the module's docstring).

    A calibration that measured only some LEDs leaves the others uneven: a bright image under
    one of those is explained as on an uncalibrated dome (its reshoot had been asked for),
    one under a measured LED is not.

    On a dome that cannot dim (an on/off firmware) the images stay off the reshoot list (a
    reshoot under the same LED repeats them), and the verdict says the firmware cannot even
    them out and what can: a card's gains divided out of the images in Python.

    ``session`` (the session's folder) names the card session's folder beside it in the
    commands the verdict gives (:func:`card_commands`)."""
    cannot_dim = recorded_dimming_refusal(manifest)
    if cannot_dim is not None:
        # with or without a recorded correction: an older session's correction on such a link
        # was never applied (every LED lit at full light), so every LED is as uneven as shot
        bright = qa.bright_within_light_scatter()
        why = "on a dome whose LEDs cannot be dimmed"
        fix = (
            f", and {cannot_dim}, so no light correction can even it out: to take the "
            "unevenness out of the images, shoot a level matte card under every LED and divide "
            "its gains out of them in Python (rti_rig.reconstruct.estimate_light_gains, "
            'apply_light_gains; docs/reconstruction.md, "Light gains")'
        )
    elif uncalibrated_serial_dome(manifest):
        bright = qa.bright_within_light_scatter()
        why = "and no light calibration applied"
        card = card_commands(manifest, session)
        fix = f": even out the LEDs with rti-rig calibrate-lights ({card})"
    else:
        unmeasured = unmeasured_leds(manifest)
        led_of = {
            Path(str(s.get("image", ""))).stem: s.get("led") for s in manifest.get("steps") or []
        }
        bright = [c for c in qa.bright_within_light_scatter() if led_of.get(c.name) in unmeasured]
        why = "under LEDs the light calibration did not measure"
        card = card_commands(manifest, session)
        fix = f": calibrate them with rti-rig calibrate-lights ({card})"
    if not bright:
        return qa
    listed = ", ".join(f"{c.name} ({c.gain:.1f}×)" for c in bright)
    verb = "is" if len(bright) == 1 else "are"
    its = "its LED's own light" if len(bright) == 1 else "their LEDs' own light"
    note = (
        f"the dome's LEDs are uneven: {listed} {verb} {BRIGHTER}, within the spread of this "
        f"session's lights ({100 * qa.light_scatter:.0f} % RMS from image to image, {why}), "
        f"so it is {its}, which a reshoot repeats{fix}"
    )
    return qa.explain_bright_by_lights(note, only={c.index for c in bright})
