"""The fit a complete session is told to run next, with the ``--model`` where only that fits.

Why one place: a session whose lights the default fit (``--model auto``) cannot take (three
lights of a band: too few for a PTM or an HSH file, enough for a normal map) was told
``Next: rti-rig fit S --out S-fit`` in every message but the run's own summary, and that
command, pasted, was refused.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from rti_rig.core.out_folders import fit_beside

if TYPE_CHECKING:
    import numpy as np


def model_for_lights(lights: np.ndarray) -> str | None:
    """The ``--model`` words a fit of ``lights`` needs: ``" --model ps"`` where the default
    ``--model auto`` fits nothing but photometric stereo makes their normal map, ``" --model
    hsh1"`` where they cannot determine a normal and auto fits nothing but an order-1 HSH
    (its 4 coefficients) can be fitted, ``""`` where the default fits them; None where no
    model of ``rti-rig fit`` takes them.

    Why: ``run --allow-no-normals`` of 3 or 4 raking lights at one azimuth named ``rti-rig fit
    S --out S-fit`` as the fit that "still writes the relighting files", and that fit refused
    them (without photometric stereo auto's simplest model needs 5)."""
    from rti_rig.app.normals_determined import undetermined_normals
    from rti_rig.core.fit_minimums import FIT_MINIMUMS, AutoFit

    n = len(lights)
    determined = n >= FIT_MINIMUMS.normal and undetermined_normals(lights) is None
    if AutoFit(n, determined).fits:
        return ""
    if determined:
        return " --model ps"
    return " --model hsh1" if n >= FIT_MINIMUMS.hsh(1) else None


def _lights_of(session: Path) -> np.ndarray | None:
    """The directions in ``session``'s lights.lp, or None where there is none to read (the
    fit's own refusal then says why)."""
    import numpy as np  # here: the CLI imports this module, and its --help loads no numpy

    from rti_rig.core.lp_format import read_lp

    try:
        entries = read_lp(Path(session) / "lights.lp")
    except Exception:
        return None
    return np.array([e.direction for e in entries], dtype=np.float64).reshape(-1, 3)


def fit_model_for(session: Path) -> str:
    """:func:`model_for_lights` of the lights in ``session``'s lights.lp ("" where there is no
    lights.lp to read, or where no model takes them: :func:`next_step` says so)."""
    lights = _lights_of(session)
    return "" if lights is None else model_for_lights(lights) or ""


def next_fit(session: Path) -> str:
    """``rti-rig fit S --out S-fit`` (:func:`~rti_rig.core.out_folders.fit_beside`), with
    ``--model ps`` where the default fit would refuse the session's lights."""
    return fit_beside(session) + fit_model_for(session)


def next_step(session: Path) -> str:
    """What a finished run names as its next step: :func:`next_fit`, or, where no fit takes
    the session, what to do instead (fewer lights than a normal map needs: a test shot; CFA
    mosaics: their RAW files to decode).

    Why: a run of 1 or 2 lights, and one shot with ``decode.mode = "mosaic"``, ended on
    "Next: rti-rig fit S --out S-fit", which fit then refused."""
    import json

    from rti_rig.core.fit_minimums import FIT_MINIMUMS
    from rti_rig.core.shell_words import shell_word

    root = Path(session)
    lights = _lights_of(root)
    count = None if lights is None else len(lights)
    if count is not None and count < FIT_MINIMUMS.normal:
        return (
            f"no fit: {count} light{' makes' if count == 1 else 's make'} a test shot (a normal "
            f"map needs {FIT_MINIMUMS.normal}); look at the images, or shoot a session of more "
            "lights"
        )
    model = None if lights is None else model_for_lights(lights)
    if lights is not None and model is None:
        return (
            f"no fit: {count} lights that cannot determine a normal are too few for any model "
            f"of `rti-rig fit` (an order-1 HSH needs {FIT_MINIMUMS.hsh(1)}); look at the "
            "images, or shoot a session of more lights"
        )
    try:
        with (root / "journal.jsonl").open(encoding="utf-8") as journal:
            first = json.loads(journal.readline() or "{}")
    except (OSError, ValueError):
        first = {}
    decode = first.get("decode") if isinstance(first, dict) else None
    if isinstance(decode, dict) and decode.get("mode") == "mosaic":
        return (
            'no fit of CFA mosaics (decode.mode = "mosaic"): decode the RAW files in '
            f"{shell_word(str(root / 'raw'))} to demosaiced linear TIFFs with your RAW "
            "converter, list them in an .lp and fit that"
        )
    return fit_beside(root) + (model or "")  # next_fit's, the lights read once
