"""Where the planner's preview image and its light come from (the CLI's edge, file reads only).

A preview shot on a rig is an image *and* the light that made it; the planner reads the light's
direction far better than it can estimate it from the image. So when the user does not give
``--preview-light``, the light is taken from what already records it:

* an rti-rig session folder holding one image (``rti-rig preview`` writes one): its linear
  image, and the direction that actually fired, from the manifest;
* an image with an `.lp` beside it that lists it (an rti-rig session's ``lights.lp``, a dome's
  acquisition ``.lp``; for a session's ``linear/`` TIFF, the session's ``lights.lp`` lists the
  JPEG of the same number).

Two `.lp` files that disagree about the light are an error, not a guess.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from rti_rig.errors import RtiRigError, ScheduleError
from rti_rig.geometry import angle_between_deg, az_el_from_direction
from rti_rig.lp_format import read_lp
from rti_rig.session import LINEAR_DIR, LP_NAME, MANIFEST, session_lp_entries

#: `.lp` files whose directions for one image differ by more than this (degrees) disagree.
AGREE_DEG = 0.5


@dataclass(frozen=True)
class PreviewSource:
    """The preview image file, and its light (azimuth, elevation in degrees) when recorded."""

    image: Path
    light_az_el_deg: tuple[float, float] | None = None
    light_source: str | None = None


def _az_el(direction: tuple[float, float, float]) -> tuple[float, float]:
    az, el = az_el_from_direction(np.asarray(direction, dtype=np.float64))
    return float(az), float(el)


def lights_listing(image: Path) -> list[tuple[Path, tuple[float, float, float]]]:
    """``(lp file, direction)`` for every readable `.lp` beside ``image`` that lists it.

    An entry lists the image when its name, relative to the `.lp`'s folder, is the image file;
    a session's ``lights.lp`` also lists the ``linear/`` TIFF of the same number. `.lp` files
    that cannot be read are skipped: the user did not name them.
    """
    target = image.resolve()
    folders = [image.parent]
    if image.parent.name == LINEAR_DIR:
        folders.append(image.parent.parent)
    found = []
    for folder in folders:
        for lp in sorted(folder.glob("*.lp")):
            try:
                entries = read_lp(lp)
            except RtiRigError:
                continue
            for e in entries:
                named = (lp.parent / e.name).resolve()
                same_number = (
                    folder != image.parent
                    and lp.name == LP_NAME
                    and Path(e.name).stem == image.stem
                )
                if named == target or same_number:
                    found.append((lp, e.direction))
                    break
    return found


def resolve_preview(path: Path) -> PreviewSource:
    """The preview image behind ``path`` (a file or a one-image session) and its light."""
    if path.is_dir():
        if not (path / MANIFEST).is_file():
            raise ScheduleError(
                f"{path} is a folder: give one preview image file, or a session folder from "
                "'rti-rig preview'"
            )
        entries = session_lp_entries(path, linear=True)
        if len(entries) != 1:
            raise ScheduleError(
                f"{path} is a session of {len(entries)} images: give the one to plan from, e.g. "
                f"{path / entries[0].name}"
            )
        image = path / entries[0].name
        return PreviewSource(
            image,
            _lit_from_above(entries[0].direction, path / LP_NAME, image),
            f"recorded by the session {path.name}",
        )
    found = lights_listing(path) if path.is_file() else []
    if not found:
        return PreviewSource(path)
    first_lp, first = found[0]
    for lp, d in found[1:]:
        off = float(angle_between_deg(np.asarray(first), np.asarray(d)))
        if off > AGREE_DEG:
            raise ScheduleError(
                f"{first_lp.name} and {lp.name} beside {path.name} give its light {off:.1f}° "
                "apart: give the preview's light with --preview-light AZ,EL"
            )
    return PreviewSource(
        path, _lit_from_above(first, first_lp, path), f"from {first_lp.name} beside the preview"
    )


def _lit_from_above(
    direction: tuple[float, float, float], record: Path, image: Path
) -> tuple[float, float]:
    """The recorded light as (azimuth, elevation), refused if it cannot have lit the object."""
    az_el = _az_el(direction)
    if not az_el[1] > 0.0:
        raise ScheduleError(
            f"{record}: the light it lists for {image.name} is at {az_el[1]:.1f}° elevation, at "
            "or below the object plane, so it cannot have lit the preview: fix the .lp, or give "
            "the light with --preview-light AZ,EL"
        )
    return az_el
