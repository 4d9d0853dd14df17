"""The fit a complete session is told to run next, with ``--model ps`` where only that fits.

Why one place: a session whose lights the default fit (``--model auto``) cannot take (three
lights of a band: too few for a PTM or an HSH file, enough for a normal map) was told
``Next: rti-rig fit S --out S-fit`` in every message but the run's own summary, and that
command, pasted, was refused.
"""

from __future__ import annotations

from pathlib import Path

from rti_rig.core.out_folders import fit_beside


def fit_model_for(session: Path) -> str:
    """`` --model ps`` where the fit's default ``--model auto`` fits nothing of the lights in
    ``session``'s lights.lp but photometric stereo makes their normal map ("" otherwise, and
    where there is no lights.lp to read: the fit's own refusal says why)."""
    import numpy as np  # here: the CLI imports this module, and its --help loads no numpy

    from rti_rig.app.normals_determined import undetermined_normals
    from rti_rig.core.fit_minimums import FIT_MINIMUMS, AutoFit
    from rti_rig.core.lp_format import read_lp

    try:
        entries = read_lp(Path(session) / "lights.lp")
    except Exception:
        return ""
    lights = np.array([e.direction for e in entries], dtype=np.float64)
    determined = len(entries) >= FIT_MINIMUMS.normal and undetermined_normals(lights) is None
    if determined and not AutoFit(len(entries), True).fits:
        return " --model ps"
    return ""


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
    from rti_rig.core.lp_format import read_lp
    from rti_rig.core.shell_words import shell_word

    root = Path(session)
    try:
        count = len(read_lp(root / "lights.lp"))
    except Exception:
        count = None
    if count is not None and count < FIT_MINIMUMS.normal:
        return (
            f"no fit: {count} light{' makes' if count == 1 else 's make'} a test shot (a normal "
            f"map needs {FIT_MINIMUMS.normal}); look at the images, or shoot a session of more "
            "lights"
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
    return next_fit(root)
