"""The adaptive settings a session's manifest records, checked before a resume reads them.

Why: a resume takes the session's stop (target, minimum, factor, terms, lamps) from the
manifest's ``adaptive`` table as given. A value edited to another type (``"abc"`` for
``until_error_deg``, null for ``start_lights``) ended in "unexpected TypeError … please report
it" once the rig was open, and an ``upper_factor`` edited to 0.5 made the stop claim a target
its own estimate had not reached (an "upper" estimate half the point estimate) without a word.
Each value is checked to be of the kind rti-rig writes, from the manifest alone, before
anything in the folder or on the rig is touched; the refusal names the key and the way on.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable
from pathlib import Path
from typing import Any

from rti_rig.core.errors import RtiRigError
from rti_rig.core.shell_words import shown_path


def _number(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value)


def _count(value: Any) -> bool:
    return isinstance(value, int) and not isinstance(value, bool) and value >= 1


def _optional(check: Callable[[Any], bool]) -> Callable[[Any], bool]:
    return lambda value: value is None or check(value)


def _elevation(value: Any) -> bool:
    return _number(value) and 0 <= value <= 90


def _lamps(value: Any) -> bool:
    return value is None or (
        isinstance(value, dict)
        and all(_number(value.get(k)) and value[k] > 0 for k in ("distance_mm", "field_width_mm"))
    )


#: Each recorded setting a resume reads: (what it must be, as said; the check). A key absent
#: is a session begun before it existed (each reader has its default for it), except those in
#: :data:`REQUIRED`.
SETTINGS: dict[str, tuple[str, Callable[[Any], bool]]] = {
    "start_lights": ("a number of lights, at least 1", _count),
    "candidates": ("a number of candidate lights, at least 1", _count),
    "until_error_deg": (
        "null or a target in degrees above 0",
        _optional(lambda v: _number(v) and v > 0),
    ),
    "min_lights": ("null or a number of lights, at least 1", _optional(_count)),
    "design_lights": ("null or a number of lights, at least 1", _optional(_count)),
    "lights_given": ("true or false", lambda v: isinstance(v, bool)),
    "min_elevation_deg": ("an elevation in degrees, 0 to 90", _elevation),
    "max_elevation_deg": ("an elevation in degrees, 0 to 90", _elevation),
    # an upper estimate below the point estimate is no upper bound on the error
    "upper_factor": ("null or a factor of at least 1", _optional(lambda v: _number(v) and v >= 1)),
    "unsolved_deg": ("null or degrees, 0 or more", _optional(lambda v: _number(v) and v >= 0)),
    "misfit_noise_k": ("null or a factor, 0 or more", _optional(lambda v: _number(v) and v >= 0)),
    "lamps": ("null or the lamps' distance_mm and field_width_mm, both above 0", _lamps),
}

#: Settings every adaptive session has recorded (``max_lights`` is checked where the session
#: folder is read: ``rti_rig.runtime.session.read_manifest``).
REQUIRED = ("start_lights", "candidates")


def refuse_damaged_settings(header: dict[str, Any], root: Path) -> None:
    """Refuse the resume of session ``root`` whose adaptive settings (``header``) hold a value
    rti-rig never writes there, naming the first such key and what to do (see the module
    docstring)."""
    for key, (kind, check) in SETTINGS.items():
        if key not in header:
            if key in REQUIRED:
                _refuse(root, f"has no {key}", kind)
            continue
        if not check(header[key]):
            _refuse(root, f"says {key} {json.dumps(header[key])}", kind)
    lo, hi = header.get("min_elevation_deg"), header.get("max_elevation_deg")
    if _number(lo) and _number(hi) and lo > hi:
        _refuse(
            root,
            f"says min_elevation_deg {lo} and max_elevation_deg {hi}",
            "a band, its floor not above its ceiling",
        )
    start, most = header["start_lights"], header.get("max_lights")
    if _count(most) and start > most:
        _refuse(root, f"says start_lights {start} above max_lights {most}", "at most max_lights")


def _refuse(root: Path, said: str, kind: str) -> None:
    raise RtiRigError(
        f"{shown_path(root)}: the manifest.json of this adaptive session {said} in its "
        f'"adaptive" settings, where rti-rig writes {kind} (edited, or damaged by a copy?), so a '
        "resume cannot continue the session as it began. Nothing in the folder was changed: "
        "restore manifest.json from a backup copy of the folder and resume again (export-lp "
        "and fit use the images as they are)"
    )
