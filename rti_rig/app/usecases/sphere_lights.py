"""`rti-rig lights-from-sphere`: a dome's LED directions from a session of a reflective sphere.

Why: a new dome has no ``.lp`` yet. The user shoots one session under every LED with a black
glossy or chrome sphere in frame (a dome config with ``layout = "fibonacci"`` and ``count`` =
its LEDs stands in for the directions while shooting), and this measures each LED's direction
from the sphere's highlight (:mod:`rti_rig.reconstruct.sphere_lights`) and writes the dome's
``.lp``, line i = LED i, for ``layout = "lp"``. An LED whose highlight cannot be measured is
named with why, and no ``.lp`` is written: a guessed line would be fitted as if measured.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from rti_rig.app.light_calibration import refuse_unverified
from rti_rig.app.output_files import check_output_file, session_rig_inputs
from rti_rig.app.usecases.run_options import run_words
from rti_rig.core.errors import RtiRigError, SessionError
from rti_rig.core.image_files import linear_tiff_white_level, read_linear_tiff
from rti_rig.core.lp_format import LpEntry, write_lp
from rti_rig.core.out_folders import free_folder_beside
from rti_rig.core.shell_words import shell_word, shown_path
from rti_rig.reconstruct.sphere_lights import (
    Circle,
    Highlight,
    Rejected,
    SphereCircleError,
    as_grey,
    find_highlight,
    outline_circle,
)
from rti_rig.runtime.disowned import refuse_if_disowned
from rti_rig.runtime.flash_sync import CameraTriggeredLighting
from rti_rig.runtime.session import planned_steps, read_manifest, unresumable


@dataclass(frozen=True)
class SphereRequest:
    """What the command was asked: the session, the sphere's circle, the ``.lp`` to write."""

    session: Path
    circle: Circle
    out: Path
    force: bool = False


@dataclass(frozen=True)
class SphereLights:
    """Each LED's image and highlight, in LED index order, and the ``.lp`` written."""

    out: Path
    images: tuple[str, ...]
    highlights: tuple[Highlight, ...]
    #: the rig config the session was shot with (its manifest's), None if it names none
    config: Path | None = None
    #: what the user should hear of the measurement (a circle the images' outline disputes)
    notes: tuple[str, ...] = ()
    #: the [dome] layout the session was shot with ("fibonacci", "rings", "lp"; its
    #: manifest's), whose keys the measured .lp replaces; None if it names none
    layout: str | None = None


def _steps_by_led(root: Path, manifest: dict[str, Any]) -> list[dict[str, Any]]:
    """The session's captured steps in LED order, when it shot every LED of its dome once."""
    rig = manifest.get("rig") or {}
    if rig.get("kind") != "dome":
        raise SessionError(
            f"{shown_path(root)}: a session of the {rig.get('kind')!r} rig '{rig.get('name')}'; "
            "light directions from a sphere are measured for a dome's LEDs"
        )
    count = len(((rig.get("identity") or {}).get("light_directions")) or [])
    steps = manifest.get("steps") or []
    by_led: dict[int, dict[str, Any]] = {}
    for step in steps:
        led = step.get("led")
        if isinstance(led, int) and not isinstance(led, bool):
            if led in by_led:
                raise SessionError(
                    f"{shown_path(root)}: LED {led} was shot twice ({by_led[led]['image']} and "
                    f"{step.get('image')}): shoot the sphere once under every LED"
                )
            by_led[led] = step
    missing = [k for k in range(count) if k not in by_led]
    finish = (manifest.get("runner") or {}).get("finish_reason")
    flash_synced = ((rig.get("config") or {}).get("dome") or {}).get("flash_sync") is not None
    config = rig.get("config_path")
    if missing and finish != "completed" and flash_synced and isinstance(config, str) and config:
        # a dome the camera's flash steps cannot resume: its own count went on
        raise SessionError(
            f"{shown_path(root)}: the session did not finish ({finish or 'no finish recorded'}; "
            f"{len(by_led)} of the dome's {count} LEDs shot). "
            + CameraTriggeredLighting.resume_hint(
                shell_word(config), shell_word(str(free_folder_beside(root, "sphere")))
            )
        )
    if missing and finish != "completed":
        # a stopped session has the images it shot: "shoot it again" would throw them away.
        # Its stop may be one a resume meets again (an LED the firmware refused), which its
        # run said: the resume is for once that is put right, not at once
        raise SessionError(
            f"{shown_path(root)}: the session did not finish ({finish or 'no finish recorded'}; "
            f"{len(by_led)} of the dome's {count} LEDs shot): once what stopped it, as its run "
            f"said, is put right, continue it with rti-rig run --resume "
            f"{shell_word(str(root))}, then measure it"
        )
    if not count or missing:
        again = (
            run_words(Path(config), free_folder_beside(root, "sphere"))
            if isinstance(config, str) and config
            else "rti-rig run with the dome's config"
        )
        said = ", ".join(str(k) for k in missing[:10]) + (" …" if len(missing) > 10 else "")
        raise SessionError(
            f"{shown_path(root)}: the session has images of {len(by_led)} of the dome's "
            f"{count} LEDs (missing: {said or 'all'}); a dome's .lp needs every LED: shoot the "
            f"sphere under all of them ({again}, without --lights or --plan)"
        )
    return [by_led[k] for k in range(count)]


def _grey_image(root: Path, step: dict[str, Any]) -> tuple[np.ndarray, float, str]:
    """A step's image as linear grey (its linear TIFF where the session kept one), the value
    of a clipped pixel, and the image's name to say."""
    import cv2

    name = str(step.get("image"))
    linear = step.get("linear_image")
    path = root / str(linear) if linear and (root / str(linear)).is_file() else root / name
    try:
        if path.suffix.lower() in (".tif", ".tiff"):
            pixels = read_linear_tiff(path)
        else:
            pixels = cv2.imread(str(path), cv2.IMREAD_UNCHANGED)
    except Exception as exc:  # tifffile and OpenCV raise many kinds for a damaged file
        raise SessionError(f"{shown_path(path)} cannot be read ({exc}): is it complete?") from None
    if pixels is None:
        raise SessionError(f"{shown_path(path)} cannot be read as an image: is it there?")
    white = float(np.iinfo(pixels.dtype).max) if pixels.dtype.kind in "ui" else 1.0
    if path.suffix.lower() in (".tif", ".tiff"):
        # a replay of 12-bit data keeps its codes: its label says the white (4095)
        white = float(linear_tiff_white_level(path) or white)
    return as_grey(pixels), white, name


def lights_from_sphere(request: SphereRequest) -> SphereLights:
    """Measure every LED's direction from the sphere session and write the dome's ``.lp``.

    Raises :class:`SessionError` naming the session, the image or the file: a session that is
    not a dome's, misses an LED, an image unreadable or without a usable highlight (all such
    images listed, with why), or an ``--out`` that is there already without ``force``."""
    root = Path(request.session)
    out = Path(request.out)
    lights_lp = root / "lights.lp"
    if out.exists() and lights_lp.exists() and out.resolve() == lights_lp.resolve():
        raise SessionError(
            f"{shown_path(out)} is the session's own record of what ran: give --out another "
            "file (e.g. my_dome.lp beside the dome's config)"
        )
    if out.is_file() and not request.force:
        raise SessionError(
            f"{shown_path(out)} is there already: give --out another file, or add --force to "
            "replace it (nothing was measured or written)"
        )
    manifest = read_manifest(root)
    config = (manifest.get("rig") or {}).get("config_path")
    # a session's files, the rig config and what it reads are never replaced, --force or not
    check_output_file(out, request.force, session_rig_inputs(config))
    refuse_if_disowned(root)
    steps = _steps_by_led(root, manifest)
    # a camera-triggered dome cannot reshoot one image: what it can do instead is said
    instead = unresumable(root)
    refuse_unverified(
        root,
        steps,
        planned_steps(manifest),
        "sphere",
        f"reshoot them: rti-rig run --resume {shell_word(str(root))} --reshoot-lost"
        if instead is None
        else instead[0].lower() + instead[1:],
        "directions measured from them would be wrong for those LEDs",
    )
    found: list[Highlight] = []
    names: list[str] = []
    refused: list[str] = []
    crops: list[np.ndarray] = []  # around the sphere, for its outline
    every = -(-len(steps) // _OUTLINE_IMAGES)  # at most that many kept: a median's worth
    for led, step in enumerate(steps):
        grey, white, name = _grey_image(root, step)
        if led % every == 0:
            crops.append(_around(grey, request.circle))
        try:
            result = find_highlight(grey, request.circle, white)
        except SphereCircleError as exc:
            raise RtiRigError(f"--sphere: {exc}") from None
        if isinstance(result, Rejected):
            refused.append(f"{name} (LED {led}): {result.reason}")
        else:
            found.append(result)
            names.append(name)
    if refused:
        raise SessionError(
            f"{shown_path(root)}: {len(refused)} of {len(steps)} images give no direction, so "
            f"nothing was written to {shown_path(out)}:\n  " + "\n  ".join(refused)
        )
    width = max(2, len(str(len(found) - 1)))
    entries = [LpEntry(f"led_{k:0{width}d}.jpg", h.direction) for k, h in enumerate(found)]
    write_lp(out, entries)
    shot_with = Path(config) if isinstance(config, str) and config else None
    notes = _circle_disputed(crops, request.circle, shown_path(root / str(steps[0]["image"])))
    layout = (((manifest.get("rig") or {}).get("config") or {}).get("dome") or {}).get("layout")
    shot_layout = layout if isinstance(layout, str) else None
    return SphereLights(out, tuple(names), tuple(found), shot_with, notes, shot_layout)


#: How far around the circle (× its radius) the outline is looked for: the crop kept of each
#: image, so a 24-megapixel session's outline costs the sphere's pixels, not the frames'.
_AROUND = 1.4
#: The images whose median shows the outline, at most (evenly spread over the LEDs: each
#: highlight is in one of them, so the median has none); a 600 px sphere's crops then take
#: under 200 MB.
_OUTLINE_IMAGES = 15


def _around(grey: np.ndarray, circle: Circle) -> np.ndarray:
    """The part of ``grey`` around ``circle`` (float32), where its outline is searched."""
    x0, y0, x1, y1 = _crop_box(circle)
    return grey[y0:y1, x0:x1].astype(np.float32)


def _crop_box(circle: Circle) -> tuple[int, int, int, int]:
    """(first column, first row, end column, end row) of the crop :func:`_around` takes."""
    reach = int(np.ceil(_AROUND * circle.radius))
    cx, cy = int(np.floor(circle.x)), int(np.floor(circle.y))
    return max(0, cx - reach), max(0, cy - reach), cx + reach + 1, cy + reach + 1


def _circle_disputed(crops: list[np.ndarray], circle: Circle, first: str) -> tuple[str, ...]:
    """A note when the centre of the sphere's outline in the images (their median: the
    highlights gone) is found clearly and lies off the circle's centre given by more than a
    pixel and by more than about 1° of direction near the sphere's centre (a pixel is about
    115°/R there, more towards the rim); none otherwise.

    Why: ``--sphere`` 3 px off (R = 48) had moved every LED by 7°, written without a word,
    though the outline stood in every image (:func:`outline_circle`). The centre only: a
    glossy sphere's bright rim, a chrome sphere's band mirroring the ground and a shadow's
    halo are rings about the same centre, which the steepest step along a ray may take for
    the outline, so the radius found is no evidence (a warning had then advised a worse
    radius); the centre stays right to a twentieth of a pixel. A note, not a refusal: an
    outline can be another's (a stand, a shadow on a dark ground), the user judges."""
    x0, y0, _, _ = _crop_box(circle)
    local = Circle(circle.x - x0, circle.y - y0, circle.radius)
    found = outline_circle(np.median(np.stack(crops), axis=0), local)
    if found is None:
        return ()
    cx, cy = found.x + x0, found.y + y0
    off = math.hypot(cx - circle.x, cy - circle.y)
    per_px = math.degrees(2.0 / circle.radius)  # a normal's tilt doubles in the reflection
    if off <= max(1.0, 1.0 / per_px):
        return ()
    given = ",".join(f"{v:g}" for v in (circle.x, circle.y, circle.radius))
    again = f"{cx:.1f},{cy:.1f},{circle.radius:g}"
    return (
        f"the sphere's outline in the images is centred at column {cx:.1f}, row {cy:.1f} "
        f"(open {first} to see it), {off:.1f} px from the centre of --sphere {given}: near the "
        f"sphere's centre a direction moves about {per_px:.1f}° per pixel the circle is off "
        f"(more towards its rim), so these may be off by {off * per_px:.0f}° or more; if that "
        f"is the sphere's outline, measure again with --sphere {again} (the radius as given: "
        "check it against the image too)",
    )
