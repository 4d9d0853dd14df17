"""A bright image that an uncalibrated dome's own LED explains is no reason to reshoot it.

Why: the QA verdict judges each image against a fit of the others, and called an image
"1.6× brighter than the other images predict" — advice: reshoot — also where the image was
exactly what its LED gives. A real dome's LEDs differ by tens of percent, and a reshoot under the
same LED gives the same image. Where the session's gains scatter light to light as uneven LEDs
make them (:data:`rti_rig.reconstruct.qa.LIGHT_SCATTER_MIN`), the bright image lies within that
scatter (:data:`~rti_rig.reconstruct.qa.LIGHT_SCATTER_Z`) and the dome can be evened out but
was not (a serial dome with no ``intensity_correction`` applied), the verdict points to
``rti-rig calibrate-lights`` instead. Anywhere else — a calibrated dome, an arm (one lamp), an
object no rendering explains (gloss), an image far brighter than the scatter — the reshoot
stands: a stray flash or a wrong exposure is a fault of that image.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from rti_rig.app.config import MEASURED_KEY
from rti_rig.reconstruct.qa import BRIGHTER, QAReport


def calibratable_uncalibrated_dome(manifest: dict[str, Any]) -> bool:
    """True if the session was shot on a dome that can dim its LEDs one by one (a
    ``[dome.serial]`` table: what ``rti-rig calibrate-lights`` needs) with no light calibration
    applied (no ``intensity_correction``, which a calibration file is read into)."""
    serial = _dome_serial(manifest)
    if serial is None:
        return False
    return "intensity_correction" not in serial and "intensity_correction_file" not in serial


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


def with_uneven_lights(qa: QAReport, manifest: dict[str, Any]) -> QAReport:
    """``qa`` with its bright images that the dome's uneven LEDs explain taken off the reshoot
    list, and the verdict pointing to ``rti-rig calibrate-lights`` for them (unchanged where
    the session's rig or evidence does not allow it: see the module's docstring).

    A calibration that measured only some LEDs leaves the others uneven: a bright image under
    one of those is explained as on an uncalibrated dome (its reshoot had been asked for),
    one under a measured LED is not."""
    if calibratable_uncalibrated_dome(manifest):
        bright = qa.bright_within_light_scatter()
        why, fix = "and no light calibration applied", "even out the LEDs with"
    else:
        unmeasured = unmeasured_leds(manifest)
        led_of = {
            Path(str(s.get("image", ""))).stem: s.get("led") for s in manifest.get("steps") or []
        }
        bright = [c for c in qa.bright_within_light_scatter() if led_of.get(c.name) in unmeasured]
        why = "under LEDs the light calibration did not measure"
        fix = "calibrate them with"
    if not bright:
        return qa
    listed = ", ".join(f"{c.name} ({c.gain:.1f}×)" for c in bright)
    verb = "is" if len(bright) == 1 else "are"
    its = "its LED's own light" if len(bright) == 1 else "their LEDs' own light"
    note = (
        f"the dome's LEDs are uneven: {listed} {verb} {BRIGHTER}, within the spread of this "
        f"session's lights ({100 * qa.light_scatter:.0f} % RMS from image to image, {why}), "
        f"so it is {its}, which a reshoot repeats: {fix} rti-rig calibrate-lights (a card "
        "shot under every LED; docs/guide.md, section 6)"
    )
    return qa.explain_bright_by_lights(note, only={c.index for c in bright})
