"""A session's QA verdict also names the images lost since capture.

Why: the QA judges the pixels it can read, and ``fit`` reads a session's linear TIFFs; a JPEG
deleted or truncated since capture went unseen and the verdict said "good", while
``lights.lp`` still listed it, so relight (which pairs the ``.lp``'s lines with the folder's
JPEGs in order) gave every later image the wrong light. The journal says what was captured;
:func:`rti_rig.runtime.session.files_lost_since_capture` is the one criterion the verdict and
``run --resume --reshoot-lost`` share.
"""

from __future__ import annotations

import contextlib
import math
from dataclasses import replace
from pathlib import Path
from typing import Any, TypeVar

import numpy as np

from rti_rig.app.usecases.uneven_lights import with_uneven_lights
from rti_rig.core.errors import RtiRigError
from rti_rig.core.lp_format import image_path, lp_files_in, read_lp
from rti_rig.core.shell_words import shell_word, shown_path
from rti_rig.reconstruct.qa import (
    BLACK_ADVICE,
    BLACK_THROUGHOUT,
    EVERY_IMAGE,
    FLAT_ADVICE,
    LESS_EXPOSURE,
    MORE_EXPOSURE,
    MOVED_ADVICE,
    UNCHANGING_ADVICE,
    UNDEREXPOSED,
    QAReport,
)
from rti_rig.runtime.session import (
    JOURNAL,
    LINEAR_DIR,
    LP_NAME,
    MANIFEST,
    RAW_DIR,
    RECORDS_DIR,
    RUN_ENDED,
    STRAY_DIR,
    all_held,
    files_lost_since_capture,
    held_by_acquisition,
    image_names,
    journal_mend_note,
    lost_image_advice,
    lp_again,
    originals_lost,
    planned_steps,
    read_manifest,
    rebuild_advice,
    renamed_note,
    renamed_since_capture,
    scan_journal,
    stopped_while_committing,
    tiff_check_note,
    unchecked_images,
    unresumable,
)
from rti_rig.runtime.unrecorded_end import unrecorded_end

V = TypeVar("V")


def with_lost_files(qa: QAReport, source: Path) -> QAReport:
    """``qa`` with a problem added to each image of session ``source`` whose JPEG or linear
    TIFF is gone or changed since capture (checked against the journal's checksums: a TIFF
    edited after capture changes what a fit reads), a caveat naming the images no journal record
    vouches for, and advice a replayed or adaptive session can follow (unchanged for an
    ``.lp`` acquisition, which has no journal). ``source`` is a session folder, its
    ``lights.lp``, or another ``.lp`` in it: then only the images that ``.lp`` lists (the
    ones fitted and judged) are named."""
    source = Path(source)
    lp = source / LP_NAME
    if source.is_dir() and not lp.is_file():  # the .lp a fit of the folder reads instead
        lp = next(iter(lp_files_in(source)), lp)
    fitted: set[str] | None = None  # the images judged, when not every one of the session's
    if not source.is_dir():
        lp, source = source, source.parent
        if lp.name != LP_NAME:
            # an .lp of the user's own beside a session's images (exported, edited, a subset):
            # its images are checked as lights.lp's are, and only those (it had been fitted
            # without a check: an edited TIFF was judged "good")
            fitted = {c.name for c in qa.images}
    qa = _with_stopped_while_committing(_with_unchecked(qa, source, fitted), source)
    try:
        manifest = read_manifest(source)  # once, for what the session's kind and end allow
    except RtiRigError:
        manifest = None
    if manifest is None and not any((source / n).exists() for n in (MANIFEST, JOURNAL, LINEAR_DIR)):
        # no session record, nor a session's layout (a session that lost its manifest is
        # still rti-rig's, and may be reshot): an acquisition rti-rig did not shoot here,
        # unless what rti-rig writes beside them is still there
        traces = session_traces(source, lp)
        qa = _with_record_missing(qa, traces) if traces else _with_imported(qa)
        qa = _with_unlisted_beside(qa, lp)
    if manifest is not None:
        qa = _with_relabelled(qa, lp, source, manifest)
    if manifest is not None:
        qa = with_uneven_lights(qa, manifest, source)  # a bright image its LED explains
        qa = _with_unfinished(_with_session_kind(qa, manifest), source, manifest)
    renamed = _only(renamed_since_capture(source), fitted)
    if renamed:  # there, under another name: said, and not called lost (nothing to reshoot)
        note = renamed_note(renamed)
        qa = _noted(qa, note)
    lost = _only(files_lost_since_capture(source), fitted)
    if not lost:
        return qa
    if any(
        g.startswith(f"{LINEAR_DIR}/") and g.endswith(" changed") for v in lost.values() for g in v
    ):
        old = tiff_check_note(source)  # a session journaled before pixel checksums: said once
        if old:
            qa = _noted(qa, old)
    todo = lost_image_advice(source, bool(read_manifest(source).get("adaptive")))
    listed = _listed(lp)
    relisted = [n for n, g in lost.items() if f"{n}.jpg" in listed and f"{n}.jpg missing" in g]
    relight = (
        f"{lp.name} still lists {'it' if len(relisted) == 1 else 'them'}, so relight (which "
        "pairs the .lp's lines with the JPEGs in order) gives every later image the wrong light"
    )
    # an image lost that the .lp fitted does not list (a lights.lp written again without it)
    # is said too: it had gone unsaid, the verdict "good", of a session no longer whole
    unlisted = [n for n in sorted(lost) if n not in {c.name for c in qa.images}]
    once = len(lost) > 1 or bool(unlisted)  # the advice said once, not after each of 48 images
    held = held_by_acquisition(source)  # a replay's copies its acquisition still holds
    flawed_before = {c.name for c in qa.images if c.problems}
    images = []
    for check in qa.images:
        gone = lost.get(check.name)
        if gone:
            problem = f"{', '.join(gone)} since capture" + _developed_stand(gone, held)
            if not once:
                problem += f"; {relight}" if check.name in relisted else ""
                problem += f"; {todo}"
            check = replace(check, problems=(*check.problems, problem))
        images.append(check)
    qa = replace(qa, images=tuple(images))
    if once:
        shown = ", ".join(sorted(lost)[:8]) + (
            f" and {len(lost) - 8} more" if len(lost) > 8 else ""
        )
        if unlisted:
            shown += f"; {', '.join(unlisted[:8])}{' …' if len(unlisted) > 8 else ''} not in "
            shown += f"{lp.name}, so not fitted"
        plural = "images" if len(lost) > 1 else "image"
        raws = sorted(n for n, g in lost.items() if originals_lost(g) and not all_held(g, held))
        if raws:  # the camera's originals: lost, though what was fitted of them stands
            shown += (
                f"; of {', '.join(raws[:8])}{' …' if len(raws) > 8 else ''} the RAW original is "
                "lost, the developed JPEG and linear TIFF are as captured and were fitted"
            )
        copies = sorted(n for n, g in lost.items() if originals_lost(g) and all_held(g, held))
        if copies:  # a replay's copies of its recorded files: the acquisition holds them
            shown += (
                f"; of {', '.join(copies[:8])}{' …' if len(copies) > 8 else ''} "
                f"{_held_said(len(copies))}"
            )
        note = f"{len(lost)} {plural} missing or changed since capture ({shown}): {todo}"
        if relisted:
            note += f"; {relight} ({', '.join(relisted[:8])}{' …' if len(relisted) > 8 else ''})"
        qa = _noted(qa, note)
    if unlisted:
        qa = replace(qa, lost_unfitted=tuple(unlisted))
    return _recoverable_word(qa, lost, held, flawed_before)


#: The verdict's word when all it names are a replay's copies in raw/ that the acquisition
#: still holds as recorded: the session is not whole, but one ``cp`` makes it so.
RECOVERABLE = "recoverable"


def _recoverable_word(
    qa: QAReport, lost: dict[str, list[str]], held: dict[str, str], flawed_before: set[str]
) -> QAReport:
    """``qa`` headed "recoverable" where every image it names is so only for its kept copy of
    a recorded file that the acquisition still holds as recorded (``held``), nothing else
    found wrong (``flawed_before``: the images with problems before the lost files were
    added). An image the session itself uses that is damaged keeps the session's word.

    Why: a replay whose copy in raw/ had been deleted was judged "flawed: image_002 (…; copy
    it back from the acquisition: cp …)": the fitted images were as captured and the cp puts
    the copy back; "flawed" told a conservator the recording was at fault. Not "good" (it is
    not whole until the cp: ``qa.json``'s ``good`` stays false)."""
    if flawed_before or qa.lost_unfitted or qa.lights_likely_wrong or qa.lights_mirrored:
        return qa
    named = {c.name for c in qa.reshoot}
    recoverable = {n for n, g in lost.items() if originals_lost(g) and all_held(g, held)}
    if not named or not named <= recoverable:
        return qa
    return replace(qa, verdict_word=RECOVERABLE)


def _held_said(images: int) -> str:
    """What is said of ``images`` images whose kept originals are missing copies a replay's
    acquisition still holds as recorded (:func:`rti_rig.runtime.session.held_by_acquisition`)."""
    if images == 1:
        return (
            "the copy of the recorded file kept in raw/ is missing, the acquisition still "
            "holds it as recorded; the JPEG and linear TIFF are as captured and were fitted"
        )
    return (
        "the copies of the recorded files kept in raw/ are missing, the acquisition still "
        "holds them as recorded; their JPEGs and linear TIFFs are as captured and were fitted"
    )


def _developed_stand(gone: list[str], held: dict[str, str]) -> str:
    """What to add to an image's lost files ``gone`` when only its camera originals are lost:
    the RAW is the original capture, so the image is lost, but its developed JPEG and linear
    TIFF are as captured and were fitted (the verdict had called a missing RAW no reason to
    reshoot while a resume and a rebuild called the step unproven). A replay's copies that
    its acquisition still holds (``held``) are said as such: "the original capture is lost"
    had stood beside the ``cp`` that copies it back."""
    if not originals_lost(gone):
        return ""
    if all_held(gone, held):
        return f": {_held_said(1)}"
    return (
        ": the camera's original capture is lost, its developed JPEG and linear TIFF are as "
        "captured and were fitted"
    )


#: How far (radians) an .lp's light may be from the journal's and still be the same one:
#: 0.1°. Rounding is no edit: lights.lp written again with three decimals (a spreadsheet's,
#: another tool's) moves each light by up to ~0.05°, and had been judged "lights.lp wrong" of
#: every image (1e-4 rad, 0.006°); a light edited or swapped moves by degrees, two decimals'
#: rounding by up to ~0.5°, both still named. An LED's calibration is good to a degree at best.
_SAME_LIGHT_RAD = math.radians(0.1)


def _with_relabelled(qa: QAReport, lp: Path, source: Path, manifest: dict) -> QAReport:  # type: ignore[type-arg]
    """``qa`` with a note naming the images the fitted ``lp`` gives another light than the one
    the journal records as fired (the ``.lp`` edited since capture, or lines swapped).

    Why: lights.lp with two lines' directions swapped by hand was fitted as it was, and the
    verdict said "reshoot: image_002 (wrong light …)": the images were as captured, and the
    journal held the lights that really fired; it is the ``.lp`` to write again."""
    try:
        entries = read_lp(lp)
        total = planned_steps(manifest)
        scan = scan_journal(source, image_names(total) if total else None)
    except (OSError, RtiRigError, ValueError):
        return qa
    records = scan.records
    # a step its record file proves, its journal line (and lights.lp's) never written: not an
    # .lp edited since capture, but a run stopped between the two (said by journal_mend_note)
    proven = {Path(rel).stem for rel in scan.mended}
    fired: dict[str, np.ndarray] = {}
    for rec in records:  # a later record of a step (a reshot image) replaces an earlier one
        d = np.asarray(rec["actual_direction"], dtype=np.float64)
        for name in (rec["image"], rec["linear_image"]):
            fired[name] = d
    differ = []
    for e in entries:
        d = fired.get(e.name)
        if d is None:
            continue
        a = np.asarray(e.direction, dtype=np.float64)
        cos = float(a @ d) / max(float(np.linalg.norm(a) * np.linalg.norm(d)), 1e-12)
        if math.acos(min(1.0, max(-1.0, cos))) > _SAME_LIGHT_RAD:
            differ.append(Path(e.name).stem)
    listed = [e.name for e in entries]
    # relight pairs lights.lp's lines with the folder's JPEGs in name order (a fit pairs by
    # name): lines reordered by hand had been judged "good", every image relit wrongly
    reordered = lp.name == LP_NAME and listed != sorted(listed)
    # a captured image on disk the session's lights.lp leaves out (a line deleted by hand):
    # not fitted, judged "good", and relight pairs 7 lines with 8 JPEGs
    # (one lost or changed since capture is named by the lost-files note, with what to do)
    latest = {rec["index"]: rec for rec in records}
    unlisted: list[str] = []
    if lp.name == LP_NAME:
        candidates = [
            Path(rec["image"]).stem
            for rec in latest.values()
            if rec["image"] not in listed
            and rec["linear_image"] not in listed
            and (source / rec["image"]).is_file()
            and Path(rec["image"]).stem not in proven
        ]
        lost = files_lost_since_capture(source) if candidates else {}
        unlisted = sorted(n for n in candidates if n not in lost)
    if not differ and not reordered and not unlisted:
        return qa
    again = lp_again(
        source / lp.name, linear=any(e.name.startswith(f"{LINEAR_DIR}/") for e in entries)
    )
    if differ:
        shown = ", ".join(differ[:8]) + (f" and {len(differ) - 8} more" if len(differ) > 8 else "")
        note = (
            f"{lp.name} gives {shown} another light than the journal records as fired (the .lp "
            "edited since capture?): the fit paired "
            f"{'it' if len(differ) == 1 else 'them'} with {lp.name}'s, and relight would too; "
            + again
        )
    elif unlisted:
        shown = ", ".join(unlisted[:8]) + (" …" if len(unlisted) > 8 else "")
        note = (
            f"{lp.name} does not list {shown}, captured and on disk (the .lp edited since "
            f"capture?): {'it was' if len(unlisted) == 1 else 'they were'} not fitted, and "
            "relight, which pairs the .lp's lines with the folder's JPEGs in name order, would "
            f"give every later image the wrong light; {again}"
        )
    else:
        note = (
            f"{lp.name} lists the images out of their name order (edited since capture?): the "
            "fit paired each with its own line, but relight pairs the lines with the folder's "
            f"JPEGs in name order, so it would give them the wrong lights; {again}"
        )
    if lp.name != LP_NAME:
        # another .lp of the user's (measured or corrected lights, fitted on purpose): a note,
        # not a defect of the session's own record, which relight reads
        return _integrity_noted(qa, note)
    return replace(qa, lp_defect=f"{qa.lp_defect}; {note}" if qa.lp_defect else note)


def _integrity_noted(qa: QAReport, note: str) -> QAReport:
    """``qa`` with ``note`` added to its integrity note."""
    return replace(qa, integrity_note=f"{qa.integrity_note}; {note}" if qa.integrity_note else note)


def _noted(qa: QAReport, note: str) -> QAReport:
    """``qa`` with ``note`` added to its session note."""
    return replace(qa, session_note=f"{qa.session_note}; {note}" if qa.session_note else note)


def _with_session_kind(qa: QAReport, manifest: dict) -> QAReport:  # type: ignore[type-arg]
    """``qa`` with its advice fitted to what the session can do: a replayed acquisition cannot
    be reshot, and an adaptive one cannot reshoot one image ("reshoot with less exposure" had
    been the advice to both, which neither could follow)."""
    word = "reshoot"
    recorded: dict[str, str] = {}
    if (manifest.get("rig") or {}).get("backend") == "replay":
        word = "flawed"  # "reshoot: …" headed advice that said it could not be
        advice = "clipped in the recording (a replayed acquisition cannot be reshot)"
        if any(LESS_EXPOSURE in p for c in qa.images for p in c.problems):
            recorded = _replayed_names(manifest)  # checks the acquisition: only when named
        note = (
            "this session replays a recorded acquisition: the problems named are the "
            "recording's, and cannot be reshot here"
        )
    elif manifest.get("adaptive"):
        advice = "a new session with a shorter camera.exposure_s avoids it"
        note = (
            "an adaptive session cannot reshoot single images (the lights after each were "
            "chosen from it): the images named are fixed only by a new session"
        )
    else:
        # a planned session keeps one exposure (a resume with another is refused): "reshoot
        # with less exposure" named images no command could shoot again so
        images = tuple(
            replace(c, problems=tuple(_planned_advice(p) for p in c.problems)) for c in qa.images
        )
        return replace(qa, images=images)

    table = REPLAYED_ADVICE if word == "flawed" else ADAPTIVE_ADVICE

    def said(name: str, phrase: str) -> str:
        if phrase != LESS_EXPOSURE:
            return table[phrase]
        if name not in recorded:
            return advice
        return advice.replace("the recording", f"the recording, {recorded[name]}", 1)

    qa = qa.with_advice(said)
    # the note speaks of the images named: none under lights likely wrong, where problems
    # remain that the lights explain (QAReport.named)
    named = bool(qa.named or qa.lost_unfitted)
    return replace(qa, session_note=note if named else "", verdict_word=word)


#: What a replayed acquisition is told in place of each reshoot advice but the clipped one's
#: (that names the recorded file: :func:`_with_session_kind`).
REPLAYED_ADVICE = {
    FLAT_ADVICE: "so it was recorded (a replayed acquisition cannot be reshot)",
    UNCHANGING_ADVICE: "so they were recorded (a replayed acquisition cannot be reshot)",
    BLACK_ADVICE: "so they were recorded (a replayed acquisition cannot be reshot)",
    MORE_EXPOSURE: "so they were recorded (a replayed acquisition cannot be reshot)",
    MOVED_ADVICE: (
        "so it was recorded (a replayed acquisition cannot be reshot): align the images from "
        "the move on to the earlier ones before fitting, or fit one position's images alone"
    ),
}
#: What a planned session is told in place of the advice it cannot follow image by image.
PLANNED_ADVICE = {
    LESS_EXPOSURE: (
        "a session keeps one exposure: shoot it again as a new session with a shorter "
        "camera.exposure_s, or with --auto-exposure"
    ),
    MORE_EXPOSURE: (
        "a session keeps one exposure: shoot it again as a new session with a longer "
        "camera.exposure_s (or more light), or with --auto-exposure"
    ),
}


def _planned_advice(problem: str) -> str:
    """``problem`` with the advice a planned session cannot follow image by image replaced
    (:data:`PLANNED_ADVICE`); every other word kept (a move's alternatives among them)."""
    for phrase, said in PLANNED_ADVICE.items():
        problem = problem.replace(phrase, said)
    return problem


#: What an adaptive session is told in their place (it can start again, not reshoot one image).
ADAPTIVE_ADVICE = {
    FLAT_ADVICE: "a new session replaces it (an adaptive session cannot reshoot one image)",
    UNCHANGING_ADVICE: "check that each light fires, then start a new session",
    BLACK_ADVICE: "mend that, then start a new session",
    MORE_EXPOSURE: "start a new session with a longer camera.exposure_s (or more light)",
    MOVED_ADVICE: (
        "start a new session (an adaptive session cannot reshoot part of one), or align the "
        "images from the move on to the earlier ones before fitting"
    ),
}


#: What a clipped image of an imported acquisition is said to be (what to do: the note, once).
IMPORTED_CLIPPED = "clipped in the acquisition"
#: What an imported acquisition is told in place of each reshoot advice (its images were shot
#: elsewhere: what it can do is said once, in the note).
IMPORTED_ADVICE = {
    LESS_EXPOSURE: IMPORTED_CLIPPED,
    FLAT_ADVICE: "so it is in the acquisition",
    UNCHANGING_ADVICE: "so they are in the acquisition: no fit of them can be trusted",
    BLACK_ADVICE: "so they are in the acquisition: there is nothing to fit",
    MORE_EXPOSURE: "so they are in the acquisition: its fit is the noisier for it",
    # a move part-way through: the acquisition holds two positions of the object, which no
    # reshoot here mends (it had been told "reshoot the whole session")
    MOVED_ADVICE: (
        "so it is in the acquisition: align the images from the move on to the earlier ones "
        "before fitting, or leave one position's images out of the .lp"
    ),
}


def _with_imported(qa: QAReport) -> QAReport:
    """``qa`` with advice an imported acquisition (an ``.lp`` and its images, no rti-rig
    session record beside them) can follow. Why: its images were shot elsewhere, often long
    ago, of an object no longer under any dome; "reshoot: image01 (... reshoot with less
    exposure)" of a published archive acquisition told its user to do what nobody can. The
    problems are still named, as the acquisition's ("flawed"), with what they cost the fit.

    Every image's advice is replaced (``qa.json`` lists each image's problems, named in the
    verdict or not), the note and the verdict's word only where the verdict names an image
    (:attr:`QAReport.named`): under lights likely wrong it names none for what its lights
    explain, and the note of "the images named" had been said of a shuffled ``.lp`` that
    named none."""
    if not qa.reshoot:
        return qa
    qa = qa.with_advice(lambda _name, phrase: IMPORTED_ADVICE[phrase])
    if not qa.named and not qa.lost_unfitted:
        return qa
    whole = [c for c in qa.named if any(p.startswith(EVERY_IMAGE) for p in c.problems)]
    if qa.named and len(whole) == len(qa.named):
        # a fault of every image (under-exposed, black, unchanging): leaving the images named
        # out of the .lp had been the advice, which leaves nothing
        note = (
            "an imported acquisition (an .lp with no rti-rig session record beside it): the "
            "problems named are its images', kept as they are; a fault of every image is "
            "mended only by photographing the object again, where it can be"
        )
    else:
        note = (
            "an imported acquisition (an .lp with no rti-rig session record beside it): the "
            "problems named are its images', kept as they are; reshoot only if the object can "
            "be photographed again (a clipped image with less exposure), else leave the images "
            "named out of the .lp and move their files out of its folder, which relight reads "
            "whole (or keep them and accept what they cost the fit)"
        )
    return replace(_noted(qa, note), verdict_word="flawed")


def unlisted_beside(lp: Path) -> list[str]:
    """The image files beside ``lp`` that it does not list, of a kind it lists images of
    (their extension), by name; [] where it lists none beside it or cannot be read. Hidden
    files (``._IMG_0001.JPG``, what macOS leaves on a FAT card) are not images.

    Why: an acquisition whose ``.lp`` had lost an image's line (its JPEG still beside it)
    was fitted without it and judged "good"; relight's folder mode takes every JPEG beside
    the ``.lp`` with its lines, in name order (its ``ImageSet``, whose versions read refuse a
    folder where the two counts differ)."""
    try:
        entries = read_lp(lp)
    except (OSError, RtiRigError):
        return []
    folder = lp.parent
    own = [image_path(folder, e.name) for e in entries]
    kinds = {p.suffix.lower() for p in own if p.parent == folder}
    if not kinds:
        return []
    # the images any .lp of the folder lists (a subset's .lp beside the whole one leaves the
    # others to it), told by the file itself: on a case-insensitive disk IMG_0001.JPG lists
    # img_0001.jpg
    listed = {_file_id(p) for p in own}
    for other in lp_files_in(folder):
        if other != lp:
            with contextlib.suppress(OSError, RtiRigError):
                listed |= {_file_id(image_path(folder, e.name)) for e in read_lp(other)}
    try:
        beside = sorted(folder.iterdir())
    except OSError:
        return []
    return [
        p.name
        for p in beside
        if p.suffix.lower() in kinds
        and not p.name.startswith(".")
        and p.is_file()
        and _file_id(p) not in listed
    ]


def _file_id(path: Path) -> tuple[int, int] | Path:
    """The file ``path`` names, as (device, inode) where it exists (one file under two
    spellings is one), else the path."""
    try:
        st = path.stat()
    except OSError:
        return path
    return (st.st_dev, st.st_ino)


def _with_unlisted_beside(qa: QAReport, lp: Path) -> QAReport:
    """``qa`` with a caveat naming the images beside an acquisition's ``lp`` that it does not
    list (:func:`unlisted_beside`): not fitted, and out of step in relight."""
    unlisted = unlisted_beside(lp)
    if not unlisted:
        return qa
    one = len(unlisted) == 1
    shown = ", ".join(unlisted[:8]) + (
        f" and {len(unlisted) - 8} more" if len(unlisted) > 8 else ""
    )
    # relight's folder mode lists *.jpg and *.JPG (its ImageSet): no other extension
    jpeg = any(Path(n).suffix.lower() == ".jpg" for n in unlisted)
    relight = (
        "; relight's folder mode takes every JPEG beside the .lp with its lines, in name "
        "order, which an image not listed puts out of step"
        if jpeg
        else ""
    )
    note = (
        f"{shown}, beside {lp.name}, {'is' if one else 'are'} not listed in it, so not fitted "
        f"(left out on purpose, or {'its line' if one else 'their lines'} lost?){relight}: "
        f"add {'its line' if one else 'their lines'} to {lp.name} with "
        f"{'its light' if one else 'their lights'}, or move {'it' if one else 'them'} out "
        "of the folder"
    )
    return _integrity_noted(qa, note)


def session_traces(source: Path, lp: Path) -> list[str]:
    """What in folder ``source`` (fitted by ``lp``) rti-rig writes into a session, where its
    record (manifest, journal, linear TIFFs) is gone; [] where nothing is.

    Why: such a folder was called "an imported acquisition (an .lp with no rti-rig session
    record beside it)", its images "kept as they are", where it is a session of this rig whose
    record was lost: the object may still be under the dome, and what was lost is what
    vouches for the images. rti-rig writes no comment into ``lights.lp``
    (:func:`~rti_rig.core.lp_format.format_lp`), and its JPEGs' colour tags (Exif ColorSpace
    and an sRGB ICC profile, :func:`~rti_rig.core.image_files.write_srgb_jpeg`; none on a
    camera-RGB or grey JPEG) are not read here as a trace: its traces are the names it gives
    and the folders it keeps beside them."""
    found = []
    if lp.name == LP_NAME:
        try:
            names = [e.name for e in read_lp(lp)]
        except (RtiRigError, OSError):
            names = []
        if names and names == [f"{n}.jpg" for n in image_names(len(names))]:
            found.append(
                f"{LP_NAME} lists {names[0]}{f' … {names[-1]}' if len(names) > 1 else ''}, "
                "rti-rig's names for a session's images"
            )
    for folder, what in (
        (RECORDS_DIR, "step records"),
        (RAW_DIR, "RAW originals"),
        (STRAY_DIR, "a camera's stray pictures"),
        ("recovered", "files set aside on resume"),
    ):
        if (source / folder).is_dir():
            found.append(f"a {folder}/ folder ({what})")
    return found


def _with_record_missing(qa: QAReport, traces: list[str]) -> QAReport:
    """``qa`` with a note that the folder is a session of this rig whose record is lost
    (:func:`session_traces`); its advice (reshoot) stands, since the object may still be under
    the dome."""
    note = (
        f"the session record is missing: this folder holds what rti-rig writes into a session "
        f"({'; '.join(traces)}) but not its {MANIFEST}, {JOURNAL} or {LINEAR_DIR}/ (deleted, "
        "or not copied with it?): the fit read its 8-bit JPEGs, not the linear TIFFs, and no "
        "image could be checked against its capture; restore the session folder from a backup "
        "if there is one and fit it again"
    )
    return _noted(qa, note)


def _replayed_names(manifest: dict) -> dict[str, str]:  # type: ignore[type-arg]
    """The recorded file each image of a replay session is (``image_064`` → ``image10.jpg``),
    from the LED its step fired and the replayed acquisition's `.lp`; {} when that `.lp` can
    no longer be read (moved since) or it, or its images, are no longer the ones replayed.

    Why: the verdict named the session's images only, "clipped in the recording", so a user
    replaying their own acquisition could not tell which of its photographs was clipped."""
    rig = manifest.get("rig") or {}
    steps = manifest.get("steps")
    if not isinstance(steps, list):
        return {}
    # the `.lp` the session began with, else the one it was last resumed from (the
    # acquisition moved since: the names had been dropped, the old path read)
    began = ((rig.get("config") or {}).get("dome") or {}).get("lp_file")
    last = rig.get("config_path")
    for lp_file in dict.fromkeys((began, last)):  # the same one: read once
        entries = _replayed_entries(manifest, lp_file)
        if entries is not None:
            break
    else:
        return {}
    assert isinstance(lp_file, str)
    names: dict[str, str] = {}
    for step in steps:
        if not isinstance(step, dict):
            continue
        led, image = step.get("led"), step.get("image")
        if isinstance(led, int) and 0 <= led < len(entries) and isinstance(image, str):
            names[Path(image).stem] = _recorded_file_shown(Path(lp_file).parent, entries[led].name)
    return names


def _replayed_entries(manifest: dict, lp_file: object) -> list | None:  # type: ignore[type-arg]
    """The lines of ``lp_file`` if it is the `.lp` session ``manifest`` replayed, as it was
    then; None if it cannot be read, or it (or its images) are not the ones replayed.

    Named only where the `.lp` and its images are still the ones the session replayed (their
    digest, recorded when it began): an `.lp` edited since (lines reordered or removed) or
    images re-exported had the verdict name other photographs, and a session from before the
    digest was recorded cannot tell. Files whose stamps are the ones recorded with it are not
    hashed again (:func:`~rti_rig.app.rig_identity.recorded_images_stamped` says why that is
    safe enough): every verdict had hashed every image of the acquisition."""
    if not isinstance(lp_file, str) or not lp_file.lower().endswith(".lp"):
        return None
    try:
        entries = read_lp(Path(lp_file))
    except (RtiRigError, OSError):
        return None
    from rti_rig.app.rig_identity import recorded_images_digest

    identity = (manifest.get("rig") or {}).get("identity") or {}
    began = identity.get("recorded_images")
    if began is None or began != recorded_images_digest(
        Path(lp_file).parent, [e.name for e in entries], identity.get("recorded_files")
    ):
        return None
    return entries


def _recorded_file_shown(lp_dir: Path, name: str) -> str:
    """The file an `.lp` line ``name`` was replayed from, as a user finds it: relative to the
    `.lp`'s folder, with ``/``, through :func:`shown_path`; the name as written where it was
    read from outside that folder.

    Why: the name as the `.lp` writes it had been shown: ``C:\\RTI\\image01.jpg``, a path on
    the machine that wrote the file (read here beside the `.lp`), and ``jpg\\image01.jpg``,
    which a shell reads as ``jpgimage01.jpg``."""
    found = image_path(lp_dir, name)
    try:
        return shown_path(found.relative_to(lp_dir).as_posix())
    except ValueError:
        return shown_path(name)


#: How a session that did not finish ended, as the manifest's finish_reason records it.
def _with_unfinished(qa: QAReport, source: Path, manifest: dict) -> QAReport:  # type: ignore[type-arg]
    """``qa`` with a caveat for a session that did not finish: its verdict judges the images
    taken so far, and a "good" there had read as a session to fit and archive."""
    runner = manifest.get("runner") or {}
    reason = runner.get("finish_reason")
    if reason == "completed":
        return replace(qa, session_complete=True)
    qa = replace(qa, session_complete=False)
    total = planned_steps(manifest)
    # the journal's steps and those the manifest records (a lost journal had made it "0 of 8
    # images" of a session with 4 on disk, fitted and judged)
    steps = manifest.get("steps")
    recorded = {
        s["index"]
        for s in (steps if isinstance(steps, list) else [])
        if isinstance(s, dict) and isinstance(s.get("index"), int)
    }
    # read once: its records also name the last image, whose size tells a full disk (it had
    # been read again for that, line by line, and a step proven by its record file alone, the
    # line a full disk never let the run write, was not among them)
    journal = scan_journal(source, image_names(total)).records
    taken = len({r["index"] for r in journal} | recorded)
    how = (
        RUN_ENDED.get(reason or "", f"it ended: {reason}")
        if reason
        else unrecorded_end(source, journal)
    )
    of = f"of at most {total}" if manifest.get("adaptive") else f"of {total}"
    # of the images taken, those lost since: "12 of 12 images" of a session not finished (a
    # --reshoot-lost stopped part-way) had read as a contradiction
    gone = files_lost_since_capture(source)
    lost = len(gone)
    since = f", {lost} of them lost since" if lost else ""
    instead = unresumable(source) or _adaptive_gap(manifest, source, gone, journal, total)
    if instead is None and any(
        p.startswith((UNDEREXPOSED, BLACK_THROUGHOUT)) for c in qa.images for p in c.problems
    ):
        # a resume keeps the session's exposure: it had been offered beside "shoot it again
        # as a new session with a longer camera.exposure_s"
        instead = (
            "a resume keeps the session's exposure and the images taken so far, so it is not "
            "offered: start a new session once that is mended"
        )
    note = (
        f"the session is not finished ({taken} {of} images{since}; {how}): this verdict judges "
        "the images taken so far; "
        + (
            instead  # its resume is refused: not named
            if instead is not None
            else f"continue it with rti-rig run --resume {shell_word(str(source))}"
            # a plain resume of a journal that lost records the manifest holds is refused
            + (
                " --rebuild-journal (or once its journal is restored)"
                if rebuild_advice(source)
                else ""
            )
        )
    )
    return _noted(qa, note)


def _adaptive_gap(
    manifest: dict[str, Any],
    source: Path,
    gone: dict[str, list[str]],
    journal: list[dict[str, Any]],
    total: int,
) -> str | None:
    """What to do instead of a plain resume of an adaptive session ``source`` that lost an
    image before its last (None: not adaptive, or no such image).

    Why: the verdict had said "continue it with rti-rig run --resume" of such a session,
    which the resume refuses (each later light was chosen from that image:
    ``refuse_broken_run``)."""
    if not manifest.get("adaptive") or not gone:
        return None
    order = {name: i for i, name in enumerate(image_names(total))}
    last = max((r["index"] for r in journal), default=-1)
    before = sorted((n for n in gone if order.get(n, last) < last), key=order.__getitem__)
    if not before:
        return None
    one = len(before) == 1
    return (
        f"an adaptive session cannot reshoot {', '.join(before)} in place (the lights after "
        f"{'it' if one else 'them'} were chosen from {'its' if one else 'their'} image): put the "
        "original files back (from a backup copy of the folder; a resume sets "
        f"what it cannot verify aside in recovered/) to continue it with rti-rig run --resume "
        f"{shell_word(str(source))}, or start a new session"
    )


def _with_stopped_while_committing(qa: QAReport, source: Path) -> QAReport:
    """``qa`` with a word on the image session ``source`` stopped while saving (on disk, no
    journal record: :func:`stopped_while_committing`).

    Why: it had been named among the images whose journal record was lost, with "restore
    journal.jsonl from a backup copy" as the advice, of a journal that had lost nothing."""
    stopped = stopped_while_committing(source)
    if stopped is None:
        return qa
    folder = shell_word(str(source))
    instead = unresumable(source)  # a resume is refused: not named
    if stopped in {c.name for c in qa.images}:  # an .lp of the user's own listed it
        note = (
            f"{stopped} was fitted, but the session stopped while saving it, before its journal "
            "record: neither its files nor its light were ever recorded as captured; leave it "
            + (
                "out of the .lp"
                if instead is not None
                else f"out of the .lp, or let rti-rig run --resume {folder} capture it again"
            )
        )
        return _integrity_noted(qa, note)
    note = (
        f"{stopped} is on disk without a journal record: the session stopped while saving it, "
        f"so it is no part of the session (not in {LP_NAME}, not fitted); "
        + (
            instead
            if instead is not None
            else f"rti-rig run --resume {folder} sets it aside in recovered/ (never deleted) and "
            "captures that step again"
        )
    )
    return _noted(qa, note)


def _only(found: dict[str, V], fitted: set[str] | None) -> dict[str, V]:
    """The entries of ``found`` (keyed by an image's base name, or a file name relative to the
    session) that concern an image of ``fitted`` (all of them when ``fitted`` is None)."""
    if fitted is None:
        return found
    return {k: v for k, v in found.items() if _stem(k) in fitted}


def _stem(name: str) -> str:
    """The image base name of a session file name (``linear/image_003.tif`` → ``image_003``)."""
    return Path(name).stem


def _with_unchecked(qa: QAReport, source: Path, fitted: set[str] | None = None) -> QAReport:
    """``qa`` with a caveat naming the images no readable journal record vouches for (of
    ``fitted`` alone when given)."""
    mended = journal_mend_note(source)
    if mended:  # checked, but against the step record files: the journal is to be mended
        qa = _noted(qa, mended)
    unchecked, why = unchecked_images(source)
    if fitted is not None:
        unchecked = [n for n in unchecked if n in fitted]
    if not unchecked:
        return qa
    shown = ", ".join(unchecked[:8]) + (
        f" and {len(unchecked) - 8} more" if len(unchecked) > 8 else ""
    )
    note = (
        f"{shown} not checked against {'its' if len(unchecked) == 1 else 'their'} capture "
        f"checksum{'' if len(unchecked) == 1 else 's'} ({why}): a change since capture would go "
        f"unseen; restore {MANIFEST if MANIFEST in why else JOURNAL} from a backup copy of the "
        "folder"
    )
    if MANIFEST not in why:  # the resume's other way on, where it would take images back
        note += rebuild_advice(source)
    return replace(qa, integrity_note=note)


def _listed(lp: Path) -> set[str]:
    """The image names a session's ``.lp`` lists (none when it is gone or unreadable)."""
    try:
        return {e.name for e in read_lp(lp)}
    except (OSError, RtiRigError):
        return set()
