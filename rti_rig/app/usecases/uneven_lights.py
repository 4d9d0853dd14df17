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

from typing import Any

from rti_rig.reconstruct.qa import BRIGHTER, QAReport


def calibratable_uncalibrated_dome(manifest: dict[str, Any]) -> bool:
    """True if the session was shot on a dome that can dim its LEDs one by one (a
    ``[dome.serial]`` table: what ``rti-rig calibrate-lights`` needs) with no light calibration
    applied (no ``intensity_correction``, which a calibration file is read into)."""
    rig = manifest.get("rig") or {}
    if rig.get("kind") != "dome":
        return False
    config = rig.get("config") or {}
    serial = (config.get("dome") or {}).get("serial")
    if not isinstance(serial, dict) or not serial:
        return False
    return "intensity_correction" not in serial and "intensity_correction_file" not in serial


def with_uneven_lights(qa: QAReport, manifest: dict[str, Any]) -> QAReport:
    """``qa`` with its bright images that the dome's uneven LEDs explain taken off the reshoot
    list, and the verdict pointing to ``rti-rig calibrate-lights`` for them (unchanged where
    the session's rig or evidence does not allow it: see the module's docstring)."""
    if not calibratable_uncalibrated_dome(manifest):
        return qa
    bright = qa.bright_within_light_scatter()
    if not bright:
        return qa
    listed = ", ".join(f"{c.name} ({c.gain:.1f}×)" for c in bright)
    verb = "is" if len(bright) == 1 else "are"
    its = "its LED's own light" if len(bright) == 1 else "their LEDs' own light"
    note = (
        f"the dome's LEDs are uneven: {listed} {verb} {BRIGHTER}, within the spread of this "
        f"session's lights ({100 * qa.light_scatter:.0f} % RMS from image to image, and no "
        f"light calibration applied), so it is {its}, which a reshoot repeats: even out the "
        "LEDs with rti-rig calibrate-lights (a card shot under every LED; docs/guide.md, "
        "section 6)"
    )
    return qa.explain_bright_by_lights(note)
