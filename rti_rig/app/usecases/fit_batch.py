"""`rti-rig fit` over several sessions: a resumable batch, one output folder per session.

Why a module of its own: the single fit (:mod:`rti_rig.app.usecases.fit`) reads, fits and
writes one acquisition; the batch decides, per session, whether an earlier fit stands, fits
the others into partial folders, and swaps a refit in for the fit its session outgrew. The
Dask runner (:mod:`rti_rig.app.usecases.fit_dask`) runs :func:`fit_one` per session too.
"""

from __future__ import annotations

import contextlib
import json
import os
from dataclasses import dataclass, field
from enum import Enum
from pathlib import Path
from typing import Any

from rti_rig.app.usecases.fit import (
    BandRunner,
    FitInputError,
    FitRequest,
    acquisition_inputs,
    refuse_out_inside_a_session,
    run_fit,
)
from rti_rig.app.usecases.fit_attempts import AttemptFolder, Kind
from rti_rig.app.usecases.fit_inputs import (
    INPUTS_KEY,
    change_since,
    confirmed_update,
    is_record,
    journal_lost,
    judged_by_stat,
)
from rti_rig.app.usecases.fit_owners import (
    OWNER_SUFFIX,
    Owner,
    owner_of,
    remove_owner_record,
    write_owner_record,
)
from rti_rig.core.errors import RtiRigError
from rti_rig.core.out_folders import ensure_writable_folder
from rti_rig.core.shell_words import shell_word, shown_path
from rti_rig.runtime.session import JOURNAL, file_sha256


class Outcome(Enum):
    """What a batch did with one session; its value begins the words said of it."""

    DONE = "done"
    SKIPPED = "skipped"  # an earlier fit stands
    REFITTED = "refitted"  # an earlier fit its session outgrew, replaced
    FAILED = "failed"
    #: fitted on a Dask worker whose report could not be fetched: its outputs are there
    FINISHED = "finished"


@dataclass(frozen=True)
class BatchItem:
    """One session's result in a batch. Why an enum: the CLI's exit code had been decided by
    whether the words began with "failed", words that also carry "refitted (…)" and a
    session's own reasons."""

    source: Path
    out_dir: Path
    outcome: Outcome
    #: what follows the outcome's word in :attr:`status` (" (finished earlier)", ": <why>")
    detail: str = ""
    verdict: str | None = None
    #: the fit's notes and warnings, as a single fit prints them (a batch had dropped them:
    #: "fit.ptm not written" for a 5-light session was said by fit S, not by fit S1 S2)
    notes: tuple[str, ...] = ()
    warnings: tuple[str, ...] = ()
    #: how the session changed while its own fit ran (:func:`changed_while_fitted`), or None:
    #: its fit is of the session as it was read, and the batch's exit code says so
    changed_meanwhile: str | None = None

    @property
    def stale(self) -> bool:
        """The fit in place is of its session as it was read, not as it is now (it changed
        while it was fitted): the next batch refits it. Why a flag and not only words: a
        script running batches had only "done; but …" to find, the exit code being 0."""
        return self.changed_meanwhile is not None

    @property
    def status(self) -> str:
        """The words said of the session ("done", "refitted (…)", "failed: …")."""
        return self.outcome.value + self.detail


def batch_out_dir(root: Path, source: Path) -> Path:
    """Where a batch writes one source: ``root/<session folder name>``, or for an ``.lp`` file
    ``root/<its folder>-<its stem>``: acquisitions of a backlog often all name their file
    ``dirs.lp`` (one folder per object), and the name must not depend on the rest of the batch
    (a resumed batch finds what it finished by this name).

    A folder's name is taken from its absolute path: ``.`` (the folder one is in) and ``..``
    have no name of their own, and ``root / "."`` is ``root`` itself, which exists once the
    batch begins, so ``fit . OTHER --out OUT`` had reported the current session "skipped
    (finished earlier)" without fitting it (``..`` named ``OUT/..``, likewise skipped)."""
    if source.is_dir():
        name = Path(os.path.abspath(source)).name
        if not name:
            raise FitInputError(
                f"{shown_path(source)}: the root of a file system is no session folder; give "
                "the session's own folder"
            )
        return root / name
    folder = source.resolve().parent.name
    return root / (f"{folder}-{source.stem}" if folder else source.stem)


def run_batch(sources: list[Path], root: Path, template: FitRequest) -> list[BatchItem]:
    """Fit several sessions one after another, resumably.

    Each goes to :func:`batch_out_dir`, built in a hidden ``.name.*.partial`` folder and renamed
    when complete: a finished session (its folder exists) is skipped unless its session changed
    since that fit (:func:`earlier_fit`; refitted then, the earlier fit replaced only once the
    new one is complete), a killed batch leaves partial folders only, which the next run
    removes and redoes. A session that fails is
    reported and the batch goes on. (:func:`rti_rig.app.usecases.fit_dask.run_batch_dask` runs
    the same :func:`fit_one` per session as parallel tasks on a Dask cluster.)

    A ``root`` inside a session folder is refused first, as given, here rather than by each
    caller (each session's fit would be refused by :func:`run_fit` too, but once per session,
    naming its partial folder, after the batch folder was made inside the session).
    """
    refuse_out_inside_a_session(root)
    said = prepare_batch(sources, root)  # each session is judged at its turn (fit_one)
    return with_notes([fit_one(source, root, template) for source in sources], said)


def with_notes(items: list[BatchItem], said: dict[Path, tuple[str, ...]]) -> list[BatchItem]:
    """``items`` with what :func:`prepare_batch` said of each one's session before its notes
    (matched by source)."""
    from dataclasses import replace

    return [
        replace(item, notes=(*said[item.source], *item.notes)) if said.get(item.source) else item
        for item in items
    ]


def partial_folders(root: Path, name: str) -> list[Path]:
    """The partial folders of the session whose output is ``root/name`` (``.NAME.PID-ID.partial``,
    or ``.NAME.partial`` of older runs; :class:`AttemptFolder`)."""
    return _attempt_folders(root, name, Kind.PARTIAL)


def _attempt_folders(root: Path, name: str, kind: Kind) -> list[Path]:
    """The folders of ``kind`` of the attempts at session output ``root/name``."""
    try:
        listed = list(root.iterdir())
    except OSError:  # no root yet: nothing there
        return []
    return [
        p
        for p in listed
        if (found := AttemptFolder.parse(p.name, name)) is not None
        and found.kind is kind
        and p.is_dir()
    ]


def owner_gone(folder: Path, *, mine_too: bool = False) -> bool:
    """Whether the process that made attempt folder ``folder`` no longer runs, so that its
    folder may be removed (``mine_too``: this process's own count as gone, for a batch
    that begins and fits nothing yet). A folder naming no PID counts as gone.

    Why: two batches given one ``--out`` each removed the other's in-progress partial
    folder, and both reported a session "failed … No such file or directory". The process
    is judged by its owner record (:func:`~rti_rig.app.usecases.fit_owners.owner_of`): only
    one of this host's is ever called gone; another host's (a Dask worker sharing the
    folder) is left to it."""
    return owner_of(folder, mine_too=mine_too).gone


def remove_attempt_folder(folder: Path) -> None:
    """Remove an attempt's folder, and its owner record once none of its folders is left."""
    import shutil

    shutil.rmtree(folder, ignore_errors=True)
    attempt = AttemptFolder.parse(folder.name)
    if attempt is None or attempt.attempt is None:
        return
    if not any(attempt.as_kind(k).path(folder.parent).exists() for k in Kind):
        remove_owner_record(attempt, folder.parent)


def _left_to_its_owner(folder: Path, owner: Owner) -> str:
    """What a batch says, once, of an attempt's folder it leaves to a process elsewhere."""
    pid = "" if owner.pid is None else f" (PID {owner.pid} there)"
    return (
        f"{shown_path(folder)} is the folder of a fit running on {owner.elsewhere}{pid}, which "
        "this host cannot see: it is left to that fit. If it still runs there, let it finish; "
        "if that host is gone or its fit was stopped, remove the folder by hand (rm -r "
        # a shell word: hand-quoted '...', a name with a quote (or not UTF-8) did not paste
        f"{shell_word(folder)}) "
        "and run the same command again"
    )


def _removed_unrecorded(folder: Path, owner: Owner) -> str:
    """What a batch says of an older rti-rig's folder, recording no host, that it removed."""
    return (
        f"removed {shown_path(folder)}, left by an interrupted fit of an older rti-rig, which "
        f"records no host: its PID {owner.pid} was taken as this host's, where no such process "
        "runs (a fit of that older rti-rig still running on another host sharing this folder "
        "fails there; run it again with this rti-rig)"
    )


def _orphan_records(root: Path, name: str) -> list[AttemptFolder]:
    """The attempts of session output ``root/name`` whose owner record is left without any
    of their folders (a batch killed between its last rename and the record's removal)."""
    try:
        listed = [p.name for p in root.iterdir()]
    except OSError:
        return []
    found = []
    for entry in listed:
        stem = entry.removesuffix(f".{OWNER_SUFFIX}")
        if stem == entry:
            continue
        attempt = AttemptFolder.parse(f"{stem}.{Kind.PARTIAL.value}", name)
        if attempt is None or attempt.attempt is None:
            continue
        if not any(attempt.as_kind(k).path(root).exists() for k in Kind):
            found.append(attempt)
    return found


def plan_batch(sources: list[Path], root: Path) -> dict[Path, EarlierFit]:
    """What a batch finds of each source's earlier fit (:func:`earlier_fit`; the sources still
    to fit are those whose fit does not stand), once :func:`prepare_batch` (the caller's, whose
    notes it keeps) has made its folders ready, keeping each earlier fit's record a hash
    brought up to date (:func:`keep_confirmed`).

    Why apart from :func:`prepare_batch`: only a cluster batch judges here, to know which
    sessions to send at once. A batch that fits its sessions one after another leaves each to
    :func:`fit_one`'s judgement at its turn, which one made when the batch began cannot
    replace (a session may change meanwhile); judging here as well had read each session's
    record and stat-ed its images twice."""
    plan: dict[Path, EarlierFit] = {}
    for source in sources:
        plan[source] = earlier_fit(batch_out_dir(root, source), source)
        keep_confirmed(plan[source])  # once, here: a later asker finds the record up to date
    return plan


def prepare_batch(sources: list[Path], root: Path) -> dict[Path, tuple[str, ...]]:
    """Make ``root`` ready for a batch of ``sources``: two sources with one output name are
    refused, the folder is made, and the partial folders (and outgrown earlier fits) killed
    runs left for these sources are removed; another batch's running attempts are left.
    Returns what is to be said of each source's session (a folder left to a fit on another
    host, an older rti-rig's folder removed), for :func:`with_notes`."""
    by_name: dict[str, list[Path]] = {}
    for s in sources:
        by_name.setdefault(batch_out_dir(root, s).name, []).append(s)
    clashes = {n: ss for n, ss in by_name.items() if len(ss) > 1}
    if clashes:
        # which sources, and what to do: it had said only "two sources would write to the same
        # folder: ['coin']", of two days' sessions both named coin (or one given twice)
        said = "; ".join(
            f"{', '.join(map(str, ss))} -> {root / n}" for n, ss in sorted(clashes.items())
        )
        raise FitInputError(
            f"sources would write to the same output folder ({said}): a batch names each "
            "output after its session folder (an .lp's after its folder and stem); give each "
            "source once, and fit sessions whose folders share a name in separate batches "
            "(another --out) or rename one of the folders"
        )
    # a file given for --out is said to be one (it had been "cannot create the batch folder
    # (File exists)"), and a folder that takes no file (read-only) is said of --out, once: each
    # session had failed on its own hidden partial folder, "--out OUT/.s1.5928-a1d0.partial:
    # cannot write there", and the batch ended as if the others had fitted. Its probe file has
    # a name of its own, so two batches may plan into one folder at once
    try:
        ensure_writable_folder(root)
    except RtiRigError as exc:
        raise FitInputError(str(exc)) from None
    notes: dict[Path, tuple[str, ...]] = {}
    for source in sources:
        final = batch_out_dir(root, source)
        # a finished session's too: a Dask worker killed mid-session leaves its attempt's
        # partial folder while the retry finishes the session (see fit_one)
        # an interrupted swap's new fit is kept for fit_one to put in place (finish_swap)
        keep = {_swap_partial(b) for b in earlier_backups(root, final.name)}
        held = list(partial_folders(root, final.name))
        if final.exists():  # the swap had ended: its backup is an outgrown fit
            keep = set()
            held += earlier_backups(root, final.name)
        said: list[str] = []
        for folder in held:
            # another batch's attempt, running now into the same --out, is left to it
            if folder in keep:
                continue
            owner = owner_of(folder, mine_too=True)
            if owner.gone:
                remove_attempt_folder(folder)
                if owner.unrecorded:
                    said.append(_removed_unrecorded(folder, owner))
            elif owner.elsewhere:
                said.append(_left_to_its_owner(folder, owner))
        for orphan in _orphan_records(root, final.name):
            if owner_of(orphan.path(root), mine_too=True).gone:
                remove_owner_record(orphan, root)
        notes[source] = tuple(said)
    return notes


def earlier_backups(root: Path, name: str) -> list[Path]:
    """The earlier fits of session output ``root/name`` that a refit set aside
    (``.NAME.ATTEMPT.earlier``), oldest first: a refit keeps the fit it replaces under this
    name until the new one is in place (:func:`fit_one`)."""
    found = _attempt_folders(root, name, Kind.EARLIER)

    def when(p: Path) -> int:
        try:
            return p.stat().st_mtime_ns
        except OSError:  # removed meanwhile by another attempt
            return 0

    return sorted(found, key=when)


def _swap_partial(backup: Path) -> Path:
    """The partial folder of the attempt that set ``backup`` aside (the same ATTEMPT)."""
    attempt = AttemptFolder.parse(backup.name)
    assert attempt is not None, backup  # listed by earlier_backups
    return attempt.as_kind(Kind.PARTIAL).path(backup.parent)


def finish_swap(root: Path, final: Path) -> tuple[str, ...]:
    """Finish or undo a refit's swap that a kill interrupted, so that ``final`` holds a fit
    again; what was done, and what was left to another host's fit, in words (none when there
    was nothing to do).

    Why: the swap is two renames (the earlier fit aside, the new one in); a batch killed
    between them had left neither in ``final``, and the next run removed both as partial
    folders, so a session whose refit then failed had no fit at all. The new fit, complete
    (its ``fit.json`` is written last), is put in place; otherwise, if the attempt's partial
    folder is there, the earlier fit is put back. Without it, the swap had ended (the new
    fit was put in place, and removed since, by the user) and the earlier fit is outgrown:
    it is removed, not put back (it had been, said "interrupted before its new fit was
    complete"). A swap whose process still runs on this host (another batch into the same
    ``--out``) is left to it. Only set-aside fits whose process is gone are ever removed: the
    older ones had been removed unjudged, and on a shared ``--out`` another host's running
    refit lost the earlier fit it had set aside (its owner cannot be seen from here: its
    folder is left, and said, with what to do if that host is gone)."""
    backups = earlier_backups(root, final.name)
    if not backups or final.exists():
        return ()
    owners = {b: owner_of(b) for b in backups}
    if any(not o.gone and not o.elsewhere for o in owners.values()):
        return ()  # a swap of this host's, running now: left to it, and the rest with it
    left = tuple(_left_to_its_owner(b, o) for b, o in owners.items() if not o.gone)
    gone = [b for b in backups if owners[b].gone]
    if not gone:
        return left
    backup, older = gone[-1], gone[:-1]
    new = _swap_partial(backup)
    if not new.is_dir():
        for stale in (*older, backup):
            remove_attempt_folder(stale)
        return left
    try:
        if (new / "fit.json").is_file():
            new.rename(final)
            words = (
                f"a refit of this session was interrupted while it swapped in its new fit: "
                f"the new fit, complete, was put in place in {final}"
            )
        else:
            backup.rename(final)
            words = (
                f"a refit of this session was interrupted before its new fit was complete: "
                f"the earlier fit was put back in {final}"
            )
    except OSError:  # another attempt finished it meanwhile
        if not final.exists():
            raise
        return left
    for stale in (*older, backup, new):
        remove_attempt_folder(stale)
    return (words, *left)


#: What a batch says of a session another run into the same --out fitted meanwhile, after
#: "done".
DONE_ELSEWHERE = " (by another run into the same --out, meanwhile)"

#: What a batch says of a session whose earlier fit stands, after "skipped".
FINISHED_EARLIER = " (finished earlier)"


@dataclass(frozen=True)
class RecordUpdate:
    """A fit's ``fit.json`` (``summary``) with its inputs record to be replaced by ``record``."""

    fit_json: Path
    summary: dict[str, Any]
    record: dict[str, Any]


@dataclass(frozen=True)
class EarlierFit:
    """What a batch finds of a session's earlier fit (:func:`earlier_fit`)."""

    #: its output folder holds an earlier fit
    found: bool
    #: why that fit is to be replaced (its session changed since), or None
    outgrown: str | None = None
    #: what a skip says after "skipped (finished earlier)"
    note: str = ""
    #: why the output folder is no fit to judge (files with no ``fit.json``, or a file): the
    #: session is then failed, the folder left as it is
    foreign: str | None = None
    #: the earlier fit's record brought up to date with the images a hash confirmed unchanged
    #: (new sizes or times, e.g. a copy), for the caller to keep (:func:`keep_confirmed`)
    confirmed: RecordUpdate | None = field(default=None, compare=False)

    @property
    def stands(self) -> bool:
        """The earlier fit is kept and the session skipped."""
        return self.found and self.outgrown is None and self.foreign is None

    @property
    def skip_detail(self) -> str:
        """The words after "skipped" in a batch's line for the session."""
        return FINISHED_EARLIER + self.note


def earlier_fit(final: Path, source: Path) -> EarlierFit:
    """Whether ``final`` holds an earlier fit of ``source``, and whether it stands: not when
    its session changed since that fit (its ``fit.json`` records what it was made from,
    :func:`acquisition_inputs`; ``outgrown`` says how). It writes nothing: a record that
    hashes confirmed is returned as ``confirmed`` for the caller to keep once
    (:func:`keep_confirmed`; it had been written by whichever of the up to three askers of a
    session came first).

    Why: only the folder's existence was checked, so a session fitted while interrupted and
    then continued with ``run --resume`` (or mended with ``--reshoot-lost``) kept its
    out-of-date fit, reported "skipped (finished earlier)". A fit that records nothing (made
    before the record was kept) is skipped with a word on how to have it refitted: refitting
    every such session unasked would redo a whole backlog (so is one whose record is in the
    form kept before the lights were recorded as directions)."""
    if not final.exists():
        return EarlierFit(found=False)
    foreign = _no_fit(final)
    if foreign == "":
        return EarlierFit(found=False)  # an empty folder: the fit goes into it
    if foreign is not None:
        return EarlierFit(found=True, foreign=foreign)
    try:
        summary = json.loads((final / "fit.json").read_text(encoding="utf-8"))
    except (OSError, ValueError):
        summary = None
    if (
        not isinstance(summary, dict)
        or summary.get(INPUTS_KEY) is None
        or (isinstance(summary[INPUTS_KEY], dict) and not is_record(summary[INPUTS_KEY]))
    ):
        return EarlierFit(
            found=True,
            note=(
                "; its fit.json does not record what it was fitted from, so whether its "
                f"session changed since cannot be told: delete {final} to fit it again"
            ),
        )
    files: dict[str, Path] = {}
    now = acquisition_inputs(source, files)
    if now is None:  # the refit says what is wrong with the source; the earlier fit stays
        return EarlierFit(True, "its session cannot be read as it was when fitted")
    record = summary[INPUTS_KEY]
    lost = journal_lost(record, now)
    if lost and not judged_by_stat(record):
        return EarlierFit(
            True,
            f"{_journal_gone(source)}, and the earlier fit's record names its images by that "
            "journal's checksums only, so whether they changed cannot be told: refitted",
        )
    confirmed: dict[str, dict[str, Any]] = {}
    changed = change_since(
        record,
        now,
        lambda name: _file_sha256(files.get(name)),
        lambda name: _tiff_pixels(files.get(name)),
        confirmed,
    )
    update = None
    if changed is None and confirmed:
        update = RecordUpdate(final / "fit.json", summary, confirmed_update(record, confirmed))
    if lost:
        how = "judged by its images' sizes and modification times"
        if changed is None:
            note = f"; {_journal_gone(source)}: {how}, which match the fit"
            return EarlierFit(True, note=note, confirmed=update)
        return EarlierFit(True, f"{_journal_gone(source)}; {how}: {changed}")
    if changed is None:
        return EarlierFit(found=True, confirmed=update)
    return EarlierFit(True, CHANGED_SINCE + changed)


def _no_fit(final: Path) -> str | None:
    """Why ``final`` (which exists) holds no fit to judge, "" when it is an empty folder, None
    when it holds a ``fit.json``.

    Why: a folder of a session's name holding anything but a fit (a user's notes, a folder
    made ahead) was "skipped (finished earlier)", exit 0 and "every fit is written", with no
    fit anywhere; and refitting into it would have thrown its files away."""
    if not final.is_dir():
        return (
            f"{shown_path(final)} is a file, not a fit's folder: move it aside, or fit into "
            "another --out"
        )
    if (final / "fit.json").exists():
        return None
    try:
        held = sorted(p.name for p in final.iterdir())
    except OSError as exc:
        return f"{shown_path(final)} cannot be read ({exc.strerror or exc})"
    if not held:
        return ""
    more = f" and {len(held) - 3} more" if len(held) > 3 else ""
    return (
        f"{shown_path(final)} holds files but no fit (no fit.json: {', '.join(held[:3])}{more}), "
        "so it was left as it is: move them aside, or fit into another --out"
    )


def _set_aside_kept(set_aside: Path, final: Path) -> str:
    """Remove an earlier fit set aside by a refit, unless it holds files the fit did not write
    (its ``fit.json`` lists those it wrote): it is then kept beside ``final``, and what is said
    of the session says where. Why: a refit had removed the earlier fit's folder whole, with a
    user's notes or a condition report put in it."""
    import shutil

    try:
        summary = json.loads((set_aside / "fit.json").read_text(encoding="utf-8"))
        written = {str(n) for n in summary.get("files") or ()} | {"fit.json"}
        others = sorted(p.name for p in set_aside.iterdir() if p.name not in written)
    except (OSError, ValueError, AttributeError, TypeError):
        others = ["(what it holds could not be told from its fit.json)"]
    if not others:
        shutil.rmtree(set_aside, ignore_errors=True)
        return ""
    from rti_rig.core.out_folders import free_folder_beside

    kept = free_folder_beside(final, "earlier-fit")
    more = f" and {len(others) - 3} more" if len(others) > 3 else ""
    named = ", ".join(others[:3])
    held = f"; its earlier fit's folder held files the fit had not written ({named}{more})"
    try:
        set_aside.rename(kept)
    except OSError as exc:  # left under its backup's name, which the next batch removes
        return (
            f"{held}: it could not be renamed ({exc.strerror or exc}) and is left as "
            f"{shown_path(set_aside)}: move it out of --out before the next batch into it"
        )
    return f"{held}: it is kept, with them, as {shown_path(kept)}"


#: How :func:`earlier_fit` begins the words on a session whose images or lights changed since.
CHANGED_SINCE = "its session changed since the earlier fit: "


def changed_while_fitted(fit: Path, source: Path) -> str | None:
    """How ``source`` no longer matches the fit just written to ``fit`` (its record was taken
    before the images were read), or None when it still does.

    Why: a batch judged each session once; a session whose capture was resumed, or whose image
    was replaced, while its own fit ran got a fit of the session as it was before, reported
    "done" as if it matched the session's images now."""
    outgrown = earlier_fit(fit, source).outgrown
    if outgrown is None:
        return None
    return outgrown.removeprefix(CHANGED_SINCE)


def keep_confirmed(earlier: EarlierFit) -> None:
    """Keep the record :func:`earlier_fit` brought up to date, if any, in its ``fit.json``, so
    that the next batch need not hash those images again (a session copied without its
    times had been read in full on every batch)."""
    if earlier.confirmed is not None:
        update = earlier.confirmed
        _keep_record(update.fit_json, update.summary, update.record)


def _keep_record(path: Path, summary: dict[str, Any], record: dict[str, Any]) -> None:
    """Write ``summary`` with ``record`` as its inputs over ``path`` (a fit's ``fit.json``),
    atomically: a temporary file in the same folder, then ``os.replace``, so that a kill or a
    full disk leaves the old ``fit.json`` whole. Not written (the old record stands, and the
    next batch hashes again) when that fails: a fit folder one may not write to is no
    error of the batch's."""
    import tempfile

    text = json.dumps({**summary, INPUTS_KEY: record}, indent=1) + "\n"
    tmp: str | None = None
    try:
        fd, tmp = tempfile.mkstemp(prefix=".fit.json.", suffix=".tmp", dir=path.parent)
        with os.fdopen(fd, "w", encoding="utf-8") as fh:
            fh.write(text)
        os.replace(tmp, path)
        tmp = None
    except OSError:
        pass
    finally:
        if tmp is not None:
            with contextlib.suppress(OSError):
                os.unlink(tmp)


def _tiff_pixels(path: Path | None) -> str | None:
    """The pixel checksum of the TIFF at ``path`` (None when it is none or cannot be read)."""
    from rti_rig.core.image_files import tiff_pixels_sha256

    if path is None or path.suffix.lower() not in (".tif", ".tiff"):
        return None
    return tiff_pixels_sha256(path)


def _journal_gone(source: Path) -> str:
    """Words for a session whose journal the earlier fit's record relied on and that is now
    missing or unreadable, naming the file."""
    root = source if source.is_dir() else source.parent
    journal = root / JOURNAL
    state = "cannot be read" if journal.exists() else "is missing"
    return f"its session's journal {journal} {state} since the earlier fit"


def _file_sha256(path: Path | None) -> str | None:
    """The sha256 of the file at ``path`` (:func:`rti_rig.runtime.session.file_sha256`: one
    cache per process, so a session judged twice, by a cluster batch's plan and at its turn, is
    read once), or None when it cannot be read."""
    if path is None:
        return None
    try:
        return file_sha256(path)
    except OSError:
        return None


def fit_one(
    source: Path,
    root: Path,
    template: FitRequest,
    bands: BandRunner | None = None,
) -> BatchItem:
    """One session of a batch: fitted into a partial folder of its own (unique per attempt, so
    that a retried or orphaned attempt never writes into another's), renamed to
    :func:`batch_out_dir` when complete. If another attempt finished first, its folder stands
    and this one's is discarded. Runs in this process or as a task on a Dask worker; ``bands``
    as for :func:`run_fit`.

    The earlier fit is judged here, at the session's turn, not taken from what
    :func:`plan_batch` found when the batch began: the session may have changed since (a capture
    resumed, an image replaced while other sessions were fitted: it had been reported "skipped
    (finished earlier)", its fit of fewer images kept), and another batch into the same
    ``--out`` may have finished it (a swap finished here puts another fit in place). Its
    images are stat-ed again; only one whose size or time changed is hashed. A session that
    changed while its own fit ran is said so (:func:`changed_while_fitted`)."""
    final = batch_out_dir(root, source)
    said = finish_swap(root, final)
    earlier = earlier_fit(final, source)
    keep_confirmed(earlier)
    if earlier.foreign is not None:
        return BatchItem(source, final, Outcome.FAILED, f": {earlier.foreign}", notes=said)
    if earlier.stands:
        return BatchItem(source, final, Outcome.SKIPPED, earlier.skip_detail, notes=said)
    attempt = AttemptFolder.new(final.name)
    # who makes the attempt's folders, recorded before they exist: another run into this
    # --out, on this host or another, leaves them to this process while it runs (fit_owners);
    # a folder it cannot write in is left to run_fit to say, in its words
    with contextlib.suppress(OSError):
        write_owner_record(attempt, root)
    try:
        return _fit_attempt(source, root, template, bands, final, attempt, earlier, said)
    finally:
        if not any(attempt.as_kind(k).path(root).exists() for k in Kind):
            remove_owner_record(attempt, root)


def _fit_attempt(
    source: Path,
    root: Path,
    template: FitRequest,
    bands: BandRunner | None,
    final: Path,
    attempt: AttemptFolder,
    earlier: EarlierFit,
    said: tuple[str, ...],
) -> BatchItem:
    """:func:`fit_one`'s fit of ``source`` into ``attempt``'s partial folder, put in place in
    ``final`` (an ``earlier`` fit its session outgrew replaced once the new one is complete)."""
    import shutil
    from dataclasses import replace

    outgrown = earlier.outgrown
    partial = attempt.path(root)
    try:
        result = run_fit(replace(template, source=source, out_dir=partial), bands)
    except RtiRigError as exc:
        shutil.rmtree(partial, ignore_errors=True)
        if final.exists() and earlier_fit(final, source).stands:
            # another run into the same --out finished this session meanwhile (its failure
            # here, a folder gone under it, is no failure of the session's)
            return BatchItem(source, final, Outcome.DONE, DONE_ELSEWHERE, notes=said)
        kept = f" (the earlier fit in {final} is kept)" if outgrown and final.exists() else ""
        return BatchItem(source, final, Outcome.FAILED, f": {exc}{kept}", notes=said)
    moved_on = changed_while_fitted(partial, source)
    if outgrown is not None and final.exists() and earlier_fit(final, source).stands:
        # Another attempt put a current fit in place while this one ran (a worker of a batch
        # whose Dask scheduler was lost goes on with its session, and the user's rerun fits it
        # too): the swap below would have set that finished fit aside and put this one in,
        # replacing a finished output. It is kept; this attempt's copy is discarded.
        shutil.rmtree(partial, ignore_errors=True)
        return BatchItem(source, final, Outcome.DONE, DONE_ELSEWHERE, notes=said)
    kept_said = ""
    if outgrown is not None and final.exists():
        # the earlier fit is set aside only now that its successor is complete, under a
        # backup's name: a batch killed between the renames is finished by the next run's
        # finish_swap (the new fit put in place), never left without a fit
        set_aside = attempt.as_kind(Kind.EARLIER).path(root)
        try:
            final.rename(set_aside)
        except FileNotFoundError:  # another attempt replaced it meanwhile: rename as below
            pass
        else:
            try:
                partial.rename(final)
            except OSError:
                set_aside.rename(final)
                shutil.rmtree(partial, ignore_errors=True)
                raise
            kept_said = _set_aside_kept(set_aside, final)
    try:
        if partial.exists():
            partial.rename(final)  # atomic; refused when a finished folder is already there
    except OSError:
        shutil.rmtree(partial, ignore_errors=True)
        if not final.exists():
            raise
    # Earlier attempts' partial folders: a Dask worker killed mid-session cannot remove its
    # own, and the retry that finished the session had left it in --out (hundreds of MB of a
    # large session, a successful batch, never removed: later runs skip finished sessions).
    # An attempt still running (another batch into the same --out, or a worker of this
    # host) is left alone: it finds the session finished and discards its own copy.
    for stale in partial_folders(root, final.name):
        if owner_gone(stale):
            remove_attempt_folder(stale)
    detail = ("" if outgrown is None else f" ({outgrown})") + kept_said
    if moved_on is not None:
        # the fit is of the session as it was read, and its record says so: the next batch
        # refits it; said on the session's line, as "done" alone claims it matches
        detail += (
            f"; but its session changed while it was being fitted ({moved_on}): this fit is "
            "of the session as it was read; run the same command again once the session is "
            "no longer being changed to refit it"
        )
    return BatchItem(
        source,
        final,
        Outcome.DONE if outgrown is None else Outcome.REFITTED,
        detail,
        result.qa.verdict if result.qa is not None else None,
        (*said, *result.notes),
        tuple(result.warnings),
        moved_on,
    )
