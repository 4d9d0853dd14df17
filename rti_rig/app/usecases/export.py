"""Use case: write a session's ``.lp`` from its verified journal (``rti-rig export-lp``).

The lights that actually fired, for every image on disk as it was captured — an interrupted
session's too; an image missing or changed since is left out and named. The session's own
``lights.lp``, left one image short by a run stopped between a step's record file and its
journal line, is completed alike (:func:`rti_rig.runtime.session.list_unwritten_step`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from rti_rig.app.output_files import check_output_file, lp_name_note, session_rig_inputs
from rti_rig.core.errors import RtiRigError
from rti_rig.core.lp_format import LpEntry, write_lp
from rti_rig.core.qt_names import qt_name_key
from rti_rig.core.shell_words import shell_word, shown_path
from rti_rig.runtime.disowned import refuse_if_disowned
from rti_rig.runtime.session import (
    LINEAR_DIR,
    LP_NAME,
    MANIFEST,
    JournalScan,
    all_held,
    files_lost_since_capture,
    held_by_acquisition,
    image_names,
    list_unwritten_step,
    lost_image_advice,
    originals_lost,
    planned_steps,
    read_manifest,
    rebuild_advice,
    refuse_if_in_use,
    renamed_note,
    renamed_since_capture,
    rewrite_session_lp,
    scan_journal,
    session_lp_report,
    unchecked_images,
)


@dataclass(frozen=True)
class ExportLpRequest:
    session_dir: Path
    out_file: Path
    #: Name the 16-bit linear TIFFs instead of the JPEGs.
    linear: bool = False
    force: bool = False


@dataclass(frozen=True)
class ExportedLp:
    entries: list[LpEntry]
    #: Images the journal lists that are missing or changed on disk (not in the file).
    left_out: list[str]
    #: The file is not in the session folder, so its image names (relative to the session
    #: folder) do not resolve beside it, where relight, RTIBuilder and ``rti-rig fit`` look.
    outside_session: bool = False
    #: Images no readable journal record vouches for (not in the file), and why.
    unchecked: list[str] = field(default_factory=list)
    unchecked_why: str = ""
    #: ", or rebuild it …": how to take the unchecked images back ("" if it cannot)
    rebuild: str = ""
    #: What to say of left-out JPEGs that are in the folder under another name ("" if none).
    renamed: str = ""
    #: What to say of listed images whose kept RAW original is lost ("" if none).
    raw_lost: str = ""
    #: What to do about the images left out as missing or changed ("" if none, or if every
    #: one is in the folder under another name).
    left_out_advice: str = ""
    #: What was done to the session's own lights.lp, one image short of what it holds (a run
    #: stopped between a step's record file and its journal line), or why it could not be.
    relisted: str = ""
    #: What to say of listed images that are CFA mosaics (``decode.mode = "mosaic"``), "" if
    #: none: the .lp is written, but a viewer or fitter given it fits a checkerboard.
    mosaic: str = ""
    #: What to say of a file written under a name that is not ``.lp`` ("" if it is one).
    misnamed: str = ""
    #: What was written into the session's own folder and what was left as captured ("" for
    #: a file written elsewhere: :attr:`outside_session` says that).
    in_session: str = ""
    #: False where ``--out`` was the session's own lights.lp, already its journal's listing:
    #: nothing was written (the CLI says so, not "N lights → …").
    written: bool = True


def export_lp(req: ExportLpRequest) -> ExportedLp:
    """Write the session's ``.lp`` and say what it leaves out and why.

    The manifest and the journal are read once, and that one scan serves every question
    below. Why: each reader scanned the journal again (three times for a session as a kill
    left it, more with images left out), and each scan checks every record file the journal
    lacks against its images' checksums."""
    refuse_if_disowned(req.session_dir)
    refuse_if_in_use(req.session_dir, "export its .lp")
    root = Path(req.session_dir)
    manifest = read_manifest(root)
    total = planned_steps(manifest)  # an adaptive session's maximum, not its starting layout
    scan = scan_journal(root, image_names(total) if total else None)
    entries, left_out = session_lp_report(root, req.linear, scan, manifest)
    _refuse_another_session(Path(req.out_file), root, entries[0].name if entries else None)
    # never the session's own files, nor the rig config it names and what that reads (a
    # dome's lp_file calibration, a replayed acquisition's .lp and images): `--out
    # ACQ/dirs.lp --force` had replaced the acquisition's 12 lights with the session's 6
    # (read only where the file exists, the one case they are compared with: a new file never
    # loads the rig config, which an export needs nothing of)
    config = (manifest.get("rig") or {}).get("config_path")
    own = _own_listing(Path(req.out_file), root, entries, req.linear)
    written = True
    if own is None:
        rig_files = session_rig_inputs(config) if Path(req.out_file).exists() else {}
        check_output_file(req.out_file, req.force, rig_files)
        in_session = _in_session_said(Path(req.out_file), root)  # before lights.lp is written
        write_lp(req.out_file, entries)
    else:
        in_session, written = own
    # lights.lp one image short of the session (a run stopped between a step's record file
    # and its journal line): completed once the export is written, so that both list alike
    relisted = list_unwritten_step(root, scan)
    outside = Path(req.out_file).resolve().parent != root.resolve()
    unchecked, why = unchecked_images(root, scan, manifest)
    # a left-out JPEG renamed in the folder is named with its new name: "missing" of a file
    # that is there had read as one to reshoot
    renamed = renamed_since_capture(root, scan) if left_out and not req.linear else {}
    rebuild = rebuild_advice(root, scan) if unchecked else ""
    adaptive = bool(manifest.get("adaptive"))
    return ExportedLp(
        list(entries),
        list(left_out),
        outside,
        unchecked,
        why,
        rebuild=rebuild,
        renamed=renamed_note(renamed),
        relisted=relisted or "",
        raw_lost=_raw_lost(root, {Path(e.name).stem for e in entries}, scan, adaptive),
        mosaic=_mosaic_said({Path(e.name).stem for e in entries}, scan),
        # the images left out named with what gets them back, as the verdict does (the note
        # named them alone)
        left_out_advice=(
            lost_image_advice(root, adaptive, scan) if len(left_out) > len(renamed) else ""
        ),
        misnamed=lp_name_note(Path(req.out_file)) or "",
        in_session=in_session,
        written=written,
    )


def _own_listing(
    out_file: Path, root: Path, entries: list[LpEntry], linear: bool
) -> tuple[str, bool] | None:
    """What becomes of session ``root``'s own ``lights.lp`` when ``out_file`` is it and it
    exists, said, and whether it was written; None for any other file (checked and written as
    one, so refused).

    The session's ``lights.lp`` is the one file of a session ``export-lp`` writes over, and
    only with a listing of the kind it holds (the JPEGs, or with ``--linear`` the linear
    TIFFs; an empty or unreadable one as the run writes it, the JPEGs): it is the listing the
    run writes from the journal, so writing it again from the journal replaces no capture,
    and the one there is kept (:func:`rewrite_session_lp`)."""
    own = root / LP_NAME
    if not own.is_file() or out_file.resolve() != own.resolve():
        return None
    try:
        present = own.read_bytes()
    except OSError:
        present = b""  # unreadable as it is: taken as the run writes it, the JPEGs
    lists_linear = any(line.startswith(f"{LINEAR_DIR}/".encode()) for line in present.splitlines())
    if linear != lists_linear:
        return None  # another kind of listing: not the session's own mended
    kept = rewrite_session_lp(root, entries)
    if kept is None:
        return f"{shown_path(own)} is already the listing of the journal: left as it is", False
    if not kept:
        return f"{shown_path(own)} written again from the journal", True
    return (
        f"{shown_path(own)} differed from the listing of the journal: the one there is kept as "
        f"{shown_path(root / kept)}, and {LP_NAME} is written again from the journal"
    ), True


def _in_session_said(out_file: Path, root: Path) -> str:
    """What an export written at the top of its own session folder does there ("" elsewhere).

    Why: it was written there without a word, beside the session's captured files, and whether
    the session's own lights.lp was replaced (only ever by its own listing again, with the one
    there kept: :func:`_own_listing`), or which of the two ``rti-rig fit`` of the folder reads,
    was left to guess."""
    if out_file.resolve().parent != root.resolve():
        return ""
    own = root / LP_NAME
    if out_file.name == LP_NAME:  # refused if it existed: so the session had lost it
        return (
            f"{shown_path(out_file)} is the session's own {LP_NAME}, which was missing: written "
            "again from its journal"
        )
    if own.is_file():
        return (
            f"{shown_path(out_file)} is written inside the session {shown_path(root)}, beside its "
            f"own {LP_NAME}, which is left as captured (a session's files are never replaced); "
            f"rti-rig fit {shown_path(root)} reads {LP_NAME}: give {shown_path(out_file)} "
            "itself to use this one; " + _relight_reads(root, out_file.name)
        )
    return (
        f"{shown_path(out_file)} is written inside the session {shown_path(root)}, which has no "
        f"{LP_NAME}: rti-rig export-lp {shell_word(root)} --out {shell_word(own)} writes the "
        f"session's own {LP_NAME} again"
    )


def _relight_reads(root: Path, new: str) -> str:
    """Which ``.lp`` relight-cli takes when given the session folder: the first by name, case
    ignored (relight's ``ImageSet`` takes ``QDir::entryList({"*.lp"})[0]``, whose default sort
    is ``Name | IgnoreCase``), ``new`` among them (said before it is written).

    Why: an export named before lights.lp (``demo_linear.lp``, ``export.lp``) became the .lp
    relight-cli read for the session without a word. relight-cli pairs the folder's JPEGs with
    its lines by order and checks only their count, so one exported before a resume (the
    images taken by then) or with images left out stops it with "Lp number of lights (…)
    different from the number of images found", naming neither file."""
    order = _relight_order(root, new)
    if not order:  # no .lp there, and an export named otherwise is none to it
        return f"relight-cli given {shown_path(root)} finds no .lp there"
    first = order[0]
    if first == LP_NAME:
        return (
            f"relight-cli given {shown_path(root)} reads the first .lp there by name, still "
            f"{LP_NAME}"
        )
    return (
        f"relight-cli given {shown_path(root)} reads the first .lp there by name, now {first}, not "
        f"{LP_NAME}: move {first} out of the folder before giving the folder to relight-cli"
    )


def _relight_order(root: Path, new: str) -> list[str]:
    """The ``.lp`` files at the top of ``root``, ``new`` among them, in the order relight-cli
    lists them (by name, case ignored: :func:`_relight_reads`, compared as Qt compares them:
    :func:`~rti_rig.core.qt_names.qt_name_key`); the first is the one it reads. Why Qt's key:
    ``str.casefold`` read an export named ``ﬁnal.lp`` (a ligature, 0xFB01) as ``final.lp``,
    before lights.lp, and said relight-cli would read it, where Qt lists lights.lp first."""
    names = {p.name for p in root.iterdir() if p.suffix.lower() == ".lp" and p.is_file()}
    if Path(new).suffix.lower() == ".lp":  # relight-cli lists no other file
        names.add(new)
    return sorted(names, key=qt_name_key)


def relight_move_advice(root: Path, new: str) -> str:
    """What else to move for relight-cli given session ``root`` once an export named ``new``,
    written outside it, is moved in: the ``.lp`` files listed before it (relight-cli reads the
    first, :func:`_relight_order`), and one of its very name, which the move would replace.

    Why: the note of an export written outside its session always said to move the session's
    lights.lp out for relight-cli, also for a name that sorts before it (the guide's
    ``demo_linear.lp``), which relight-cli reads first anyway: the session left without its
    own lights.lp for nothing."""
    if Path(new).suffix.lower() != ".lp":
        # relight-cli lists a folder's .lp files only: "then reads e.txt there" had been said
        # just after the note that such a file is found by no tool under that name
        return f"relight-cli reads only a file named .lp: name it {Path(new).stem}.lp there"
    try:
        order = _relight_order(root, new)
    except OSError:  # a folder that cannot be listed: the moves are the user's to judge
        order = [new]
    ahead = order[: order.index(new)] + ([new] if (root / new).is_file() else [])
    said = "relight-cli, which reads the first .lp of a folder by name (case ignored)"
    if not ahead:
        return f"{said}, then reads {new} there: nothing else needs moving"
    listed = " and ".join(ahead)
    again = (
        f" (`rti-rig export-lp {shell_word(str(root))} --out "
        f"{shell_word(str(root / LP_NAME))}` writes it again)"
        if LP_NAME in ahead
        else ""
    )
    replaced = f"; {new} there would be replaced by the move" if new in ahead else ""
    return f"for {said}, move that folder's {listed} out too{again}{replaced}"


def _refuse_another_session(out_file: Path, root: Path, first: str | None) -> None:
    """Refuse an ``--out`` inside another session's folder than the one exported, saying
    why as it is there: beside images of the same names, or inside that session.

    Why: every session names its images alike (image_001.jpg, ...), and relight, RTIBuilder
    and ``rti-rig fit`` read an ``.lp``'s names beside it. ``export-lp A --out B/a.lp`` was
    written with a note to move it, and left in B, relight or RTIBuilder given it paired B's
    images with A's lights without a word (``rti-rig fit B/a.lp`` fitted them too, its verdict
    saying "a.lp gives image_002 ... another light than the journal records")."""
    own = root.resolve()
    folder = out_file.resolve().parent
    for f in (folder, *folder.parents):
        if f == own:  # its own session: names resolve there (the note says where they do)
            return
        if (f / MANIFEST).is_file():
            name = first or "image_001.jpg"
            if (folder / name).is_file():  # the names resolve there, to other images
                where = f"{f.name}'s own images" if folder == f else f"images ({folder / name})"
                why = (
                    "relight, RTIBuilder and rti-rig fit read those names beside it, where "
                    f"{where} of the same names lie"
                )
            else:
                # a subfolder (B/exports/a.lp): B's images are not beside it, as had been said,
                # but the .lp sits inside B, where it could be taken for B's own
                why = (
                    f"the .lp would sit inside the session {f.name}, where relight or "
                    f"RTIBuilder (or whoever opens {f.name}) could take it for that session's "
                    "own"
                )
            raise RtiRigError(
                f"--out {shown_path(out_file)} is in another session ({f}): this .lp names "
                f"{shown_path(root)}'s images ({name}, ...), and {why}; write it into "
                f"{shown_path(root)} or outside any session"
            )


def _raw_lost(root: Path, listed: set[str], scan: JournalScan, adaptive: bool) -> str:
    """What to say of the images ``listed`` whose camera originals alone are lost: the RAW is
    the original capture, so the image is lost, though its developed file is as captured and
    listed. Why: export-lp said nothing of it, while the QA verdict names it and
    ``--reshoot-lost`` shoots it again. A replay's copies that its acquisition still holds
    (:func:`held_by_acquisition`) are said as missing copies, not as a lost capture (that had
    stood beside the ``cp`` that copies them back)."""
    lost = sorted(
        (n, g)
        for n, g in files_lost_since_capture(root, scan).items()
        if n in listed and originals_lost(g)
    )
    if not lost:
        return ""
    held = held_by_acquisition(root, scan)
    copies = [(n, g) for n, g in lost if all_held(g, held)]
    gone = [(n, g) for n, g in lost if (n, g) not in copies]
    said = []
    for group, held_there in ((gone, False), (copies, True)):
        if not group:
            continue
        one = len(group) == 1
        files = ", ".join(f for _, g in group[:8] for f in g) + (" …" if len(group) > 8 else "")
        names = ", ".join(n for n, _ in group[:8])
        what = (
            f"the copy of {names}'s recorded file kept in raw/ is missing, the acquisition "
            "still holds it as recorded"
            if held_there and one
            else f"the copies of {names}'s recorded files kept in raw/ are missing, the "
            "acquisition still holds them as recorded"
            if held_there
            else f"the camera's original capture of {names} is lost"
        )
        said.append(
            f"{files} since capture: {what} (the developed "
            f"{'image is' if one else 'images are'} as captured, and listed)"
        )
    return "; ".join(said) + "; " + lost_image_advice(root, adaptive, scan)


def _mosaic_said(listed: set[str], scan: JournalScan) -> str:
    """What to say of the images ``listed`` that the journal records as CFA mosaics, "" if
    none. Why: ``rti-rig fit`` refuses a mosaic, but export-lp wrote its .lp for other tools
    without a word, and relight or RTIBuilder given it fit grey checkerboards (one colour per
    pixel) as if they were pictures."""
    records = [r for r in scan.records if Path(str(r.get("image", ""))).stem in listed]
    mosaics = sum(
        isinstance(r.get("decode"), dict) and r["decode"].get("mode") == "mosaic" for r in records
    )
    if not mosaics:
        return ""
    return (
        f"{mosaics} of the {len(listed)} images listed are CFA mosaics (the session was shot "
        'with decode.mode = "mosaic"): one colour per pixel, not pictures (their JPEGs are '
        "grey checkerboards): relight or RTIBuilder given this .lp would fit the checkerboard "
        "(rti-rig fit refuses it); decode the camera's RAW files kept in the session's raw/ "
        "folder to linear RGB (demosaiced) TIFFs with your RAW converter and list those "
        "instead, and set "
        'decode.mode = "demosaic" or "half" in the rig config for the next session'
    )
