"""Where the planner's preview image and its light come from (the CLI's edge, file reads only).

A preview shot on a rig is an image *and* the light that made it; the planner reads the light's
direction far better than it can estimate it from the image (on the real icon of
docs/research/planner.md the estimate is 17–59° off, and 106° on a real dome image lit at
16°). So when the user does not give
``--preview-light``, the light is taken from what records it, and only from that:

* an rti-rig session folder holding one image (``rti-rig preview`` writes one): its linear
  image, and the direction that actually fired, as the session records it;
* an image of an rti-rig session (``image_007.jpg``, or ``linear/image_007.tif``): that step's
  direction, as the session records it: its journal's record when the image is as that
  record captured it (a session cut off lists in its manifest only the steps of its last
  finished run), else its manifest's;
* an image that the bare ``.lp`` given as ``--rig`` lists (a dome's acquisition ``.lp``): its
  line there, the user having named that file; else its one line naming it but for upper/lower
  case (``image08.jpg`` listed, ``image08.JPG`` given: one file on Windows and macOS), said
  with both names; two such lines are refused, naming both.

Any other ``.lp`` lying beside the image is *not* read: it may be a plan (whose names look like
a session's) or belong to another acquisition. Two records that disagree are an error.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from rti_rig.core.errors import RtiRigError, ScheduleError
from rti_rig.core.geometry import (
    angle_between_deg,
    az_el_from_direction,
    direction_from_az_el,
)
from rti_rig.core.lp_format import LpEntry, image_path, lights_said
from rti_rig.core.shell_words import shell_word, shown_path
from rti_rig.runtime.session import (
    JOURNAL,
    LINEAR_DIR,
    MANIFEST,
    RAW_DIR,
    image_names,
    planned_steps,
    read_manifest,
    refuse_if_in_use,
    scan_journal,
    verified_steps,
)

#: A bare `.lp` given as ``--rig``: its path and its entries.
RigLp = tuple[Path, Sequence[LpEntry]]

#: Two records of one preview's light more than this far apart (degrees) disagree.
AGREE_DEG = 0.5

#: A --preview-light more than this far (degrees) from the light recorded for the preview is
#: said to differ from it: a light typed by hand is rounded to a degree or so.
GIVEN_DIFFERS_DEG = 1.0


@dataclass(frozen=True)
class PreviewSource:
    """The preview image file, and its light (azimuth, elevation in degrees) when recorded."""

    image: Path
    light_az_el_deg: tuple[float, float] | None = None
    light_source: str | None = None
    #: Which record gave the light, without what :attr:`light_source` adds of how it was read
    #: (a name matched but for upper/lower case: why, and what to do): what a note beside
    #: another light names it by.
    recorded_by: str | None = None
    #: Why no record of the light was found (None where it was, or where it was given):
    #: what the plan says beside the light it then estimates.
    unrecorded: str | None = None


def session_of_image(image: Path) -> Path | None:
    """The rti-rig session folder ``image`` belongs to (its own folder, or the one above a
    session's ``linear/`` or ``raw/`` folder: a DSLR user hands over the camera's RAW), if
    any."""
    folder = image.resolve().parent
    roots = (folder, folder.parent) if folder.name in (LINEAR_DIR, RAW_DIR) else (folder,)
    return next((r for r in roots if (r / MANIFEST).is_file()), None)


def _files_of(step: dict[str, Any]) -> tuple[str, ...]:
    """The session files of one step's record: its JPEG, its linear TIFF, the camera's own."""
    return tuple(
        n
        for n in (step.get("image"), step.get("linear_image"), *(step.get("originals") or {}))
        if n
    )


def _recorded_steps(
    root: Path, light_given: bool = False
) -> tuple[list[dict[str, Any]], dict[int, dict[str, Any]]]:
    """The steps the session records, one per step in step order, and the journal's latest
    record of each step it journaled; an error saying what to do when it records none.

    Why the journal: a session's manifest lists its steps only when a run ends, so one cut off
    (a run killed, a power cut), or a resume of it cut off, holds images its manifest does not
    list, while its journal (``export-lp`` reads it) records every image with the light that
    fired. Their lights had been estimated from the image, 25° off, with no word. Why the
    in-use check: a session still being captured was said to have "no finished images" and
    sent to a ``--resume`` the running capture refuses; ``fit`` and ``export-lp`` say it as
    this does.
    """
    refuse_if_in_use(root, "plan from it")
    manifest = read_manifest(root)
    total = planned_steps(manifest)
    journaled = {
        r["index"]: r for r in scan_journal(root, image_names(total) if total else None).records
    }
    steps = {s["index"]: s for s in manifest.get("steps") or [] if isinstance(s, dict)}
    steps.update((i, r) for i, r in journaled.items() if i not in steps)
    if steps:
        return [steps[i] for i in sorted(steps)], journaled
    resume = f"rti-rig run --resume {shell_word(str(root))}"
    if light_given:  # the light is given: only an image is missing
        raise ScheduleError(
            f"{shown_path(root)}: the session has no finished images; if it was interrupted, "
            f"finish it with {resume} (or shoot the preview again)"
        )
    raise ScheduleError(
        f"{shown_path(root)}: the session has no finished images, so its lights are not recorded "
        f"yet; if it was interrupted, finish it with {resume} (or shoot the preview again), or "
        "give the light with --preview-light AZ,EL"
    )


def _manifest_light(
    root: Path, step: dict[str, Any], image: Path, journal: str
) -> tuple[float, ...]:
    """The direction the manifest's ``step`` records as fired, refused when it records none.

    Why: the manifest's steps are not checked as the journal's records are, and a step
    written without its light (a manifest damaged or edited, no journal beside it to stand in)
    raised a KeyError traceback out of ``rti-rig plan PREVIEW``; the light the user can give is
    what stands in for it. ``journal``: why the journal's record does not (said after "and")."""
    direction = step.get("actual_direction")
    try:
        light = tuple(float(v) for v in direction)  # type: ignore[union-attr]
    except (TypeError, ValueError):
        light = ()
    if len(light) == 3 and all(np.isfinite(light)) and any(light):
        return light
    what = "no light" if direction is None else f"the light {direction!r}, not a direction"
    index = step.get("index")
    which = f"step {index + 1}" if isinstance(index, int) else "the step"
    raise ScheduleError(
        f"{shown_path(root / MANIFEST)}: {which} ({image.name}) records {what} ('actual_direction' "
        f"is {'missing' if direction is None else 'unreadable'}), and {journal}, so the light "
        "that lit the preview is not known: give it with --preview-light AZ,EL"
    )


def _step_light(
    root: Path, step: dict[str, Any], journaled: dict[int, dict[str, Any]], image: Path
) -> Any:
    """The direction that lit ``image`` (a file of ``step``), as the session records it.

    The journal's latest record of the step wins when the image is as that record captured it
    (a step shot again on a resume is journaled again); else the manifest's step, as before;
    an image the journal alone records, changed since, is refused: which shot it is, is not
    known."""
    latest = journaled.get(step["index"])
    if latest is None:
        return _manifest_light(root, step, image, f"{JOURNAL} holds no record of it")
    target = image.resolve()
    kind = next(
        (k for k in ("image", "linear_image") if (root / latest[k]).resolve() == target), None
    )
    if verified_steps(root, [latest], only=kind):
        return latest["actual_direction"]
    if step is not latest and _as_the_manifest_records(root, step, kind):
        journal = f"{JOURNAL}'s record of it does not match the image on disk"
        return _manifest_light(root, step, image, journal)
    raise ScheduleError(
        f"{shown_path(image)}: the image is not as the session {shown_path(root)} captured it "
        "(changed or replaced since; its checksum differs from the one recorded at capture), so "
        "the light recorded for it may not be the one that lit it: put the captured file back, "
        "or give the light with --preview-light AZ,EL"
    )


def _as_the_manifest_records(root: Path, step: dict[str, Any], kind: str | None) -> bool:
    """Whether the manifest's ``step`` (its journal record not matching the image) vouches for
    the image: its checksum matches, or the step holds none to compare (a manifest damaged or
    edited: its light is taken, as before).

    Why: an image copied over a preview's (another session's image_030, lit from az 0°, el
    10°) was planned from as lit by the preview's recorded light (az 112.5°, el 55°), the
    manifest's step taken without its checksum being compared, where fit refuses it."""
    if not isinstance(step.get("sha256"), dict):
        return True
    try:
        return bool(verified_steps(root, [step], only=kind))
    except (KeyError, TypeError, ValueError):
        return True


def _linear_image(root: Path, step: dict[str, Any]) -> str:
    """The linear image a one-image session's step records, refused when it records none.

    Why: a manifest's step written without it (the manifest damaged or edited) raised a
    KeyError traceback out of ``rti-rig plan PREVIEW_DIR``, with or without --preview-light."""
    name = step.get("linear_image")
    if isinstance(name, str) and name:
        return name
    jpeg = step.get("image")
    instead = (
        f"give the image itself as PREVIEW ({root / jpeg})"
        if isinstance(jpeg, str) and jpeg
        else "give the preview's image file itself as PREVIEW"
    )
    raise ScheduleError(
        f"{shown_path(root / MANIFEST)}: its step records no linear image ('linear_image' is "
        f"missing): {instead}"
    )


def _lit_from_above(direction: Any, record: str, image: Path) -> tuple[float, float]:
    """The recorded light as (azimuth, elevation), refused if it cannot have lit the object."""
    az, el = (float(v) for v in az_el_from_direction(np.asarray(direction, dtype=np.float64)))
    if not el > 0.0:
        raise ScheduleError(
            f"{record}: the light it gives for {image.name} is at {el:.1f}° elevation, at or "
            "below the object plane, so it cannot have lit the preview: give the light with "
            "--preview-light AZ,EL"
        )
    return az, el


def _refuse_disowned_label(root: Path) -> None:
    """Refuse the light a disowned session records for its image (its labels may be wrong:
    :mod:`rti_rig.runtime.disowned`), as fit and export-lp refuse the session, with the way
    on that plan has: the light given by hand.

    Why: plan was the one reader that took such a session's label, without a word."""
    from rti_rig.runtime.disowned import DisownedSessionError, refuse_if_disowned

    try:
        refuse_if_disowned(root)
    except DisownedSessionError as exc:
        raise ScheduleError(
            f"{exc}; to plan from its image, give the light it was shot under with "
            "--preview-light AZ,EL"
        ) from None


def _records(image: Path, rig_lp: RigLp | None) -> list[tuple[str, str, Any, str | None]]:
    """``(where, short name, direction, how it was read)`` of every record of ``image``'s light
    (module notes); how it was read is None unless said (:func:`_lp_record`)."""
    target = image.resolve()
    found = []
    root = session_of_image(image)
    if root is not None:
        _refuse_disowned_label(root)
        steps, journaled = _recorded_steps(root)
        for step in steps:
            if any((root / n).resolve() == target for n in _files_of(step)):
                light = _step_light(root, step, journaled, image)
                found.append((f"the session {root}", f"the session {root.name}", light, None))
                break
    if rig_lp is not None:
        found.extend(_lp_record(image, rig_lp))
    return found


@dataclass(frozen=True)
class _LpNames:
    """Which lines of the ``--rig`` ``.lp`` name a preview (indexes into its entries): by its
    very path; by a name differing from it only in upper/lower case that is it (no file of
    that name here, or this file on a system that ignores case); by such a name whose file
    here is another (this system tells the two names apart, and both files exist)."""

    exact: list[int]
    twins: list[int]
    other_files: list[int]


def _same_file(a: Path, b: Path) -> bool:
    """Whether ``a`` and ``b`` are one file on this system (False where either is not there)."""
    try:
        return a.samefile(b)
    except OSError:
        return False


def _lp_names(image: Path, rig_lp: RigLp) -> _LpNames:
    """The lines of ``rig_lp`` that name ``image`` (:class:`_LpNames`).

    Why the case twins: Windows and macOS ignore the case of file names, so an acquisition
    listed there as ``image08.jpg`` may be on disk as ``image08.JPG`` (a camera's own name, a
    card mounted with ``shortname=lower``); a preview of that name matched no line, and its
    light was estimated from its shading, more than 100° from the one recorded. Compared as
    :func:`rti_rig.core.lp_format.case_hint` compares names for ``run``, ``fit`` and ``bench``
    (``str.casefold``), so the commands agree on what a case twin is. A listed name whose own
    file here is another file (both spellings on disk, told apart by this system) names that
    file, not the preview."""
    lp, entries = rig_lp
    target = image.resolve()
    exact: list[int] = []
    twins: list[int] = []
    other_files: list[int] = []
    for i, e in enumerate(entries):
        listed = image_path(lp.parent, e.name).resolve()
        if listed == target:
            exact.append(i)
        elif str(listed).casefold() == str(target).casefold():
            if not listed.exists() or _same_file(listed, target):
                twins.append(i)
            else:
                other_files.append(i)
    return _LpNames(exact, twins, other_files)


def _on_line(entry: LpEntry) -> str:
    """`` on line 4``: where the ``.lp`` holds ``entry``, for a user who opens it to correct
    it (the light's number is not its line: a count line and comments come before); "" for
    an entry not read from a file."""
    return "" if entry.line is None else f" on line {entry.line}"


def _lp_record(image: Path, rig_lp: RigLp) -> list[tuple[str, str, Any, str | None]]:
    """The ``--rig`` ``.lp``'s record of ``image``'s light, as :func:`_records` lists one: its
    line naming the image, else its one line naming it but for upper/lower case (said, with
    both spellings, in the words the plan prints beside the light); two or more such lines
    and none exact are refused, naming them: which of them lit the preview is not ours to
    guess."""
    lp, entries = rig_lp
    names = _lp_names(image, rig_lp)
    if names.exact:
        return [(str(lp), lp.name, entries[names.exact[0]].direction, None)]
    if not names.twins:
        return []
    if len(names.twins) > 1:
        raise ScheduleError(
            f"{shown_path(lp)}: {lights_said(entries, names.twins)} each name the preview "
            f"{image.name} but for upper/lower case (one file on Windows and macOS, which ignore "
            "the case of file names), so which light lit it is not known: correct the names in "
            "the .lp, or give the light with --preview-light AZ,EL"
        )
    (i,) = names.twins
    listed = entries[i].name
    if image_path(lp.parent, listed).exists():  # this system ignores case: one file
        why = "one file here, this system ignoring the case of file names as Windows and macOS do"
    else:
        why = (
            "read as one file, as Windows and macOS read it; this system tells the two "
            "apart, so rename the file or correct the name in the .lp"
        )
    said = (
        f"{lp.name} for {listed}, light {i + 1}{_on_line(entries[i])}, the preview {image.name} "
        "but for upper/lower case"
    )
    return [(f"{lp} (as {listed})", said, entries[i].direction, why)]


def _refuse_a_rig_as_preview(path: Path) -> None:
    """A rig config or an ``.lp`` given where the preview goes (``rti-rig plan RIG.toml``, the
    ``--rig`` forgotten) is said to be one, with where it belongs: it had been told only
    "cannot read this file as an image (JPEG, PNG or TIFF)"."""
    suffix = path.suffix.lower()
    if suffix == ".toml":
        raise ScheduleError(
            f"{shown_path(path)} is a rig config, not a preview image: give it as --rig "
            f"{shell_word(path)} (rti-rig plan [PREVIEW] --rig RIG.toml; without a preview, "
            "uniform, or optimal for a level surface)"
        )
    if suffix == ".lp":
        raise ScheduleError(
            f"{shown_path(path)} is an .lp light list, not a preview image: give it as --rig "
            f"{shell_word(path)} (a dome with exactly those lights), and as PREVIEW one of the "
            "images it lists"
        )


def _unrecorded(image: Path, rig_lp: RigLp | None) -> str:
    """Why ``image`` has no record of its light, from what was looked in (module notes).

    Why: an image of a session that records no step with it (a copy, an image whose journal
    line was never written) had its light estimated with no word of the session at all."""
    root = session_of_image(image)
    where = []
    if root is not None:
        where.append(f"the session {root.name} records no step with {image.name}")
    if rig_lp is not None:
        where.append(f"{rig_lp[0].name} (--rig) does not list it{_other_file_said(image, rig_lp)}")
    if not where:
        return "no rti-rig session or --rig .lp records its light"
    return " and ".join(where)


def _other_file_said(image: Path, rig_lp: RigLp) -> str:
    """What to add to "does not list it" when the ``.lp`` lists the preview's name but for
    upper/lower case and that name's file here is another (:func:`_lp_names`): "" otherwise.

    Why: a user who sees the name in the .lp had been told only that it "does not list it"."""
    entries = rig_lp[1]
    if not image.is_file():
        return ""
    others = _lp_names(image, rig_lp).other_files
    if not others:
        return ""
    i = others[0]
    return (
        f" (its light {i + 1}{_on_line(entries[i])}, {entries[i].name}, differs only in "
        "upper/lower case from "
        f"{image.name} and is another file on this system, which tells the two names apart)"
    )


def resolve_preview(
    path: Path, rig_lp: RigLp | None = None, light_given: bool = False
) -> PreviewSource:
    """The preview image behind ``path`` (a file or a one-image session) and its light.

    ``rig_lp`` is the bare ``.lp`` given as ``--rig`` with its entries (as the caller already
    read them), if it was one. With ``light_given``
    (``--preview-light``) no record of the light is read (of a session folder, only which
    image it holds), so an unreadable or unfinished one cannot stand in the way of the light
    the user gave.
    """
    if not path.exists():  # "preview image not found" had read as a damaged session
        raise ScheduleError(
            f"{shown_path(path)}: no such file or folder: give a preview image, or the session "
            "folder 'rti-rig preview RIG --out DIR' wrote; or plan with no preview: rti-rig "
            "plan --rig RIG --lights N --method optimal --out PLAN.lp"
        )
    if path.is_dir():
        if not (path / MANIFEST).is_file():
            raise ScheduleError(
                f"{shown_path(path)} is a folder: give one preview image file, or a session folder "
                "from 'rti-rig preview'"
            )
        steps, journaled = _recorded_steps(path, light_given)
        if len(steps) != 1:
            raise ScheduleError(
                f"{shown_path(path)} is a session of {len(steps)} images: give the one to plan "
                f"from, e.g. {path / (steps[0].get('linear_image') or 'linear/image_001.tif')}"
            )
        image = path / _linear_image(path, steps[0])
        if light_given:  # the user's light stands: the session's record of it is not read
            return PreviewSource(image)
        where = f"the session {path.resolve().name}"
        _refuse_disowned_label(path)
        light = _lit_from_above(_step_light(path, steps[0], journaled, image), where, image)
        return PreviewSource(image, light, f"recorded by {where}")
    _refuse_a_rig_as_preview(path)
    found = _records(path, rig_lp) if path.is_file() and not light_given else []
    if not found:
        return PreviewSource(path, unrecorded=None if light_given else _unrecorded(path, rig_lp))
    (first_where, short, first, how), *others = found
    for where, _, d, _ in others:
        off = float(angle_between_deg(np.asarray(first), np.asarray(d)))
        if off > AGREE_DEG:
            raise ScheduleError(
                f"{first_where} and {where} give the light of {path} {off:.1f}° apart: give "
                "it with --preview-light AZ,EL"
            )
    light = _lit_from_above(first, first_where, path)
    said = f"recorded by {short}" + (f": {how}" if how else "")
    return PreviewSource(path, light, said, recorded_by=f"recorded by {short}")


def given_light_differs(
    path: Path, given_az_el: tuple[float, float], rig_lp: RigLp | None = None
) -> str | None:
    """A note when ``--preview-light`` is more than :data:`GIVEN_DIFFERS_DEG` from the light a
    session or the ``--rig`` ``.lp`` records for the preview, else None.

    Why: the given light wins, silently, and the relief is read from the shading as that light
    would make it. ``rti-rig plan PREVIEW_DIR --preview-light 135,50`` (the preview's default
    light, typed as the older docs did) planned from a light 14.5° off the LED the dome fired,
    saying only "(given)". Read at its best: a record that cannot be read says nothing, as the
    given light stands in for it (:func:`resolve_preview`)."""
    try:
        source = resolve_preview(path, rig_lp)
    except (RtiRigError, KeyError, IndexError, TypeError, ValueError):
        # a record damaged or written otherwise (a step without its light had raised a
        # KeyError out of plan, where the light given had always stood in for it)
        return None
    if source.light_az_el_deg is None:
        return None
    given = direction_from_az_el(*given_az_el)
    recorded = direction_from_az_el(*source.light_az_el_deg)
    off = float(angle_between_deg(np.asarray(given), np.asarray(recorded)))
    if off <= GIVEN_DIFFERS_DEG:
        return None
    az, el = source.light_az_el_deg
    return (
        f"--preview-light {given_az_el[0]:g},{given_az_el[1]:g} is {off:.1f}° from the light "
        f"{source.recorded_by or source.light_source} (az {az:.1f}°, el {el:.1f}°): the plan "
        "used the light given; "
        "leave --preview-light out to plan with the recorded one"
    )
