"""The session folder: images, the `.lp` from what actually ran, a journal and a manifest.

Layout (opens directly in relight-cli's folder mode, which takes the first ``*.lp`` and the
``*.jpg`` files in name order)::

    SESSION/
      image_001.jpg ...      8-bit sRGB, one per step, named in execution order
      linear/image_001.tif   16-bit linear data for fitting (same numbering)
      raw/image_001.nef      the camera's original file(s) for the step, named by the session
                             (the camera's own name is kept in the journal); RAW+JPEG pairs
                             keep both files
      lights.lp              one line per image, from the light that actually fired
      journal.jsonl          one line per completed step, flushed to disk as it happens
      records/image_001.json the same record of each committed step, one file per step,
                             written atomically right before its journal line: what proves
                             the step if that line is damaged later or was never written
                             (see :func:`scan_journal`)
      manifest.json          rig config, schedule, per-step timings, versions, finish reason
      strays/image_002-IMG_0002.CR2
                             a picture the camera delivered with a step's but not of it (a
                             DSLR that answered busy yet took one): kept, in the step's
                             ``strays``, never one of the session's images
      recovered/STAMP/...    what a resume set aside: unverified images, rejected journal lines
                             (``--rebuild-journal``: the damaged journal, and the images the
                             manifest does not vouch for under ``unproven/``, ``not-in-manifest/``)

Nothing already captured is ever overwritten: a folder holding images is refused, and image
writes refuse existing files. Nothing is created on disk until :meth:`SessionFolder.begin`
(called once the rig is connected), and ``lights.lp`` is rewritten atomically after every
committed image, so a killed session opens in relight at once — except after a kill (SIGKILL,
a power cut) in the fraction of a second between an image's files and its journal line: that
image is then on disk but not in ``lights.lp``, and relight-cli refuses the folder for the
count; ``run --resume`` sets it aside. Other writers (a camera's RAW originals, say) may add
their own sub-folders: only ``image_*`` files and the files above are the session store's.
"""

from __future__ import annotations

import contextlib
import errno
import hashlib
import json
import math
import os
import platform
import shutil
import sys
import threading
import time
from collections.abc import Callable, Collection, Mapping
from concurrent.futures import ThreadPoolExecutor, wait
from dataclasses import asdict, dataclass, field
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from rti_rig.core.deferred_signals import signals_deferred
from rti_rig.core.devices import Frame
from rti_rig.core.errors import SessionError
from rti_rig.core.fit_minimums import PLAN_DEFAULT_LIGHTS
from rti_rig.core.image_colour import (
    ASSUMED_JPEG_WORDS,
    ASSUMED_LINEAR_WORDS,
    JPEG_COLOUR_WORDS,
    LINEAR_CAMERA_RGB,
    LINEAR_COLOUR_WORDS,
    LINEAR_GREY,
    LINEAR_SRGB,
    converted_words,
    decode_colour,
    file_colour_kind,
    icc_profile,
    other_space_words,
)
from rti_rig.core.image_files import (
    MOSAIC_TIFF_LABEL,
    labelled_white_level,
    linear_to_srgb8,
    pixels_sha256,
    tiff_pixels_sha256,
    write_linear_tiff,
    write_srgb_jpeg,
    write_untagged_jpeg,
)
from rti_rig.core.lp_format import LpEntry, format_lp, lp_files_in
from rti_rig.core.out_folders import (
    fit_beside,
    free_folder_beside,
    free_name,
    refuse_a_file_in_the_way,
)
from rti_rig.core.shell_words import shell_word, shown_path
from rti_rig.runtime.disowned import MARKER as DISOWNED_MARKER
from rti_rig.runtime.unrecorded_end import CAUSES, unrecorded_end
from rti_rig.runtime.unrecorded_end import UNRECORDED as RUN_UNRECORDED

MANIFEST = "manifest.json"
JOURNAL = "journal.jsonl"
LP_NAME = "lights.lp"
LINEAR_DIR = "linear"
RAW_DIR = "raw"
#: One file per committed step holding its journal record (see :meth:`SessionFolder.write_step`)
RECORDS_DIR = "records"
#: Where a DSLR downloads before the step is committed (files left here by a crash are moved to
#: recovered/ on resume, never used as a step's image and never deleted).
RAW_INCOMING = f"{RAW_DIR}/.incoming"
FORMAT = "rti-rig-session/1"


@dataclass(frozen=True)
class StepRecord:
    """What one step actually did, with its timings on the rig clock."""

    index: int
    image: str
    linear_image: str
    planned_direction: tuple[float, float, float]
    actual_direction: tuple[float, float, float]
    led: int | None
    exposure_s: float
    rig_start_s: float
    light_s: float
    settle_s: float
    capture_s: float
    write_wall_s: float
    saturated_fraction: float
    black_fraction: float
    sha256: dict[str, str] = field(default_factory=dict)
    #: linear TIFF → :func:`~rti_rig.core.image_files.pixels_sha256` of its pixels: a TIFF whose
    #: bytes differ from ``sha256`` but whose pixels match was re-saved, not edited (empty in
    #: sessions written before 2026-11-29: their TIFFs are checked by their bytes alone)
    pixels_sha256: dict[str, str] = field(default_factory=dict)
    #: session file → the camera's (or watched folder's) own name for it
    originals: dict[str, str] = field(default_factory=dict)
    #: session file → the absolute path of the user's file it was copied from and that stays
    #: there (a replay's recorded acquisition file): where a lost one is copied back from
    #: (empty in sessions written before 2026-12-02, and for a camera's own downloads)
    copied_from: dict[str, str] = field(default_factory=dict)
    #: how the linear image was made from the RAW file (mode, CFA pattern, black/white levels
    #: per channel, white balance, colour, orientation, source file); empty for non-RAW cameras
    decode: dict[str, Any] = field(default_factory=dict)
    notices: list[str] = field(default_factory=list)
    #: what a non-RAW camera file said of its colour space (``space``, ``name``, ``said_by``:
    #: :mod:`~rti_rig.drivers.cameras.file_colour`); empty for a RAW, a camera that writes no
    #: file, and sessions written before 2026-12-02 (all then declared sRGB)
    file_colour: dict[str, str] = field(default_factory=dict)
    #: an adaptive session's decision for this step and its evidence (None: a fixed schedule)
    decision: dict[str, Any] | None = None
    #: each time the step's light was switched off while a busy camera was awaited past the
    #: time the light may stay lit, and lit again for the shot: how long it had been lit
    #: (``lit_s``), what the all-off established (``off``: "acknowledged", "sent-no-ack"…),
    #: how long it was dark (``dark_s``), the camera's busy answers so far
    #: (``camera_busy_tries``) and the wait for its next try (``camera_wait_s``)
    relit: list[dict[str, Any]] = field(default_factory=list)
    #: pictures the camera delivered with this step's but not of it (a DSLR that answered busy
    #: yet took a picture): session file under ``strays/`` → {``camera_file``, ``sha256``};
    #: never one of the session's images, listed nowhere else
    strays: dict[str, dict[str, str]] = field(default_factory=dict)


#: Where a step's strays are kept (see ``StepRecord.strays``): apart from ``raw/``, whose
#: ``image_*`` files are a step's own.
STRAY_DIR = "strays"


def planned_steps(manifest: dict[str, Any]) -> int:
    """How many steps a session may take: its schedule's, or an adaptive session's maximum."""
    adaptive = manifest.get("adaptive")
    if isinstance(adaptive, dict) and adaptive.get("max_lights"):
        return int(adaptive["max_lights"])
    steps = (manifest.get("schedule") or {}).get("steps")
    return len(steps) if isinstance(steps, list) else 0


def image_names(total: int) -> list[str]:
    """``image_001`` ... zero-padded so that name order equals execution order."""
    width = max(3, len(str(total)))
    return [f"image_{i + 1:0{width}d}" for i in range(total)]


def software_versions() -> dict[str, str]:
    import cv2
    import numpy

    from rti_rig import __version__

    return {
        "rti_rig": __version__,
        "python": sys.version.split()[0],
        "numpy": numpy.__version__,
        "opencv": cv2.__version__,
        "platform": platform.platform(),
    }


def _now_iso() -> str:
    return datetime.now(UTC).isoformat(timespec="seconds")


class SessionWriteError(SessionError):
    """A session file could not be written (no space, read-only, I/O error): the session stops.

    ``path`` is the file; ``errno_name`` the system's reason (``ENOSPC``, ``EROFS``, ``EIO``…).
    """

    def __init__(self, path: Path, exc: OSError) -> None:
        import errno as _errno

        self.path = Path(path)
        #: the step this write came after the commit of (its journal line or ``lights.lp``
        #: failed once its record file was on disk): kept, and to be counted as such
        self.committed: StepRecord | None = None
        #: the camera's own names of the files of the step being written when this failed
        #: before its commit (its shot): not recorded, reshot by a resume
        self.shot: list[str] = []
        self.errno_name = _errno.errorcode.get(exc.errno or 0, "") if exc.errno else ""
        reason = exc.strerror or str(exc)
        code = f" ({self.errno_name})" if self.errno_name else ""
        super().__init__(f"cannot write {shown_path(self.path)}: {reason}{code}")


class SourceReadError(SessionWriteError):
    """A camera file the session was to keep (a replay's recorded file, a watched folder's)
    could not be read: its drive unplugged, the file moved, deleted or unreadable. The
    session's own disk is not at fault; ``source`` is the file, ``path`` the session's name it
    was to be kept under.

    Why: it was said as the session's failed write ("cannot write …/raw/image_003.jpg: No
    such file or directory … check that disk"), naming a file that was never the problem and
    a disk that was fine."""

    def __init__(self, source: Path, dest: Path, exc: OSError) -> None:
        super().__init__(dest, exc)
        self.source = Path(source)
        reason = exc.strerror or str(exc)
        code = f" ({self.errno_name})" if self.errno_name else ""
        self.args = (
            f"cannot read {shown_path(self.source)} (to keep it in the session as "
            f"{self.path.parent.name}/{self.path.name}): {reason}{code}",
        )


class _SourceUnreadable(Exception):
    """An OSError reading the file being copied, not writing its copy (:func:`_copy_whole`)."""

    def __init__(self, error: OSError) -> None:
        super().__init__(error)
        self.error = error


def _write_bytes_atomic(path: Path, data: bytes) -> None:
    """Replace ``path`` with ``data`` atomically (temporary file, fsync, rename); the temporary
    file is removed if anything fails, so a failed write leaves the old file and nothing else."""
    tmp = path.with_name(f".{path.name}.tmp")
    try:
        with open(tmp, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except OSError as exc:
        with contextlib.suppress(OSError):
            tmp.unlink(missing_ok=True)
        raise SessionWriteError(path, exc) from None


#: What a file system that cannot fsync a folder answers (some network and FUSE mounts):
#: the entries are then as durable as that file system makes them, and nothing more can be
#: done (PostgreSQL's fsync_fname ignores exactly these for folders).
_DIR_FSYNC_UNSUPPORTED = {errno.EINVAL, errno.EBADF, errno.ENOTSUP, errno.EOPNOTSUPP}


def _fsync_dir(path: Path) -> None:
    """Make a folder's entries (a file just renamed into it) durable across a power loss.

    A file system that does not fsync folders is let be: the step's files, its record file
    (the commit) and its journal line are each fsynced; stopping every run on such a disk (as
    this did) keeps nothing more."""
    try:
        fd = os.open(path, os.O_RDONLY)
    except OSError as exc:
        if exc.errno in _DIR_FSYNC_UNSUPPORTED:
            return
        raise
    try:
        os.fsync(fd)
    except OSError as exc:
        if exc.errno not in _DIR_FSYNC_UNSUPPORTED:
            raise
    finally:
        os.close(fd)


def _write_json_atomic(path: Path, data: dict[str, Any]) -> None:
    text = json.dumps(data, indent=2, default=str) + "\n"
    _write_bytes_atomic(path, text.encode("utf-8"))


def write_lp_atomic(path: Path, entries: list[LpEntry]) -> None:
    """Write an `.lp` file atomically, fsynced (relight may open it at any moment)."""
    _write_bytes_atomic(path, format_lp(entries).encode("ascii"))


#: Bytes a kept camera RAW may take per photosite: 16 bits, uncompressed (a DNG as
#: ``drivers.cameras.dng_writer`` writes it; a maker's compressed or 14-bit-packed file is less)
RAW_BYTES_PER_PHOTOSITE = 2
#: The JPEGs' bound per sample (8-bit, quality 95, 4:4:4, as ``write_srgb_jpeg`` writes them
#: and a camera's fine JPEG is): what the worst picture can take, not a typical one.
#: Measured with that writer at 512 x 512: a smooth lit relief 0.06 B a sample, the simulator's
#: painting 0.30, sensor-like noise (sd 40 of 255) 0.64, uniform noise 0.81, each channel
#: black or white at random 0.97 (the worst found). It had been 0.5 ("well under half a byte
#: a sample"): a noisy or finely textured object's JPEGs outgrew the disk check, by 34 MB an
#: image of a 24 MP camera, four times the check's 8 MB margin
#: (tests/app/test_jpeg_allowance.py).
JPEG_BYTES_PER_SAMPLE = 1.0


def estimated_bytes_per_image(
    width: int,
    height: int,
    decode_mode: str | None = None,
    *,
    kept_raw: bool = False,
    kept_jpeg: bool = False,
) -> int:
    """A generous upper bound for one step's files on disk, for a sensor of ``width`` ×
    ``height``: the uncompressed 16-bit linear TIFF and our sRGB JPEG of what the camera
    delivers, plus the camera's own files the session keeps beside them.

    ``decode_mode``: how a RAW camera's file is decoded (``[camera.device.decode] mode``):
    ``"demosaic"`` or None (frames straight from the camera) give RGB at full size, ``"half"``
    RGB at half width and height, ``"mosaic"`` one value per photosite. ``kept_raw``: the
    camera's RAW is kept in the session's ``raw/``; ``kept_jpeg``: the camera's JPEG too
    (``keep_jpeg``).

    Why: every RAW camera had been allowed 7.5 bytes a pixel (a full-size RGB TIFF and JPEG)
    whatever it wrote: twice what a ``"half"`` or ``"mosaic"`` session writes (disks that
    held the session were refused), and in ``"demosaic"`` mode the kept RAW and JPEG were not
    counted (a disk too small was let through until it filled mid-session)."""
    if decode_mode == "half":
        samples = (width // 2) * (height // 2) * 3
    elif decode_mode == "mosaic":
        samples = width * height
    else:
        samples = width * height * 3
    total = 2 * samples + int(samples * JPEG_BYTES_PER_SAMPLE) + 16_384
    if kept_raw:
        total += RAW_BYTES_PER_PHOTOSITE * width * height + 16_384
    if kept_jpeg:
        total += int(width * height * 3 * JPEG_BYTES_PER_SAMPLE) + 16_384
    return total


#: The manifest's record (under ``rig``) of a session whose camera delivered frames of another
#: size than its ``[camera]`` width x height: ``{"frames": [w, h], "config": [w, h]}``.
FRAME_SIZE_KEY = "frame_size"


def recorded_frame_size(
    manifest: dict[str, Any], width: int, height: int
) -> tuple[int, int] | None:
    """The frame size (width, height) the session's camera was seen to deliver, where its
    manifest records one that differed from a ``[camera]`` of ``width`` x ``height`` (the
    config as it still is); None otherwise.

    Why: a resume counted the disk at the config's size again (a 24 MP camera's images as
    0.26 MP) and said the config's size was wrong again, as if newly found."""
    seen = (manifest.get("rig") or {}).get(FRAME_SIZE_KEY)
    if not isinstance(seen, dict) or list(seen.get("config") or []) != [width, height]:
        return None
    frames = seen.get("frames")
    if not (isinstance(frames, list) and len(frames) == 2):
        return None
    return int(frames[0]), int(frames[1])


class SessionComplete(SessionError):
    """A resume of a session that completed every step, each image as captured: nothing to
    do, and no error (the command's exit says the session is complete).

    Why: a lab's script runs ``run --resume`` with the same line after a run that may or may
    not have finished; a complete session had been refused as an error (exit 2) with no word
    of the next step, though nothing was wrong with it. ``next_step`` is that step."""

    def __init__(self, message: str, next_step: str, root: Path | None = None) -> None:
        super().__init__(message)
        self.next_step = next_step
        #: the session's folder (the CLI adds the fit's ``--model`` from its lights.lp)
        self.root = root


class CompleteJournalNotWhole(SessionError):
    """A resume of a session that completed, its images as captured, whose journal is missing
    or lacks records (proved by the step record files instead): refused, naming
    ``--rebuild-journal``. Not :class:`SessionComplete` (exit 0): the session's record is not
    whole, and a script running the same ``--resume`` line must see that."""


class ImagesLostSinceCapture(SessionError):
    """A resume refused because the session completed: ``note`` is what the refusal says of
    its images missing or changed since capture (:func:`_lost_note`) or renamed (empty when
    none is).

    Why: a camera-triggered dome's resume is refused by the app with words of its own, and
    had dropped this refusal, so the image lost was never named; the note lets it say the
    same words, with no second copy of the listing."""

    def __init__(self, message: str, note: str) -> None:
        super().__init__(message)
        self.note = note


class NoSpaceError(SessionError):
    """The disk cannot hold the next image(s): checked before the rig starts and before each
    image, so the session stops cleanly rather than on a write that fails half-way.

    Carries its figures (``where``, ``steps``, ``need`` and ``free`` in bytes) so that a caller
    whose advice differs can say it again in its own words: a resume must not be told to
    "choose another --out", which ``run --resume`` refuses."""

    def __init__(self, message: str, where: Path, steps: int, need: int, free: int) -> None:
        super().__init__(message)
        self.where, self.steps, self.need, self.free = where, steps, need, free

    @property
    def shortfall(self) -> int:
        """How many bytes must be freed on that disk for the images asked for."""
        return max(0, self.need - self.free)


def steps_to_hold(total: int, done: int, sure: int) -> int:
    """How many images the disk must hold before a session (re)starts: those it is sure to
    take (``sure`` of ``total``, ``done`` already taken), and at least the next one while any
    is left.

    Why: an adaptive session stopped by its --until-error target takes an unknown number of
    images up to ``total``; asking room for ``total`` (48 images, 103.5 MB, for a session that
    stopped after 4) refused sessions that fit. The rest is checked image by image, and a
    session stopped by a full disk is kept and can be resumed."""
    left = max(0, total - done)
    return min(left, max(1, sure - done)) if left else 0


def megabytes_said(need: int, free: int) -> tuple[str, str]:
    """``need`` and ``free`` bytes as "N MB", with as many decimals (up to 3) as it takes for
    the two to read differently when they differ: "need about 10 MB, 10 MB free" had refused
    a session for 0.4 MB (QA, 2026-12-06)."""
    for places in range(4):
        said = (f"{need / 1e6:.{places}f} MB", f"{free / 1e6:.{places}f} MB")
        if said[0] != said[1] or need == free:
            return said
    return said


def check_free_space(
    root: Path, steps: int, bytes_per_image: int, *, holds_images: bool = False
) -> None:
    """Refuse to go on when the disk cannot hold the images still to be captured.

    ``holds_images``: the session under ``root`` already holds images, so it can only go on
    there: the advice is to free space on that disk, never to "choose another --out" (a new
    session elsewhere, which a resume refuses)."""
    probe = Path(root)
    while not probe.exists():
        probe = probe.parent
    free = shutil.disk_usage(probe).free
    need = steps * bytes_per_image + 8 * 1024 * 1024
    if free < need:
        advice = (
            f"free at least {math.ceil((need - free) / 1e6)} MB on that disk to go on"
            if holds_images
            else "free space or choose another --out"
        )
        need_mb, free_mb = megabytes_said(need, free)
        raise NoSpaceError(
            f"not enough free disk space for {steps} image(s) under {probe}: need about "
            f"{need_mb}, {free_mb} free; {advice}",
            probe,
            steps,
            need,
            free,
        )


#: Files a session folder that holds no image may contain (left by a session that stopped
#: before its first image): such a folder may be reused for a new session.
_NO_IMAGE_FILES = {MANIFEST, JOURNAL, LP_NAME}


_HASH_POOL: ThreadPoolExecutor | None = None


def _hash_pool() -> ThreadPoolExecutor:
    """The one thread that checksums a step's pixels while its files are written (made on
    first use and kept: a session writes hundreds of steps, each had started a thread)."""
    global _HASH_POOL
    if _HASH_POOL is None:
        _HASH_POOL = ThreadPoolExecutor(max_workers=1, thread_name_prefix="pixel-sha256")
    return _HASH_POOL


#: Files an operating system's file browser leaves in any folder it shows (macOS Finder,
#: Windows Explorer): a folder made for a session and opened there holds one before any image,
#: and had been refused as "not empty"
_FOLDER_METADATA = {".DS_Store", "Thumbs.db", "desktop.ini", ".directory"}


def holds_no_image(root: Path) -> bool:
    """True if ``root`` holds nothing but an image-less session's own files.

    Its own folders, empty, are no image: ``raw/.incoming`` is made for a DSLR's first
    download, and a download that failed leaves it empty (a stop there had said "holds files of
    the camera" of a folder holding none, and a new run in it was refused)."""
    for path in root.rglob("*"):
        rel = path.relative_to(root)
        if path.is_dir():
            if rel.as_posix() not in (LINEAR_DIR, RAW_DIR, RAW_INCOMING):
                return False
            continue
        name = rel.as_posix()
        if name.startswith(".") and name.endswith((".tmp", ".partial")):
            continue
        if path.name in _FOLDER_METADATA:
            continue
        if name not in _NO_IMAGE_FILES:
            return False
    journal = root / JOURNAL
    return not (journal.exists() and scan_journal(root).records)


def is_session_folder(folder: Path) -> bool:
    """True if ``folder`` holds a session's own record: its manifest or its journal (a folder
    with only a ``lights.lp`` is an acquisition any tool may have written, not a session)."""
    return (folder / MANIFEST).is_file() or (folder / JOURNAL).is_file()


def enclosing_session(root: Path) -> Path | None:
    """The nearest folder above ``root`` that is a session (:func:`is_session_folder`), named
    as ``root`` was (relative to the working folder when ``root`` is and it lies within it);
    ``None`` if there is none.

    Why: a new session given an ``--out`` inside a finished one was written there, nested
    among its images; a copy, a fit or a ``--resume`` of the outer session then carries or
    stumbles over the inner one. The path is resolved first, so ``S/../T/new`` is not taken
    for a folder inside ``S`` and a symbolic link into a session is. A folder that cannot be
    looked into (PermissionError on Python 3.11) is passed over: the ``--out`` checks that
    follow refuse it by name, where this had raised past them as a traceback.
    """
    resolved = Path(root).resolve()
    for ancestor in resolved.parents:
        try:
            inside = is_session_folder(ancestor)
        except OSError:  # a folder the user may not look into: the write check says so
            continue
        if inside:
            if Path(root).is_absolute():
                return ancestor
            try:
                shown = ancestor.relative_to(Path.cwd().resolve())
            except ValueError:
                return ancestor
            return shown if shown.parts else ancestor
    return None


#: session folders this process writes, locked against a second rti-rig process (resolved
#: path → the folder's open descriptor, whose ``flock`` is the lock)
_LOCKED: dict[str, int] = {}


def lock_session(root: Path) -> None:
    """Hold ``root`` for this process's session, or refuse: another process writes it.

    Nothing stopped a second ``run --resume`` on a session still being captured (it seemed
    stuck, or another terminal): it moved the running session's image in flight to
    ``recovered/``, shot a step the first then failed on, and the manifest kept only one of the
    two runs; on a real rig both would drive the dome. The lock is the kernel's ``flock`` on the
    folder itself (no file is added to the session), released by :func:`unlock_session` or when
    the process ends, however it ends (``kill -9`` included)."""
    try:
        import fcntl
    except ImportError:  # not on POSIX: no lock
        return
    key = str(Path(root).resolve())
    if key in _LOCKED:
        return
    try:
        fd = os.open(key, os.O_RDONLY)
    except OSError:  # a folder that cannot be opened for reading: its writes will say more
        return
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        os.close(fd)
        raise SessionError(
            f"{shown_path(root)} is in use by another rti-rig process (a session is being captured "
            "or resumed in it): let it finish, or stop it (Ctrl-C in its terminal), then "
            f"continue with: rti-rig run --resume {shell_word(str(root))}"
        ) from None
    except OSError:  # a filesystem without flock (some network mounts): no lock, as before
        os.close(fd)
        return
    _LOCKED[key] = fd


def _finished_hint(root: Path, manifest: dict[str, Any]) -> str:
    """What to do with the finished session in ``root`` that a new one may not overwrite: a
    preview (``rti-rig preview``'s one image, its schedule's method ``preview``) is planned
    from, any other session fitted.

    Why: a preview folder given twice to ``preview --out`` had been told "fit it with rti-rig
    fit", which cannot fit one image; the command that uses a preview is ``plan``, given its
    rig (the config the preview recorded, as ``preview`` itself advises)."""
    folder = shell_word(str(root))
    if (manifest.get("schedule") or {}).get("method") == "preview":
        rig = (manifest.get("rig") or {}).get("config_path")
        shown = shell_word(str(rig)) if isinstance(rig, str) and rig else "RIG.toml"
        plan_lp = shell_word(str(free_name(Path("plan.lp"))))  # plan refuses an existing one
        # the count the rig allows, recorded at capture (the rig's geometry is not loaded
        # here): plan's default 12 was refused on a dome of 8 LEDs; a session recorded before
        # the count was gets plan's default
        lights = (manifest.get("rig") or {}).get("plan_lights")
        if not isinstance(lights, int) or isinstance(lights, bool) or lights < 1:
            lights = PLAN_DEFAULT_LIGHTS
        return (
            f" (it holds a finished preview: plan from it with rti-rig plan {folder} --rig "
            f"{shown} --lights {lights} --out {plan_lp})"
        )
    # a real, free folder beside the session (fit refuses one inside it): ``--out DIR`` had
    # been printed, which pasted made a folder named DIR
    return f" (it holds a finished session: fit it with {fit_beside(root)})"


def refuse_if_in_use(root: Path, what: str) -> None:
    """Refuse to read session ``root`` while another process holds it (:func:`lock_session`: a
    run or resume capturing into it), saying to ``what`` ("fit it", "export its .lp") once that
    run has ended (a verb alone had read "export its .lp it once that run has ended").

    Why: ``fit`` of a session still being captured read its ``lights.lp`` and its images at
    different moments: "error: 40 image names for 33 light directions", or a verdict of a part
    of the session that advised a ``--resume`` the running capture would refuse. A shared
    ``flock`` is tried and released at once; a folder this process holds is not in use by
    another (``run``'s own verdict), and one that cannot be locked (not POSIX, some network
    mounts) is read as before."""
    if in_use_by_another(root):
        raise SessionError(
            f"{shown_path(root)} is being captured by another rti-rig process right now (its "
            f"images and {LP_NAME} change as it goes): {what} once that run has ended (or stop it "
            "with Ctrl-C in its terminal)"
        )


def in_use_by_another(root: Path) -> bool:
    """Whether another process holds session ``root`` (:func:`lock_session`), tried with a
    shared ``flock`` released at once; ``False`` where that cannot be known (not POSIX, a
    folder that cannot be locked) or this process holds it."""
    try:
        import fcntl
    except ImportError:
        return False
    key = str(Path(root).resolve())
    if key in _LOCKED or not (Path(root) / MANIFEST).is_file():
        return False
    try:
        fd = os.open(key, os.O_RDONLY)
    except OSError:
        return False
    try:
        fcntl.flock(fd, fcntl.LOCK_SH | fcntl.LOCK_NB)
    except BlockingIOError:
        return True
    except OSError:
        return False
    finally:
        os.close(fd)  # releases the shared lock, if it was taken
    return False


def unlock_session(root: Path) -> None:
    """Release :func:`lock_session`'s hold on ``root`` (nothing if it is not held)."""
    fd = _LOCKED.pop(str(Path(root).resolve()), None)
    if fd is not None:
        os.close(fd)  # closing the descriptor releases its flock


@dataclass(frozen=True)
class PutBack:
    """What a reshoot that never began put back (:meth:`SessionFolder.put_back_unshot`): the
    files (relative to the session folder), and the images among them that are as captured
    and those still missing or changed since capture (``--reshoot-lost``'s), by name."""

    files: tuple[str, ...]
    as_captured: tuple[str, ...]
    not_as_captured: tuple[str, ...]


class SessionFolder:
    """Writes one session: created empty (or reopened to resume), filled step by step.

    ``rig_identity`` (set by whoever opens the session) is what the images depend on — the
    rig's kind, lights, camera size, exposure, decoding — recorded in the manifest so a resume
    can refuse another rig; ``rig_change`` records a difference the user accepted.
    """

    def __init__(self, root: Path, total_steps: int) -> None:
        self.root = Path(root)
        self.total_steps = total_steps
        self.names = image_names(total_steps)
        self.manifest: dict[str, Any] = {}
        self.resume: ResumeState | None = None
        self.rig_identity: dict[str, Any] | None = None
        self.rig_change: list[str] | None = None
        #: the steps already shot that the rig as changed could not take (one line each, as
        #: the schedule check says them): kept, shot on the rig as it was; recorded in the run
        self.shot_beyond_change: list[str] | None = None
        #: an adaptive session's starting layout as recorded before a resume on a changed rig
        #: placed what was left of it again (the manifest's ``schedule`` then says the lights
        #: that fire): kept in the run, so the layout the session began with is not lost
        self.schedule_before_change: dict[str, Any] | None = None
        #: what reading the run's input files tolerated (a `.lp` light clamped at the horizon, a
        #: count line that disagreed): recorded in the manifest, so the session says what it
        #: was shot from and what was assumed about it, not only the terminal that ran it
        self.input_notes: list[str] = []
        self.begun = False
        #: this run's end as the controller handed it to :meth:`finish` (its ``runner``
        #: record: finish reason, teardown failures, arm end), None before; kept also for a
        #: run that never began. Why: a resume whose rig did not connect writes no manifest,
        #: whose ``runner`` then still holds the previous run's end, and ``run`` had printed
        #: that run's teardown problems ("stop incomplete: servo 1 held where it is") as this
        #: run's, beside "Nothing was commanded: the arm could not be connected"
        self.run_end: dict[str, Any] | None = None
        #: every committed step (earlier runs' verified ones and this run's), by index
        self.committed: dict[int, StepRecord] = {}
        #: what a reshoot that never shot put back (:meth:`put_back_unshot`), to be said
        self.put_back: PutBack | None = None

    @staticmethod
    def check_new(root: Path) -> None:
        """Refuse a folder a new session may not be written into (checked before the rig is
        even opened, so nothing moves or lights for a session that cannot be kept).

        A folder that holds no image (empty, or left by a session that stopped before its
        first image) may be reused.
        """
        root = Path(root)
        # a file at --out or above it is named as fit and bench name it (it had been "exists
        # and is not a folder" here, and "cannot write …: Not a directory" for one under it)
        refuse_a_file_in_the_way(root)
        outer = enclosing_session(root)
        if outer is not None:  # a session written inside another goes wherever that one goes
            try:
                finished = (read_manifest(outer).get("runner") or {}).get(
                    "finish_reason"
                ) == "completed"
                resume = f"rti-rig run --resume {shell_word(str(outer))}"
                what = (
                    "a finished session"
                    if finished
                    else "a session another rti-rig process is capturing into right now"
                    if in_use_by_another(outer)  # running, not interrupted: no resume to offer
                    else f"an interrupted session (continue it with {resume})"
                )
            except SessionError:  # a journal without a manifest, or a damaged manifest
                what = f"a session folder (it holds rti-rig's {MANIFEST} or {JOURNAL})"
            raise SessionError(
                f"--out {shown_path(root)} is inside {shown_path(outer)}, {what}: give an --out "
                "outside it, so that each session stays a folder of its own"
            )
        if root.exists() and any(root.iterdir()) and not holds_no_image(root):
            resume = ""  # not a session: no resume to offer
            if (root / MANIFEST).is_file():
                try:
                    manifest = read_manifest(root)
                    finished = (manifest.get("runner") or {}).get("finish_reason") == "completed"
                except SessionError:
                    manifest, finished = {}, False
                resume = (
                    _finished_hint(root, manifest)
                    if finished
                    else ", or continue the interrupted session in it with "
                    f"rti-rig run --resume {shell_word(str(root))}"
                )
                if not finished and in_use_by_another(root):  # running, not interrupted
                    resume = " (another rti-rig process is capturing a session in it right now)"
            # a folder that does not exist yet, named: "choose a new --out folder" named none
            fresh = shell_word(str(free_name(root, folder=True)))
            raise SessionError(
                f"{shown_path(root)} is not empty: refusing to write a session over existing "
                f"files; choose a new --out folder (such as --out {fresh}, which does not exist "
                f"yet){resume}"
            )
        # where the session's folder would be made: found unwritable only at the first image,
        # a session had lit the rig (and on an arm, moved it) for nothing
        nearest = root
        while not nearest.exists() and nearest != nearest.parent:
            nearest = nearest.parent
        if nearest.is_dir() and not os.access(nearest, os.W_OK | os.X_OK):
            raise SessionError(
                f"{shown_path(root)}: cannot write there ({shown_path(nearest)} is read-only or "
                "not writable by you); choose an --out folder you can write to"
            )

    @classmethod
    def create(cls, root: Path, total_steps: int) -> SessionFolder:
        """A new session in ``root`` (checked, but not created: :meth:`begin` creates it)."""
        root = Path(root)
        cls.check_new(root)
        return cls(root, total_steps)

    @classmethod
    def reopen(
        cls,
        root: Path,
        check_done: Callable[[dict[int, StepRecord]], None] | None = None,
        reshoot_lost: bool = False,
        rebuild_journal: bool = False,
        also_reshoot: tuple[int, ...] = (),
    ) -> SessionFolder:
        """Open an interrupted session to capture the steps it has not done yet.

        What is on disk is verified against the journal's checksums first, and the journal is
        repaired; see :func:`prepare_resume` (``check_done`` may refuse the verified steps
        before anything in the folder changes; ``reshoot_lost`` reopens a completed session to
        reshoot what was lost since capture; ``rebuild_journal`` rebuilds a journal that lost
        records from the manifest's; ``also_reshoot``: steps to reshoot with the lost ones,
        their images intact but named by the user, ``--reshoot``).
        """
        state = prepare_resume(Path(root), check_done, reshoot_lost, rebuild_journal, also_reshoot)
        folder = cls(Path(root), planned_steps(state.manifest))
        folder.manifest = state.manifest
        folder.resume = state
        folder.committed = dict(state.done)
        return folder

    @property
    def done(self) -> dict[int, StepRecord]:
        return dict(self.resume.done) if self.resume else {}

    def put_back_unshot(self) -> PutBack | None:
        """Undo a reshoot's reopen of a completed session that never began to shoot (its rig
        did not open or connect, or a stop came before the capture): every image file it set
        aside goes back where it was and ``lights.lp`` lists every step again, as the
        completed session had, and :attr:`committed` is what the folder then holds as captured;
        returns what was put back, None when this reopen was not such
        a one or did more than set image files aside (a hand-edited ``lights.lp`` kept, the
        journal repaired or its records restored, a RAW download set aside: then the folder
        stays as the reopen left it, each of those said by the resume as it did them).

        Why: the images named with ``--reshoot`` were moved to ``recovered/`` before the rig
        opened; with the dome's port held, the session stayed "completed" with those images
        missing, and every later command (a plain resume, the verdict) called them "missing
        or changed since capture", files rti-rig itself had moved. What ``--reshoot-lost`` set
        aside (lost or changed since capture) goes back as it was found, and is said so."""
        state = self.resume
        runner = (state.manifest.get("runner") if state else None) or {}
        if (
            state is None
            or self.begun
            or runner.get("finish_reason") != "completed"
            or not state.recovered
            or state.edited_lp is not None
            or state.journal_repair
            or state.journal_rebuild
        ):
            return None
        back: list[tuple[Path, Path]] = []
        for rel in state.recovered:
            parts = Path(rel).parts
            if len(parts) < 3 or parts[0] != "recovered" or not parts[-1].startswith("image_"):
                return None
            back.append((self.root / rel, self.root.joinpath(*parts[2:])))
        if any(place.exists() or not aside.is_file() for aside, place in back):
            return None
        with signals_deferred():
            for aside, place in back:
                try:
                    os.replace(aside, place)
                except OSError as exc:
                    raise SessionWriteError(place, exc) from None
            records = scan_journal(self.root, self.names).records
            latest = _latest_records(records)
            # every step listed, as the completed session had (lost ones too: as found)
            _relist_verified(self.root, {i: _to_record(r) for i, r in latest.items()}, "")
            for aside, _ in back:  # the folders the reopen made and left empty now
                for folder in aside.parents:
                    if not folder.is_relative_to(self.root / "recovered"):
                        break
                    if folder.is_dir() and not any(folder.iterdir()):
                        folder.rmdir()
        intact = verified_steps(self.root, records)
        self.committed = intact  # what the folder holds as captured now
        stems = sorted({Path(place.name).stem for _, place in back})
        by_stem = {Path(str(rec["image"])).stem: i for i, rec in latest.items()}
        return PutBack(
            files=tuple(place.relative_to(self.root).as_posix() for _, place in back),
            as_captured=tuple(s for s in stems if by_stem.get(s) in intact),
            not_as_captured=tuple(s for s in stems if by_stem.get(s) not in intact),
        )

    def put_back_now(self) -> None:
        """:meth:`put_back_unshot` once, what it put back kept in :attr:`put_back` (a second
        call finds the files in place and would say nothing was)."""
        if self.put_back is None:
            self.put_back = self.put_back_unshot()

    @property
    def images_kept(self) -> int:
        """Committed images in the folder (earlier runs' and this one's)."""
        return len(self.committed)

    def image_layout(self) -> tuple[int, int, bool] | None:
        """(height, width, colour) of the session's images, from the header of its first
        committed linear TIFF; None before any image (or if that header says nothing)."""
        from rti_rig.core.image_files import header_layout

        for index in sorted(self.committed):
            try:
                return header_layout(self.root / self.committed[index].linear_image)
            except OSError:
                return None
        return None

    def set_aside(self, index: int, frame: Frame, why: str) -> list[str]:
        """Keep ``frame``, which cannot be one of the session's images, as a linear TIFF under
        ``recovered/`` (never listed, never deleted), and beside it, under ``raw/``, the
        camera's own files of it that the session holds (a DSLR download staged in
        ``raw/.incoming``); their paths relative to the folder, the TIFF's first.

        Why: only the TIFF was named; the RAW, the capture itself and perhaps its only copy
        (a body shooting to its RAM keeps none), stayed in the hidden ``raw/.incoming`` under a
        staging name until a resume moved it to another ``recovered/`` folder, unsaid."""
        stamp = _new_stamp(self.root)
        rel = f"recovered/{stamp}/{LINEAR_DIR}/{self.names[index]}.tif"
        dest = self.root / rel
        try:
            dest.parent.mkdir(parents=True, exist_ok=True)
            # labelled as a session's linear TIFF of it would be, then why it is not one (it
            # had said only why: no word of its pixels being linear, no profile)
            label, icc = linear_tiff_labels(dict(frame.metadata.get("decode") or {}), frame)
            write_linear_tiff(dest, frame.pixels, description=f"{label}; {why}", iccprofile=icc)
        except OSError as exc:
            raise SessionWriteError(dest, exc) from None
        kept = [rel]
        root = self.root.resolve()
        for item in frame.metadata.get("originals") or []:
            src = Path(item["path"])
            if item.get("copy") or not src.is_file() or not src.resolve().is_relative_to(root):
                continue  # a watched folder's (or a replay's) own file: left where it is
            raw_rel = f"recovered/{stamp}/{RAW_DIR}/{src.name}"
            try:
                (self.root / raw_rel).parent.mkdir(parents=True, exist_ok=True)
                os.replace(src, self.root / raw_rel)
            except OSError as exc:
                raise SessionWriteError(self.root / raw_rel, exc) from None
            kept.append(raw_rel)
        return kept

    def _make_folder(self) -> None:
        try:
            (self.root / LINEAR_DIR).mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise SessionWriteError(self.root, exc) from None
        lock_session(self.root)  # two runs given the same new --out: the second stops here
        # ... and one that was checked before another run in the same --out began and finished
        # (it took its images while this one's rig was opening): what that left is no image-less
        # leftover to clear; its journal, lights.lp and manifest had been replaced by this one's
        self.check_new(self.root)
        # an image-less session left here before (see check_new): its files go
        for name in (JOURNAL, LP_NAME):
            with contextlib.suppress(FileNotFoundError):
                (self.root / name).unlink()

    def begin(self, header: dict[str, Any]) -> None:
        """Record what is about to run, once the rig is connected and before anything moves.

        A new session's folder is created here, not before: a rig that cannot be reached leaves
        nothing on disk.
        """
        run: dict[str, Any] = {
            "started_at": _now_iso(),
            "software": software_versions(),
            # which config (and light calibration) this run's images were shot with
            "config_sha256": (header.get("rig") or {}).get("config_sha256"),
        }
        if self.input_notes:
            run["input_notes"] = list(self.input_notes)
        if self.resume is not None:
            if header["schedule"] != self.manifest["schedule"]:
                raise SessionError(
                    f"{shown_path(self.root)}: the schedule to resume differs from the one the "
                    "session began with; a resumed session must run the same steps"
                )
            runs = self.manifest.setdefault("runs", [])
            for old in runs:
                # a run that never recorded its end: killed, a power cut or a disk too full
                # to record it (it had been marked "crashed", a cause nobody established)
                old.setdefault("finish_reason", RUN_UNRECORDED)
            run["resumed_with_steps_done"] = len(self.resume.done)
            run["recovered_files"] = self.resume.recovered
            if self.resume.journal_repair:
                run["journal_repair"] = [note.text for note in self.resume.journal_repair]
            if self.resume.journal_rebuild:
                run["journal_rebuild"] = self.resume.journal_rebuild
            if self.resume.lost_since_capture:
                run["lost_since_capture"] = self.resume.lost_since_capture
            if self.rig_change:
                run["rig_change"] = self.rig_change
            if self.shot_beyond_change:
                run["shot_before_rig_change"] = {
                    "note": "shot on the rig as it was before this run's rig_change, which "
                    "could not take them; kept, lights.lp lists the lights that fired",
                    "steps": self.shot_beyond_change,
                }
            if self.schedule_before_change is not None:
                run["schedule_before_rig_change"] = self.schedule_before_change
            if self.rig_identity is not None:
                self.manifest.setdefault("rig", {})["identity"] = self.rig_identity
            used = (header.get("rig") or {}).get("config")
            if used is not None:
                # the config as this run read it: the rig record keeps the first run's, and an
                # adaptive resume compares the times its decisions weigh with the last run's
                run["config"] = used
            new_path = (header.get("rig") or {}).get("config_path")
            if new_path:
                # the config this run used is the session's own from now on (a change of rig was
                # accepted, or the same rig's config was given from elsewhere)
                run["config_path"] = new_path
                self.manifest.setdefault("rig", {})["config_path"] = new_path
            runs.append(run)
            self.manifest["runner"] = self._running()
        else:
            self._make_folder()
            rig = dict(header.get("rig") or {})
            if self.rig_identity is not None:
                rig["identity"] = self.rig_identity
            self.manifest = {
                "format": FORMAT,
                "software": run["software"],
                "started_at": run["started_at"],
                **header,
                "rig": rig,
                **({"input_notes": list(self.input_notes)} if self.input_notes else {}),
                "runner": self._running(),
                "runs": [run],
                "steps": [],
            }
        _write_json_atomic(self.root / MANIFEST, self.manifest)
        self.begun = True

    def _running(self) -> dict[str, Any]:
        """The manifest's ``runner`` while a run is under way: its steps counted from the
        start.

        Why: ``steps_done`` and ``steps_planned`` had been written only at a run's end, so a
        script reading the manifest during a run, or after a run killed outright, found
        neither. The manifest is not rewritten per image (``lights.lp`` and the journal are):
        ``steps_done`` here is the images committed when the run began, a lower bound, brought
        up to date where the run's end is recorded."""
        return {
            "state": "running",
            "finish_reason": None,
            "steps_planned": self.total_steps,
            "steps_done": len(self.committed),
        }

    def record_cut_end(self, reason: str, teardown_failures: list[str] | None = None) -> bool:
        """Record in the manifest that this run was stopped (``reason``: a finish reason such
        as ``"emergency-stop"``) where the stop cut the run's end before :meth:`finish` could
        record it; nothing for a session never begun, or a run whose end is recorded.

        Why: the run's entry was left as a killed run leaves it (no end, no time), so a later
        ``--resume`` said "1 run(s) killed" of a run a Ctrl-C or SIGTERM had stopped. Only the
        manifest is written, atomically, from what it held at the run's start: the images,
        their records, the journal and ``lights.lp`` are left as they are (the resume reads
        them as after a kill); the run's time is not known here and stays unrecorded. A write
        that fails changes nothing on disk (the run then reads as killed, as before).

        ``teardown_failures``: what making the rig safe in the teardown's stead could not do
        (a port that did not close cleanly among them), recorded as the controller's teardown
        records its own (``runner.teardown_failures``): said in words alone, it had been in no
        record of the run. True when the manifest was written with them (False: nothing to
        record them in, or the write failed)."""
        if not self.begun or self.run_end is not None or not self.manifest.get("runs"):
            return False
        run = self.manifest["runs"][-1]
        run.update({"finished_at": _now_iso(), "finish_reason": reason, "end_cut": True})
        self.manifest["runner"] = {
            **(self.manifest.get("runner") or {}),
            "state": "stopped",
            "finish_reason": reason,
            "end_cut": True,
            # the images committed by the time the stop came (one whose commit the stop cut
            # is read back by the resume, as after a kill)
            "steps_done": len(self.committed),
            "teardown_failures": list(teardown_failures or []),
        }
        try:
            _write_json_atomic(self.root / MANIFEST, self.manifest)
        except (OSError, SessionWriteError):
            return False
        return True

    def write_step(self, index: int, frame: Frame, record_fields: dict[str, Any]) -> StepRecord:
        """Write one captured frame (linear TIFF, then sRGB JPEG), then journal it.

        A step is committed once its record file (``records/BASE.json``) is on disk and its
        files match the checksums in it; its journal line follows, and a resume writes a
        missing line back from the record file. Only if the record file cannot be written does
        the journal line alone commit the step. ``lights.lp`` is then rewritten from every
        committed step. A write that fails (no space, read-only, I/O error) raises
        :class:`SessionWriteError` naming the file, with no temporary file left behind and the
        journal as it was; if the step was committed before the failure, the error's
        ``committed`` holds its record, so that the run counts it as the folder does; if not,
        its ``shot`` names the step's camera files (the stop had not said which shot was lost
        to the disk, nor that a resume shoots it again).
        """
        t0 = time.perf_counter()
        base = self.names[index]
        listed = frame.metadata.get("originals") or []
        try:
            return self._write_step(index, frame, record_fields, t0, base, listed)
        except SessionWriteError as exc:
            if exc.committed is None:  # the step's shot is not recorded: say which it was
                exc.shot = [str(item.get("name") or Path(item["path"]).name) for item in listed]
            raise

    def _write_step(
        self,
        index: int,
        frame: Frame,
        record_fields: dict[str, Any],
        t0: float,
        base: str,
        listed: list[dict[str, Any]],
    ) -> StepRecord:
        """:meth:`write_step`'s writes, whose failure it completes with the step's shot."""
        jpg, tif = f"{base}.jpg", f"{LINEAR_DIR}/{base}.tif"
        decode = dict(frame.metadata.get("decode") or {})
        originals = self._keep_originals(base, listed)  # names the file if a write fails
        strays = self._keep_strays(base, frame.metadata.get("stray_originals") or [])
        current = self.root / tif
        try:
            for item, rel in zip(listed, originals, strict=True):
                if decode.get("source_file") == str(item["path"]):
                    # where the decoded RAW is kept now, and the camera's (or the watched
                    # folder's) own name for it; source_file names the kept file too: it had
                    # named the staged download (raw/.incoming/cap0001_…), gone once moved
                    decode["raw_file"] = rel
                    decode["source_file"] = rel
                    decode["camera_file"] = originals[rel][1]
            sha = {name: digest for name, (digest, _) in originals.items()}
            current = self.root / tif
            description, icc = linear_tiff_labels(decode, frame)
            colour = decode_colour(decode)
            if not decode and file_colour_kind(_file_colour(frame)) == "other":
                colour = "camera"  # another space's primaries: never tagged sRGB
            jpeg_writer = write_srgb_jpeg if colour == "srgb" else write_untagged_jpeg
            # the pixels' checksum is taken while the files are encoded and written (hashing
            # releases the GIL): about 0.4 s of CPU for a 24 MP frame, overlapped, not added
            pixel_digest = _hash_pool().submit(pixels_sha256, frame.pixels)
            try:
                sha[tif] = write_linear_tiff(
                    current, frame.pixels, description=description, iccprofile=icc
                )
                current = self.root / jpg
                srgb8 = linear_to_srgb8(frame.pixels, frame.white_level)
                sha[jpg] = jpeg_writer(current, srgb8)
            finally:
                wait((pixel_digest,))  # the frame's hash ends before the step does
            pixel_sums = {tif: pixel_digest.result()}
        except OSError as exc:
            raise SessionWriteError(current, exc) from None
        for name in (tif, jpg, *originals):  # this process need not read them back to trust them
            _remember_digest(self.root / name, sha[name])
        record = StepRecord(
            index=index,
            image=jpg,
            linear_image=tif,
            exposure_s=frame.exposure_s,
            saturated_fraction=frame.saturated_fraction,
            black_fraction=frame.black_fraction,
            write_wall_s=time.perf_counter() - t0,
            sha256=sha,
            pixels_sha256=pixel_sums,
            originals={name: source for name, (_, source) in originals.items()},
            copied_from={
                rel: os.path.abspath(item["path"])
                for item, rel in zip(listed, originals, strict=True)
                if item.get("copy")
            },
            decode=decode,
            notices=[str(n) for n in frame.metadata.get("notices") or []],
            file_colour=_file_colour(frame),
            strays=strays,
            **record_fields,
        )
        line = json.dumps(asdict(record)) + "\n"
        # the record file before the journal line: a kill between the two had left a step
        # whose line was written with no record file, unprovable once the journal was later
        # cut or lost. The record file on disk commits the step (the resume takes it with its
        # files as it says, :func:`_mend_from_step_records`, and writes its line back); a
        # record file that cannot be written leaves the commit to the journal line
        try:
            self._write_step_record(base, line)
        except SessionWriteError as exc:
            record_failed: SessionWriteError | None = exc
        else:
            record_failed = None
            self.committed[index] = record
        try:
            self._append_journal(line)
            self.committed[index] = record
            if record_failed is not None:
                raise record_failed
            self.write_lp()
        except SessionWriteError as exc:
            # a journal line (or lights.lp) that failed after the record file: the step is
            # kept all the same, and had gone uncounted (progress 2/8 of 3 images kept)
            if self.committed.get(index) is record:
                exc.committed = record
            raise
        return record

    def _write_step_record(self, base: str, line: str) -> None:
        """Keep the step's record, about to be journaled, in ``records/BASE.json`` too
        (atomically, fsynced, the folder entry made durable).

        Why: the journal is one file appended to; a line damaged later (a cut tail, a sync tool,
        a power loss that tears the file) left nothing proving a step a killed run had committed
        (the manifest lists a run's steps only when the run ends), and the resume set its
        image aside and shot it again, after the object may have been taken away. A record
        file is never appended to, so no later write can tear it; :func:`scan_journal` takes it
        as the step's record when the journal holds no intact record of the step."""
        folder = self.root / RECORDS_DIR
        try:
            new = not folder.is_dir()
            folder.mkdir(exist_ok=True)
            if new:
                _fsync_dir(self.root)
        except OSError as exc:
            raise SessionWriteError(folder, exc) from None
        _write_bytes_atomic(folder / f"{base}.json", line.encode("utf-8"))
        try:
            _fsync_dir(folder)
        except OSError as exc:
            raise SessionWriteError(folder, exc) from None

    def _keep_originals(
        self, base: str, originals: list[dict[str, Any]]
    ) -> dict[str, tuple[str, str]]:
        """Put the camera's own files under ``raw/`` with the session's name for the step.

        A file already inside the session (a DSLR download staged in ``raw/.incoming``) is
        moved; a file elsewhere (a watched folder another program owns) is copied. The session
        names the files itself, so a camera whose counter wraps or repeats names can never make
        one step's original overwrite another's. Returns {session name: (sha256, camera name)}.
        """
        kept: dict[str, tuple[str, str]] = {}
        root = self.root.resolve()
        for item in originals:
            src = Path(item["path"])
            suffix = src.suffix.lower()
            rel = f"{RAW_DIR}/{base}{suffix}"
            n = 2
            while rel in kept:  # two files of one step with one suffix
                rel = f"{RAW_DIR}/{base}_{n}{suffix}"
                n += 1
            dest = self.root / rel
            if dest.exists():
                raise SessionError(
                    f"{shown_path(dest)} already exists: refusing to overwrite a captured file"
                )
            # a replay's recorded file is the user's acquisition: copied, never moved, even
            # from inside the session folder (``"copy": True``)
            owner = None if item.get("copy") else root
            kept[rel] = (_take_whole(src, dest, owner), str(item.get("name") or src.name))
        return kept

    def _keep_strays(self, base: str, strays: list[dict[str, Any]]) -> dict[str, dict[str, str]]:
        """Put the pictures a camera delivered besides the step's own (see
        ``StepRecord.strays``) under ``strays/``, named after the step they came with and the
        camera's own name (``strays/image_003-IMG_0002.CR2``): kept, never one of the step's
        files. Returns {session name: {camera_file, sha256}}."""
        kept: dict[str, dict[str, str]] = {}
        root = self.root.resolve()
        for item in strays:
            src = Path(item["path"])
            camera_name = str(item.get("name") or src.name)
            stem, suffix = Path(camera_name).stem, Path(camera_name).suffix
            rel = f"{STRAY_DIR}/{base}-{stem}{suffix}"
            n = 2
            while rel in kept or (self.root / rel).exists():  # never over a kept picture
                rel = f"{STRAY_DIR}/{base}-{stem}_{n}{suffix}"
                n += 1
            digest = _take_whole(src, self.root / rel, root)
            kept[rel] = {"camera_file": camera_name, "sha256": digest}
        return kept

    def _append_journal(self, line: str) -> None:
        """Append one line and fsync it; on failure cut the journal back to what it was."""
        path = self.root / JOURNAL
        size = path.stat().st_size if path.exists() else 0
        try:
            with open(path, "a", encoding="utf-8") as fh:
                fh.write(line)
                fh.flush()
                os.fsync(fh.fileno())
        except OSError as exc:
            with contextlib.suppress(OSError):
                os.truncate(path, size)
            raise SessionWriteError(path, exc) from None

    def lp_listing(self) -> tuple[bool, int]:
        """Whether ``lights.lp`` lists exactly the committed images in step order (what a
        stopped session promises), and how many it lists (0: missing or unreadable). A write
        that failed, on a full disk, leaves it behind the journal."""
        from rti_rig.core.errors import RtiRigError
        from rti_rig.core.lp_format import read_lp

        want = [self.committed[i].image for i in sorted(self.committed)]
        try:
            have = [e.name for e in read_lp(self.root / LP_NAME)]
        except (RtiRigError, OSError, ValueError):
            have = []
        return have == want, len(have)

    def write_lp(self) -> None:
        """Rewrite ``lights.lp`` from every committed step, in step order (atomically)."""
        ordered = [self.committed[i] for i in sorted(self.committed)]
        if ordered:
            write_lp_atomic(
                self.root / LP_NAME, [LpEntry(r.image, r.actual_direction) for r in ordered]
            )

    def finish(
        self,
        records: list[StepRecord],
        runner: dict[str, Any],
        timing: dict[str, Any],
        source_result: dict[str, Any] | None = None,
    ) -> None:
        """Write the `.lp` from what actually ran (all runs, in step order), then the manifest
        (with ``source_result``, an adaptive session's outcome, under ``adaptive.result``: in
        the one write that says the session completed, so that no stop can fall between them).

        Writes nothing for a session that never began (nothing was created on disk), but keeps
        ``runner`` as :attr:`run_end` whatever happens (the very dict: a failure the caller
        appends to it after a failed write is this run's too).
        """
        self.run_end = runner
        try:
            self._finish(records, runner, timing, source_result)
        finally:
            unlock_session(self.root)

    def _finish(
        self,
        records: list[StepRecord],
        runner: dict[str, Any],
        timing: dict[str, Any],
        source_result: dict[str, Any] | None = None,
    ) -> None:
        if not self.begun:
            # a reshoot whose rig never connected: its images back, the session as it was
            self.put_back_now()
            return
        if source_result is not None:
            self.manifest.setdefault("adaptive", {})["result"] = source_result
        for r in records:
            self.committed.setdefault(r.index, r)
        # a stop that came between a step's commit and its return (a signal during the
        # fsync) still leaves a committed step: its record file (or, if that failed, its
        # journal line) is the commit, so both are read back as a resume reads them
        with contextlib.suppress(SessionError):
            late = [
                e
                for e in scan_journal(self.root, self.names).records
                if e["index"] not in self.committed
            ]
            self.committed.update(verified_steps(self.root, late))
        ordered = [self.committed[i] for i in sorted(self.committed)]
        lp_error: SessionWriteError | None = None
        try:
            self.write_lp()
        except SessionWriteError as exc:  # the manifest still says how the run ended
            lp_error = exc
        run = self.manifest["runs"][-1]
        run.update({"finished_at": _now_iso(), "finish_reason": runner["finish_reason"], **timing})
        if "arm_end" in runner:
            # each run's own record of where it left the arm: ``runner`` is the last run's
            # alone (a resume resets it), so a resumed session had kept only the last park
            run["arm_end"] = runner["arm_end"]
        runs = self.manifest["runs"]
        self.manifest.update(
            {
                "finished_at": run["finished_at"],
                "runner": {**runner, "steps_done": len(ordered)},
                "timing": {
                    "rig_time_s": sum(r.get("rig_time_s", 0.0) for r in runs),
                    "wall_time_s": sum(r.get("wall_time_s", 0.0) for r in runs),
                    "runs": len(runs),
                },
                "lp_file": LP_NAME if ordered and lp_error is None else None,
                "steps": [asdict(r) for r in ordered],
                "notices": session_notices(ordered),
                "image_colour": image_colour(ordered, self.root),
            }
        )
        _write_json_atomic(self.root / MANIFEST, self.manifest)
        if lp_error is not None:
            raise lp_error


#: said once of a session whose RAWs were decoded with no colour matrix (or with
#: ``output_color = "raw"``): its colours are the sensor's, which the guide had called sRGB
CAMERA_RGB_NOTICE = (
    "the images are in camera RGB, not sRGB: the RAW holds no colour matrix "
    "(or [camera.device.decode] output_color = 'raw'), so the sensor's colours were kept; "
    "the JPEGs are untagged and their colours may look off, while relighting and fitting are "
    "unaffected. For sRGB colours shoot a RAW (or DNG) that carries the camera's colour "
    "matrix, with output_color = 'srgb'"
)


def image_colour(records: list[StepRecord], root: Path | None = None) -> dict[str, str]:
    """What the manifest says of the colour of the session's JPEGs and linear TIFFs, as their
    tags and ImageDescriptions say it (one colour for a session whose images all share it,
    else each colour with the images in it). ``root``: the session folder, whose one-channel
    linear TIFFs not from a RAW are said to be linear grey, as their ImageDescription says
    (the manifest had called them linear sRGB, tagged, while the file said linear grey)."""
    jpeg: dict[str, list[str]] = {}
    linear: dict[str, list[str]] = {}
    jpeg_words, linear_words = dict(JPEG_COLOUR_WORDS), dict(LINEAR_COLOUR_WORDS)
    for r in records:
        colour = decode_colour(r.decode)
        if colour == "srgb" and not r.decode:
            # what the camera's file said: sRGB, nothing (assumed), or another space
            kind = file_colour_kind(r.file_colour)
            if kind == "assumed":
                colour = "assumed"
                jpeg_words[colour], linear_words[colour] = ASSUMED_JPEG_WORDS, ASSUMED_LINEAR_WORDS
            elif kind == "other":
                colour = f"other: {r.file_colour.get('name')} ({r.file_colour.get('said_by')})"
                jpeg_words[colour], linear_words[colour], _ = other_space_words(r.file_colour)
            elif kind == "converted":
                colour = f"from: {r.file_colour.get('name')} ({r.file_colour.get('said_by')})"
                jpeg_words[colour], linear_words[colour], _ = converted_words(r.file_colour)
        jpeg.setdefault(colour, []).append(Path(r.image).stem)
        if colour == "srgb" and not r.decode and root is not None and _grey_tiff(root, r):
            colour = "grey"
        linear.setdefault(colour, []).append(Path(r.image).stem)
    return {
        "jpeg": _colour_words(jpeg_words, jpeg),
        "linear": _colour_words(linear_words, linear),
    }


def _colour_words(words: Mapping[str, str], by: dict[str, list[str]]) -> str:
    """One colour's words for a session whose images all share it, else each with its images."""
    if len(by) <= 1:
        return words[next(iter(by), "srgb")]
    return "; ".join(f"{words[c]}: {', '.join(n)}" for c, n in by.items())


def _grey_tiff(root: Path, record: StepRecord) -> bool:
    """Whether the step's linear TIFF holds one channel (its first page's header alone is read;
    a file that cannot be read is not said to be grey: the verdict names it)."""
    import tifffile  # on use, as the writer imports it

    try:
        with tifffile.TiffFile(root / record.linear_image) as tif:
            return tif.pages.first.ndim == 2
    except (OSError, ValueError, tifffile.TiffFileError):
        return False


def session_notices(records: list[StepRecord]) -> list[str]:
    """What the user should know about the images as a whole (each distinct notice once, with
    how many images it concerns), e.g. that a rotated camera gave sensor-oriented images, or
    that the images are CFA mosaics rather than pictures."""
    counts: dict[str, int] = {}
    for r in records:
        for n in r.notices:
            counts[n] = counts.get(n, 0) + 1
        if r.relit:
            n = (
                "the camera was still busy (writing its previous shot?) when its next try "
                "would have kept the LED lit past the time it may stay lit (max_on_s, or a "
                "timed firmware's own light_on_s): the LED was switched off while the camera "
                "was awaited and lit again for the image (the journal's 'relit' says how long, "
                "and whether the dome acknowledged each all-off)"
            )
            counts[n] = counts.get(n, 0) + 1
        if r.decode.get("mode") == "mosaic":
            n = (
                "the images are CFA mosaics (decode.mode = 'mosaic'): one colour per pixel, "
                "not demosaiced; the JPEGs are grey checkerboards, not pictures"
            )
            counts[n] = counts.get(n, 0) + 1
        elif r.decode and decode_colour(r.decode) == "camera":
            counts[CAMERA_RGB_NOTICE] = counts.get(CAMERA_RGB_NOTICE, 0) + 1
    total = len(records)
    return [f"{n} [{c} of {total} images]" for n, c in counts.items()]


@dataclass(frozen=True)
class RepairNote:
    """One thing a resume did to the journal before appending to it, in words, and whether
    it set bytes of the journal aside (to ``recovered/STAMP/journal-rejected.txt``) or only
    took records back into it.

    Why a field: the resume's message had told the two apart by the note's wording (a note
    holding "written back from" was a record kept), and a rejected line's reason quotes the
    line itself (its ``image``), so a damaged line could read as a record kept and its
    setting aside go unsaid. The manifest keeps the words only (``journal_repair``: a list of
    strings, as in sessions written before this field)."""

    text: str
    #: the note's bytes were taken out of the journal and kept in recovered/, not appended onto
    set_aside: bool

    def __str__(self) -> str:
        return self.text


@dataclass
class ResumeState:
    """What an interrupted session folder holds, verified."""

    manifest: dict[str, Any]
    done: dict[int, StepRecord]
    recovered: list[str]
    #: what was done to the journal before appending to it (torn tail, rejected lines,
    #: records written back from their record files)
    journal_repair: list[RepairNote] = field(default_factory=list)
    #: what ``--rebuild-journal`` did: the journal rebuilt from the manifest, what it took back,
    #: where the old journal and every file the manifest does not vouch for were set aside
    journal_rebuild: list[str] = field(default_factory=list)
    #: a session not finished: its committed images whose files are missing or changed since
    #: capture, set aside to be shot again, said as the verdict says them
    #: (:func:`lost_since_capture_said`'s words: ``image_005: raw/image_005.dng changed``)
    lost_since_capture: list[str] = field(default_factory=list)
    #: a session not finished: its committed images an earlier resume set aside to reshoot
    #: (``--reshoot`` cut short), whose files are in recovered/ as captured: shot again now,
    #: and said so, never "lost" (``image_004 (in recovered/20261206T001242)``)
    set_aside_before: list[str] = field(default_factory=list)
    #: where a ``lights.lp`` that was not rti-rig's own listing of the journal's lights (edited
    #: by hand) was kept before the resume wrote it again (``recovered/STAMP/lights.lp``, also
    #: in ``recovered``), said by :func:`edited_lp_note`; None when there was none
    edited_lp: str | None = None


@dataclass
class JournalScan:
    """A journal read tolerantly: its well-formed records and what is not one.

    ``kept`` holds the raw bytes of the good lines (each ending in a newline), ``rejected``
    the line numbers, texts and reasons of the others, ``torn`` a last line with no newline
    (the process died while appending it, or the file's tail was cut), ``mended`` the step
    record files (``records/BASE.json``) taken as records the journal lacks: appended to
    ``records`` and ``kept``, so a repair writes them back into the journal.
    """

    records: list[dict[str, Any]] = field(default_factory=list)
    kept: list[bytes] = field(default_factory=list)
    rejected: list[tuple[int, str, str]] = field(default_factory=list)
    torn: bytes = b""
    mended: list[str] = field(default_factory=list)
    #: the journal file is not there at all (every record in ``records`` is a record file's)
    missing: bool = False

    @property
    def needs_repair(self) -> bool:
        return bool(self.rejected or self.torn or self.mended)


_REQUIRED = {
    name
    for name, f in StepRecord.__dataclass_fields__.items()
    if f.default is f.default_factory  # both MISSING: a field every record must have
}


#: What :func:`_record_problem` says of a record past the planned steps.
OUTSIDE_SCHEDULE = "is outside the schedule's"


def _record_problem(entry: object, names: list[str] | None) -> str | None:
    """Why a parsed journal line is not a step record (``None`` if it is one)."""
    if not isinstance(entry, dict):
        return f"a JSON {type(entry).__name__}, not a step record"
    missing = sorted(_REQUIRED - entry.keys())
    if missing:
        return f"a record without {', '.join(missing)}"
    sha = entry.get("sha256")
    if (
        not isinstance(sha, dict)
        or not sha
        or not all(isinstance(k, str) and isinstance(v, str) for k, v in sha.items())
    ):
        return "a record without its checksums (sha256)"
    idx = entry["index"]
    if not isinstance(idx, int) or isinstance(idx, bool):
        return f"index {idx!r} is not a step number"
    if names is not None:
        if not 0 <= idx < len(names):
            return f"index {idx} {OUTSIDE_SCHEDULE} {len(names)} steps"
        own = {entry["image"], entry["linear_image"]}
        originals = entry.get("originals") or {}
        # besides its JPEG and TIFF a step may keep the camera's own files, under raw/
        kept_raw = all(
            name in originals and name.startswith(f"{RAW_DIR}/{names[idx]}")
            for name in set(sha) - own
        )
        if entry["image"] != f"{names[idx]}.jpg" or not own <= set(sha) or not kept_raw:
            return f"image {entry['image']!r} does not fit step {idx + 1} of the schedule"
    try:
        _to_record(entry)
    except (TypeError, ValueError) as exc:
        return f"a malformed record ({exc})"
    return None


def _to_record(entry: dict[str, Any]) -> StepRecord:
    rec = {k: v for k, v in entry.items() if k in StepRecord.__dataclass_fields__}
    for key in ("planned_direction", "actual_direction"):
        vec = tuple(float(x) for x in rec[key])
        if len(vec) != 3:
            raise ValueError(f"{key} has {len(vec)} components")
        rec[key] = vec
    return StepRecord(**rec)


def _refuse_steps_beyond(
    root: Path, manifest: dict[str, Any], scan: JournalScan, total: int
) -> None:
    """Refuse, before anything moves, a resume of a session whose journal records steps past
    the ones its manifest plans: one of the two files was edited, or comes from another
    session, and which one holds the truth is not for a resume to guess.

    Why: such records had been rejected as "outside the schedule" and their images moved to
    ``recovered/`` as unverified, then shot again (an adaptive session's ``max_lights`` edited
    from 12 to 8 set images 9–11 aside, and refused only after)."""
    beyond = [line for line, _text, why in scan.rejected if OUTSIDE_SCHEDULE in why]
    if not beyond:
        return
    planned = (
        f"its adaptive settings' max_lights {total}"
        if isinstance(manifest.get("adaptive"), dict)
        else f"the {total} steps of its schedule"
    )
    lines = ", ".join(str(n) for n in beyond[:5]) + (" …" if len(beyond) > 5 else "")
    raise SessionError(
        f"{shown_path(root)}: {JOURNAL} records steps beyond what {MANIFEST} plans ({planned}; "
        f"line{'s' if len(beyond) > 1 else ''} {lines} of {JOURNAL}): the two files disagree, so "
        f"one was edited or comes from another session. Nothing in the folder was changed: "
        f"restore {MANIFEST} (or {JOURNAL}) from a backup copy of the folder and resume again"
    )


def scan_journal(root: Path, names: list[str] | None = None) -> JournalScan:
    """Read the journal without changing it; every line is either a record or rejected."""
    path = Path(root) / JOURNAL
    scan = JournalScan()
    try:
        data = path.read_bytes()
    except FileNotFoundError:
        # a journal deleted outright loses no step its record file proves (each verified
        # against its files): it had been refused as lost for good, records/ holding them all
        scan.missing = True
        _mend_from_step_records(Path(root), names, scan)
        return scan
    except OSError as exc:
        raise SessionError(f"cannot read {shown_path(path)}: {exc.strerror or exc}") from None
    *lines, scan.torn = data.split(b"\n")
    for i, raw in enumerate(lines):
        if not raw.strip():
            continue
        try:
            text = raw.decode("utf-8")
            entry = json.loads(text)
        except (UnicodeDecodeError, json.JSONDecodeError):
            scan.rejected.append((i + 1, raw.decode("utf-8", "replace"), "not valid JSON"))
            continue
        problem = _record_problem(entry, names)
        if problem:
            scan.rejected.append((i + 1, text, problem))
            continue
        scan.records.append(entry)
        scan.kept.append(raw + b"\n")
    _mend_from_step_records(Path(root), names, scan)
    return scan


def _mend_from_step_records(root: Path, names: list[str] | None, scan: JournalScan) -> None:
    """Add to ``scan`` the step record files (``records/BASE.json``, written at each commit)
    of the steps the journal holds no intact record of, whose files are on disk as they say.

    One rule for every reader (resume, ``--rebuild-journal``, fit's verdict, export-lp): a
    step is proven by its journal record, or, when its line is lost or damaged, by its record
    file, with its files matching the checksums. Why: a journal whose line of a committed
    step was damaged (the tail cut after a kill) proved nothing of it, and the resume shot it
    again. The journal's latest record of a step decides when its files match it; the record
    file is taken over it only when they do not and the record file's do (a step shot again,
    its new line cut). A record file whose files are not as it says (set aside, changed since)
    is passed over: the step is then unproven, as before. Sessions from before these files
    have none, and read as they always did."""
    folder = root / RECORDS_DIR
    if not folder.is_dir():
        return
    latest = _latest_records(scan.records)
    for path in sorted(folder.glob("image_*.json")):
        try:
            raw = path.read_bytes().strip()
            entry = json.loads(raw.decode("utf-8"))
        except (OSError, UnicodeDecodeError, json.JSONDecodeError):
            continue
        if _record_problem(entry, names) is not None or entry["image"] != f"{path.stem}.jpg":
            continue
        journaled = latest.get(entry["index"])
        if journaled == entry:
            continue  # the journal holds this very record: nothing to mend, nothing hashed
        if journaled is not None and verified_steps(root, [journaled]):
            continue  # the journal's latest record proves the step: it decides
        if not verified_steps(root, [entry]):
            continue
        # no record of the step in the journal, or only an earlier one its files no longer
        # match (a step shot again whose new line was cut: the old record had won, failed its
        # checksums, and the step was shot once more): the record file, written just before
        # the journal line of the latest commit (a kill between the two leaves it with no
        # line), proves it
        scan.records.append(entry)
        scan.kept.append(raw + b"\n")
        scan.mended.append(path.relative_to(root).as_posix())
        latest[entry["index"]] = entry


def stopped_before_journal_line(scan: JournalScan) -> str | None:
    """The image (``image_004``) whose record file proves its step but whose journal line the
    run never wrote: killed (or stopped by a full disk) between the two writes, its step
    committed. That is the one step ``scan`` takes from a record file, just after the
    journal's last line (the first step, when no journal was ever written), with nothing
    else wrong with the journal. None otherwise.

    Why: nothing told such a folder from a damaged one. fit's verdict called it "damaged
    (records missing)" and "lights.lp does not list image_004 … (the .lp edited since
    capture?)"; a resume said "journal.jsonl was missing" of a journal never written."""
    if len(scan.mended) != 1 or scan.rejected or scan.torn:
        return None
    *intact, last = scan.records  # a record file's record is appended after the journal's
    after = max((int(r["index"]) for r in intact), default=-1) + 1
    stem = Path(scan.mended[0]).stem
    return stem if int(last["index"]) == after and last["image"] == f"{stem}.jpg" else None


def _take_whole(src: Path, dest: Path, root: Path | None) -> str:
    """Put the camera's file ``src`` at ``dest`` whole and return its SHA-256.

    A download staged inside the session (``root``, e.g. raw/.incoming) may be the only copy
    (the camera may have deleted its own): it is checksummed where it lies, then renamed in one
    step, so at every moment it is whole under one of its two names; one from elsewhere (or
    any, when ``root`` is None) is copied whole. An OSError writing is the session's write
    error, naming ``dest``; one reading a file copied from elsewhere is
    :class:`SourceReadError`, naming ``src`` (a replay's acquisition on a drive unplugged
    mid-run had been said as a failed write of ``dest``)."""
    try:
        dest.parent.mkdir(parents=True, exist_ok=True)
        if root is not None and src.resolve().is_relative_to(root):
            digest = _fsync_sha256(src)
            os.replace(src, dest)
            return digest
        return _copy_whole(src, dest)
    except _SourceUnreadable as exc:
        raise SourceReadError(src, dest, exc.error) from None
    except OSError as exc:
        raise SessionWriteError(dest, exc) from None


#: How much of a file :func:`_copy_whole` reads at a time.
_COPY_CHUNK = 1 << 20


def _copy_whole(src: Path, dest: Path) -> str:
    """Copy ``src`` to ``dest`` through a temporary file, never leaving a partial one; returns
    the copy's SHA-256. A failure to open or read ``src`` raises :class:`_SourceUnreadable`
    (the file's drive, not the session's), any other OSError is the copy's."""
    tmp = dest.with_name(f".{dest.name}.partial")
    try:
        try:
            source = open(src, "rb")  # noqa: SIM115 - closed below, its errors told apart
        except OSError as exc:
            raise _SourceUnreadable(exc) from None
        with source, open(tmp, "wb") as copy:
            while True:
                try:
                    chunk = source.read(_COPY_CHUNK)
                except OSError as exc:
                    raise _SourceUnreadable(exc) from None
                if not chunk:
                    break
                copy.write(chunk)
        digest = _fsync_sha256(tmp)
        os.replace(tmp, dest)
    except BaseException:
        with contextlib.suppress(OSError):
            tmp.unlink()
        raise
    return digest


def _fsync_sha256(path: Path) -> str:
    """SHA-256 of a file just written, after making sure it is on disk."""
    h = hashlib.sha256()
    with open(path, "rb+") as fh:
        for chunk in iter(lambda: fh.read(1 << 20), b""):
            h.update(chunk)
        os.fsync(fh.fileno())
    return h.hexdigest()


def linear_tiff_labels(decode: dict[str, Any], frame: Frame) -> tuple[str, bytes | None]:
    """The ImageDescription and ICC profile (None: untagged) of a linear TIFF of ``frame``
    decoded as ``decode`` says: a session's, and an image kept aside under ``unlabelled/``,
    which had carried neither and was taken as sRGB-encoded by viewers. Only sRGB pixels are
    said to be sRGB: camera RGB or a mosaic carries no profile (nor does a grey image, the
    writer's rule)."""
    description = _tiff_description(decode, frame.white_level, grey=frame.pixels.ndim == 2)
    icc = icc_profile("linear") if decode_colour(decode) == "srgb" else None
    if not decode and frame.pixels.ndim == 3:
        # a camera file's own word on its colours: assumed sRGB said so, another space
        # said and left untagged (it had been declared, and tagged, linear sRGB)
        said = _file_colour(frame)
        kind = file_colour_kind(said)
        white = f", white level {frame.white_level}" if frame.white_level else ""
        if kind == "assumed":
            description = (
                f"rti-rig: {LINEAR_SRGB}, assumed sRGB (the file does not say), 16-bit{white} "
                "(the camera's own, not a RAW's)"
            )
        elif kind == "other":
            description = f"rti-rig: {other_space_words(said)[2]}, 16-bit{white}"
            icc = None
        elif kind == "converted":
            description = f"rti-rig: {converted_words(said)[2]}, 16-bit{white}"
    return description, icc


def labelled_white(frame: Frame) -> int:
    """The white level ``frame``'s linear TIFF states in its label, read from the label itself
    (:func:`linear_tiff_labels`, :func:`labelled_white_level`; 65535 where it states none: a
    RAW's label, whose pixels are scaled to 65535, or a mosaic's). Why: a live reader of the
    frame (an adaptive run's chooser) must weigh it as a resume reading the TIFF back will, or
    the resume decides another light; derived from the label, the two cannot drift apart."""
    decode = dict(frame.metadata.get("decode") or {})
    return labelled_white_level(linear_tiff_labels(decode, frame)[0]) or 65535


def _file_colour(frame: Frame) -> dict[str, str]:
    """What the frame's camera file said of its colour space (empty: nothing recorded)."""
    said = frame.metadata.get("file_colour") or {}
    return {str(k): str(v) for k, v in said.items()} if isinstance(said, dict) else {}


def _tiff_description(
    decode: dict[str, Any], white_level: int | None = None, grey: bool = False
) -> str:
    """A label inside the linear TIFF saying what its pixels are: linear (not sRGB-encoded),
    in which colours, and for a RAW-derived image how it was decoded.

    Why for every image: a TIFF not from a RAW had held only tifffile's ``{"shape": ...}``,
    nothing saying it is linear, and viewers took it as sRGB and showed it dark. The mosaic
    label begins :data:`MOSAIC_TIFF_LABEL` (``rti-rig fit`` refuses a file by it). ``grey``:
    one channel, said to be linear grey (it had been called linear sRGB, colours it has none
    of)."""
    if not decode:
        white = f", white level {white_level}" if white_level else ""
        if grey:
            return f"rti-rig: {LINEAR_GREY}, 16-bit{white} (the camera's own, not a RAW's)"
        return f"rti-rig: {LINEAR_SRGB}, 16-bit{white} (the camera's own colours, not a RAW's)"
    if decode.get("mode") == "mosaic":
        return (
            f"{MOSAIC_TIFF_LABEL} ({decode.get('cfa_pattern')}), black level removed per "
            "photosite, NOT demosaiced, no white balance: one colour per pixel"
        )
    colours = LINEAR_SRGB if decode_colour(decode) == "srgb" else LINEAR_CAMERA_RGB
    return (
        f"rti-rig: {colours} from RAW ({decode.get('mode')}), "
        f"white balance {decode.get('white_balance')}, sensor orientation"
    )


#: checksums this process wrote or computed, by resolved path, with the file's identity then
#: (device, inode, size, modification and change times in ns): a session's last verdict had
#: read back every file the run had just written, seconds per image at 24 MP. At most
#: :data:`_KNOWN_LIMIT` are kept, the oldest given up first (a long-lived process, such as a
#: GUI that runs session after session, had kept one for every file it ever wrote or read)
_KNOWN_DIGESTS: dict[str, tuple[tuple[int, int, int, int, int], str]] = {}
_KNOWN_LIMIT = 1 << 16  # files: a few sessions' worth, some 15 MB at most
_KNOWN_LOCK = threading.Lock()  # a fit checksums its session on a thread of its own


def _know(key: str, identity: tuple[int, int, int, int, int], digest: str) -> None:
    """Keep ``digest`` of the file at resolved path ``key`` with its ``identity``, within
    :data:`_KNOWN_LIMIT`."""
    with _KNOWN_LOCK:
        _KNOWN_DIGESTS.pop(key, None)  # to the newest end
        _KNOWN_DIGESTS[key] = (identity, digest)
        while len(_KNOWN_DIGESTS) > _KNOWN_LIMIT:
            del _KNOWN_DIGESTS[next(iter(_KNOWN_DIGESTS))]


def _identity(st: os.stat_result) -> tuple[int, int, int, int, int]:
    """What changes whenever a file's content may have (its ctime moves on any write, rename
    or ``utime``, and no tool can set it back)."""
    return (st.st_dev, st.st_ino, st.st_size, st.st_mtime_ns, st.st_ctime_ns)


def _remember_digest(path: Path, digest: str) -> None:
    """Record ``digest`` as the checksum of ``path`` as it is now (see :data:`_KNOWN_DIGESTS`)."""
    with contextlib.suppress(OSError):
        _know(str(Path(path).resolve()), _identity(path.stat()), digest)


def remember_pixel_digest(path: Path, st: os.stat_result, digest: str) -> None:
    """Record ``digest``, the :func:`pixels_sha256` of the TIFF at ``path`` as it was when
    ``st`` was taken (read whole by this process: a fit's pass through its rows), so that the
    check of a session's linear TIFF need not read it again (:func:`_as_captured`)."""
    with contextlib.suppress(OSError):
        _know(_PIXELS + str(Path(path).resolve()), _identity(st), digest)


#: the key prefix of a pixel checksum in :data:`_KNOWN_DIGESTS` (a file's own has none)
_PIXELS = "pixels:"


def _known_pixels(path: Path) -> str | None:
    """The pixel checksum :func:`remember_pixel_digest` holds for ``path`` as it is now (None
    when none, or when the file changed since it was taken)."""
    try:
        st = path.stat()
        key = _PIXELS + str(path.resolve())
    except OSError:
        return None
    known = _KNOWN_DIGESTS.get(key)
    return known[1] if known is not None and known[0] == _identity(st) else None


def file_sha256(path: Path) -> str | None:
    """SHA-256 of the file at ``path`` (None if it is not a file), read in chunks; a file this
    process wrote or hashed and that has not changed since is not read again.

    The one checksum cache of a process: the session's integrity check and a batch's judgement
    of an earlier fit (:func:`rti_rig.app.usecases.fit_batch.earlier_fit`) share it, keyed by
    the resolved path and the file's :func:`_identity` (a batch had kept a second cache of its
    own, keyed by path, size and mtime alone, and read files the session had just hashed)."""
    try:
        st = path.stat()
        key = str(path.resolve())
    except (FileNotFoundError, NotADirectoryError):
        return None
    known = _KNOWN_DIGESTS.get(key)
    if known is not None and known[0] == _identity(st):
        return known[1]
    try:
        with open(path, "rb") as fh:
            digest = hashlib.file_digest(fh, "sha256").hexdigest()
    except (FileNotFoundError, IsADirectoryError):
        return None
    _know(key, _identity(st), digest)
    return digest


def _as_captured(root: Path, rec: dict[str, Any], name: str, digest: str | None) -> bool:
    """Whether file ``name`` of journal record ``rec`` is on disk as captured: its bytes match
    ``digest``, or (its linear TIFF) its pixels match the journaled pixel checksum, re-saved
    by another tool without a change to what a fit reads. One criterion for the QA verdict,
    ``--reshoot-lost``, a resume and ``export-lp`` (``export-lp --linear`` had left out a
    TIFF the verdict called intact)."""
    path = root / name
    pixels = (rec.get("pixels_sha256") or {}).get(name)
    if pixels is not None and name == rec.get("linear_image") and _known_pixels(path) == pixels:
        return True  # this process read the very pixels captured (a fit, as it went through)
    if file_sha256(path) == digest:
        return True
    if pixels is None or name != rec.get("linear_image") or not path.is_file():
        return False
    return tiff_pixels_sha256(path) == pixels


def verified_steps(
    root: Path, records: list[dict[str, Any]], only: str | None = None
) -> dict[int, StepRecord]:
    """The steps whose files are on disk with their journaled checksums (the later record of a
    step wins: a recaptured image replaces one set aside). ``only`` ("image" or
    "linear_image"): the step's file of that kind is the one checked, for a listing that names
    only it (an ``.lp`` of the TIFFs needs no intact JPEG)."""
    done: dict[int, StepRecord] = {}
    for entry in records:
        idx = entry["index"]
        sums = entry["sha256"]
        if only is not None:
            sums = {entry[only]: sums.get(entry[only])}
        if all(_as_captured(Path(root), entry, name, digest) for name, digest in sums.items()):
            done[idx] = _to_record(entry)
        else:
            done.pop(idx, None)
    return done


def _repair_journal(root: Path, scan: JournalScan, stamp: str) -> list[RepairNote]:
    """Set aside what is not a record, then rewrite the journal with the records only.

    The torn tail and every rejected line go, with the reason, to
    ``recovered/STAMP/journal-rejected.txt``; the journal is then replaced atomically by its
    good lines, so the next record is never appended onto a torn one.
    """
    notes: list[RepairNote] = []
    report = []
    for lineno, text, reason in scan.rejected:
        notes.append(RepairNote(f"journal line {lineno}: {reason}", set_aside=True))
        report.append(f"# line {lineno}: {reason}\n{text}\n")
    cut = scan.torn.strip()
    if cut and any(line.startswith(cut) for line in scan.kept[len(scan.kept) - len(scan.mended) :]):
        # the cut line of a step its record file proves: committed, its record written back
        notes.append(
            RepairNote(f"journal: a last line cut to {len(scan.torn)} byte(s)", set_aside=True)
        )
        report.append(
            "# last line cut short (the step's record file holds it whole, written back)\n"
            f"{scan.torn.decode('utf-8', 'replace')}\n"
        )
    elif scan.torn:
        notes.append(
            RepairNote(
                f"journal: a torn last line of {len(scan.torn)} byte(s) (never committed)",
                set_aside=True,
            )
        )
        report.append(
            "# torn last line (no newline: the process died while writing it; never "
            f"committed)\n{scan.torn.decode('utf-8', 'replace')}\n"
        )
    unwritten = stopped_before_journal_line(scan)
    if scan.missing and unwritten is not None:
        # no journal because none was begun: "was missing" had read as a file lost
        notes.append(
            RepairNote(
                f"the run stopped before its first journal line: {JOURNAL} begun from "
                f"{scan.mended[0]} ({unwritten}'s files are as it says: the image is kept, "
                "not shot again)",
                set_aside=False,
            )
        )
    elif scan.missing and scan.mended:
        stems = [Path(rel).stem for rel in scan.mended]
        notes.append(
            RepairNote(
                f"{JOURNAL} was missing: rebuilt from {len(stems)} step record file(s) in "
                f"{RECORDS_DIR}/ ({', '.join(stems[:8])}{' …' if len(stems) > 8 else ''}), "
                "each taken only with its files on disk as its checksums say: those images "
                "are kept, not shot again",
                set_aside=False,
            )
        )
    for rel in [] if scan.missing else scan.mended:
        notes.append(
            RepairNote(
                f"journal: the record of {Path(rel).stem}, which it lacked, written back from "
                f"{rel} (its files are as that record says: the image is kept, not shot again)",
                set_aside=False,
            )
        )
    dest = root / "recovered" / stamp / "journal-rejected.txt"
    try:
        if not report:  # only records written back: nothing to set aside
            _write_bytes_atomic(root / JOURNAL, b"".join(scan.kept))
            return notes
        dest.parent.mkdir(parents=True, exist_ok=True)
        with open(dest, "a", encoding="utf-8") as fh:
            fh.write("".join(report))
            fh.flush()
            os.fsync(fh.fileno())
    except OSError as exc:
        raise SessionWriteError(dest, exc) from None
    _write_bytes_atomic(root / JOURNAL, b"".join(scan.kept))
    return notes


def _new_stamp(root: Path) -> str:
    """A ``recovered/`` sub-folder name not used yet (resumes may follow within a second)."""
    base = datetime.now(UTC).strftime("%Y%m%dT%H%M%S")
    stamp, n = base, 1
    while (root / "recovered" / stamp).exists():
        n += 1
        stamp = f"{base}-{n}"
    return stamp


def prepare_resume(
    root: Path,
    check_done: Callable[[dict[int, StepRecord]], None] | None = None,
    reshoot_lost: bool = False,
    rebuild_journal: bool = False,
    also_reshoot: tuple[int, ...] = (),
) -> ResumeState:
    """:func:`_prepare_resume` with the folder locked (:func:`lock_session`) before anything in
    it is read or moved: held for the resumed run, released if the resume is refused."""
    root = Path(root)
    held = str(root.resolve()) in _LOCKED
    if root.is_dir():
        lock_session(root)
    try:
        return _prepare_resume(root, check_done, reshoot_lost, rebuild_journal, also_reshoot)
    except BaseException:
        if not held:
            unlock_session(root)
        raise


def _prepare_resume(
    root: Path,
    check_done: Callable[[dict[int, StepRecord]], None] | None = None,
    reshoot_lost: bool = False,
    rebuild_journal: bool = False,
    also_reshoot: tuple[int, ...] = (),
) -> ResumeState:
    """Verify an interrupted session, repair its journal and set aside what is not committed.

    ``check_done`` sees the verified steps before anything is repaired or moved: a resume it
    refuses (by raising) leaves the folder exactly as it was.

    A session that **completed** is refused, unless ``reshoot_lost``: then exactly the steps
    whose JPEG or linear TIFF is gone or changed since capture, or whose kept RAW original is
    gone (:func:`_lost_files`, what the QA verdict names) are reshot, their files set aside;
    every other step stands as it is (a TIFF re-saved with its pixels unchanged is no reason
    to reshoot a finished session). ``also_reshoot`` (with ``reshoot_lost``): steps reshot as
    well though their files are intact, the user's choice (``--reshoot image_006``: an image
    the QA verdict calls misfired); their files are set aside as a lost step's are.

    A step counts as done when its journal line is a well-formed record and every file it names
    is on disk with the journaled checksum. Journal lines that are not records (a torn last
    line, junk) are moved to ``recovered/`` with the reason and the journal rewritten without
    them, before anything is appended. Image files that no committed step accounts for (a write
    cut short between the TIFF and the JPEG, a checksum mismatch) are *moved* to
    ``recovered/``, never deleted; half-written temporary files are removed (they never were
    an image).

    A journal that lost records the manifest holds (deleted, cut short, overwritten) is
    refused, naming ``rebuild_journal``; with it the journal is rebuilt from what the files
    prove (:func:`_provable_steps`, :func:`_rebuild_journal`).
    """
    root = Path(root)
    manifest = read_manifest(root)
    total = planned_steps(manifest)
    if total == 0:
        raise SessionError(
            f"{shown_path(root)}: the manifest holds no schedule, so there is nothing to resume"
        )
    runner = manifest.get("runner") or {}
    names = image_names(total)
    scan = scan_journal(root, names)
    _refuse_steps_beyond(root, manifest, scan, total)
    if rebuild_journal and reshoot_lost:
        raise SessionError(
            f"{shown_path(root)}: --rebuild-journal and --reshoot-lost go one at a time: rebuild "
            "the journal first, then reshoot what the rebuilt journal finds lost (--reshoot-lost "
            "needs a journal to know what was captured): drop --reshoot-lost"
        )
    if rebuild_journal and runner.get("finish_reason") == "completed":
        raise SessionError(
            f"{shown_path(root)}: this session completed: nothing is captured to rebuild its "
            "journal, which rebuild_finished_journal does without the rig (rti-rig run --resume "
            f"{shell_word(str(root))} --rebuild-journal)"
        )
    rebuilt: dict[int, dict[str, Any]] | None = None  # the records taken back
    lost_now: list[str] = []  # a session not finished: committed images lost since capture
    aside_before: list[str] = []  # ... and those an earlier resume set aside to reshoot
    restored: dict[int, dict[str, Any]] = {}  # --reshoot-lost: the manifest's, restored
    if runner.get("finish_reason") == "completed":
        finished = runner.get("steps_done", total)
        latest = _latest_records(scan.records)
        if reshoot_lost and not manifest.get("adaptive"):
            # the records the journal lost, from the manifest: an image intact is kept, one
            # lost is reshot, as if the journal had lost nothing
            restored = _restorable(root, manifest, scan, names)
            latest.update(restored)
        renamed = renamed_jpegs(root, [*scan.records, *restored.values()])
        lost = {i: _lost_files(root, rec, renamed) for i, rec in latest.items()}
        lost = {i: gone for i, gone in lost.items() if gone}
        if reshoot_lost:
            for i in also_reshoot:  # named to reshoot: set aside and shot again as if lost
                lost.setdefault(i, ["named with --reshoot"])
        moved = f"; {renamed_note(renamed)}" if renamed else ""
        intact = not reshoot_lost and not lost and not renamed
        # the manifest and journal as read above (they had been read again for this)
        unchecked, why = unchecked_images(root, scan, manifest)
        if intact and not unchecked:
            _refuse_complete(root, manifest, total, finished, scan)
        if manifest.get("adaptive") and finished < total:  # an adaptive session that stopped
            stop = (manifest["adaptive"].get("result") or {}).get("stop") or {}
            raise SessionError(
                f"{shown_path(root)}: this adaptive session already completed: it stopped after "
                f"{finished} of at most {total} lights ({stop.get('reason', 'its stopping rule')})"
                + _lost_note(root, latest, lost, adaptive=True)
                + (_unchecked_note(root, unchecked, why, scan) if unchecked else "")
            )
        if reshoot_lost and not lost and not manifest.get("adaptive"):
            if unchecked:  # nothing found lost is not nothing lost
                raise SessionError(
                    f"{shown_path(root)}: --reshoot-lost finds nothing lost among the images it "
                    "can check, but "
                    f"{', '.join(unchecked[:8])}{' …' if len(unchecked) > 8 else ''} cannot be "
                    f"checked ({why}): restore {MANIFEST if MANIFEST in why else JOURNAL} from a "
                    "backup copy of the folder"
                    + ("" if MANIFEST in why else rebuild_advice(root))
                    + ", then run this again"
                )
            if renamed:
                raise SessionError(
                    f"{shown_path(root)}: nothing to reshoot: this session completed all {total} "
                    "steps" + moved
                )
            raise SessionError(
                f"{shown_path(root)}: nothing to reshoot: this session completed all {total} steps "
                "and every image is as captured (each JPEG and linear TIFF matches its journaled "
                "checksum)"
            )
        if not lost or manifest.get("adaptive") or not reshoot_lost:
            note = _lost_note(root, latest, lost, adaptive=bool(manifest.get("adaptive")))
            if unchecked:
                note += _unchecked_note(root, unchecked, why, scan)
            raise ImagesLostSinceCapture(
                f"{shown_path(root)}: this session already completed all {total} steps"
                + note
                + moved,
                note + moved,  # an image renamed is named too (the flash refusal had not)
            )
        # the lost steps are reshot; the others stand as they are, verified or not
        done = {i: _to_record(rec) for i, rec in latest.items() if i not in lost}
    else:
        if reshoot_lost:
            if check_done is not None:
                # what the plain resume would refuse is said first: an adaptive session with
                # a step lost before later ones had been sent from here to that very resume
                check_done(verified_steps(root, scan.records))
            # the command named: after a --reshoot-lost stopped part-way, the user's next try
            # is the same command again, and "drop --reshoot-lost" left the rest to guess
            raise SessionError(
                f"{shown_path(root)}: --reshoot-lost is for a session that completed; this one did "
                f"not ({_ended_as(runner.get('finish_reason'), root, scan.records)}), "
                "and its resume sets aside and shoots again whatever it cannot verify anyway "
                "(nothing in this folder was changed): continue it with rti-rig run --resume "
                f"{shell_word(str(root))}"
            )
        unjournaled = _unjournaled_steps(root, manifest, scan, names)
        if rebuild_journal and (unjournaled or scan.missing):
            # a journal gone: rebuilt from what proves each step (the manifest's records, the
            # step record files), the rest set aside, as asked
            rebuilt = _provable_steps(root, manifest, names, scan.records)
            done = {i: _to_record(e) for i, e in rebuilt.items()}
        else:
            if unjournaled:
                _refuse_unjournaled(root, scan, names, unjournaled)
            _refuse_lost_journal(root, names, scan)
            done = verified_steps(root, scan.records)
        latest = _latest_records(scan.records)
        renamed = renamed_jpegs(root, scan.records)
        lost_now = []
        for i, rec in sorted(latest.items()):
            if i in done or not (gone := _lost_entries(root, rec, renamed)):
                continue
            earlier = _set_aside_earlier(root, rec, [name for name, _ in gone])
            if earlier is not None:  # rti-rig's own move: a reshoot asked for, cut short
                aside_before.append(f"{names[i]} (in {earlier})")
            else:
                lost_now.append(f"{names[i]}: {', '.join(f'{n} {how}' for n, how in gone)}")
    stamp = _new_stamp(root)
    if check_done is not None:
        check_done(done)
    # the journal's repair, the moves and the relisting are one change of the folder: a
    # Ctrl-C or SIGTERM among them (acted on once they are done) had left lights.lp listing
    # an image already moved to recovered/, which relight then paired with another light
    with signals_deferred():
        recovered: list[str] = []
        rebuild: list[str] = []
        if rebuilt is not None:
            rebuild, moved_aside = _rebuild_journal(
                root, manifest, rebuilt, names, stamp, scan.records, from_records=scan.missing
            )
            recovered.extend(moved_aside)
        elif rebuild_journal and not scan.mended:  # a rebuild from records/: said by repair
            rebuild = [
                f"{JOURNAL} already holds a record of every image {MANIFEST} lists as captured: "
                "nothing rebuilt (the resume goes on as without --rebuild-journal)"
            ]
        repair = _repair_journal(root, scan, stamp) if scan.needs_repair and rebuilt is None else []
        if restored:
            lines = [json.dumps(restored[i]).encode("utf-8") + b"\n" for i in sorted(restored)]
            _write_bytes_atomic(root / JOURNAL, b"".join([*scan.kept, *lines]))
            kept = sorted(i for i in restored if i in done)
            rebuild = [
                f"{JOURNAL}: {len(restored)} record(s) it had lost restored from {MANIFEST} "
                f"({_shown(names, sorted(restored))}), each with its step's light; "
                + (
                    f"{len(kept)} of those images kept, their files as recorded ("
                    f"{_shown(names, kept)}), not reshot"
                    if kept
                    else "none of those images is as recorded"
                )
            ]
        keep = {name for rec in done.values() for name in rec.sha256}
        leftovers = [
            *root.glob("image_*"),
            *(root / LINEAR_DIR).glob("image_*"),
            *(root / RAW_DIR).glob("image_*"),
            *(p for p in (root / RAW_INCOMING).glob("*") if p.is_file()),
        ]
        for path in sorted(leftovers):
            rel = path.relative_to(root).as_posix()
            if rel in keep:
                continue
            recovered.append(_set_aside(root, path, stamp))
        for partial in [
            *root.glob(".*.partial"),
            *(root / LINEAR_DIR).glob(".*.partial"),
            *(root / RAW_DIR).glob(".*.partial"),
            *root.glob(".*.tmp"),
            *(root / RECORDS_DIR).glob(".*.tmp"),
        ]:
            partial.unlink()
        try:
            (root / LINEAR_DIR).mkdir(exist_ok=True)
        except OSError as exc:
            raise SessionWriteError(root / LINEAR_DIR, exc) from None
        if repair and (root / "recovered" / stamp / "journal-rejected.txt").is_file():
            recovered.append(f"recovered/{stamp}/journal-rejected.txt")
        # a lights.lp edited by hand is kept before it is written again from the journal; the
        # last step recorded (a journal line or record file, lights.lp then still to write) and
        # a journal rebuilt (its last commit unknown) may be left out of the run's own listing
        last = scan.records[max(0, len(scan.records) - len(scan.mended) - 1) :]
        edited_lp = _keep_edited_lp(
            root,
            stamp,
            [*scan.records, *(rebuilt or {}).values(), *restored.values()],
            done,
            None
            if rebuilt is not None or scan.missing
            else _may_lack(manifest, {int(rec["index"]) for rec in last} | set(restored)),
        )
        if edited_lp is not None:
            recovered.append(edited_lp)
        moved_lp = _relist_verified(root, done, stamp)
        if moved_lp is not None:
            recovered.append(moved_lp)
    return ResumeState(
        manifest=manifest,
        done=done,
        recovered=recovered,
        journal_repair=repair,
        journal_rebuild=rebuild,
        lost_since_capture=lost_now,
        set_aside_before=aside_before,
        edited_lp=edited_lp,
    )


def _set_aside_earlier(root: Path, rec: dict[str, Any], gone: list[str]) -> str | None:
    """The ``recovered/STAMP`` folder where an earlier resume set aside every file of the
    step ``rec`` journals that is no longer in its place (``gone``, as :func:`_lost_entries`
    found them), each with its journaled checksum; None when any of them is not there so
    (then it is lost).

    Why: a ``--reshoot`` (or ``--reshoot-lost``) cut short moves the steps to reshoot aside
    before it shoots them; the plain resume it then advises had said of them "lost since
    capture: what was captured is no longer there", of files rti-rig itself had moved."""
    recovered = root / "recovered"
    if not recovered.is_dir():
        return None
    for stamp in sorted(recovered.iterdir(), reverse=True):
        if gone and all(file_sha256(stamp / n) == rec["sha256"][n] for n in gone):
            return f"recovered/{stamp.name}"
    return None


def _refuse_complete(
    root: Path, manifest: dict[str, Any], total: int, finished: int, scan: JournalScan
) -> None:
    """Raise :class:`SessionComplete` for ``root``, a session that completed with every image
    as captured (checked by the caller), naming its next step: ``rti-rig fit``.

    A journal missing or lacking records (``scan.mended``: images vouched for by their step
    record files instead) raises :class:`CompleteJournalNotWhole`, naming the rebuild. Why: a
    session whose ``journal.jsonl`` was deleted had been called complete with "every image
    … matches its journaled checksum … nothing was changed", exit 0, and left with no
    journal: its record gone, it was said to be intact."""
    folder = shell_word(str(root))
    mend = journal_mend_note(root) if scan.mended else None
    if mend is not None:
        fit = fit_beside(root)
        raise CompleteJournalNotWhole(
            f"{shown_path(root)}: this session completed all {finished} steps, but its "
            f"record is not whole: {mend} (no rig is opened, nothing is shot). Nothing was "
            f"changed. Run that first, then {fit}"
        )
    if manifest.get("adaptive") and finished < total:
        stop = (manifest["adaptive"].get("result") or {}).get("stop") or {}
        done = (
            f"this adaptive session is complete: it stopped after {finished} of at most "
            f"{total} lights ({stop.get('reason', 'its stopping rule')})"
        )
    else:
        done = f"this session is complete: all {finished} steps were captured"
    said = (
        f"{shown_path(root)}: {done}, and every image is as captured (each JPEG and linear "
        "TIFF matches its journaled checksum); nothing to resume, nothing was changed"
    )
    fit = fit_beside(root)
    lp = root / LP_NAME
    if not lp.is_file():
        # fit refuses a session folder without it (naming export-lp): the next step had been
        # named as fit alone, which then failed
        said += f"; only its {LP_NAME} is missing"
        own = shell_word(str(lp))
        fit = f"rti-rig export-lp {folder} --out {own} writes it from the journal, then {fit}"
    elif not _lp_is_the_journals(lp, scan):
        # a lights.lp cut short, emptied or edited had been called intact here, and fit then
        # refused it or judged it wrong: said, with the mend (nothing is changed by a resume)
        said += (
            f"; but its {LP_NAME} is not the listing rti-rig wrote from {JOURNAL} (edited, "
            "cut short or emptied since?)"
        )
        if _journal_lights_are_the_manifests(manifest, scan):
            fit = f"unless that edit was on purpose, {lp_again(lp)}, then {fit}"
        else:  # the journal's lights edited too: a listing written from it would be wrong
            said += f", and {JOURNAL} does not give every image the light {MANIFEST} records"
            fit = f"restore the folder from a backup copy, then {fit}"
    raise SessionComplete(said, fit, root)


def _journal_lights_are_the_manifests(manifest: dict[str, Any], scan: JournalScan) -> bool:
    """Whether each image's latest journal record gives it the light the manifest's record of
    its step does (a complete session's manifest holds them all): only then is a listing
    written again from the journal the one the run wrote."""
    recorded = {
        step.get("image"): step.get("actual_direction")
        for step in manifest.get("steps") or []
        if isinstance(step, dict)
    }
    latest = _latest_records(scan.records).values()
    return all(recorded.get(r.get("image")) == r.get("actual_direction") for r in latest)


def _lp_is_the_journals(lp: Path, scan: JournalScan) -> bool:
    """Whether a complete session's ``lp`` is what the run wrote of its journal's lights,
    every step listed (:func:`_run_wrote_lp`); an unreadable file is not."""
    try:
        data = lp.read_bytes()
    except OSError:
        return False
    done = {int(r["index"]) for r in scan.records}
    return _run_wrote_lp(data, scan.records, done, may_lack=())


#: How a run that did not finish ended, by the manifest's finish_reason (for a refusal).
#: How a session's last run ended, by its manifest's ``finish_reason``, as messages say it
#: (the verdict of a session not finished and a refused ``--reshoot-lost`` say it alike).
RUN_ENDED = {
    "cancelled": "stopped by Ctrl-C",
    "interrupted": "interrupted",
    "error": "stopped by an error",
    "emergency-stop": "stopped by an emergency stop",
    "write-failed": "a file could not be written",
    "no-space": "the disk was full",
    RUN_UNRECORDED: f"it stopped without recording why ({CAUSES})",
    # what a resume had marked such a run before (older manifests)
    "crashed": f"it stopped without recording why ({CAUSES})",
}


def _ended_as(reason: object, root: Path, journal: list[dict[str, Any]]) -> str:
    """``its last run …`` for :data:`RUN_ENDED`'s ``reason`` (None: it recorded no end, by
    :func:`~rti_rig.runtime.unrecorded_end.unrecorded_end`: "killed" had been said of a run
    whose disk was too full to record its end). ``journal``: the caller's records
    (``scan_journal``'s), read once (it had been read again here)."""
    if reason is None:
        return f"its last run: {unrecorded_end(root, journal)}"
    said = RUN_ENDED.get(reason) if isinstance(reason, str) else None
    return f"its last run: {said}" if said else "its last run did not finish"


def _manifest_records(manifest: dict[str, Any], names: list[str]) -> dict[int, dict[str, Any]]:
    """The step records the manifest holds (written when a run of the session ended, also by
    Ctrl-C, SIGTERM or an error: each with the checksums its journal line held), well-formed
    ones only, by step."""
    steps = manifest.get("steps")
    if not isinstance(steps, list):
        return {}
    return {e["index"]: e for e in steps if _record_problem(e, names) is None}


def _unjournaled_steps(
    root: Path, manifest: dict[str, Any], scan: JournalScan, names: list[str]
) -> list[int]:
    """The steps the manifest records as captured, whose files are on disk as its checksums
    say, and of which the journal holds no record: what a journal deleted, cut short or
    overwritten has lost (a journal line torn by a kill is never that: the step it was
    committing is in no manifest, which only a run's end writes)."""
    journaled = {r["index"] for r in scan.records}
    return sorted(
        i
        for i, entry in _manifest_records(manifest, names).items()
        if i not in journaled and verified_steps(root, [entry])
    )


def rebuildable_journal(root: Path, scan: JournalScan | None = None) -> bool:
    """Whether ``run --resume ROOT --rebuild-journal`` would take back images of session
    ``root``: it did not finish, and its journal lost records its manifest holds of images
    still on disk as captured; or it completed, its journal lost or damaged, and every image
    it captured is proven (:func:`rebuild_finished_journal`). False for a folder that is no
    session. ``scan``: the caller's scan of the journal with the schedule's image names."""
    root = Path(root)
    try:
        manifest = read_manifest(root)
    except SessionError:
        return False
    total = planned_steps(manifest)
    if not total:
        return False
    names = image_names(total)
    try:
        if scan is None:
            scan = scan_journal(root, names)
        if (manifest.get("runner") or {}).get("finish_reason") == "completed":
            # every image proven, or recorded with its light, its files alone lost (the
            # rebuild records it as lost, for --reshoot-lost)
            _taken, unproven, lost = _finished_rebuild(root, manifest, names, scan)
            return unproven is not None and len(lost) == len(unproven)
    except SessionError:
        return False
    if unresumable(root) is not None:  # a resume, which the rebuild goes with, is refused
        return False
    return bool(_unjournaled_steps(root, manifest, scan, names))


def _finished_steps(manifest: dict[str, Any], total: int) -> range:
    """The steps a completed session captured: all of its schedule's, or as many as an
    adaptive one took before its stopping rule ended it."""
    done = (manifest.get("runner") or {}).get("steps_done")
    if manifest.get("adaptive") and isinstance(done, int) and not isinstance(done, bool):
        return range(min(done, total))
    return range(total)


def _finished_rebuild(
    root: Path, manifest: dict[str, Any], names: list[str], scan: JournalScan
) -> tuple[dict[int, dict[str, Any]], list[str] | None, dict[int, dict[str, Any]]]:
    """What a completed session's journal would be rebuilt from (:func:`_provable_steps`),
    why each captured image that nothing proves is not (None: the journal is whole, nothing to
    rebuild), and, by step, the record of each of those that only has files missing or changed
    (its record and light are there: the rebuild records it as lost, and ``--reshoot-lost``
    can shoot it again). Nothing in the folder changes."""
    steps = _finished_steps(manifest, len(names))
    journaled = {r["index"] for r in scan.records}
    if (root / JOURNAL).exists() and not scan.needs_repair and set(steps) <= journaled:
        return {}, None, {}
    taken = _provable_steps(root, manifest, names, scan.records)
    listed = _manifest_records(manifest, names)
    latest = _latest_records(scan.records)
    unproven: list[str] = []
    lost_only: dict[int, dict[str, Any]] = {}  # only files missing or changed
    for i in steps:
        if i in taken:
            continue
        records = [e for e in (latest.get(i), listed.get(i)) if e is not None]
        lit = [e for e in records if _light_as_recorded(manifest, e)]
        if not records:
            why = f"neither {MANIFEST} nor an intact line of {JOURNAL} records it"
        elif not lit:
            why = "its recorded light is not the one its step was given"
        else:
            gone = sorted(
                name
                for e in records
                for name, digest in e["sha256"].items()
                if not _as_captured(root, e, name, digest)
            )
            why = f"{', '.join(dict.fromkeys(gone))} missing or changed since capture"
            lost_only[i] = lit[0]  # the journal's line, else the manifest's
        unproven.append(f"{names[i]} ({why})")
    return taken, unproven, lost_only


def rebuild_finished_journal(root: Path) -> list[str]:
    """Rebuild the journal of a session that **completed** from what proves each image (its
    manifest's records, an intact line of the damaged journal: :func:`_provable_steps`), with
    no rig: nothing is captured. Returns what was done, as :func:`_rebuild_journal` says it.

    An image whose record and light are there but whose files are not all as captured (a JPEG
    edited, a RAW original gone) is recorded as captured and lost: its record goes back into
    the journal, its files that are not as recorded are set aside in ``recovered/`` (never
    deleted), and the QA verdict and ``--reshoot-lost`` then see it as lost, as with the
    journal intact. Why: one such image had refused the whole rebuild, and every image that
    was provable stayed unproven until a backup was found.

    Refused, naming each image and why, if an image the session captured has no record with its
    step's light; nothing in the folder changes then. Why: a completed session whose journal
    was lost (a copy to a NAS or a sync tool that skipped it) could not be made whole:
    ``--rebuild-journal`` was refused as "for a session that did not finish", export-lp refused
    the session, and its verdict could check no image against its capture checksum; its
    manifest holds every record the journal did."""
    root = Path(root)
    held = str(root.resolve()) in _LOCKED
    lock_session(root)
    try:
        manifest = read_manifest(root)
        runner = manifest.get("runner") or {}
        if runner.get("finish_reason") != "completed":
            raise SessionError(
                f"{shown_path(root)}: this session did not complete: resume it instead"
            )
        names = image_names(planned_steps(manifest))
        scan = scan_journal(root, names)
        taken, unproven, lost = _finished_rebuild(root, manifest, names, scan)
        fit = fit_beside(root)
        if unproven is None:
            # what is lost, named with what gets it back: the user who reached for the rebuild
            # had been sent to a fit to find out
            gone = lost_since_capture_said(root, manifest)
            raise SessionError(
                f"{shown_path(root)}: this session completed and its {JOURNAL} holds a record of "
                "every image it captured: nothing to rebuild; drop --rebuild-journal"
                + (
                    f"; but {gone}"
                    if gone
                    else f" (the QA verdict of {fit} names any image changed since capture)"
                )
            )
        if len(lost) < len(unproven):
            shown = "; ".join(unproven[:8]) + (" …" if len(unproven) > 8 else "")
            raise SessionError(
                f"{shown_path(root)}: {JOURNAL} cannot be rebuilt: {len(unproven)} of the "
                f"session's images cannot be proven as captured: {shown}; nothing in this folder "
                f"was changed: restore {JOURNAL} (or those files) from a backup copy of the "
                f"folder, then run this again; meanwhile {fit} fits "
                "the session as it is, its verdict naming the images it cannot check"
            )
        notes: list[str] = []
        try:
            with signals_deferred():  # the journal, the moves and lights.lp: one change
                stamp = _new_stamp(root)
                notes, _moved = _rebuild_journal(
                    root, manifest, taken, names, stamp, scan.records, lost
                )
                # lights.lp lists what is on disk as captured: a lost image is not listed
                # (relight pairs its lines with the JPEGs in order); one edited by hand is kept
                records = [*scan.records, *taken.values(), *lost.values()]
                edited_lp = _keep_edited_lp(root, stamp, records, (), None)
                if edited_lp is not None:
                    notes.append(edited_lp_note(root, edited_lp, run=False))
                _relist_verified(
                    root, verified_steps(root, [*taken.values(), *lost.values()], "image"), stamp
                )
        except BaseException as exc:
            if notes:  # a stop held while the folder changed, acted on once it had: said so
                exc.journal_rebuild = notes  # type: ignore[attr-defined]
            raise
        return notes
    finally:
        if not held:
            unlock_session(root)


def rebuild_advice(root: Path, scan: JournalScan | None = None) -> str:
    """The words that name ``run --resume ROOT --rebuild-journal`` (to follow the advice to
    restore the journal from a backup) where it would take images back
    (:func:`rebuildable_journal`), else "": said where a lost journal is named (export-lp had
    advised a backup alone, of a session its manifest can vouch for). A completed session with
    images missing or changed since capture is told the reshoot too, which restores the records
    the journal lost before it shoots exactly those (the backup alone had been advised), beside
    the rebuild, which records them as lost without the rig. ``scan``: the caller's scan of
    the journal with the schedule's image names, if it holds one."""
    folder = shell_word(str(root))
    lost = _lost_beside_a_lost_journal(Path(root), scan)
    if lost:
        return (
            f", or, as {', '.join(lost[:5])}{' …' if len(lost) > 5 else ''} "
            f"{'is' if len(lost) == 1 else 'are'} missing or changed since capture, reshoot "
            f"exactly those with the object where it was: rti-rig run --resume {folder} "
            f"--reshoot-lost (it restores the journal's records from {MANIFEST} first; "
            f"without the rig, rti-rig run --resume {folder} --rebuild-journal rebuilds the "
            f"journal and records {'it' if len(lost) == 1 else 'them'} as lost)"
        )
    if rebuildable_journal(root, scan):
        return (
            f", or rebuild it from {MANIFEST}'s records: rti-rig run --resume {folder} "
            "--rebuild-journal"
        )
    return ""


def _lost_beside_a_lost_journal(root: Path, scan: JournalScan | None = None) -> list[str]:
    """The images of a completed session that its rebuild refuses only as missing or changed
    since capture, when ``--reshoot-lost`` could shoot them again (not adaptive, not on a
    camera-triggered dome); empty otherwise, or when anything else is unproven."""
    try:
        manifest = read_manifest(root)
        total = planned_steps(manifest)
        if (
            not total
            or (manifest.get("runner") or {}).get("finish_reason") != "completed"
            or manifest.get("adaptive")
            or unresumable(root) is not None
        ):
            return []
        names = image_names(total)
        if scan is None:
            scan = scan_journal(root, names)
        _taken, unproven, lost = _finished_rebuild(root, manifest, names, scan)
    except SessionError:
        return []
    return [names[i] for i in sorted(lost)] if unproven and len(lost) == len(unproven) else []


def _refuse_unjournaled(
    root: Path, scan: JournalScan, names: list[str], unjournaled: list[int]
) -> None:
    """Refuse a resume that would set aside and reshoot images the manifest proves were
    captured, because the journal lost their records; nothing in the folder changes.

    Why: a journal cut short was read as a line torn by a kill ("never committed") and one
    overwritten as junk, and the resume moved every image they had lost to ``recovered/`` and
    shot them again, though ``manifest.json`` held each one's checksums and light; a missing
    journal was refused with no way on but a backup."""
    if not (root / JOURNAL).exists():
        what = f"{JOURNAL} is missing"
    else:
        parts = []
        if scan.rejected:
            parts.append(f"{len(scan.rejected)} unreadable line(s)")
        if scan.torn.strip():
            parts.append("its last line cut short")
        what = f"{JOURNAL} is damaged ({', '.join(parts) or 'records missing'})"
    shown = ", ".join(names[i] for i in unjournaled[:8]) + (" …" if len(unjournaled) > 8 else "")
    folder = shell_word(str(root))
    raise SessionError(
        f"{shown_path(root)}: {what}: it holds no record of {len(unjournaled)} image(s) that "
        f"{MANIFEST} lists as captured, with files on disk as its checksums say ({shown}); a "
        "resume would set them aside and shoot them again (nothing in this folder was changed): "
        f"restore {JOURNAL} from a backup copy of the folder and resume again, or rebuild it "
        f"from the manifest: rti-rig run --resume {folder} --rebuild-journal (it takes back "
        "only the images whose files match the checksums and light the manifest or an intact "
        "journal line records, and sets the old journal and anything else aside in "
        "recovered/, never deleted)"
    )


def _restorable(
    root: Path, manifest: dict[str, Any], scan: JournalScan, names: list[str]
) -> dict[int, dict[str, Any]]:
    """The manifest's records of a completed session's steps its journal lost the line of (its
    well-formed records only), for ``--reshoot-lost`` to restore: an image whose files are as
    those checksums say is kept, one lost or changed is reshot. Refused, nothing moved, if the
    light a record gives is not its step's (nothing then proves which image it is).

    Why: the reshoot keeps the journaled images and shoots every other step, so an intact image
    whose journal line was overwritten (a sync tool) was set aside and shot again with the one
    lost ("reshoot exactly those" reshot more, on a rig where the object may have moved); a
    journal lost whole found nothing to reshoot; and the rebuild, which needs every image as
    captured, could not help while one was lost."""
    journaled = {r["index"] for r in scan.records}
    listed = _manifest_records(manifest, names)
    restored = {
        i: e for i, e in listed.items() if i not in journaled and _light_as_recorded(manifest, e)
    }
    unproven = sorted(i for i in listed if i not in journaled and i not in restored)
    if unproven:
        raise SessionError(
            f"{shown_path(root)}: {JOURNAL} holds no record of {_shown(names, unproven)}, and the "
            f"light {MANIFEST} records for {'it' if len(unproven) == 1 else 'them'} is not the one "
            "its step was given: --reshoot-lost would set them aside and shoot them again with "
            "the images lost (nothing in this folder was changed): restore "
            f"{JOURNAL} from a backup copy of the folder, then run this again"
        )
    return restored


def _light_as_recorded(manifest: dict[str, Any], entry: dict[str, Any]) -> bool:
    """Whether the light of the manifest's record ``entry`` is the one the manifest's schedule
    gives its step (the same LED, the same planned direction): a record moved to another step
    or edited by hand is not taken back. An adaptive session's steps have no scheduled light
    (each was chosen from the images before it): the resume decides each again and refuses
    one decided otherwise (:meth:`~rti_rig.app.usecases.adaptive.AdaptiveSteps.replay`); its
    record must hold that decision."""
    if manifest.get("adaptive"):
        return isinstance(entry.get("decision"), dict)
    steps = (manifest.get("schedule") or {}).get("steps")
    i = entry["index"]
    if not isinstance(steps, list) or not 0 <= i < len(steps) or not isinstance(steps[i], dict):
        return False
    step = steps[i]
    if step.get("led") != entry.get("led"):
        return False
    try:
        planned = [float(x) for x in step.get("direction") or ()]
        recorded = [float(x) for x in entry["planned_direction"]]
    except (TypeError, ValueError):
        return False
    if len(planned) != 3 or len(recorded) != 3:
        return False
    return all(abs(a - b) <= 1e-9 for a, b in zip(planned, recorded, strict=True))


def _provable_steps(
    root: Path,
    manifest: dict[str, Any],
    names: list[str],
    journaled: list[dict[str, Any]],
) -> dict[int, dict[str, Any]]:
    """The records whose files are on disk as their checksums say (bytes, or a linear TIFF's
    pixels) and whose light is the one the manifest gives the step: all a rebuilt journal may
    hold. Nothing in the folder changes.

    A step's record is its last intact line of the damaged journal (``journaled``, well-formed
    records only) when that proves it, else the manifest's. Why the journal's too: the manifest
    is written only when a run ends, so the images a run committed before it was killed (SIGKILL,
    a power cut) are recorded in the journal alone; a rebuild from the manifest alone set them
    aside and shot them again, though their journal lines held their checksums and lights, the
    very proof a plain resume takes.

    An adaptive session whose record of an image on disk holds no decision is refused: the
    resume could not decide that step again as it was, nor the lights after it."""
    listed = _manifest_records(manifest, names)
    if manifest.get("adaptive"):
        undecided = [
            names[i]
            for i, e in sorted(listed.items())
            if not isinstance(e.get("decision"), dict) and verified_steps(root, [e])
        ]
        if undecided:
            raise SessionError(
                f"{shown_path(root)}: {MANIFEST} records {', '.join(undecided[:8])} without the "
                "adaptive decision that chose its light, so a rebuilt journal could not prove the "
                "session continues as it began; nothing in this folder was changed: restore "
                f"{JOURNAL} from a backup copy of the folder, or start a new session with "
                "another --out"
            )
    latest = _latest_records(list(journaled))
    taken: dict[int, dict[str, Any]] = {}
    for i in sorted(set(listed) | set(latest)):
        for entry in (latest.get(i), listed.get(i)):
            if (
                entry is not None
                and _light_as_recorded(manifest, entry)
                and verified_steps(root, [entry])
            ):
                taken[i] = entry
                break
    return taken


def _rebuild_journal(
    root: Path,
    manifest: dict[str, Any],
    taken: dict[int, dict[str, Any]],
    names: list[str],
    stamp: str,
    journaled: list[dict[str, Any]],
    lost: Mapping[int, dict[str, Any]] | None = None,
    from_records: bool = False,
) -> tuple[list[str], list[str]]:
    """Rebuild the journal from ``taken`` (:func:`_provable_steps`) and the records of a
    completed session's images recorded as lost (``lost``: their light as recorded, their
    files not all as captured; those files are set aside as unproven, the others stay where
    they are, as with the journal intact): the old journal is copied
    to ``recovered/STAMP/journal-damaged.jsonl``, every image file no taken record vouches for
    to ``recovered/STAMP/not-in-manifest/`` (neither the manifest nor an intact line of the old
    journal, ``journaled``, records its step) or ``recovered/STAMP/unproven/`` (recorded, but
    its file or light is not as recorded), never deleted; then the journal is written with the
    taken records, as their lines were. Returns what was done (said, and recorded in the
    manifest's run) and the paths set aside.

    The old journal is copied aside and replaced by the new one in one rename, last: it had been
    moved aside first, so a kill (SIGKILL, a power cut) before the new one was written left the
    session with no journal at all, and the next rebuild, reading none, set aside and shot again
    the images only its intact lines proved.

    ``from_records``: the journal was missing, so the records ``journaled`` holds are the step
    record files' (``records/``), each verified against its files, and are said to be."""
    notes: list[str] = []
    moved: list[str] = []
    aside = root / "recovered" / stamp
    journal = root / JOURNAL
    if journal.exists():
        dest = aside / "journal-damaged.jsonl"
        try:
            dest.parent.mkdir(parents=True, exist_ok=True)
            _copy_whole(journal, dest)
        except OSError as exc:
            raise SessionWriteError(dest, exc) from None
        # said, and recorded in the run's journal_rebuild, but no image: not counted with them
        notes.append(f"the damaged {JOURNAL} was kept as {dest.relative_to(root).as_posix()}")
    lost = dict(lost or {})
    keep = {name for e in taken.values() for name in e["sha256"]}
    keep |= {
        name
        for e in lost.values()
        for name, digest in e["sha256"].items()
        if _as_captured(root, e, name, digest)
    }
    listed = _manifest_records(manifest, names)
    recorded = set(listed) | {e["index"] for e in journaled}
    steps_of = {n: i for i, n in enumerate(names)}
    files = [
        *root.glob("image_*"),
        *(root / LINEAR_DIR).glob("image_*"),
        *(root / RAW_DIR).glob("image_*"),
    ]
    latest = _latest_records(list(journaled))
    # said before anything moves (a move makes a file missing)
    unproven_why: dict[int, str | None] = {
        step: _why_unproven(root, manifest, latest.get(step), listed.get(step))
        for step in {steps_of.get("_".join(p.stem.split("_")[:2])) for p in files} | set(lost)
        if step is not None and step not in taken
    }
    for path in sorted(p for p in files if p.is_file()):
        rel = path.relative_to(root).as_posix()
        if rel in keep:
            continue
        step = steps_of.get("_".join(path.stem.split("_")[:2]))  # image_003_2.nef: step 3
        why = "unproven" if step is not None and step in recorded else "not-in-manifest"
        dest = aside / why / rel
        try:
            dest.parent.mkdir(parents=True, exist_ok=True)
            os.replace(path, dest)
        except OSError as exc:
            raise SessionWriteError(dest, exc) from None
        moved.append(dest.relative_to(root).as_posix())
        said = (
            f"its step is recorded (in {MANIFEST} or an intact line of the old {JOURNAL}), but "
            + (unproven_why.get(step) or "not all its files (or its light) are as recorded there")
            if why == "unproven" and step is not None
            else f"{MANIFEST} does not list its step, nor does an intact line of the old "
            f"{JOURNAL}, so nothing proves its light"
        )
        notes.append(f"{rel} set aside as {moved[-1]}: {said}")
    written = {**lost, **taken}
    lines = b"".join(json.dumps(written[i]).encode("utf-8") + b"\n" for i in sorted(written))
    _write_bytes_atomic(journal, lines)
    from_manifest = [i for i in sorted(taken) if listed.get(i) == taken[i]]
    from_journal = [i for i in sorted(taken) if listed.get(i) != taken[i]]
    notes.insert(
        0,
        f"{JOURNAL} rebuilt from {MANIFEST}: {len(from_manifest)} image(s) taken back"
        + (f" ({_shown(names, from_manifest)})" if from_manifest else "")
        + ", each file matching the manifest's checksum and its light the manifest's"
        + (
            f"; and {len(from_journal)} from "
            + (
                f"their step record files in {RECORDS_DIR}/ ({JOURNAL} was missing)"
                if from_records
                else f"the old {JOURNAL}'s intact lines"
            )
            + f" ({_shown(names, from_journal)}), committed after {MANIFEST} was last written "
            "(a run killed before its end), each file matching its record's checksum and its "
            "light the one its step was given"
            if from_journal
            else ""
        ),
    )
    if lost:  # what each lost, as found before anything moved
        notes.insert(
            1,
            f"{len(lost)} image(s) recorded as captured and lost ("
            + "; ".join(
                f"{names[i]}: {unproven_why.get(i) or 'its files not as captured'}"
                for i in sorted(lost)[:8]
            )
            + (" …" if len(lost) > 8 else "")
            + "): each one's record and light are back in the journal, its files that are not "
            "as recorded set aside, the others left in place",
        )
    # said on disk too, beside what was set aside: a stop before the run records it in the
    # manifest (the rig not answering, a Ctrl-C while it opens) had left recovered/ unexplained
    report = aside / "journal-rebuild.txt"
    try:
        aside.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise SessionWriteError(aside, exc) from None
    _write_bytes_atomic(report, "".join(f"{n}\n" for n in notes).encode("utf-8"))
    notes.append(f"what was done is written in {report.relative_to(root).as_posix()}")
    return notes, moved


def _why_unproven(
    root: Path,
    manifest: dict[str, Any],
    journaled: dict[str, Any] | None,
    listed: dict[str, Any] | None,
) -> str | None:
    """Why a recorded step's image is not proven (its record from an intact journal line,
    ``journaled``, or the manifest's, ``listed``): its light, or the files of it missing or
    changed since capture, named (a RAW original too: the original capture). None when
    neither records it.

    Why: the rebuild said "not all its files (or its light) are as recorded" of a step whose
    RAW original alone was missing, not naming what was lost."""
    records = [e for e in (journaled, listed) if e is not None]
    if not records:
        return None
    lit = [e for e in records if _light_as_recorded(manifest, e)]
    if not lit:
        return "its recorded light is not the one its step was given"
    gone = [
        f"{name} {'changed' if (root / name).is_file() else 'missing'}"
        for name, digest in lit[0]["sha256"].items()
        if not _as_captured(root, lit[0], name, digest)
    ]
    if not gone:
        return None
    return f"{', '.join(gone)} since capture"


def _shown(names: list[str], steps: list[int]) -> str:
    """The image names of ``steps``, the first 8 of them."""
    return ", ".join(names[i] for i in steps[:8]) + (" …" if len(steps) > 8 else "")


def _refuse_lost_journal(root: Path, names: list[str], scan: JournalScan) -> None:
    """Refuse to resume an interrupted session whose journal is gone while images of its later
    steps are on disk, before anything moves.

    Why: its resume had moved every image to ``recovered/`` ("0 of 16 images verified on disk,
    25 unverified file(s) moved to recovered/") and shot them all again, never saying that the
    journal was missing (deleted by hand, or left behind by a copy). A step begins only once the
    previous one's journal line is on disk, so files of a step after the first prove there was
    a journal; files of the first step alone are a kill before the first line, which a resume
    sets aside and reshoots as ever.

    The step record files (``records/``) that ``scan`` took in the journal's place prove their
    steps; files of the step after the last of them are the step a kill cut short, set aside
    and reshot as ever. Files of any other step are still refused: a record file of theirs is
    gone or no longer matches them, and only the journal's backup could vouch for them."""
    if (root / JOURNAL).exists():
        return
    proven = {int(r["index"]) for r in scan.records}
    if proven:  # the steps proven, and the one after the last of them (cut short by a kill)
        proven.add(min(max(proven) + 1, len(names) - 1))
    allowed = {names[i] for i in proven}
    later = [
        stem
        for stem in _files_after_first_step(root, names)
        if not any(stem == n or stem.startswith(f"{n}_") for n in allowed)
    ]
    if not later:
        return
    if proven:
        bases = sorted(
            {n for n in names for stem in later if stem == n or stem.startswith(f"{n}_")}
        )
        shown = ", ".join(bases[:8]) + (" …" if len(bases) > 8 else "")
        raise SessionError(
            f"{shown_path(root)}: {JOURNAL} is missing; the step record files in {RECORDS_DIR}/ "
            f"prove {len(scan.records)} image(s) as captured, but not {shown}, whose record files "
            "are gone or no longer match them: restore "
            f"{JOURNAL} (or {RECORDS_DIR}/) from a backup copy of the folder, then run "
            f"rti-rig run --resume {shell_word(str(root))} again; if it is lost for good, "
            "rti-rig run --resume "
            f"{shell_word(str(root))} --rebuild-journal sets them aside in recovered/ (never "
            "deleted) and shoots them again (nothing in this folder was changed)"
        )
    first = names[0] if names else ""
    count = len({stem.split("_")[1] for stem in later} | {first.split("_")[1]})
    raise SessionError(
        f"{shown_path(root)}: {JOURNAL} is missing, so none of the images on disk (about {count} "
        "steps) can be verified as captured with its light: restore "
        f"{JOURNAL} from a backup copy of the folder (or from where it was moved), then run "
        f"rti-rig run --resume {shell_word(str(root))} again; if it is lost for good, shoot "
        "the session again with another --out (nothing in this folder was changed; "
        f"--rebuild-journal cannot help either: {MANIFEST} vouches for none of these images, "
        "as a session killed before any run of it ended records none)"
    )


def _files_after_first_step(root: Path, names: list[str]) -> list[str]:
    """The base names of image files on disk of any step after the first (``image_002``,
    ``image_003_raw``…): what proves a session had a journal (a step begins only once the
    previous one's journal line is on disk)."""
    first = names[0] if names else ""
    return sorted(
        p.stem
        for folder in (root, root / LINEAR_DIR, root / RAW_DIR)
        for p in folder.glob("image_*")
        if p.is_file() and p.stem != first and not p.stem.startswith(f"{first}_")
    )


#: What :func:`stopped_before_first_journal` says of a session stopped before its first record.
UNRECORDED = "unrecorded"


def stopped_before_first_journal(root: Path, scan: JournalScan | None = None) -> str | None:
    """How session ``root`` (its manifest readable) came to have no journal, or None where it
    is not one that never wrote one: :data:`UNRECORDED` when it stopped (killed, a power cut)
    before its first image was journaled, with at most that first image's files on disk and
    no record file proving it (files a resume sets aside and shoots again); the first image's
    stem (``image_001``) when it stopped after that image's record file and before any journal
    line (:func:`stopped_before_journal_line`): its step is committed, but no ``journal.jsonl``
    or ``lights.lp`` lists it yet.

    Why: such a folder had been called "not a session folder" by ``fit``, and ``export-lp``
    advised restoring a journal.jsonl from a backup, of a journal that never existed. One
    function over one :func:`scan_journal`: the two cases had been two functions with one
    preamble, and ``fit`` read the manifest and scanned the journal twice to tell them apart.
    ``scan``: the caller's scan of the journal with the schedule's image names, if it holds one.
    """
    root = Path(root)
    if (root / JOURNAL).exists():
        return None
    try:
        total = planned_steps(read_manifest(root))
    except SessionError:
        return None
    if not total:
        return None
    names = image_names(total)
    if scan is None:
        scan = scan_journal(root, names)
    if not scan.records:
        return None if _files_after_first_step(root, names) else UNRECORDED
    return stopped_before_journal_line(scan) if scan.missing else None


def _relist_verified(root: Path, done: dict[int, StepRecord], stamp: str) -> str | None:
    """Make ``lights.lp`` list exactly the verified steps, once the others were set aside.

    Why here, before the rig opens: the run rewrites it only from its first commit (or its
    finish, once begun). A resume that set an image aside and then stopped before that — a
    Ctrl-C or a dome that did not answer while the rig opened — had left ``lights.lp`` listing
    the image it had just moved to ``recovered/``; relight, pairing the `.lp`'s lines with the
    JPEGs by order, then gave every later image the wrong light. With no verified step left,
    the stale ``lights.lp`` is moved to ``recovered/`` (never deleted); its path is returned.
    """
    path = root / LP_NAME
    ordered = [done[i] for i in sorted(done)]
    if ordered:
        write_lp_atomic(path, [LpEntry(r.image, r.actual_direction) for r in ordered])
        return None
    if not path.is_file():
        return None
    return _set_aside(root, path, stamp)


def _may_lack(manifest: dict[str, Any], last: set[int]) -> set[int]:
    """The steps of ``last`` (the last recorded) that the stopped session's ``lights.lp`` may
    leave out without an edit: none the manifest lists as steps of a run whose end it records,
    which wrote ``lights.lp`` listing every one of them before that record (its last line
    deleted by hand had gone unnoticed). A run still "running" (killed, or a resume begun
    since) or one whose end a stop cut (``end_cut``: no ``lights.lp`` written) may lack them.
    Read from the manifest the resume already holds."""
    runner = manifest.get("runner") or {}
    if (
        manifest.get("lp_file") != LP_NAME
        or runner.get("state") == "running"
        or runner.get("end_cut")
    ):
        return last
    listed = {s.get("index") for s in manifest.get("steps") or () if isinstance(s, dict)}
    return last - listed


def _keep_edited_lp(
    root: Path,
    stamp: str,
    records: list[dict[str, Any]],
    done: Collection[int],
    may_lack: Collection[int] | None,
) -> str | None:
    """Move session ``root``'s ``lights.lp`` to ``recovered/STAMP/`` (a name never taken
    before) if it is not a listing rti-rig wrote of the journal's lights, before the resume
    writes it again; returns where it went (relative to ``root``), or None when it is the run's
    own (or missing, or empty: nothing of the user's to keep).

    Why: the resume writes ``lights.lp`` again from the journal, the record of the lights that
    fired, and a ``lights.lp`` edited by hand in the stopped session (a name or a light
    corrected, a comment added, a line deleted) was overwritten, unsaid, with no copy.

    The run's own listing is what :func:`write_lp_atomic` writes for some of the lights
    ``records`` hold (any record of a step: an image shot again has two), byte for byte, in
    step order, listing every step of ``done`` (the steps this resume verified) but those of
    ``may_lack``: the run writes ``lights.lp`` after a step's journal line (and its record file
    before that), so a run stopped in between left the last step recorded out of it, which is
    no edit. It may list steps ``done`` leaves out (images lost or set aside since it was
    written). ``may_lack`` None: any step may be left out (a journal rebuilt from the manifest
    or record files, whose last commit before the loss is not known)."""
    path = root / LP_NAME
    try:
        data = path.read_bytes()
    except FileNotFoundError:
        return None
    except OSError:
        data = None  # unreadable as it is: kept all the same, never overwritten unread
    if data is not None and (not data.strip() or _run_wrote_lp(data, records, done, may_lack)):
        return None
    return _set_aside(root, path, stamp, fresh=True)


def _run_wrote_lp(
    data: bytes,
    records: list[dict[str, Any]],
    done: Collection[int],
    may_lack: Collection[int] | None,
) -> bool:
    """Whether ``data`` is a ``lights.lp`` rti-rig wrote of ``records``' lights (see
    :func:`_keep_edited_lp`)."""
    lines: dict[str, set[str]] = {}  # image → the lines format_lp writes for its lights
    index: dict[str, int] = {}
    for entry in records:
        try:
            rec = _to_record(entry)
            text = format_lp([LpEntry(rec.image, rec.actual_direction)])
        except (KeyError, TypeError, ValueError):
            continue
        lines.setdefault(rec.image, set()).add(text.split("\n")[1])
        index[rec.image] = rec.index
    try:
        head, *body = data.decode("ascii").split("\n")
    except UnicodeDecodeError:
        return False
    if not body or body.pop() != "" or head != str(len(body)):
        return False  # format_lp: the count, one line a light, each ending in a newline
    listed = [line.split(" ", 1)[0] for line in body]
    if any(line not in lines.get(name, ()) for name, line in zip(listed, body, strict=True)):
        return False
    steps = [index[name] for name in listed]
    if steps != sorted(set(steps)):
        return False  # reordered, or a light given twice
    return may_lack is None or set(done) - set(steps) <= set(may_lack)


def lp_again(lp: Path, linear: bool = False) -> str:
    """ "write it again from the journal (the present one is kept in recovered/): rti-rig
    export-lp S --out S/lights.lp": what a session's ``lp`` that is not the journal's listing
    (edited, cut short, emptied) is mended by, in one set of words for the fit's verdict, its
    refusal of a ``lights.lp`` that cannot be read, and a complete session's resume. ``linear``: the
    listing names the linear TIFFs (``export-lp --linear``)."""
    folder = shell_word(str(lp.parent))
    return (
        f"write it again from the journal (the present one is kept in recovered/): rti-rig "
        f"export-lp {folder} --out {shell_word(str(lp))}" + (" --linear" if linear else "")
    )


def edited_lp_note(root: Path, kept: str, run: bool = True) -> str:
    """What a resume says of a ``lights.lp`` it set aside (:func:`_keep_edited_lp`) as kept
    at ``kept`` (relative to session ``root``): both paths, why, and what to do to keep the
    edit (once the run has ended, if ``run``: it writes ``lights.lp`` at every image)."""
    lp = shown_path(root / LP_NAME)
    return (
        f"{lp} differs from what rti-rig wrote from {JOURNAL} (edited by hand?): kept as "
        f"{shown_path(root / kept)}; {LP_NAME} is written again from the journal, which is the "
        f"record of the lights that fired; to keep your edit, make it again in {lp}"
        + (" once this run has ended" if run else "")
    )


def rewrite_session_lp(root: Path, entries: list[LpEntry]) -> str | None:
    """Write session ``root``'s ``lights.lp`` again as ``entries`` (the journal's listing,
    from ``export-lp``), under the session's lock, keeping a copy of the one there in a new
    ``recovered/STAMP/``: returns that copy's path relative to ``root`` ("" where there was no
    file left to keep), or None where the file already is that listing (nothing written).

    A copy, then the new listing renamed over the old whole: stopped at any point, the session
    has a ``lights.lp``. Why: the verdict on a hand-edited ``lights.lp`` advised "rti-rig
    export-lp S --out S/lights.lp", and that command, pasted, was refused ("would replace a
    file of the session"); the advice had said to move the file aside by hand first."""
    path = root / LP_NAME
    wanted = format_lp(entries).encode("ascii")
    held = str(root.resolve()) in _LOCKED
    lock_session(root)  # a run or resume begun since: refused, nothing changed
    try:
        try:
            if path.read_bytes() == wanted:
                return None
        except FileNotFoundError:
            write_lp_atomic(path, entries)
            return ""
        except OSError:
            pass  # unreadable as it is: copied all the same, never replaced uncopied
        dest = free_name(root / "recovered" / _new_stamp(root) / LP_NAME)
        try:
            dest.parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(path, dest)
        except OSError as exc:
            raise SessionWriteError(dest, exc) from None
        write_lp_atomic(path, entries)
        return dest.relative_to(root).as_posix()
    finally:
        if not held:
            unlock_session(root)


def _set_aside(root: Path, path: Path, stamp: str, fresh: bool = False) -> str:
    """Move ``path`` (inside session ``root``) to ``recovered/STAMP/`` under the same relative
    path, never deleting anything; returns where it went, relative to ``root``. ``fresh``: a
    name no earlier move there took (``free_name``), for a file set aside more than once in
    one run's folder (an edited ``lights.lp``)."""
    dest = root / "recovered" / stamp / path.relative_to(root)
    dest = free_name(dest) if fresh else dest
    try:
        dest.parent.mkdir(parents=True, exist_ok=True)
        os.replace(path, dest)
    except OSError as exc:
        raise SessionWriteError(dest, exc) from None
    return dest.relative_to(root).as_posix()


def unresumable(root: Path) -> str | None:
    """What to do instead of ``run --resume`` for session ``root`` if no resume can continue
    it or reshoot its images (None when one can, or when ``root`` is no session): one shot on
    a camera-triggered dome, whose own count went on since (its resume, ``--reshoot-lost``
    and an unfinished session's ``--rebuild-journal`` are refused before anything moves), or
    with an image-sequence camera (:func:`image_sequence_restarts`).

    Why: the QA verdict, export-lp and fit advised ``run --resume`` (with
    ``--rebuild-journal`` or ``--reshoot-lost``) for such sessions, commands that are refused
    for them. Read from the rig config the manifest records (``dome.flash_sync``)."""
    try:
        manifest = read_manifest(Path(root))
    except SessionError:
        return None
    rig = manifest.get("rig") or {}
    config_of = (rig.get("config") or {}) if isinstance(rig, dict) else {}
    dome = config_of.get("dome")
    sync = dome.get("flash_sync") if isinstance(dome, dict) else None
    config = shell_word(str(rig.get("config_path") or "CONFIG"))
    # a folder that does not exist yet beside it: ``--out NEWDIR`` pasted made NEWDIR
    again = shell_word(str(free_folder_beside(Path(root), "again")))
    if not isinstance(sync, dict):
        camera = config_of.get("camera")
        device = camera.get("device") if isinstance(camera, dict) else None
        return image_sequence_restarts(device, config, again)
    return (
        f"a camera-triggered dome ({sync.get('firmware', 'flash-stepped')}) cannot continue a "
        "session or reshoot single images (its own count went on): long-press its start "
        f"button to rewind it, then shoot the session again: rti-rig run {config} --out {again}"
    )


def image_sequence_restarts(device: object, config: str, out: str) -> str | None:
    """Why a session cannot be resumed, nor single images reshot, if its camera (the
    ``[camera.device]`` table ``device`` of rig config ``config``) is an image sequence
    (``backend = "images"``), with what to do instead (shoot again into ``out``, a shell word);
    None for any other camera.

    Why: an image sequence is opened at its first file by every run, so a resume gave the
    lights still to shoot the files of the lights already shot (image_006 held f_000's
    picture), recorded as lit by LEDs that never lit them, and the verdict then blamed dim
    or bright images. Which file belongs to which light is not known to the camera (metering
    shots and retries read files too), so nothing can say where to start again."""
    if not isinstance(device, dict):
        return None
    if device.get("kind") != "opencv" or device.get("backend") != "images":
        return None
    return (
        "its camera is an image sequence ([camera.device] backend = 'images', device = "
        f"{device.get('device')!r}), which every run reads from its first file again, so it "
        "cannot continue a session or reshoot single images: a resume would give the lights "
        "still to shoot the pictures of the lights already shot. Shoot the dry run again into "
        f"a new folder: rti-rig run {config} --out {out} (to rehearse on recorded images "
        "paired with their lights, a replay rig resumes: give run a recorded acquisition's "
        ".lp, its images beside it, as the rig)"
    )


def lost_image_advice(root: Path, adaptive: bool, scan: JournalScan | None = None) -> str:
    """What to do about images of a finished session lost since capture (the QA verdict and
    a refused resume say the same). ``scan``: the caller's scan of the journal, if it holds one
    (:func:`_journal_records`)."""
    copies, only_those = _copy_back(Path(root), scan)
    if copies and only_those:  # a replay's recorded files: the acquisition still holds them
        return f"copy {'it' if len(copies) == 1 else 'them'} back from the acquisition: " + (
            " && ".join(copies)
        )
    back = f"; copy the acquisition's back: {' && '.join(copies)}" if copies else ""
    return _lost_image_advice(root, adaptive, scan) + back


def _copy_back(root: Path, scan: JournalScan | None = None) -> tuple[list[str], bool]:
    """The ``cp`` commands (shell words) that put back the missing files of session ``root``
    that the acquisition still holds (:func:`held_by_acquisition`), and whether they are all
    that is lost. A file changed in the session is not copied over (the user's edit is
    theirs to set aside).

    Why: a replay session whose kept original was deleted was told "the camera's original
    capture is lost … reshoot with the object where it was": the acquisition holds it."""
    held = held_by_acquisition(root, scan)
    if not held:
        return [], False
    copies = [
        f"cp -- {shell_word(source)} {shell_word(str(Path(root) / name))}"
        for name, source in held.items()
    ]
    lost = files_lost_since_capture(root, scan)
    covered = all(all_held(gone, held) for gone in lost.values())
    return copies, covered


def all_held(gone: list[str], held: Mapping[str, str]) -> bool:
    """Whether every file of one image :func:`files_lost_since_capture` names (``gone``) is a
    copy its acquisition still holds (``held``, :func:`held_by_acquisition`): each is what
    :func:`_lost_files` says of a held file, matched whole. Why: the file's name had been
    parsed back out of those words (``rpartition(" ")``) in three places, the verdict, export-lp
    and the ``cp`` advice; one criterion, no parsing."""
    said = {f"{name} missing" for name in held}
    return bool(gone) and all(g in said for g in gone)


def held_by_acquisition(root: Path, scan: JournalScan | None = None) -> dict[str, str]:
    """Per file of session ``root`` missing since capture (its path in the session,
    ``raw/image_002.jpg``) that was copied from a file still there as captured
    (``StepRecord.copied_from``: a replay's recorded acquisition file, its checksum the
    journaled one), that file's path; in capture order.

    Why: the verdict and export-lp said of a replay's deleted copy "the camera's original
    capture is lost" beside the ``cp`` that puts it back; what is lost is the copy alone, and
    what they say of it is told from this one criterion, the one the ``cp`` advice uses."""
    records = _journal_records(Path(root), scan)
    if not records or not any(r.get("copied_from") for r in records):
        return {}
    held: dict[str, str] = {}
    renamed = renamed_jpegs(Path(root), records)
    moved = _acquisition_moved(Path(root))
    for rec in _latest_records(records).values():
        sources = rec.get("copied_from") or {}
        for name, how in _lost_entries(Path(root), rec, renamed):
            source = sources.get(name)
            if how != "missing" or not isinstance(source, str):
                continue
            for path in (Path(source), *([moved(Path(source))] if moved else [])):
                if path is not None and file_sha256(path) == rec["sha256"].get(name):
                    held[name] = str(path)
                    break
    return held


def _acquisition_moved(root: Path) -> Callable[[Path], Path | None] | None:
    """Where a replay session's recorded file (its path when copied) is now, if the
    acquisition was moved and the session resumed from the new place (``rig.config_path``, the
    ``.lp`` last run, in another folder than the one it began with); None otherwise.

    Why: the verdict of such a session said a deleted copy's "original capture is lost … put
    the originals back from a copy", its acquisition still holding the file under the new
    folder (the records keep each file's path at its capture)."""
    try:
        rig = read_manifest(root).get("rig") or {}
    except SessionError:
        return None
    dome = (rig.get("config") or {}).get("dome") or {}
    began, now = dome.get("lp_file"), rig.get("config_path")
    if not isinstance(began, str) or not isinstance(now, str) or not now.lower().endswith(".lp"):
        return None
    before, after = Path(began).parent, Path(now).parent
    if before == after:
        return None

    def moved(source: Path) -> Path | None:
        try:
            return after / source.relative_to(before)
        except ValueError:
            return None

    return moved


def _lost_image_advice(root: Path, adaptive: bool, scan: JournalScan | None) -> str:
    """:func:`lost_image_advice` for the files no acquisition holds."""
    instead = unresumable(root)
    if instead is not None:  # --reshoot-lost is refused for it
        return f"put the originals back from a copy; {instead}"
    if adaptive and _only_the_last_lost(root, scan):
        return (
            "put the originals back from a copy, or let its resume set the files aside and "
            "shoot the image again (no light was chosen from it yet), with the object where it "
            f"was: rti-rig run --resume {shell_word(str(root))}"
        )
    if adaptive:
        return (
            "put the originals back from a copy (an adaptive session cannot reshoot one image: "
            "the lights after it were chosen from it, and the session's estimate and stop from "
            "every image), or start a new session with another --out"
        )
    try:
        finished = (read_manifest(root).get("runner") or {}).get("finish_reason")
    except SessionError:
        finished = None
    if finished != "completed":
        # a session not finished (a --reshoot-lost killed part-way, say): --reshoot-lost is
        # refused for it, and its plain resume sets aside and shoots again what it cannot
        # verify (the advice had named --reshoot-lost, which then said to drop it)
        aside = _set_aside_as_captured(root, scan)
        where = (
            f" ({', '.join(aside[:4])}{' …' if len(aside) > 4 else ''} "
            f"{'is' if len(aside) == 1 else 'are'} as captured, set aside by a resume; any "
            "other from a copy)"
            if aside
            else " from a copy"
        )
        return (
            f"put the originals back{where}, or let its resume set them aside and shoot "
            f"them again, with the object where it was: rti-rig run --resume "
            f"{shell_word(str(root))}"
        )
    return (
        "put the originals back from a copy, or reshoot exactly those, with the object where "
        f"it was: rti-rig run --resume {shell_word(str(root))} --reshoot-lost"
    )


def _only_the_last_lost(root: Path, scan: JournalScan | None) -> bool:
    """Whether the one image lost since capture of session ``root``, not finished, is its
    last journaled one: a resume sets it aside and shoots it again, an adaptive session's
    too (no later light was chosen from it). Why: the verdict had told such a session that
    "an adaptive session cannot reshoot one image", of the one image its resume reshoots."""
    try:
        if (read_manifest(root).get("runner") or {}).get("finish_reason") == "completed":
            return False
    except SessionError:
        return False
    latest = _latest_records(_journal_records(root, scan) or [])
    if not latest:
        return False
    last = Path(latest[max(latest)]["image"]).stem
    return set(files_lost_since_capture(root, scan)) == {last}


def _set_aside_as_captured(root: Path, scan: JournalScan | None = None) -> list[str]:
    """The files of images lost since capture that a resume (a ``--reshoot-lost`` stopped
    part-way: a full disk, a kill) set aside in ``recovered/`` and that are still as captured
    (their journaled checksum): where to put them back from.

    Why: the verdict said only "put the originals back from a copy" of a session whose intact
    linear TIFF sat in recovered/, set aside by the resume a full disk then stopped."""
    records = _journal_records(root, scan)
    if not records:
        return []
    renamed = renamed_jpegs(root, records)
    found: list[str] = []
    for rec in _latest_records(records).values():
        if not _lost_files(root, rec, renamed):
            continue
        for name, digest in rec["sha256"].items():
            if _as_captured(root, rec, name, digest):
                continue
            for stamp in sorted((root / "recovered").glob("*"), reverse=True):  # latest first
                if (stamp / name).is_file() and _as_captured(stamp, rec, name, digest):
                    found.append((stamp / name).relative_to(root).as_posix())
                    break
    return found


def lost_since_capture_said(root: Path, manifest: dict[str, Any] | None = None) -> str | None:
    """``N image(s) lost since capture (image_003: image_003.jpg changed; …): <what gets them
    back>`` for session ``root`` once its journal says what was captured; None when nothing
    is lost. ``manifest``: the session's, when the caller holds it.

    Why: a completed session's rebuild that recorded an image as lost (its file changed, set
    aside) must not end with "the session is complete and whole again", and a rebuild refused
    as needless names what is lost all the same; both say it in these words."""
    root = Path(root)
    lost = files_lost_since_capture(root)
    if not lost:
        return None
    adaptive = bool((manifest if manifest is not None else read_manifest(root)).get("adaptive"))
    shown = "; ".join(f"{n}: {', '.join(g)}" for n, g in sorted(lost.items())[:8])
    more = " …" if len(lost) > 8 else ""
    return f"{len(lost)} image(s) lost since capture ({shown}{more}): " + lost_image_advice(
        root, adaptive
    )


def _lost_note(
    root: Path,
    latest: dict[int, dict[str, Any]],
    lost: dict[int, list[str]],
    adaptive: bool,
) -> str:
    """The images of a finished session lost since capture, and what to do about them."""
    if not lost:
        return ""
    shown = ", ".join(Path(latest[i]["image"]).stem for i in sorted(lost)[:5]) + (
        " …" if len(lost) > 5 else ""
    )
    return (
        f"; but {len(lost)} of its images {'is' if len(lost) == 1 else 'are'} missing or changed "
        f"since capture ({shown}): " + lost_image_advice(root, adaptive)
    )


def _unchecked_note(root: Path, unchecked: list[str], why: str, scan: JournalScan) -> str:
    """What a completed session's refused resume says of its images no journal record vouches
    for (:func:`unchecked_images`), and the mends.

    Why: a completed session whose journal (and step record files) had been deleted was told
    only "this session already completed all 24 steps", exit 2: no image named, no mend, where
    a stopped session in the same state names both."""
    shown = ", ".join(unchecked[:8]) + (" …" if len(unchecked) > 8 else "")
    return (
        f"; but {shown} cannot be checked against the checksums taken at capture ({why}): "
        f"restore {JOURNAL} from a backup copy of the folder, then run this again"
        + rebuild_advice(root, scan)
        + " (nothing in this folder was changed)"
    )


_JSON_KIND = {
    list: "array",
    str: "string",
    type(None): "null",
    bool: "boolean",
    int: "number",
    float: "number",
}


def _acquisition_lp_use(lp: Path) -> str:
    """What to do with an `.lp` outside any session (a recorded acquisition's, its images
    beside it): it is fitted and replayed as it is, with no session to export or resume."""
    q = shell_word(str(lp))
    # folders that do not exist yet beside it: ``--out DIR`` pasted made a folder named DIR
    fit_out = shell_word(str(free_name(lp.with_name(f"{lp.stem}-fit"), folder=True)))
    run_out = shell_word(str(free_name(lp.with_name(f"{lp.stem}-replay"), folder=True)))
    return (
        "if that is a recorded acquisition's .lp (its images beside it), use it as it is: "
        f"rti-rig fit {q} --out {fit_out}, or replay it as a rig: rti-rig run {q} --out "
        f"{run_out}"
    )


def read_manifest(root: Path) -> dict[str, Any]:
    """The manifest of a session folder, with a clear error if it is not one."""
    path = Path(root) / MANIFEST
    if not Path(root).exists():
        raise SessionError(
            f"{shown_path(root)} does not exist: give a session folder written by 'rti-rig run'"
        )
    if not Path(root).is_dir():
        if Path(root).suffix.lower() == ".lp" and not (Path(root).parent / MANIFEST).is_file():
            # a recorded acquisition's .lp had been told to give "the session folder that
            # holds it", which was then refused as "not an rti-rig session folder"
            raise SessionError(
                f"{shown_path(root)} is an .lp, not a session folder, and its folder is no session "
                f"either (no {MANIFEST}): {_acquisition_lp_use(Path(root))}"
            )
        raise SessionError(
            f"{shown_path(root)} is a file: give the session folder that holds it (the one with "
            f"{MANIFEST})"
        )
    # rti-rig writes the manifest atomically, so a damaged one was damaged outside it (a disk,
    # a sync tool, an editor): say what is still intact and what to do, never a traceback
    damaged = (
        f"; the images and {JOURNAL} do not depend on it and are untouched: restore {MANIFEST} "
        "from a backup copy of the folder"
    )
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        if (Path(root) / JOURNAL).is_file():
            # a session that lost its manifest (deleted, or left out of a copy): "not an rti-rig
            # session folder" had been said of a folder of its images and journal
            fit = (
                f", but its images can still be fitted: {fit_beside(root)}"
                if (Path(root) / LP_NAME).is_file()
                else ""
            )
            raise SessionError(
                f"{shown_path(root)} is a session folder without its {MANIFEST} (its {JOURNAL} is "
                f"there): restore {MANIFEST} from a backup copy of the folder; without it the "
                f"session cannot be resumed (its schedule and rig are recorded there){fit}"
            ) from None
        lps = lp_files_in(Path(root))
        held = (
            f"; it holds {lps[0].name}{' and more .lp files' if len(lps) > 1 else ''}: "
            + _acquisition_lp_use(lps[0])
            if lps
            else ""
        )
        raise SessionError(
            f"{shown_path(root)} has no {MANIFEST}: it is not an rti-rig session folder{held}"
        ) from None
    except IsADirectoryError:
        raise SessionError(
            f"{shown_path(path)} is a folder, not the session's manifest{damaged}"
        ) from None
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise SessionError(f"{shown_path(path)} is not valid JSON ({exc}){damaged}") from None
    except OSError as exc:
        raise SessionError(f"cannot read {shown_path(path)}: {exc.strerror or exc}") from None
    if not isinstance(data, dict):
        kind = _JSON_KIND.get(type(data), "value")
        raise SessionError(
            f"{shown_path(path)} is not a session manifest (it holds a JSON {kind}, not an "
            f"object){damaged}"
        )
    if data.get("format") != FORMAT:
        # "unknown session format None" had been all that was said of a manifest whose
        # "format" key was deleted or edited
        got = data.get("format")
        said = 'has no "format" key' if got is None else f"says format {json.dumps(got)}"
        newer = (
            " (a newer rti-rig's? then run this with that version)"
            if isinstance(got, str) and got.startswith("rti-rig-session/")
            else ""
        )
        raise SessionError(
            f'{shown_path(path)} {said}, not "{FORMAT}", the session format this rti-rig '
            f"reads{newer}{damaged}"
        )
    problem = _adaptive_table_problem(data)
    if problem:
        raise SessionError(f"{shown_path(path)} {problem}{damaged}")
    return data


def _adaptive_table_problem(data: dict[str, Any]) -> str | None:
    """Why an adaptive session's manifest cannot say how many steps it may take (None: it
    can, or the session is not adaptive).

    Why: :func:`planned_steps` had fallen back on the schedule's 4 starting lights where the
    ``adaptive`` table or its ``max_lights`` was removed, null or edited, and a resume then set
    every later image aside as "outside the schedule" (or crashed on a null), before anything
    was refused: a manifest edited by hand or damaged by a sync moved captured images."""
    schedule = data.get("schedule")
    method = schedule.get("method") if isinstance(schedule, dict) else None
    if "adaptive" not in data:
        if method == "adaptive":
            return (
                'has no "adaptive" table of settings, though its schedule\'s method is '
                '"adaptive": it cannot say how many lights the session may take'
            )
        return None
    table = data["adaptive"]
    if not isinstance(table, dict):
        return f'holds "adaptive": {json.dumps(table)}, not the adaptive session\'s settings'
    most = table.get("max_lights")
    steps = schedule.get("steps") if isinstance(schedule, dict) else None
    start = len(steps) if isinstance(steps, list) else 0
    if not isinstance(most, int) or isinstance(most, bool) or most < max(start, 1):
        said = (
            "has no max_lights"
            if "max_lights" not in table
            else (f"says max_lights {json.dumps(most)}")
        )
        return (
            f'{said} in its "adaptive" settings, not a number of lights of at least its '
            f"schedule's {start} starting lights"
        )
    return None


def _lost_files(
    root: Path, rec: dict[str, Any], renamed: Mapping[str, str] | None = None
) -> list[str]:
    """:func:`_lost_entries` as the words the verdict, a resume and ``--reshoot-lost`` say
    (``raw/image_002.jpg missing``)."""
    return [f"{name} {how}" for name, how in _lost_entries(root, rec, renamed)]


def _lost_entries(
    root: Path, rec: dict[str, Any], renamed: Mapping[str, str] | None = None
) -> list[tuple[str, str]]:
    """The image files of one journaled step gone or changed since capture: its JPEG (what
    relight and RTIBuilder read) and its linear TIFF (what ``fit`` reads) against their
    journaled checksums. A TIFF whose bytes differ but whose pixels match the journaled pixel
    checksum was re-saved by another tool (a tag added, recompressed), not changed: what a fit
    reads is as captured. A session journaled before pixel checksums has only the bytes', so
    there any difference counts (:func:`tiff_check_note` says so). A kept camera original
    (``raw/…``) that is gone is lost too: the RAW is the original capture (the JPEG and TIFF
    are developed from it), and a resume and ``--rebuild-journal`` already called a step
    without it unproven, while this called it "no reason to reshoot" (its developed images
    may still be fitted: :func:`originals_lost` tells them apart). One that is there but
    changed (a raw editor that writes its metadata into the DNG, a copy over it) is lost
    alike: the captured original is no longer there. Why: it had been "good" in the verdict
    (restore it from a backup, no reshoot) and "nothing to reshoot" to ``--reshoot-lost``,
    while a resume of a session not finished set its step aside and shot it again and a
    completed session's ``--rebuild-journal`` recorded it as lost. A JPEG in ``renamed``
    (:func:`renamed_jpegs`) is not lost: it is there, under another name."""
    lost = []
    for name, digest in rec["sha256"].items():
        path = root / name
        if name not in (rec.get("image"), rec.get("linear_image")):  # a camera original
            if not path.is_file():
                lost.append((name, "missing"))
            elif not _as_captured(root, rec, name, digest):
                lost.append((name, "changed"))
            continue
        if not path.is_file():
            if renamed and name in renamed:
                continue
            lost.append((name, "missing"))
        elif not _as_captured(root, rec, name, digest):
            lost.append((name, "changed"))
    return lost


def checksum_session_files(
    root: Path, stop: Callable[[], bool] | None = None, read_by_caller: Collection[Path] = ()
) -> None:
    """Read and checksum the files of every journaled step of session ``root`` (nothing for a
    folder that is no session), so that :func:`files_lost_since_capture` finds
    their checksums known
    (:data:`_KNOWN_DIGESTS`) unless they change meanwhile.

    Why: checking every TIFF reads the whole session once more (14 GB for 100 images of
    24 MP); a fit runs this alongside its own work rather than after it. ``stop`` is asked
    between files (a fit that failed or was interrupted does not wait for the rest).
    ``read_by_caller``: linear TIFFs the caller reads whole itself, taking their pixel checksum on
    the way (:func:`remember_pixel_digest`): not read here too (24 MP TIFFs had been read twice
    by a fit, once to fit and once to checksum)."""
    root = Path(root)
    skipped = {Path(p).resolve() for p in read_by_caller}
    if root.suffix.lower() == ".lp" and root.is_file():  # an .lp of the session given for it
        root = root.parent
    records = _journal_records(root)
    for rec in _latest_records(records or []).values():
        pixels = rec.get("pixels_sha256") or {}
        for name in rec["sha256"]:  # the step's JPEG, linear TIFF and kept originals
            if stop is not None and stop():
                return
            if pixels.get(name) and (root / name).resolve() in skipped:
                continue  # its pixel checksum is taken as the caller reads it
            file_sha256(root / name)


def tiff_check_note(root: Path) -> str:
    """What to say, once, of a session journaled before linear TIFFs had pixel checksums:
    their bytes are checked, so a TIFF re-saved by another tool with unchanged pixels is
    named as changed (empty for a newer session, or a folder that is no session)."""
    records = _journal_records(Path(root))
    if not records:
        return ""
    if all((r.get("pixels_sha256") or {}).get(r["linear_image"]) for r in records):
        return ""
    return (
        f"{JOURNAL} predates pixel checksums (rti-rig before 2026-11-29): each linear TIFF is "
        "checked by its bytes alone, so one re-saved by another tool with the same pixels is "
        "named as changed too; compare it with a backup copy before reshooting it"
    )


def files_lost_since_capture(root: Path, scan: JournalScan | None = None) -> dict[str, list[str]]:
    """Per image (its base name, ``image_010``) of a session, its JPEG or linear TIFF gone or
    changed since capture, or its kept camera original gone (:func:`_lost_files`): what the
    QA verdict names and what ``run --resume --reshoot-lost`` reshoots, one criterion for
    both. A JPEG that is in the folder under another name (:func:`renamed_jpegs`) is not
    lost. Empty for a folder without a journal (an ``.lp`` acquisition is no session).
    ``scan``: the caller's scan of the journal, if it holds one (:func:`_journal_records`)."""
    root = Path(root)
    records = _journal_records(root, scan)
    if records is None:
        return {}
    lost: dict[str, list[str]] = {}
    renamed = renamed_jpegs(root, records)
    for rec in _latest_records(records).values():
        gone = _lost_files(root, rec, renamed)
        if gone:
            lost[Path(rec["image"]).stem] = gone
    return lost


def originals_lost(gone: list[str]) -> bool:
    """Whether the files of one image :func:`_lost_files` names (``gone``) are all kept camera
    originals (``raw/…``): the original capture is lost, yet the developed JPEG and linear
    TIFF are as captured, so a fit still used them (said, with the reshoot that gets the
    original back)."""
    return bool(gone) and all(g.startswith(f"{RAW_DIR}/") for g in gone)


def renamed_since_capture(root: Path, scan: JournalScan | None = None) -> dict[str, str]:
    """:func:`renamed_jpegs` of session ``root`` from its journal (empty for a folder that is
    no session, as :func:`files_lost_since_capture`; ``scan`` as there)."""
    root = Path(root)
    records = _journal_records(root, scan)
    return {} if records is None else renamed_jpegs(root, records)


def _journal_records(root: Path, scan: JournalScan | None = None) -> list[dict[str, Any]] | None:
    """The journal's records of session ``root``, or None for a folder that is no session (no
    journal or manifest, or a manifest that cannot be read). ``scan``: the caller's
    :func:`scan_journal` of it (with the schedule's image names), taken instead of reading the
    journal again (export-lp had read it three times, each time checking any record file the
    journal lacks against its images)."""
    if not (root / JOURNAL).is_file() or not (root / MANIFEST).is_file():
        return None
    if scan is not None:
        return scan.records
    try:
        total = planned_steps(read_manifest(root))
    except SessionError:
        return None
    return scan_journal(root, image_names(total) if total else None).records


def journaled_checksums(root: Path) -> dict[str, tuple[str, str | None]] | None:
    """The sha256 the journal of session ``root`` holds for each file of its steps, from each
    step's latest record, with its pixels' checksum for a linear TIFF (``{"linear/image_003.tif":
    (digest, pixels digest), "image_003.jpg": (digest, None), …}``), or None for a folder that
    is no session. Nothing is hashed: these are the checksums taken at capture.

    Why: a batch fit tells whether a session changed since its earlier fit by them; file sizes
    and modification times had called a session copied without its timestamps (plain ``cp``,
    rsync without ``-t``) changed in every image, and refitted a whole backlog."""
    records = _journal_records(Path(root))
    if records is None:
        return None
    sums: dict[str, tuple[str, str | None]] = {}
    for rec in _latest_records(records).values():
        pixels = rec.get("pixels_sha256") or {}
        for name, digest in rec["sha256"].items():
            got = pixels.get(name)
            sums[str(name)] = (str(digest), None if got is None else str(got))
    return sums


def unchecked_images(
    root: Path, scan: JournalScan | None = None, manifest: dict[str, Any] | None = None
) -> tuple[list[str], str]:
    """Images of a session (on disk, or taken by a session that completed) that no readable
    journal record vouches for, and why.

    The journal holds the checksums taken at capture; an image without a readable record (the
    journal gone, a line damaged, a last line cut short) cannot be checked, and a verdict that
    said "good" without saying so claimed what it had not established. Returns the image base
    names (``image_006``) and the reason; ``([], "")`` for a folder that is no session, or whose
    journal vouches for every image on disk. The image a session stopped while saving
    (:func:`stopped_while_committing`) is not among them: no record of it was ever lost.
    ``scan`` and ``manifest``: the caller's, read once (:func:`_journal_records`)."""
    root = Path(root)
    if manifest is None and not (root / MANIFEST).exists():
        return [], ""
    present = {
        p.stem
        for folder in (root, root / LINEAR_DIR)
        for p in folder.glob("image_*")
        if p.is_file()
    }
    if manifest is None:
        try:
            manifest = read_manifest(root)
        except SessionError:
            # the journal's records can be matched to image names only through the manifest
            return sorted(present), f"{MANIFEST} unreadable"
    total = planned_steps(manifest)
    if not total:
        return [], ""
    names = image_names(total)
    if scan is None:
        scan = scan_journal(root, names)
    recorded = {Path(r["image"]).stem for r in scan.records}
    expected = set(present)
    runner = manifest.get("runner") or {}
    if runner.get("finish_reason") == "completed":  # every step it took was captured
        expected |= set(names[: int(runner.get("steps_done") or total)])
    unchecked = [n for n in names if n in expected and n not in recorded]
    stopped = _stopped_while_committing(manifest, scan.records, names, unchecked)
    unchecked = [n for n in unchecked if n != stopped]
    if not unchecked:
        return [], ""
    if not (root / JOURNAL).is_file():
        why = f"{JOURNAL} is missing"
    else:
        parts = []
        if scan.rejected:
            lines = ", ".join(str(n) for n, _, _ in scan.rejected)
            parts.append(
                f"{JOURNAL} line{'s' if len(scan.rejected) > 1 else ''} {lines} unreadable"
            )
        if scan.torn.strip():
            parts.append(f"the last line of {JOURNAL} was cut short")
        why = "; ".join(parts) or f"no record of them in {JOURNAL}"
    return unchecked, why


def journal_mend_note(root: Path) -> str | None:
    """What to say of the images whose journal line is lost or damaged but whose step record
    file (``records/BASE.json``) proves them as captured: checked against that file, and the
    command that writes their records back into the journal. None when there are none.

    Why: those images are checked (a verdict may call them good), yet the journal is damaged;
    said, with the mend, so a copy of the folder is not taken for whole as it is."""
    root = Path(root)
    try:
        manifest = read_manifest(root)
    except SessionError:
        return None
    total = planned_steps(manifest)
    if not total:
        return None
    scan = scan_journal(root, image_names(total))
    if not scan.mended:
        return None
    completed = (manifest.get("runner") or {}).get("finish_reason") == "completed"
    # not damage ("damaged (records missing)" had been said of it), unless the run completed:
    # then it journaled every step, and a line missing now was lost after (said as "the run
    # stopped", with a plain resume as the mend, which refuses a completed session)
    unwritten = None if completed else stopped_before_journal_line(scan)
    if unwritten is not None:
        return _unwritten_line_note(root, unwritten)
    stems = [Path(rel).stem for rel in scan.mended]
    parts = []
    if scan.rejected:
        lines = ", ".join(str(n) for n, _, _ in scan.rejected)
        parts.append(f"line{'s' if len(scan.rejected) > 1 else ''} {lines} unreadable")
    if scan.torn.strip():
        parts.append("its last line cut short")
    why = ", ".join(parts) or "records missing"
    state = "is missing, so it" if scan.missing else f"is damaged ({why}) and"
    mend = f"rti-rig run --resume {shell_word(str(root))}" + (
        " --rebuild-journal" if completed else ""
    )
    one = len(stems) == 1
    shown = ", ".join(stems[:8]) + (" …" if len(stems) > 8 else "")
    # an unfinished session's resume captures the images still to take as well (lights on,
    # an arm moving): said, so a user who wants only the journal mended is not surprised
    left = total - len({int(r["index"]) for r in scan.records})
    also = (
        f", and goes on to capture the {left} image{'s' if left != 1 else ''} still to take"
        if not completed and left > 0
        else ""
    )
    return (
        f"{JOURNAL} {state} holds no record of {shown}: "
        f"{'it was' if one else 'they were'} checked against {'its' if one else 'their'} "
        f"step record file{'' if one else 's'} ({RECORDS_DIR}/) instead, as captured; "
        f"{mend} writes {'it' if one else 'them'} back into {JOURNAL}{also}"
    )


def _unwritten_line_note(root: Path, stem: str) -> str:
    """What fit's verdict says of ``stem``, committed by its record file, whose journal line
    the run never wrote (:func:`stopped_before_journal_line`): where it stopped, whether the
    fit could use the image (only if ``lights.lp`` lists it), and the command that mends it."""
    from rti_rig.core.errors import RtiRigError
    from rti_rig.core.lp_format import read_lp

    try:
        listed = f"{stem}.jpg" in {e.name for e in read_lp(root / LP_NAME)}
    except (RtiRigError, OSError, ValueError):
        listed = False
    fitted = "" if listed else f" (kept, but not yet in {LP_NAME}, so not fitted)"
    return (
        f"the run stopped after {stem}'s record file, before its journal line{fitted}; "
        f"rti-rig run --resume {shell_word(str(root))} writes it back"
    )


def unwritten_step(
    root: Path, scan: JournalScan | None = None
) -> tuple[list[LpEntry], LpEntry, str] | None:
    """What :func:`list_unwritten_step` would complete, without writing anything: the
    ``lights.lp`` entries the run wrote at its previous commit, the entry of the step it
    committed by the record file and stopped before journaling, and that step's stem; None
    when there is nothing to complete (or ``lights.lp`` is not exactly the run's own listing).

    Why: ``fit`` reads the completed listing before it may write anything, and completes the
    file itself only once all its refusals have passed (it had rewritten ``lights.lp`` of a
    session it then refused, a disowned one included)."""
    root = Path(root)
    path = root / LP_NAME
    if not (root / JOURNAL).is_file() or not path.is_file():
        return None
    if scan is None:
        try:
            total = planned_steps(read_manifest(root))
            if not total:
                return None
            scan = scan_journal(root, image_names(total))
        except SessionError:
            return None
    stem = stopped_before_journal_line(scan)
    if stem is None or scan.missing:
        return None
    *journaled, last = scan.records
    earlier = [_to_record(r) for _, r in sorted(_latest_records(journaled).items())]
    before = [LpEntry(r.image, r.actual_direction) for r in earlier]
    unwritten = _to_record(last)
    try:
        if path.read_bytes() != format_lp(before).encode("ascii"):
            return None  # not the run's own listing: edited since, or behind otherwise
    except OSError:
        return None
    return before, LpEntry(unwritten.image, unwritten.actual_direction), stem


def list_unwritten_step(root: Path, scan: JournalScan | None = None) -> str | None:
    """Make session ``root``'s ``lights.lp`` list the step its run committed by the record file
    and stopped before journaling (:func:`stopped_before_journal_line`), when ``lights.lp`` is
    exactly what that run wrote at its previous commit; returns what was done or why it could
    not be (None when there was nothing to do). ``scan``: the journal's, when the caller holds
    it (read here otherwise); it only spares the lock when there is nothing to do, the decision
    to write is taken again under the lock from the journal re-read. Call it only once the
    command's own refusals have passed.

    Why: a run writes ``lights.lp`` after the journal line, so a kill between the record file
    and the line left it one image short of what the session holds: ``export-lp`` (and a
    resume, which keeps the image) listed it, ``fit`` fitted one image fewer, and relight and
    RTIBuilder, which read ``lights.lp``, left it out. The rewrite is atomic, under the
    session's lock, and only completes the run's own listing with the line the run was about
    to write: a ``lights.lp`` edited by hand, or behind for any other reason, is left as it is
    (the verdict names it). A session stopped before its first journal line has no
    ``lights.lp`` to complete (``fit`` says so; the resume writes one). A disowned session
    (:data:`rti_rig.runtime.disowned.MARKER`) is never rewritten: nothing in it is used."""
    root = Path(root)
    if (root / DISOWNED_MARKER).exists():
        return None
    path = root / LP_NAME
    if unwritten_step(root, scan) is None:
        return None
    held = str(root.resolve()) in _LOCKED
    try:
        lock_session(root)  # a run or resume begun since: its lights.lp is its own
    except SessionError:
        return None
    try:
        # again, under the lock, from the journal and lights.lp as they are now: ``scan`` was
        # taken before the lock, and a resume that ran in between may have journaled the step
        # (and written its own lights.lp), which a stale decision would have overwritten
        pending = unwritten_step(root)
        if pending is None:
            return None
        before, entry, stem = pending
        try:
            write_lp_atomic(path, [*before, entry])
        except SessionWriteError as exc:
            return (
                f"the run stopped after {stem}'s record file, before its journal line and "
                f"before {LP_NAME} listed it; {LP_NAME} could not be rewritten to list it ({exc}) "
                f"and still lacks {stem}; rti-rig run --resume {shell_word(str(root))} lists "
                "it, once the folder can be written"
            )
    finally:
        if not held:
            unlock_session(root)
    # nothing more is claimed: an image the session once held may be gone since (the export
    # says so), so "lists the N images the session holds" had been untrue of it
    return (
        f"{LP_NAME} now lists {stem} too (rewritten atomically, nothing else changed): the run "
        f"committed {stem} by its record file and stopped before its journal line and before "
        f"{LP_NAME} listed it"
    )


def _stopped_while_committing(
    manifest: dict[str, Any],
    records: list[dict[str, Any]],
    names: list[str],
    unrecorded: list[str],
) -> str | None:
    """The image of ``unrecorded`` (on disk, no journal record) that a session stopped while
    committing, or None.

    A session killed (or powered off) after an image's files were written and before its
    journal line leaves that one image on disk unjournaled: the step right after the last one
    recorded, in a session that did not complete. It was never part of the session (its
    lights.lp does not list it, a fit leaves it out, a resume sets it aside and shoots it
    again); nothing is lost from the journal, whose restoring from a backup the verdict had
    advised. Two or more such images past the last record, or one further on, are what a
    damaged journal leaves (and so is an unrecorded image before it)."""
    if (manifest.get("runner") or {}).get("finish_reason") == "completed":
        return None
    last = max((int(r["index"]) for r in records), default=-1)
    beyond = [n for n in unrecorded if names.index(n) > last]
    # none beyond the last record: every step is recorded (a completed session whose
    # --reshoot-lost was killed while saving the image it shot again, its step recorded by the
    # capture it replaces), and fit and export-lp had died on an IndexError
    if not beyond or beyond != names[last + 1 : last + 2]:
        return None
    # a step the manifest records was committed (only a run's end writes them there): its
    # journal line was lost since, not cut by a stop, and the verdict had said "neither its
    # files nor its light were ever recorded as captured" of an image the manifest vouches for
    if last + 1 in _manifest_records(manifest, names):
        return None
    return beyond[0]


def stopped_while_committing(root: Path) -> str | None:
    """:func:`_stopped_while_committing` of session ``root`` (None for a folder that is no
    session, or whose manifest cannot be read)."""
    root = Path(root)
    if not (root / MANIFEST).is_file():
        return None
    try:
        manifest = read_manifest(root)
    except SessionError:
        return None
    total = planned_steps(manifest)
    if not total:
        return None
    names = image_names(total)
    present = {
        p.stem
        for folder in (root, root / LINEAR_DIR)
        for p in folder.glob("image_*")
        if p.is_file()
    }
    records = scan_journal(root, names).records
    recorded = {Path(r["image"]).stem for r in records}
    unrecorded = [n for n in names if n in present and n not in recorded]
    return _stopped_while_committing(manifest, records, names, unrecorded)


def journal_rig_time(root: Path) -> float:
    """The rig time a session's journal accounts for (:func:`rig_time_of_records`): a lower
    bound of the session's time that a run killed outright (which recorded no time of its own)
    still counts in."""
    return rig_time_of_records(scan_journal(Path(root)).records)


def rig_time_of_records(records: list[dict[str, Any]]) -> float:
    """Each run's last image's start on that run's clock plus its light, settle and capture,
    summed over runs (pure). A run's clock starts at 0 with its first image, so a start that
    does not grow marks the next run."""
    total, last_start, last_end = 0.0, -1.0, 0.0
    for rec in records:
        try:
            start = float(rec["rig_start_s"])
            parts = ("light_s", "settle_s", "capture_s")
            end = start + sum(float(rec.get(k) or 0.0) for k in parts)
        except (KeyError, TypeError, ValueError):
            continue
        if start <= last_start:  # the next run's clock (its first image starts at 0.0)
            total += last_end
        last_start, last_end = start, end
    return total + last_end


def _latest_records(records: list[dict[str, Any]]) -> dict[int, dict[str, Any]]:
    """Each step's last journal record (a later record of a step replaces an earlier one)."""
    return {rec["index"]: rec for rec in records}


def renamed_jpegs(
    root: Path, records: list[dict[str, Any]], only: str | None = None
) -> dict[str, str]:
    """The session's JPEGs and linear TIFFs missing under their journaled names that are in
    their folder under another name with the same bytes: ``{journaled name: name found}``
    (both relative to the session, ``linear/image_003.tif`` → ``linear/coin17_003.tif``).

    Why: a folder whose images were renamed one by one (``coin17_001.jpg`` for
    ``image_001.jpg``, a collection's own numbering) had every image called missing: ``fit``'s
    verdict advised reshooting them all, ``--reshoot-lost`` would have, and ``export-lp``
    found "none of the 12 journaled image(s) on disk", of files that were all there; the
    TIFFs renamed the same way in ``linear/`` were still called missing, and reshot. Only the
    files of a folder that no journal record names are read, and only when a journaled file of
    that folder is missing: a session as written, or one that lost a file, costs no hashing.
    ``only`` (``"image"`` or ``"linear_image"``) looks for that kind of file alone.
    """
    root = Path(root)
    found: dict[str, str] = {}
    kinds = (("image", "", (".jpg", ".jpeg")), ("linear_image", LINEAR_DIR, (".tif", ".tiff")))
    for key, sub, suffixes in kinds:
        if only is not None and key != only:
            continue
        wanted: dict[str, str] = {}  # checksum -> journaled name, of the files not on disk
        for rec in _latest_records(records).values():
            name = rec.get(key)
            digest = rec["sha256"].get(name) if name else None
            if digest and not (root / name).is_file():
                wanted.setdefault(digest, name)
        if not wanted:
            continue
        journaled = {rec.get(key) for rec in records}
        folder = root / sub if sub else root
        try:
            candidates = sorted(folder.iterdir())
        except OSError:
            continue
        for path in candidates:
            rel = path.relative_to(root).as_posix()
            if (
                path.suffix.lower() not in suffixes
                or rel in journaled
                or path.name.startswith(".")
                or not path.is_file()
            ):
                continue
            name = wanted.get(file_sha256(path) or "")
            if name is not None and name not in found:
                found[name] = rel
    return found


def renamed_note(renamed: Mapping[str, str]) -> str:
    """What to say of :func:`renamed_jpegs`: which file is which, and what to do."""
    if not renamed:
        return ""
    pairs = [f"{name} as {there}" for name, there in sorted(renamed.items())]
    shown = ", ".join(pairs[:5]) + (f" and {len(pairs) - 5} more" if len(pairs) > 5 else "")
    one = len(pairs) == 1
    return (
        f"{shown} {'is' if one else 'are'} in the folder under another name, the same bytes "
        f"as captured: give {'it' if one else 'them'} back {'its' if one else 'their'} "
        f"session name{'' if one else 's'} ({LP_NAME}, RTIBuilder and rti-rig find the images "
        f"by those names); {'it needs' if one else 'they need'} no reshooting"
    )


def session_lp_report(
    root: Path,
    linear: bool = False,
    scan: JournalScan | None = None,
    manifest: dict[str, Any] | None = None,
) -> tuple[list[LpEntry], list[str]]:
    """`.lp` entries of a session from its verified journal, and the images left out.

    Works on a finished session and on an interrupted or killed one alike: a step is listed when
    its journal record is well formed and the file the ``.lp`` names (the JPEG, or with
    ``linear`` the TIFF) is on disk with its journaled checksum, with the direction that
    actually ran. The second list names journaled files of that kind missing or changed since
    (left out): a damaged JPEG does not drop an intact TIFF from an ``.lp`` of TIFFs.
    ``scan`` and ``manifest``: the caller's (the scan with the schedule's image names), so
    that the journal is read once.
    """
    if manifest is None:
        manifest = read_manifest(root)
    total = planned_steps(manifest)  # an adaptive session's maximum, not its starting layout
    names = image_names(total) if total else None
    if scan is None:
        scan = scan_journal(root, names)
    records = scan.records
    key = "linear_image" if linear else "image"
    done = verified_steps(root, records, only=key)  # the file the .lp names, as captured
    if not records:
        if stopped_before_first_journal(root, scan) == UNRECORDED:
            instead = unresumable(root)
            raise SessionError(
                f"{shown_path(root)}: the session stopped before its first image was recorded in "
                f"its {JOURNAL}, so there is no .lp to export; "
                + (
                    instead
                    if instead is not None
                    else f"continue it with rti-rig run --resume {shell_word(str(root))} (a "
                    "first image's files left on disk without its record file are set aside in "
                    "recovered/ and shot again)"
                )
            )
        if not (Path(root) / JOURNAL).is_file():
            raise SessionError(
                f"{shown_path(root)}: {JOURNAL} is missing, so no image can be verified as "
                f"captured with its light: restore {JOURNAL} from a backup copy of the folder"
                + rebuild_advice(root, scan)
            )
        raise SessionError(
            f"{shown_path(root)}: the session recorded no images, so there is no .lp to export"
        )
    left_out = sorted({r[key] for r in records if r["index"] not in done})
    if not done:
        renamed = renamed_jpegs(root, records, only=key)  # of the kind of file the .lp lists
        raise SessionError(
            f"{shown_path(root)}: none of the {len(left_out)} journaled image(s) is on disk as "
            "captured (missing or changed), so there is no .lp to export"
            + (f"; {renamed_note(renamed)}" if renamed else "")
        )
    entries = [LpEntry(getattr(done[i], key), done[i].actual_direction) for i in sorted(done)]
    return entries, left_out
