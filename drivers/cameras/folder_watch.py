"""A camera fired by someone else: wait for its next file in a folder, with a timeout.

Why: many domes wire the camera's remote-shutter line to the dome controller, and some cameras
are only driven by their vendor's tethering program. rti-rig then cannot *take* a picture, only
*notice* it: the file that appears after the light was switched on is that light's frame.
Files present at ``connect`` are ignored; each file is used once; a file counts only when its
size has stopped changing (the writer may still be copying it). Optionally an injected
``trigger(exposure_s)`` fires the shutter (e.g. the dome driver's shutter-line command).

"Used once" is by the file, not only by its name: many tethering programs save under one name
and rename afterwards (``capt0000.CR2`` → ``IMG_0001.CR2``, or a hidden ``.IMG_0001.CR2``
temporary → ``IMG_0001.CR2``). A rename keeps the file's device, inode, size and modification
time, so a file with the identity of one already seen is not a new shot; taken by name alone it
had been the *next* light's image, every later image one light off. Hidden files (a leading
dot) are the temporaries of such programs and of sync tools (rsync's ``.name.XXXXXX``), never a
finished shot, and are not looked at. With a trigger, a file already there when the shutter is
pulsed (a duplicate, a test shot, an extra frame of the last pulse) is set aside and named in the
frame's notices, never taken as the pulse's picture.

One shot may give two files (a camera set to RAW+JPEG: ``IMG_0001.CR2`` and ``IMG_0001.JPG``).
When both match ``patterns``, the RAW is the shot's image and a file with the stem of a file
already taken is never another shot (it had been the next light's image, the lights one off
from there on).

The LED need not wait for the file: with a trigger it goes off ``shutter_lag_s`` plus the
exposure after the pulse (see ``expose``), without one once the file has come; the transfer and
the decode then happen in the dark. Held lit until the image was in hand, a RAW arriving over
Wi-Fi 9 s after the pulse ran into the dome's ``max_on_s`` = 8 s and the good shot was lost.

With a trigger, a file's own capture time (a RAW's LibRaw timestamp: EXIF DateTimeOriginal or
the TIFF DateTime; a TIFF's or JPEG's EXIF DateTimeOriginal; whole seconds on the camera's clock) is
checked against the pulses: the first
image after ``connect`` anchors the camera clock to its pulse, and each later file must have
been shot as long after the last image as its pulse came after that image's pulse, within
:data:`CAPTURE_TIME_RESOLUTION_S` plus ``shutter_lag_s``. A file out of step (a pulse's file
that came after the run had stopped at the timeout and was resumed, or a second frame) is set
aside in ``strays/`` and the pulse's own file waited for; one that fits the set-aside file as
the next pulse's proves the last image was a late file of an earlier pulse, said in a notice.
Only differences of the camera clock are used (its offset, time zone and setting are free; its
drift over a session is taken as negligible). The first image after a resume is checked against
the camera clock an earlier run learned against the computer's wall clock (kept in the
session, :class:`_LearnedClock`): a file shot before the resume connected is set aside. What
this cannot check: the first image of a new session (no clock learned yet), and files without
a capture time (PNG, a TIFF or RAW without one), which say so in a notice.

Once the rig is bound to a session, a taken file is copied into the session's
``raw/.incoming`` before it is decoded, and that copy is decoded and kept: the folder belongs
to another program, which may move its files out (an auto import) or rename them meanwhile.

Safe state: nothing to release (no device handle); ``close`` forgets the seen files.
"""

from __future__ import annotations

import contextlib
import errno
import hashlib
import json
import os
import shutil
import socket
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np

from rti_rig.core.clock import Clock, SystemClock
from rti_rig.core.devices import Frame
from rti_rig.core.errors import CaptureError, DeviceError
from rti_rig.core.image_files import (
    CAMERA_RAW_SUFFIXES,
    PNG_ALPHA_TYPES,
    TIFF_MAGIC,
    image_number,
    is_camera_raw,
    png_colour_type,
    tiff_extent,
)
from rti_rig.core.shell_words import shown_path
from rti_rig.drivers.cameras.colour_convert import (
    clipped_notice,
    converted_notice,
    needs_conversion,
    to_linear_srgb,
)
from rti_rig.drivers.cameras.dng_tags import IfdState, ifd_state
from rti_rig.drivers.cameras.exif_tags import (
    jpeg_datetime_original,
    jpeg_orientation,
    tiff_orientation,
)
from rti_rig.drivers.cameras.file_colour import file_colour, file_colour_notice
from rti_rig.drivers.cameras.image_io import (
    ImageReadError,
    read_image_file,
    tiff_extra_samples,
    to_linear_uint16,
)
from rti_rig.drivers.cameras.raw_decode import (
    DECODER,
    ORIENTATION_NAMES,
    DamagedRawError,
    MonochromeRawError,
    RawDecodeError,
    RawFileMissingError,
    UnsupportedRawError,
    decode_raw,
    exposure_stats,
    libraw_opened,
    libraw_printed,
    orientation_words,
)
from rti_rig.drivers.cameras.resume_words import resume_command
from rti_rig.drivers.cameras.settings import FolderWatchSettings
from rti_rig.drivers.cameras.tiff_structure import (
    COMPLETE_TIFF_ADVICE,
    SAVE_AGAIN,
    SAVE_READABLE,
    first_ifd,
    ifd_garbage,
)

#: the core's one list of camera RAW endings (the replay check refuses the same files)
RAW_SUFFIXES = CAMERA_RAW_SUFFIXES

#: A capture time's resolution: EXIF DateTimeOriginal is whole seconds, and LibRaw's timestamp
#: (rawpy's ``other.timestamp``) keeps no SubSecTimeOriginal; a difference of two such times is
#: off by less than this
CAPTURE_TIME_RESOLUTION_S = 1.0
#: files out of step with the pulses set aside for one pulse before the run is stopped
MAX_OUT_OF_STEP = 3

#: TIFF names: their capture time is read with tifffile (EXIF DateTimeOriginal)
TIFF_SUFFIXES = {".tif", ".tiff"}

#: 8-bit formats a camera saves beside its RAW (RAW+JPEG): never a linear image
JPEG_SUFFIXES = {".jpg", ".jpeg"}


#: how fast a camera's clock may drift from the computer's, as a fraction of the time between
#: the run that learned it and a resume (100 ppm: quartz clocks keep within a few tens, and
#: this leaves room for the computer's own time corrections)
CLOCK_DRIFT = 1e-4
#: where a session keeps the camera clock learned (in its ``raw/``, beside ``.incoming``)
CLOCK_FILE = ".folder_watch_clock.json"

#: said for a file whose capture time cannot be read (one constant text: the session summary
#: counts the images it concerns)
NO_CAPTURE_TIME = (
    "the watched folder's file holds no capture time (no EXIF DateTimeOriginal: a PNG, or a "
    "JPEG, TIFF or RAW saved without it), so it was not checked against the shutter pulses: a late "
    "or extra file in the folder would have been taken as this light's image unseen"
)


@dataclass(frozen=True)
class _LearnedClock:
    """The camera's clock against the computer's wall clock, learned from an image in step
    with its pulse: ``offset_s`` = capture time − the pulse's wall time, at ``wall_s``, the
    pulse dated within ``window_s``. Kept in the session so a resume can check its first file.

    Why: within a run, each file is checked against the image before it; the first image
    after a connect had nothing to be checked against, so a file shot before a resume (the
    late file of the pulse the stopped run waited for) was taken as the resumed light's
    image."""

    offset_s: float
    wall_s: float
    window_s: float
    #: the pulse on the computer's monotonic clock, which no NTP step or clock setting moves
    #: (None: not known, a clock file of an older version or a rig clock that is not it)
    mono_s: float | None = None
    #: the computer and boot it was learned on (:func:`computer_id`): the monotonic clock
    #: holds only within one boot of one computer
    computer: str | None = None

    @classmethod
    def load(cls, path: Path | None) -> _LearnedClock | None:
        """The clock kept at ``path``; None when there is none or it cannot be read (the
        first file is then unchecked, as in a new session)."""
        if path is None:
            return None
        try:
            data = json.loads(path.read_text(encoding="utf-8"))
            mono = data.get("mono_s")
            return cls(
                float(data["offset_s"]),
                float(data["wall_s"]),
                float(data["window_s"]),
                None if mono is None else float(mono),
                None if data.get("computer") is None else str(data["computer"]),
            )
        except (OSError, ValueError, TypeError, KeyError, AttributeError):
            return None

    def save(self, path: Path) -> None:
        """Write atomically; a failure is left unsaid (a resume then checks less, no worse)."""
        tmp = path.with_name(f"{path.name}.partial")
        with contextlib.suppress(OSError):
            tmp.write_text(json.dumps(self.__dict__), encoding="utf-8")
            os.replace(tmp, path)


def computer_id() -> str:
    """This computer and its boot: a digest of the host name and, where the system says it
    (Linux), the boot id (a digest: the session, shared with others, names no host). Two runs
    with the same id share one monotonic clock."""
    try:
        boot = Path("/proc/sys/kernel/random/boot_id").read_text(encoding="ascii").strip()
    except OSError:
        boot = ""
    return hashlib.sha256(f"{socket.gethostname()} {boot}".encode()).hexdigest()[:16]


def since_boot() -> float:
    """The computer's clock since it booted, which no NTP step or clock setting moves and
    which counts a suspend: Linux's CLOCK_BOOTTIME; on macOS CLOCK_MONOTONIC, which Apple's
    clock_gettime(3) says "will continue to increment while the system is asleep"
    (``time.monotonic`` there is mach_absolute_time, which stops during sleep);
    ``time.monotonic`` elsewhere (Windows: whether it counts a sleep depends on the Python
    version, so it is not relied on). A suspend not counted would be taken for a wall clock
    set forward, and a late file of a run stopped before a laptop slept would pass for the
    resumed light's: :meth:`FolderWatchCamera._connect_on_learned_wall` therefore also
    checks this clock against the wall clock. A clock the system refuses (an old kernel, a
    sandbox: OSError) falls back to ``time.monotonic``."""
    which = (
        getattr(time, "CLOCK_MONOTONIC", None)
        if sys.platform == "darwin"
        else getattr(time, "CLOCK_BOOTTIME", None)
    )
    if which is not None:
        with contextlib.suppress(OSError):
            return time.clock_gettime(which)
    return time.monotonic()


#: how far this computer's wall clock may be from the one the camera clock was learned
#: against when nothing measures it (another computer, a restart, or a wall clock moved
#: ahead of the clock since boot by more): NTP keeps two computers within a second and a
#: hand-set clock within minutes, while a late file of a run stopped the day before is hours
#: older. A resume's first file shot more than this before the connect is refused.
WALL_ALLOWANCE_S = 600.0

#: the first image of a resume whose connect could be dated only by this computer's wall
#: clock: said, with what the check could not catch
RESUME_WALL_CHECKED = (
    "this run is on another computer, or the computer restarted (or its clock since boot "
    "disagrees with its wall clock), since the session's earlier run learned the camera "
    "clock: the first image was checked against this computer's clock only to within "
    f"{WALL_ALLOWANCE_S / 60:.0f} min, so a late file of the stopped run shot less than that "
    "before this run connected would not have been caught; the images after it are checked "
    "against it"
)


class TriggerUnconfirmed(Exception):
    """The trigger was sent but its confirmation was lost (e.g. the dome's reply to a shutter
    pulse timed out): the camera may well have fired. The pulse is never resent (that could
    take a second picture); the camera waits for the file, and only if none comes is it an
    error."""


def is_raw_file(path: Path) -> bool:
    """True for file names LibRaw should decode (by suffix)."""
    return is_camera_raw(path)


def _identity(path: Path) -> tuple[int, int, int, int] | None:
    """(device, inode, size, mtime in ns) of ``path``, or None if it is gone: what a rename
    keeps, so a used file that reappears under another name is recognised."""
    try:
        st = path.stat()
    except FileNotFoundError:
        return None
    return (st.st_dev, st.st_ino, st.st_size, st.st_mtime_ns)


def capture_time(path: Path) -> float | None:
    """The capture time of ``path``, in seconds on the camera's clock (only differences are
    meaningful): a RAW's as LibRaw reads it (EXIF DateTimeOriginal, or the TIFF DateTime), a
    TIFF's or a JPEG's EXIF DateTimeOriginal; None when LibRaw or tifffile cannot open the
    file, it holds no time (LibRaw then gives the epoch) or it is none of them (a PNG: OpenCV
    reads no EXIF)."""
    return _read_capture_time(path)[1]


def _read_capture_time(path: Path) -> tuple[bool, float | None]:
    """(whether waiting cannot change the answer, the capture time or None).

    False for a RAW LibRaw cannot open yet (a file still being written: "Unexpected end of
    file"); True for one it opened (with or without a time), a format it does not read, or no
    RAW. The time is the camera's wall clock read as UTC: EXIF carries no time zone, and read
    in the computer's zone two shots across its daylight-saving change came out an hour apart,
    every later file then out of step."""
    if path.suffix.lower() in TIFF_SUFFIXES:
        return _tiff_capture_time(path)
    if path.suffix.lower() in JPEG_SUFFIXES:
        final, stamp = jpeg_datetime_original(path)
        return final, _exif_time(stamp)
    if not is_raw_file(path):
        return True, None
    try:
        import rawpy

        # LibRaw prints its own line about a file cut short, naming it: kept off the
        # terminal (the file's decode says what is wrong with it, naming the folder's file)
        # a path that is not UTF-8 as /dev/fd/N: LibRaw reads the header it needs, not the
        # whole file into memory at each try
        with (
            libraw_opened(path) as (name, source),
            libraw_printed(name, []),
            rawpy.imread(source) as raw,
        ):
            stamp = raw.other.timestamp
    except Exception as exc:  # no evidence yet, or none: the file's own decode says why
        unsupported = type(exc).__name__ == "LibRawFileUnsupportedError"
        return unsupported, None
    try:
        value = stamp.replace(tzinfo=UTC).timestamp()
    except (OverflowError, OSError, ValueError, AttributeError):
        return True, None
    return True, (None if stamp.year <= 1970 else float(value))


def _tiff_capture_time(path: Path) -> tuple[bool, float | None]:
    """:func:`_read_capture_time` of a TIFF: its EXIF DateTimeOriginal (the EXIF IFD, where
    tethering programs and raw converters keep the shot's time), as the camera's wall clock.

    Why: a TIFF had no capture time at all, so a late or extra TIFF was never checked against
    the pulses. IFD0's DateTime is not used: it is when the file was written (the export), which
    trails the shot by a varying transfer time, and would set in-step files aside. False (wait)
    while tifffile cannot read a file that begins as a TIFF (one still being written); True
    for one whose first bytes are written and are no TIFF's: it never will be one, and had
    cost ``timeout_s`` before its notice said it held no capture time. True too for one whose
    first IFD is garbage no writer on its way leaves (:func:`ifd_garbage`): its decode names
    it, and the wait here had cost ``timeout_s`` before that."""
    import tifffile

    try:
        with tifffile.TiffFile(path) as tif:
            # pages[0], not pages.first: newer than the tifffile pyproject.toml allows
            exif = tif.pages[0].tags.get("ExifTag")
            stamp = exif.value.get("DateTimeOriginal") if exif is not None else None
    except Exception:  # not whole yet, no TIFF, or a garbage IFD: its bytes say which
        return _not_a_tiff(path) or ifd_garbage(path) is not None, None
    return True, _exif_time(stamp)


def _not_a_tiff(path: Path) -> bool:
    """Whether ``path``'s first four bytes are written and are no TIFF's: a file waiting
    cannot make readable (one still being written begins with its header, or zeros on a
    network share that sets the size first)."""
    try:
        with path.open("rb") as f:
            head = f.read(4)
    except OSError:
        return False
    return len(head) == 4 and any(head) and head not in TIFF_MAGIC


#: Bytes a file must hold, all text, before :func:`_text_file` calls it text: every image
#: header holds a NUL or a byte UTF-8 does not allow well within them (a TIFF's and most RAWs'
#: in their first 4 bytes, a JPEG's in its first; a Fuji RAF's within its first 60, after its
#: text magic and model name), where a file still being written may be a few text-like bytes.
TEXT_FILE_MIN_BYTES = 256


def _text_file(path: Path, length: int = 4096) -> bool:
    """Whether ``path``'s first bytes (up to ``length``, at least :data:`TEXT_FILE_MIN_BYTES`)
    are text: UTF-8 with no NUL. No image file begins so."""
    try:
        with path.open("rb") as f:
            head = f.read(length)
    except OSError:
        return False
    if len(head) < TEXT_FILE_MIN_BYTES or b"\0" in head:
        return False
    try:
        head.decode("utf-8")
    except UnicodeDecodeError as exc:
        return len(head) == length and exc.start >= length - 3  # a character cut at the end
    return True


def _tiff_end_written(path: Path, start: int, end: int, length: int = 64) -> bool:
    """Whether the last bytes (up to ``length``) of ``path``'s region ``start``–``end`` (the
    piece its TIFF structure names last) are not all zero.

    Why: a program copying onto a network share may set a file's full size first and fill
    it afterwards; until then its end reads as zeros, and such a file is not yet known to be
    damaged however whole its structure looks."""
    try:
        with path.open("rb") as f:
            f.seek(max(start, end - length))
            return any(f.read(min(length, end - start)))
    except OSError:
        return False


def _exif_time(stamp: object) -> float | None:
    """An EXIF "YYYY:MM:DD HH:MM:SS" as seconds, the camera's wall clock read as UTC (see
    :func:`_read_capture_time`); None when it is blank or malformed."""
    if not isinstance(stamp, str):
        return None
    try:
        when = datetime.strptime(stamp.strip().rstrip("\x00")[:19], "%Y:%m:%d %H:%M:%S")
    except ValueError:
        return None
    return when.replace(tzinfo=UTC).timestamp() if when.year > 1970 else None


def _has_header(path: Path) -> bool:
    """Whether ``path``'s first bytes are written (not all zero).

    Why: a program copying onto a network share (Windows over SMB) may set a file's full size
    first and fill it afterwards; such a file's size is steady at once, and LibRaw reads its
    zeros as no known format. Only a file whose header is there is known to be in a format
    LibRaw does not read."""
    try:
        with path.open("rb") as f:
            head = f.read(16)
    except OSError:
        return False
    return any(head)


@dataclass
class _Pending:
    """An exposure fired (or waited for) by ``expose`` whose frame ``collect`` has not given."""

    exposure_s: float
    started: float
    path: Path | None = None
    stray: list[str] = field(default_factory=list)
    unconfirmed: str | None = None
    #: when the trigger was called (the rig's clock): the pulse a file's capture time must fit
    pulsed_at: float | None = None
    #: how long the trigger took to return: the pulse lies within it (a lost reply makes it a
    #: whole reply timeout, and the pulse had been dated at its end)
    pulse_window_s: float = 0.0
    #: files that came after the pulse but were shot out of step with it, said in notices
    out_of_step: list[str] = field(default_factory=list)
    #: when the trigger was called on the computer's wall clock (what a resume's check of its
    #: first file is learned against: the rig clock starts again with each run)
    pulsed_wall: float | None = None
    #: when the trigger was called on the computer's monotonic clock (None: not known)
    pulsed_mono: float | None = None
    #: of ``out_of_step``, those shot before this run connected (by the camera clock an earlier
    #: run of the session learned): name -> how many seconds before
    before_connect: dict[str, float] = field(default_factory=dict)
    #: of ``out_of_step``, those shot before this run's first image, by the camera clock that
    #: image anchored: name -> how many seconds before
    before_first: dict[str, float] = field(default_factory=dict)
    #: their capture times (camera clock), to set beside an earlier run's kept images
    before_first_taken: dict[str, float] = field(default_factory=dict)
    #: of ``out_of_step``, the others: name -> how many seconds its capture time is after
    #: (negative: before) where this pulse's file would be, by the clock the last image
    #: anchored
    off_step: dict[str, float] = field(default_factory=dict)
    #: the capture time of the file taken, in step with the pulse (None: not checked)
    taken: float | None = None


class FolderWatchCamera:
    """Implements the ``Camera`` protocol by waiting for new files in a folder."""

    def __init__(
        self,
        settings: FolderWatchSettings,
        clock: Clock | None = None,
        trigger: Callable[[float], None] | None = None,
        wall: Callable[[], float] = time.time,
        monotonic: Callable[[], float] | None = None,
        computer: Callable[[], str] = computer_id,
    ) -> None:
        self.settings = settings
        #: the computer's wall clock (seconds since the epoch): the camera clock learned
        #: against it holds from one run of a session to the next, the rig clock does not
        self._wall = wall
        self._clock = clock or SystemClock()
        #: the computer's clock since boot (:func:`since_boot`), which measures how far its
        #: wall clock was moved between two runs of one boot (an NTP step); None (no
        #: correction) when the rig's clock is a virtual one, whose times are no computer's
        self._monotonic = monotonic or (
            since_boot if isinstance(self._clock, SystemClock) else None
        )
        self._computer = computer
        #: the connect on the wall clock of the run that learned the camera clock (this run's
        #: wall clock less the step the monotonic clock shows it was moved by since)
        self._connected_wall: float | None = None
        #: added to the first file's allowance: :data:`WALL_ALLOWANCE_S` when the connect is
        #: dated by this computer's wall clock alone
        self._wall_allowance_s = 0.0
        #: said on the first image (:data:`RESUME_WALL_CHECKED`), None: nothing to say
        self._resume_said: str | None = None
        #: the camera clock as an earlier run of the session learned it, read at connect
        self._learned: _LearnedClock | None = None
        #: a resume with no such clock: the earlier run's last kept camera file (its name in
        #: the session) and its capture time (None: it holds none); None otherwise
        self._earlier_last: tuple[str, float | None] | None = None
        self.name = settings.name
        self._trigger = trigger
        self._seen: set[str] | None = None
        #: (device, inode, size, mtime) of every file seen: a renamed one keeps all four
        self._seen_ids: set[tuple[int, int, int, int]] = set()
        #: (device, inode) of the same files: a set, as a folder may hold thousands of them
        self._seen_inodes: set[tuple[int, int]] = set()
        #: names of used files that reappeared as another file (reported at a timeout)
        self._reused_names: set[str] = set()
        #: names of seen files written again in place (the same inode, new size or time): a
        #: tethering program saving every shot over one name (reported at a timeout)
        self._rewritten_names: set[str] = set()
        #: stems of the files taken: a later file with one is the same shot's other file
        self._taken_stems: set[str] = set()
        #: every file name in the folder at connect (a timeout names the new ones that no
        #: pattern matches)
        self._at_connect: set[str] = set()
        self._pending: _Pending | None = None
        #: (capture time, pulse time) of the last image whose file had a capture time: the
        #: camera clock's anchor to the pulses
        self._anchor: tuple[float, float, float] | None = None
        #: the first such anchor of this run: a file shot before it is no late file of a pulse
        #: of this run
        self._first_anchor: tuple[float, float, float] | None = None
        #: the rig-clock times of this run's pulses, in order: an out-of-step file that fits
        #: one may be its late file; one that fits none is not
        self._pulse_times: list[float] = []
        #: (capture time, the pulse before) of the last file set aside as out of step: a late
        #: file of the previous pulse, if the next file fits it
        self._orphan: tuple[float, float, float] | None = None
        #: where a taken file is copied before it is decoded: the session's ``raw/.incoming``,
        #: set when the rig is bound to a session (None: decoded where it lies)
        self.output_dir: Path | None = None
        #: the session folder (set by the composition root's session hook): a message that
        #: sends the user to resume names the command for it
        self.session_root: Path | None = None

    def connect(self) -> None:
        folder = self.settings.folder
        if not folder.is_dir():
            raise DeviceError(
                self.name,
                f"watched folder {shown_path(folder)} does not exist or is not a "
                "folder; create it or fix 'folder' in the rig config",
                "connect",
            )
        present = self._matching()
        self._at_connect = set(self._visible_names())
        self._seen = {p.name for p in present}
        self._seen_ids = {i for i in map(_identity, present) if i is not None}
        self._seen_inodes = {i[:2] for i in self._seen_ids}
        self._reused_names = set()
        self._rewritten_names = set()
        self._taken_stems = set()
        self._anchor = None
        self._first_anchor = None
        self._pulse_times = []
        self._orphan = None
        self._learned = _LearnedClock.load(self._clock_file())
        self._earlier_last = self._earlier_run_last_shot() if self._learned is None else None
        self._connected_wall, self._wall_allowance_s = self._connect_on_learned_wall()
        self._resume_said = RESUME_WALL_CHECKED if self._wall_allowance_s else None

    def close(self) -> None:
        self._seen = None
        self._pending = None
        self._seen_ids = set()
        self._seen_inodes = set()

    def __enter__(self) -> FolderWatchCamera:
        self.connect()
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def _matching(self) -> list[Path]:
        found: dict[str, Path] = {}
        for pattern in self.settings.patterns:
            for p in self.settings.folder.glob(pattern):
                if p.name.startswith("."):  # a tethering or sync tool's temporary
                    continue
                if p.is_file():
                    found[p.name] = p
        return list(found.values())

    def _visible_names(self) -> list[str]:
        """Names of the files in the folder, hidden temporaries left out."""
        try:
            return [
                p.name
                for p in self.settings.folder.iterdir()
                if not p.name.startswith(".") and p.is_file()
            ]
        except OSError:
            return []

    def _earlier_files_said(self) -> str:
        """The files that were in the folder before this run and have been saved over since,
        said with the fix: empty the folder.

        Why: a folder holding an earlier shoot's ``IMG_0001.CR2`` … and a camera whose file
        numbers start again (a new or formatted card, a counter reset, its wrap from IMG_9999
        to IMG_0001) has the tethering program save this run's shots over them. A name is used
        once, so the shot is not taken; the timeout said "have the tethering program give every
        shot its own file name" (which it did) and "an earlier shot had it" (none had), and
        every resume stopped again at the next number."""
        replaced = sorted(self._reused_names & self._at_connect)
        rewritten = sorted(self._rewritten_names & self._at_connect)
        if not replaced and not rewritten:
            return ""
        parts = []
        if replaced:
            many = len(replaced) > 1
            parts.append(
                f"{', '.join(replaced)} {'were' if many else 'was'} in the folder before this "
                f"run began and another file has taken {'their names' if many else 'its name'} "
                "since (the file that was there is no longer in the folder under that name)"
            )
        if rewritten:
            many = len(rewritten) > 1
            parts.append(
                f"{', '.join(rewritten)} {'were' if many else 'was'} in the folder before this "
                f"run began and {'have' if many else 'has'} been written again in place since "
                "(saved over by a shot of the same name, or still being written when the run "
                "began)"
            )
        return (
            f"; {'; '.join(parts)}: the camera's file numbers may have started again (a new or "
            "formatted card, a counter reset, or its wrap from IMG_9999 to IMG_0001) onto an "
            "earlier shoot's names. A name is used once, so such a file is never taken as a "
            f"light's image: move the files already in {shown_path(self.settings.folder)}"
            " elsewhere (the "
            "session keeps its own images in its raw/ folder), or point folder in "
            "[camera.device] at an empty folder"
        )

    def _earlier_files_lead(self) -> str:
        """The first words of a timeout that saw this run's shot saved over an earlier shoot's
        file: what came, and that it was set aside (see :meth:`_earlier_files_said`)."""
        names = sorted((self._reused_names | self._rewritten_names) & self._at_connect)
        many = len(names) > 1
        return (
            f"{', '.join(names)} came but {'were' if many else 'was'} set aside, because "
            f"{'their names were' if many else 'its name was'} an earlier shoot's file's "
            "already in the folder"
        )

    def _set_aside_lead(self, pending: _Pending) -> str:
        """The first words of a timeout after files came for ``pending``'s pulse and were set
        aside: which, and why (shot before this run connected, before its first image, or out
        of step with the pulse); empty when none came."""
        if not pending.out_of_step:
            return ""
        parts = []
        for why, names in (
            (
                "shot before this run connected",
                [n for n in pending.out_of_step if n in pending.before_connect],
            ),
            (
                "shot before this run's first image",
                [n for n in pending.out_of_step if n in pending.before_first],
            ),
            (
                "shot out of step with it",
                [
                    n
                    for n in pending.out_of_step
                    if n not in pending.before_connect and n not in pending.before_first
                ],
            ),
        ):
            if names:
                many = len(names) > 1
                parts.append(
                    f"{', '.join(names)} came after the pulse but {'were' if many else 'was'} "
                    f"set aside, {why}"
                )
        return "; ".join(parts)

    def _unmatched_said(self) -> str:
        """The files that came since connect but match no pattern, said with the fix.

        Why: a camera saving ``_DSC0001.ARW`` into a folder watched for ``*.CR2`` (the guide's
        example) timed out with "is the camera firing and saving there?" while it was doing
        just that; the patterns are case-sensitive too (``*.cr2`` does not match
        ``IMG_0001.CR2``).

        A JPEG in a folder watched for RAWs is a RAW+JPEG shot whose RAW has not come (late,
        or not saved), never a pattern to add: an 8-bit JPEG is refused as an image, and the
        advice to add ``'*.JPG'`` had sent an owner whose RAW was merely late to a pattern
        that could only stop the next run at its first JPEG."""
        patterns = self.settings.patterns
        names = sorted(
            n
            for n in self._visible_names()
            if n not in self._at_connect and not any(Path(n).match(p) for p in patterns)
        )
        if not names:
            return ""
        raw_patterns = [x for x in patterns if Path(x).suffix.lower() in RAW_SUFFIXES]
        jpegs = (
            [n for n in names if Path(n).suffix.lower() in JPEG_SUFFIXES] if raw_patterns else []
        )
        names = [n for n in names if n not in jpegs]
        said = ""
        if names:
            shown = ", ".join(names[:3]) + (f" and {len(names) - 3} more" if len(names) > 3 else "")
            suffixes = sorted({f"*{Path(n).suffix}" for n in names if Path(n).suffix})
            add = f" (e.g. {', '.join(repr(x) for x in suffixes)})" if suffixes else ""
            said = (
                f"; {shown} came into the folder but no pattern matches "
                f"{'them' if len(names) > 1 else 'it'} (patterns are case-sensitive): add "
                f"{'their' if len(names) > 1 else 'its'} pattern{add} to patterns in "
                "[camera.device]"
            )
        # a JPEG whose RAW is there under a name no pattern matches is said by that RAW above
        stems = {Path(n).stem for n in names}
        alone = [n for n in jpegs if Path(n).stem not in stems]
        if alone:
            shown = ", ".join(alone[:3]) + (f" and {len(alone) - 3} more" if len(alone) > 3 else "")
            said += (
                f"; {shown} came into the folder but not {'their' if len(alone) > 1 else 'its'} "
                f"RAW (patterns {raw_patterns}): if the camera saves RAW+JPEG, its RAW is late "
                "(raise timeout_s in [camera.device] if the link is slow, e.g. Wi-Fi) or was "
                "saved elsewhere (the card only?); if it saves JPEG only, set it to RAW or "
                "RAW+JPEG (an 8-bit JPEG is not linear data: do not add its pattern)"
            )
        return said

    def _mark_seen(self, name: str, ident: tuple[int, int, int, int] | None) -> None:
        """``name`` (and the file it is, if it still exists) is used: never taken again."""
        assert self._seen is not None
        self._seen.add(name)
        if ident is not None:
            self._seen_ids.add(ident)
            self._seen_inodes.add(ident[:2])

    def _new_files(self, seen: set[str]) -> list[Path]:
        new = []
        for p in self._matching():
            ident = _identity(p)
            if ident is None:  # removed between glob and stat
                continue
            if p.name in seen:
                if ident[:2] not in self._seen_inodes:  # another file
                    self._reused_names.add(p.name)
                elif ident not in self._seen_ids:  # the same file, written again in place
                    self._rewritten_names.add(p.name)
                continue
            if ident in self._seen_ids:  # a file already seen, renamed
                continue
            if p.stem in self._taken_stems:  # the other file of a RAW+JPEG shot already taken
                continue
            new.append((ident[3], p.name, p))
        return [p for _, _, p in sorted(new)]

    def wait_for_file(self, *, set_aside: str = "") -> Path:
        """Block (on the injected clock) until the next complete new file, or time out.

        ``set_aside``: what came after the pulse and was set aside (out of step), said first
        in the timeout's message. Why: those stops began "no new file matching … within N s",
        though a file had come, and asked whether the camera was firing and saving there: it
        did both."""
        if self._seen is None:
            raise CaptureError(self.name, "not connected; call connect() first", "capture")
        s = self.settings
        start = self._clock.now()
        last: tuple[str, int] | None = None
        stable = 0
        while True:
            new = self._new_files(self._seen)
            if new:
                path = new[0]
                if not is_raw_file(path):  # RAW+JPEG: the RAW is the shot's image
                    path = next((p for p in new if p.stem == path.stem and is_raw_file(p)), path)
                try:
                    size = path.stat().st_size
                except FileNotFoundError:
                    size = 0
                if size > 0 and last == (path.name, size):
                    stable += 1
                else:
                    stable = 1 if size > 0 else 0
                last = (path.name, size)
                if stable >= s.stable_polls:
                    ident = _identity(path)
                    if ident is not None:
                        self._mark_seen(path.name, ident)
                        self._taken_stems.add(path.stem)
                        return path
            if self._clock.now() - start >= s.timeout_s:
                growing = f"; {last[0]} appeared but was still being written" if last else ""
                lead, reused = set_aside, self._earlier_files_said()
                if reused and not lead:
                    lead = self._earlier_files_lead()
                if self._reused_names - self._at_connect:
                    names = ", ".join(sorted(self._reused_names - self._at_connect))
                    reused += (  # after the earlier shoot's words, never in their place
                        f"; {names} appeared again as another file, but a name is used once "
                        "(an earlier shot had it): have the tethering program give every shot "
                        "its own file name"
                    )
                if self._rewritten_names - self._at_connect:
                    # saved over in place: the camera was firing and saving there, but the
                    # timeout had asked whether it was (gphoto2 --force-overwrite, a program
                    # set to one file name for every shot)
                    names = ", ".join(sorted(self._rewritten_names - self._at_connect))
                    reused += (
                        f"; {names} was written again after the session had seen it (saved "
                        "over under the same name, or still being written when the session "
                        "began), but a name is used once: have the tethering program give "
                        "every shot its own file name instead of saving over one"
                    )
                unmatched = self._unmatched_said()
                ask = (
                    ""
                    if unmatched or reused or lead
                    else ": is the camera firing and saving there?"
                )
                if not s.folder.is_dir():
                    # a network share that dropped, a card reader unplugged: the question
                    # about the camera had sent the user to check a camera that was firing
                    ask = (
                        "; the folder is no longer there or cannot be reached (a network "
                        "share disconnected or unmounted, a disk unplugged?): reconnect it, "
                        f"then continue with: {resume_command(self.session_root)}"
                    )
                none = (
                    f"no other new file matching {list(s.patterns)} came to {shown_path(s.folder)}"
                    " within "
                    if lead
                    else f"no new file matching {list(s.patterns)} in {shown_path(s.folder)}"
                    " within "
                )
                raise CaptureError(
                    self.name,
                    f"{lead}{'; ' if lead else ''}{none}"
                    f"{s.timeout_s:g} s{growing}{reused}{unmatched}{ask}",
                    "wait for file",
                )
            self._clock.sleep(s.poll_interval_s)

    def capture(self, exposure_s: float) -> Frame:
        """Fire the trigger (if any), wait for the file, decode it to a linear frame."""
        self.expose(exposure_s)
        return self.collect()

    def expose(self, exposure_s: float) -> float | None:
        """Fire the trigger and return when the exposure has surely ended: ``shutter_lag_s``
        plus ``exposure_s`` after the pulse was confirmed. Without a trigger nothing says when
        someone else fires, so this waits for the file, whose arrival proves the exposure over.

        The light can then go off while the file crosses the tether or Wi-Fi link (seconds for
        a RAW), rather than stay lit into the dome's ``max_on_s``.
        """
        if self._seen is None:
            raise CaptureError(self.name, "not connected; call connect() first", "capture")
        pending = _Pending(exposure_s, started=self._clock.now())
        self._pending = None
        if self._trigger is None:
            pending.path = self.wait_for_file()
            self._pending = pending
            return self._clock.now()
        # a file already there before the pulse is not the pulse's picture (a duplicate, a test
        # shot, a second frame of the last pulse): taken as the oldest new file it had been
        # this light's image, and every later image one light off
        for p in self._new_files(self._seen):
            self._mark_seen(p.name, _identity(p))
            pending.stray.append(p.name)
        sent, wall = self._clock.now(), self._wall()
        mono = None if self._monotonic is None else self._monotonic()
        try:
            self._trigger(exposure_s)
        except TriggerUnconfirmed as exc:
            pending.unconfirmed = str(exc)
        pending.pulsed_at, pending.pulsed_wall, pending.pulsed_mono = sent, wall, mono
        self._pulse_times.append(sent)
        pending.pulse_window_s = self._clock.now() - sent
        self._pending = pending
        return self._clock.now() + self.settings.shutter_lag_s + exposure_s

    def collect(self) -> Frame:
        """The file of the last ``expose`` (waited for if it has not come yet), decoded."""
        pending, self._pending = self._pending, None
        if pending is None:
            raise CaptureError(self.name, "collect() without expose() before it", "capture")
        path = pending.path
        notes: list[str] = []
        if path is None:
            path, notes = self._await_pulse_file(pending)
        frame = self._decode_complete(path, pending.exposure_s, pending.started)
        self._learn_clock(pending)
        if notes:
            frame.metadata["notices"] = [*(frame.metadata.get("notices") or []), *notes]
        if pending.stray:
            frame.metadata["stray_files"] = pending.stray
            kept = self._hold_strays(pending.stray)
            if kept:
                frame.metadata["stray_originals"] = kept
            where = (
                ""
                if not kept
                else f"; {'it is' if len(kept) == 1 else f'{len(kept)} are'} kept aside in the "
                "session's strays/ (the step's 'strays' in the journal), never as an image"
            )
            before = [n for n in pending.stray if n not in pending.out_of_step]
            said = []
            if before:
                said.append(
                    f"{len(before)} file(s) came into the watched folder before this shot's "
                    f"trigger and were not used: {', '.join(before)} (a duplicate or a shot "
                    "no light asked for)"
                )
            if pending.out_of_step:
                said.append(
                    f"{len(pending.out_of_step)} file(s) came after this shot's trigger but "
                    f"were shot out of step with it and not used: "
                    f"{', '.join(pending.out_of_step)}"
                    + self._off_step_said(
                        pending,
                        [
                            n
                            for n in pending.out_of_step
                            if n not in pending.before_connect and n not in pending.before_first
                        ],
                    )
                    + self._before_connect_said(pending)
                )
            frame.metadata["notices"] = [
                *(frame.metadata.get("notices") or []),
                *(f"{x}{where}" for x in said),
            ]
        if pending.unconfirmed is not None:
            frame.metadata["trigger_unconfirmed"] = pending.unconfirmed
            frame.metadata["notices"] = [
                *(frame.metadata.get("notices") or []),
                "the trigger's confirmation was lost but the camera's file arrived",
            ]
        return frame

    def _await_pulse_file(self, pending: _Pending) -> tuple[Path, list[str]]:
        """The file of ``pending``'s pulse: the next new file whose capture time fits the
        pulse (see the module docstring); those out of step are set aside as strays.

        Why: a file that came after the run stopped at ``timeout_s`` and was resumed was taken
        as the resumed pulse's image (its light right), but that pulse's own file then came
        after the next pulse and was taken for the next light, and so on: every later image
        recorded under a light it was not taken under."""
        while True:
            try:
                path = self.wait_for_file(set_aside=self._set_aside_lead(pending))
            except CaptureError as exc:
                said = exc.message
                late = [n for n in pending.out_of_step if n not in pending.before_first]
                if late:
                    pending.out_of_step = late  # those shot before the first are said below
                    said += (
                        f"; {', '.join(pending.out_of_step)} "
                        f"{'were' if len(pending.out_of_step) > 1 else 'was'} not used and "
                        f"left in {shown_path(self.settings.folder)}"
                        + self._off_step_said(pending, late)
                    )
                    said += self._before_connect_said(pending)
                said += self._before_first_said(pending)
                if pending.unconfirmed is not None:
                    said += f"; the trigger was not confirmed either ({pending.unconfirmed})"
                if said == exc.message:
                    raise
                raise CaptureError(self.name, said, "wait for file") from exc
            if pending.pulsed_at is None:
                return path, []
            taken = self._whole_capture_time(path)
            if taken is None:
                return path, [NO_CAPTURE_TIME]
            early = self._shot_before_connect(taken, pending.pulse_window_s)
            placed = None
            if early is None:
                placed = self._place(taken, pending.pulsed_at, pending.pulse_window_s)
            if placed is not None:
                pending.taken = taken  # learned once the file is decoded (see collect)
                if self._resume_said is not None:
                    placed, self._resume_said = [*placed, self._resume_said], None
                return path, placed
            pending.stray.append(path.name)
            pending.out_of_step.append(path.name)
            if early is not None:
                pending.before_connect[path.name] = early
            elif (before := self._shot_before_first(taken, pending.pulse_window_s)) is not None:
                pending.before_first[path.name] = before
                pending.before_first_taken[path.name] = taken
            elif self._anchor is not None:
                anchor = self._anchor
                pending.off_step[path.name] = (taken - anchor[0]) - (pending.pulsed_at - anchor[1])
            if len(pending.out_of_step) > MAX_OUT_OF_STEP:
                raise CaptureError(
                    self.name,
                    f"{', '.join(pending.out_of_step)} came into {shown_path(self.settings.folder)}"
                    " after "
                    "this light's pulse, but none was shot in step with the pulses (its capture "
                    "time against the last image's, within "
                    f"{CAPTURE_TIME_RESOLUTION_S + self.settings.shutter_lag_s:g} s: "
                    "shutter_lag_s plus the 1 s of EXIF times): is the camera's clock being "
                    "set meanwhile, or another camera saving there? They are left in "
                    f"{shown_path(self.settings.folder)}; no image was recorded for this light",
                    "check capture time",
                )

    def _changed_and_settled(
        self, path: Path, tried: tuple[int, int, int, int] | None, deadline: float
    ) -> bool:
        """Whether ``path`` changed from ``tried`` (its identity when a read of it failed) and
        then kept one identity for ``stable_polls`` polls before ``deadline``: a file a reader
        could not use yet is read again only once more of it has come and stopped coming."""
        s = self.settings
        last, stable = tried, 0
        while self._clock.now() < deadline:
            self._clock.sleep(s.poll_interval_s)
            now = _identity(path)
            stable = stable + 1 if now == last else 1
            last = now
            if now is not None and now != tried and stable >= s.stable_polls:
                return True
        return False

    def _ifd_settled(
        self, path: Path, deadline: float
    ) -> tuple[tuple[int, int, int, int], IfdState] | None:
        """``path``'s identity and IFD state once both have stayed the same for
        ``stable_polls`` polls, or None if they have not by ``deadline`` (or it is gone).

        Why: a steady size says nothing of a file a network share sized first and is filling
        (its IFD's entries zeros, then written): a DNG's structure read then was refused as
        damaged, a good shot lost. Its bytes, not its size, must stop changing first."""
        s = self.settings
        last, stable = None, 0
        while True:
            ident, state = _identity(path), ifd_state(path)
            now = None if ident is None or state is None else (ident, state)
            stable = stable + 1 if now is not None and now == last else 1
            last = now
            if now is not None and stable >= s.stable_polls:
                return now
            if self._clock.now() >= deadline:
                return None
            self._clock.sleep(s.poll_interval_s)

    def _whole_capture_time(self, path: Path) -> float | None:
        """The capture time of ``path`` once LibRaw can open it: a file still being written
        (a network share, a Wi-Fi upload pausing) is given ``timeout_s`` to change and settle,
        as its decode is. None where it holds no time, or still cannot be opened then (its
        decode then says why).

        Why: read as it first came, half a file gave no time, and a late file of an earlier
        pulse was taken for this light unchecked: the very case the check is for."""
        s = self.settings
        deadline = self._clock.now() + s.timeout_s
        while True:
            final, taken = _read_capture_time(path)
            if final or taken is not None:
                return taken
            if not self._changed_and_settled(path, _identity(path), deadline):
                return None

    def _place(self, taken: float, pulsed_at: float, window_s: float = 0.0) -> list[str] | None:
        """Whether a file shot at ``taken`` (camera clock) is the file of the pulse at
        ``pulsed_at`` (rig clock): the notices to give it if so, None if it is out of step
        (then remembered as a possible late file of the previous pulse)."""
        base = CAPTURE_TIME_RESOLUTION_S + self.settings.shutter_lag_s + window_s
        anchor, orphan = self._anchor, self._orphan
        notes: list[str] = []
        # each pulse is known to within the time its trigger took to return
        if anchor is not None and abs((taken - anchor[0]) - (pulsed_at - anchor[1])) > (
            base + anchor[2]
        ):
            if orphan is None or abs((taken - orphan[0]) - (pulsed_at - orphan[1])) > (
                base + orphan[2]
            ):
                self._orphan = (taken, anchor[1], anchor[2])
                return None
            # the set-aside file was the previous pulse's: the last image was an earlier one's
            early = orphan[0] - anchor[0]
            notes.append(
                "the previous image's file was shot "
                f"{early:.0f} s before the file of its pulse, which came only after the next "
                "pulse and is kept in strays/: it was a late file of an earlier pulse (one the "
                "run stopped waiting for before a resume?); check that the object and the light "
                "were the same then"
            )
        self._anchor, self._orphan = (taken, pulsed_at, window_s), None
        if self._first_anchor is None:
            self._first_anchor = self._anchor
        return notes

    def _off_step_said(self, pending: _Pending, names: list[str]) -> str:
        """What the capture times of ``names`` (out of step with ``pending``'s pulse) tell:
        a late file of an earlier pulse, or the camera's clock changed, or both possible.

        Why: every such file was called "a late file of an earlier pulse?", also one shot after
        the pulse (no late file is) or between two pulses of the run (no pulse's file), where
        the evidence says the camera's clock was changed mid-session (a time-zone or
        daylight-saving change on the body). Where it fits an earlier pulse, both are said:
        the capture times cannot tell them apart."""
        said = []
        way_out = ""
        clock_file = self._clock_file()
        if clock_file is not None:
            way_out = (
                f", delete {shown_path(clock_file)} and resume (its first image is then unchecked)"
            )
        base = CAPTURE_TIME_RESOLUTION_S + self.settings.shutter_lag_s + pending.pulse_window_s
        pulses = self._pulse_times[:-1]  # those before this light's
        for name in names:
            off = pending.off_step.get(name)
            if off is None:  # no clock to judge by: the old question, plainly
                said.append(
                    f"{name}: a late file of an earlier pulse, or a shot no light asked for"
                )
                continue
            if off > 0:
                said.append(
                    f"{name} was shot {off:.0f} s after this pulse by the camera clock the last "
                    "image anchored, so it is no late file of an earlier pulse: the camera's "
                    f"clock was set forward by about {off:.0f} s (a time-zone or daylight-saving "
                    "change on the camera?), or it is a shot no light asked for. If the clock "
                    f"was set forward{way_out}"
                )
                continue
            at = (pending.pulsed_at or 0.0) + off
            fits = [k for k, t in enumerate(pulses, 1) if abs(at - t) <= base]
            if fits:
                which = " or ".join(f"this run's pulse {k}" for k in fits)
                said.append(
                    f"{name} was shot {-off:.0f} s before this pulse by the camera clock the "
                    f"last image anchored, which fits {which}: either a late file of an earlier "
                    f"pulse or the camera's clock set back by about {-off:.0f} s (a time-zone or "
                    "daylight-saving change on the camera?); the capture times cannot tell "
                    f"which. If the clock was set back{way_out}"
                )
            else:
                said.append(
                    f"{name} was shot {-off:.0f} s before this pulse by the camera clock the "
                    "last image anchored, at no pulse of this run, so it is no late file of "
                    f"one: the camera's clock was set back by about {-off:.0f} s (a time-zone or "
                    "daylight-saving change on the camera?), or an older picture was copied "
                    f"into the folder. If the clock was set back{way_out}"
                )
        return f" ({'; '.join(said)})" if said else ""

    def _shot_before_first(self, taken: float, window_s: float) -> float | None:
        """How many seconds before this run's first image a file was shot, by the camera clock
        that image anchored; None when it may be a late file of one of this run's pulses."""
        first = self._first_anchor
        if first is None:
            return None
        allowance = CAPTURE_TIME_RESOLUTION_S + self.settings.shutter_lag_s + window_s + first[2]
        early = first[0] - taken
        return early if early > allowance else None

    def _before_first_said(self, pending: _Pending) -> str:
        """The files of ``pending`` shot before this run's first image, said with what that
        means and the way out.

        Why: a camera whose clock was set back mid-session (a time-zone or daylight-saving
        change made on the body) gives the pulse's own picture a capture time before the run
        began. It is rightly not taken (the check cannot tell it from an older file), but the
        stop asked "is the camera firing and saving there?" of a camera that was doing both,
        called the file "a late file of an earlier pulse?" (no pulse of the run came before
        it), and the resume stopped again on the clock the run had learned."""
        if not pending.before_first:
            return ""
        shown = ", ".join(f"{n} {s:.0f} s" for n, s in pending.before_first.items())
        many = len(pending.before_first) > 1
        without_clock = self._without_clock_said(pending.before_first_taken)
        clock_file = self._clock_file()
        way_out = (
            f"delete {shown_path(clock_file)} and resume (its first image is then unchecked)"
            if clock_file is not None
            else "run again"
        )
        return (
            f"; {'they were' if many else 'it was'} shot before this run's first image "
            f"({shown} before, by the camera clock that image anchored), so no pulse of this "
            "run took "
            f"{'them' if many else 'it'}"
            + (
                ":" + without_clock + " "
                if without_clock
                else ": the camera's clock was set back since (a time-zone or daylight-saving "
                "change on the camera?) or an older picture was copied into the folder. "
            )
            + f"Not used, left in {shown_path(self.settings.folder)}"
            ". If the camera's clock was set "
            f"back, {way_out}"
        )

    def _before_connect_said(self, pending: _Pending) -> str:
        """The files of ``pending`` refused as shot before this run connected, said with how
        the camera clock was known and what to do if it was set since."""
        if not pending.before_connect:
            return ""
        shown = ", ".join(f"{n} {s:.0f} s" for n, s in pending.before_connect.items())
        return (
            f"; shot before this run connected ({shown} before, by the camera clock the "
            "session's earlier run learned): files of the stopped run, not of this light. If "
            "the camera's clock was set back since, the computer's clock set forward in a way "
            "its clock since boot does not show (or, on another computer or after a restart, "
            f"more than {WALL_ALLOWANCE_S / 60:.0f} min ahead of the earlier run's), or another "
            "camera now saves there, delete "
            f"{self._clock_file()} and resume again (the first image is then unchecked)"
        )

    def _earlier_run_last_shot(self) -> tuple[str, float | None] | None:
        """The last camera file an earlier run of the session kept (``raw/image_NNN.*``, the
        highest number, by number: ``image_1000`` after ``image_999``) and its capture time;
        None when the session holds none (a new one).

        Why: a resume of a session without a camera clock file (an older version's, or the
        file deleted) has only this to date a file shot before its first image by: after the
        earlier run's last kept shot, it fits the shot that run stopped waiting for."""
        raw = None if self.output_dir is None else self.output_dir.parent
        if raw is None or not raw.is_dir():
            return None
        kept = sorted((p for p in raw.glob("image_*.*") if p.is_file()), key=image_number)
        if not kept:
            return None
        last = kept[-1]
        return f"{raw.name}/{last.name}", capture_time(last)

    def _without_clock_said(self, shot: dict[str, float]) -> str:
        """What is known, and what is not, of files shot before this run's first image
        (``shot``: name → capture time) in a resume that found no camera clock of the
        session's earlier run; "" when this run is no such resume.

        Why: such a file was said to be "the camera's clock set back since … or an older
        picture copied into the folder", though the likeliest, the shot the stopped run waited
        for coming in late, fits too, and the earlier run's kept images tell which it can be;
        what cannot be known without the clock file is whether the clock was changed."""
        if self._earlier_last is None:
            return ""
        name, last = self._earlier_last
        head = (
            f" this run resumes a session that keeps no camera clock from its earlier run "
            f"({CLOCK_FILE} was missing or unreadable when it started: a session of an older "
            "version, or the file deleted), so whether the camera's clock was changed between "
            "the runs is not known."
        )
        if last is None:
            return (
                f"{head} The earlier run's last kept image ({name}) holds no capture time, so "
                "whether this is a late file of that run's last pulse (the shot it stopped "
                "waiting for) is not known either: that, the camera's clock set back, or an "
                "older picture copied into the folder."
            )
        # EXIF keeps whole seconds: within one of the last kept image, it may be after it
        after = {n: t - last for n, t in shot.items() if t - last > -CAPTURE_TIME_RESOLUTION_S}
        before = {n: last - t for n, t in shot.items() if n not in after}
        said = []
        if after:
            shown = ", ".join(f"{n} {max(s, 0.0):.0f} s" for n, s in after.items())
            said.append(
                f" By the capture times {'they were' if len(after) > 1 else 'it was'} shot "
                f"after the earlier run's last kept image ({name}; {shown} after): a late file "
                "of the earlier run's last pulse (the shot it stopped waiting for) fits that, "
                "if the camera's clock was not changed since; a clock set back or an older "
                "picture copied in would look the same, and the capture times cannot tell "
                "which."
            )
        if before:
            shown = ", ".join(f"{n} {s:.0f} s" for n, s in before.items())
            many = len(before) > 1
            said.append(
                f" By the capture times {'they were' if many else 'it was'} shot before the "
                f"earlier run's last kept image ({name}; {shown} before), so "
                f"{'none of them is a' if many else 'it is no'} late file of the shot that run "
                "stopped waiting for, unless the camera's clock was changed: the clock set "
                "back, or an older picture copied in."
            )
        return head + "".join(said)

    def _clock_file(self) -> Path | None:
        """Where the session keeps the camera clock learned: its ``raw/`` folder (the parent
        of ``output_dir``, ``raw/.incoming``); None when no session is bound."""
        return None if self.output_dir is None else self.output_dir.parent / CLOCK_FILE

    def _learn_clock(self, pending: _Pending) -> None:
        """Keep the camera clock of an image in step with its pulse, for a resume: once its
        file is decoded, so a session whose first file is refused holds nothing of it (its
        ``raw/`` folder, made for the clock, had made it a session to resume)."""
        where = self._clock_file()
        if where is None or pending.pulsed_wall is None or pending.taken is None:
            return
        learned = _LearnedClock(
            pending.taken - pending.pulsed_wall,
            pending.pulsed_wall,
            pending.pulse_window_s,
            pending.pulsed_mono,
            self._computer(),
        )
        with contextlib.suppress(OSError):
            where.parent.mkdir(parents=True, exist_ok=True)
            learned.save(where)

    def _connect_on_learned_wall(self) -> tuple[float | None, float]:
        """This connect on the wall clock of the run that learned the camera clock, and the
        allowance to add for not knowing it better (0, or :data:`WALL_ALLOWANCE_S`).

        Why: the computer's wall clock was taken to be the one the camera clock was learned
        against. A resume after an NTP step forward of a clock that ran slow, or on another
        computer whose clock is behind, dated every good file before the connect: each was
        refused and the run stopped, blaming the camera's clock. On the same boot the clock
        since boot says how far the wall clock was moved and it is taken off. On another
        computer or boot (on Linux every restart: "stopped tonight, resumed tomorrow") it was
        not checked at all, and a late file of the stopped run, days old, became the resumed
        light's image: it is now checked against this computer's wall clock within
        :data:`WALL_ALLOWANCE_S`, as it is when the wall clock moved ahead of the clock since
        boot by more than that since (a sleep the clock since boot did not count, or a step
        forward that large: the two cannot be told apart)."""
        learned, now = self._learned, self._wall()
        if learned is None or learned.mono_s is None:
            return now, 0.0  # an older session's clock, or a rig clock not the monotonic
        mono = None if self._monotonic is None else self._monotonic()
        if learned.computer == self._computer() and mono is not None and mono >= learned.mono_s:
            moved = (now - learned.wall_s) - (mono - learned.mono_s)
            # a sleep not counted only ever looks like a step forward: a step back, however
            # large, is measured (dated by the wall clock, a late file would look that much
            # younger)
            if moved <= WALL_ALLOWANCE_S:
                return now - moved, 0.0
        return now, WALL_ALLOWANCE_S

    def _shot_before_connect(self, taken: float, window_s: float) -> float | None:
        """How many seconds before this run connected a first file was shot, by the camera
        clock an earlier run of the session learned; None when it may be this run's (or there
        is no such clock, or the run has an image to check its files against already).

        Only a file shot before the connect is refused: a later one may be the pulse's. The
        allowance is the EXIF second, the shutter lag, both pulses' trigger times and a drift
        of :data:`CLOCK_DRIFT` over the time since the clock was learned, and
        :data:`WALL_ALLOWANCE_S` when the connect is dated by this computer's wall clock
        alone. A file the stopped run waited for was shot ``timeout_s`` before it stopped, so
        it is surely caught only when ``timeout_s`` is over twice the allowance (its shot is
        known only to within it), and, on another computer or boot, when it was shot over ten
        minutes before the resume."""
        learned, connected = self._learned, self._connected_wall
        if self._anchor is not None or learned is None or connected is None:
            return None
        allowance = (
            CAPTURE_TIME_RESOLUTION_S
            + self.settings.shutter_lag_s
            + window_s
            + learned.window_s
            + CLOCK_DRIFT * abs(connected - learned.wall_s)
            + self._wall_allowance_s
        )
        early = connected - (taken - learned.offset_s)
        return early if early > allowance else None

    def _drop_copy(self, held: Path) -> None:
        """Delete a copy :meth:`_hold` made, and the folders it made for it if they are left
        empty (``raw/.incoming``, ``raw/``): a session whose first file would not decode
        then holds no camera file, and the run says it may be used again (an empty ``raw/``
        had it say "holds files of the camera … Continue with: rti-rig run --resume")."""
        held.unlink(missing_ok=True)
        for folder in (held.parent, held.parent.parent):
            with contextlib.suppress(OSError):  # not empty: another file is kept there
                folder.rmdir()

    def _hold_strays(self, names: list[str]) -> list[dict[str, str]]:
        """Copy the files set aside before a pulse into the session, as the session's
        ``stray_originals`` (kept in ``strays/``, recorded in the step's ``strays``); those
        gone from the folder meanwhile are left out. Done once the shot is collected, its
        light off (a copy before the pulse had kept the LED lit for it).

        Why: such a file is a picture of the object, at a moment and under a light rti-rig
        cannot vouch for: never an image, but kept, as a DSLR's stray is; it had been named in
        a notice only, and the session held no copy of it."""
        if self.output_dir is None:
            return []
        kept = []
        for name in names:
            try:
                copy = self._hold(self.settings.folder / name)
            except CaptureError:
                continue  # moved out of the folder meanwhile: named in the notice all the same
            kept.append({"path": str(copy), "name": name})
        return kept

    def _damaged(self, message: str, path: Path, why: str, advice: str = "") -> CaptureError:
        """The stop for a watched file that will not decode and that waiting will not mend
        (``why``: what it is, "is a damaged TIFF (…)"), then ``advice`` as a sentence of its
        own.

        Why one helper: each of these stops says the same of the file (left in the folder, no
        image recorded for the light), and had been written out once for each kind of file."""
        return CaptureError(
            self.name,
            f"{message}: {path.name} {why}, so waiting will not help; it is left in "
            f"{shown_path(self.settings.folder)}, and no image was recorded for this light"
            + (f". {advice}" if advice else ""),
            "decode",
        )

    def _decode_complete(self, path: Path, exposure_s: float, started: float) -> Frame:
        """Decode ``path``; one that will not decode gets ``timeout_s`` to change and is tried
        again once its size is steady for ``stable_polls`` polls, unless waiting cannot help:
        a RAW whose header is written in a format LibRaw does not read, a file named as a
        TIFF whose first bytes are written and are no TIFF's, or a whole TIFF (every byte its
        IFDs name written, the last ones not zeros) whose data will not decode, or one read as
        no pixels whose first IFD is all written (:func:`first_ifd`) and names no data, data
        inside the file or garbage, or one whose first IFD holds what no writer on its way
        leaves (:func:`ifd_garbage`: a tag count over 4096, a count of 0 before written
        bytes, an entry of no TIFF type, an offset inside the header): each is said at once,
        naming the file. A TIFF whose IFD is not there yet (libtiff writes it last, tifffile
        zeroed until its data is out) is waited for. A RAW refused by its TIFF structure
        (a DNG's CFAPattern or StripOffsets missing) is judged only once its size and IFDs
        are unchanged over ``stable_polls`` polls (read again if they changed), and waited
        for while its IFDs hold zeros (:func:`ifd_state`: a share that set its size first).
        Messages are worded here from the decoders' fields.

        Why: a steady size only means the writer paused (a network share, a Wi-Fi upload, a
        program writing in chunks). Half a file had stopped the session at once, a shot lost
        for a pause longer than the stability polls, though the rest of it was on its way.
        """
        s = self.settings
        deadline = self._clock.now() + s.timeout_s
        while True:
            tried = _identity(path)
            held = self._hold(path)
            try:
                return self._decode(held, exposure_s, started, path)
            except CaptureError as exc:
                if held != path and _identity(path) is not None:
                    self._drop_copy(held)  # the folder's file stays; the copy is no use
                if isinstance(exc, RawFileMissingError) and held != path:
                    raise self._copy_gone(path, held) from exc
                # the decoders' own refusals: LibRaw's, or a TIFF/PNG that would not read (not
                # this camera's, of a whole file: 8-bit data, a wrong exposure)
                if exc.device != DECODER and exc.command != "read":
                    raise
                if isinstance(exc, ImageReadError):
                    # worded here from its fields: the folder's file, not the copy read
                    detail = f" ({exc.reason})" if exc.reason else ""
                    message = f"cannot read image file {shown_path(path)}{detail}"
                elif isinstance(exc, RawDecodeError):
                    # worded here from its fields too: LibRaw's own words are left as said
                    message = exc.about(path)
                else:
                    message = exc.message
                whole = None  # what the RAW's structure says of the file being whole
                if (
                    isinstance(exc, UnsupportedRawError | DamagedRawError)
                    and (seen := ifd_state(path)) is not None
                ):
                    # its structure judged: only once its bytes have stopped arriving
                    settled = self._ifd_settled(path, deadline)
                    if settled is None:
                        raise CaptureError(
                            self.name,
                            f"{message}; {path.name} was still being written "
                            f"{s.timeout_s:g} s after that (its IFD or size still changing: "
                            "if the program or share saving it is that slow, raise "
                            "timeout_s)",
                            "decode",
                        ) from exc
                    if settled != (tried, seen):
                        continue  # more of it came since it was read: read it again
                    if seen.unwritten:
                        # zeros where its IFD's entries belong: a share that set the size
                        # first and has not filled it yet, not (yet) known to be damaged
                        message += (
                            ": parts of its IFD are still zeros (a copy over a network share "
                            "that sets a file's size first, not yet filled?)"
                        )
                    whole = (
                        None
                        if seen.unwritten
                        else f"its size and IFDs steady over {s.stable_polls} polls"
                    )
                elif _has_header(path):
                    whole = f"its size steady over {s.stable_polls} polls, its header written"
                if whole and isinstance(
                    exc, UnsupportedRawError | DamagedRawError | MonochromeRawError
                ):
                    raise CaptureError(
                        self.name,
                        f"{message}. The file is whole ({whole}), so waiting will not "
                        f"help; it is left in {shown_path(s.folder)}"
                        ", and no image was recorded for this "
                        "light",
                        "decode",
                    ) from exc
                tiff = isinstance(exc, ImageReadError) and exc.is_tiff
                if tiff and _not_a_tiff(path):
                    # its first bytes are written and no TIFF's, as the capture-time read
                    # already found: it had still been given timeout_s to change
                    raise self._damaged(
                        message,
                        path,
                        "is no TIFF (its first bytes are written and are not a TIFF header: a "
                        "damaged file, or another kind saved under a TIFF name)",
                    ) from exc
                if _text_file(path) and tried is not None and _identity(path) == tried:
                    # a sidecar (an XMP a raw developer writes beside each shot), a note: it
                    # had been given timeout_s to change, then "raise stable_polls", which
                    # cannot make text an image
                    raise self._damaged(
                        message,
                        path,
                        "is a text file, not an image (a sidecar such as an XMP, or a note), "
                        "and matches patterns",
                        f"Narrow patterns in [camera.device] (now {list(s.patterns)}) to the "
                        'camera\'s image files, such as "IMG_*.CR2" or "*.tif"',
                    ) from exc
                if isinstance(exc, ImageReadError) and exc.several:
                    # two full-size images, both written: more bytes cannot make one of them
                    # a thumbnail, and "is it complete?" or "damaged" would be untrue
                    raise self._damaged(
                        message,
                        path,
                        "is a whole TIFF that reads",
                        "In the program saving the shots, save one image per TIFF (a "
                        "thumbnail or preview page besides it is fine)",
                    ) from exc
                extent = tiff_extent(path) if tiff else None
                steady = tried is not None and _identity(path) == tried  # still what was read
                if (
                    isinstance(exc, ImageReadError)
                    and exc.compression is not None
                    and steady
                    and first_ifd(path) is not None  # the tag read is in an IFD all written
                ):
                    # a compression the reader does not decode is no damage: it had been
                    # called damaged, with advice to check the disk or share
                    raise self._damaged(
                        message,
                        path,
                        "is whole (its IFD written, its size steady)",
                        f"In the program saving the shots, {SAVE_READABLE}",
                    ) from exc
                if (
                    isinstance(exc, ImageReadError)
                    and exc.no_pixels
                    and steady
                    and tried is not None
                    # its IFD is there (a writer's or a copy's pause leaves it out: libtiff
                    # writes it last, tifffile's is zeros until its data is out) and names no
                    # data, data all inside the file, or holds entries no writer writes
                    and (ifd := first_ifd(path)) is not None
                    and (extent is None or extent[1] <= tried[2] or ifd.garbled)
                    # not a file a share sized first and is still filling (its end zeros)
                    and _tiff_end_written(path, 0, tried[2])
                ):
                    # its IFD, all written, reads as naming no image at all (damaged): before,
                    # an image of no pixels went on to the conversion, whose refusal named only
                    # its shape
                    raise self._damaged(
                        message,
                        path,
                        "is a damaged TIFF (its header and first IFD are written, but its IFDs "
                        "name no image data that reads)",
                        SAVE_AGAIN,
                    ) from exc
                if (
                    tiff
                    and steady
                    and tried is not None
                    and (garbage := ifd_garbage(path)) is not None
                    # not a file a share sized first and is still filling (its end zeros)
                    and _tiff_end_written(path, 0, tried[2])
                ):
                    # a header naming an IFD inside the file that holds what no writer on its
                    # way leaves (its slot zeros, or none named yet): it had been waited for
                    raise self._damaged(
                        message,
                        path,
                        f"is a damaged TIFF ({garbage}; its size steady over "
                        f"{s.stable_polls} polls)",
                        SAVE_AGAIN,
                    ) from exc
                if (
                    isinstance(exc, ImageReadError)
                    and exc.contradicts
                    and steady
                    and tried is not None
                    and (extent is None or extent[1] <= tried[2])
                    # not a file a share sized first and is still filling (its end zeros)
                    and _tiff_end_written(path, 0, tried[2])
                ):
                    # its own tags contradict each other (an RGB TIFF whose SamplesPerPixel
                    # is lost): it had been read as a one-channel image of the same size and
                    # gone into the session as if it were the picture the camera took
                    raise self._damaged(
                        message,
                        path,
                        f"is a damaged TIFF (its size steady over {s.stable_polls} polls, "
                        "its end written, but its tags contradict each other)",
                        SAVE_AGAIN,
                    ) from exc
                thumbnail = isinstance(exc, ImageReadError) and exc.thumbnail_only
                if (
                    extent is not None
                    and not thumbnail  # whole so far: libtiff links the full image's IFD last
                    and tried is not None
                    and steady
                    and extent[1] <= tried[2]
                    and _tiff_end_written(path, *extent)
                    and _tiff_end_written(path, 0, tried[2])
                ):
                    # every byte its IFDs name is written, its size steady over the
                    # stability polls, and it still will not decode: damaged, not half-written
                    raise self._damaged(
                        message,
                        path,
                        f"is a damaged TIFF (its header and the {extent[1]} bytes its structure "
                        f"names are all written, its size steady over {s.stable_polls} polls, "
                        "but its image data will not decode)",
                        SAVE_AGAIN,
                    ) from exc
                if tiff:
                    message += f": {COMPLETE_TIFF_ADVICE}"
                if thumbnail:
                    message += (
                        " If it is, have the program saving the shots save the full-size "
                        "image in it"
                    )
                failure = exc
            if not self._changed_and_settled(path, tried, deadline):
                raise CaptureError(
                    self.name,
                    f"{message}; {path.name} did not change within "
                    f"{s.timeout_s:g} s after that (if the program saving it pauses while "
                    "writing, raise stable_polls or poll_interval_s)",
                    "decode",
                ) from failure

    def _copy_gone(self, path: Path, held: Path) -> CaptureError:
        """The stop for a copy :meth:`_hold` made that was gone when it was to be decoded,
        naming the folder's file ``path`` and whether it is still left there.

        Why: the decoder's "RAW file not found" names the file it looked for, the session's
        hidden ``raw/.incoming`` copy, a file the user never saw, and said nothing of the
        folder's own file, which may well be there (waiting for it to change would not help:
        it is the copy that went)."""
        folder = self.settings.folder
        left = (
            f"{path.name} is left in {shown_path(folder)}"
            if _identity(path) is not None
            else (
                f"{path.name} is gone from {shown_path(folder)} too (moved or deleted by another "
                "program)"
            )
        )
        return CaptureError(
            self.name,
            f"{shown_path(path)} was taken as this light's image and copied into the session "
            f"({shown_path(held.parent)}), but that copy was removed or renamed before it could be "
            "decoded: keep other programs out of the session's folder. "
            f"{left}, and no image was recorded for this light",
            "decode",
        )

    def _hold(self, path: Path) -> Path:
        """Copy the file taken from the watched folder into the session (``output_dir``, its
        ``raw/.incoming``) and return the copy, which is decoded and kept; ``path`` itself
        when no session is bound.

        Why: the folder belongs to another program, and many move its files out (Lightroom's
        auto import, a sync tool) or rename them. The file had been decoded where it lay and
        copied at the step's commit, by then gone: the session stopped with "cannot write
        raw/image_001.dng: No such file or directory", as if the disk had failed, and the
        bytes kept need not have been the bytes decoded."""
        if self.output_dir is None:
            return path
        self.output_dir.mkdir(parents=True, exist_ok=True)
        dest, n = self.output_dir / path.name, 2
        while dest.exists():
            dest, n = self.output_dir / f"{path.stem}_{n}{path.suffix}", n + 1
        tmp = dest.with_name(f".{dest.name}.partial")
        try:
            shutil.copyfile(path, tmp)
            os.replace(tmp, dest)
        except OSError as exc:
            tmp.unlink(missing_ok=True)
            raise self._copy_failed(path, exc) from exc
        return dest

    def _copy_failed(self, path: Path, exc: OSError) -> CaptureError:
        """The stop for a taken file :meth:`_hold` could not copy into the session.

        Why: a copy the session's disk refused (full) was said as "it could not be copied into
        … ([Errno 28] …)": not where the shot is, nor what a resume does with it. The shot is
        still in the watched folder, but a resume takes every file already there as seen (an
        older file is never a light's image): it will not use it, and shoots the light again.
        """
        head = (
            f"{path.name} came into {shown_path(self.settings.folder)} and was taken as this "
            "light's image"
        )
        if isinstance(exc, FileNotFoundError) and not path.exists():
            return CaptureError(
                self.name,
                f"{head}, but it was moved or deleted before rti-rig could copy it: another "
                "program takes files out of the folder (an auto import?); have it copy them, "
                "or point it at another folder; no image was recorded for this light",
                "copy",
            )
        if exc.errno in (errno.ENOSPC, errno.EDQUOT, errno.EFBIG):
            why = "full, or over a quota or file-size limit"
            fix = "free space on that disk"
        elif exc.errno == errno.EROFS:
            why, fix = "read-only", "make that disk writable again"
        else:
            why, fix = exc.strerror or str(exc), "check that disk"
        return CaptureError(
            self.name,
            f"{head}, but the disk refused the copy ({why}) into the session's "
            f"{shown_path(self.output_dir)}; no image was recorded for this light. {path.name} is "
            f"still in {shown_path(self.settings.folder)}, but a resume will not use it (a file "
            "already in the folder when a run starts is never taken as a light's image): "
            f"{fix}, then resume, which shoots this light again",
            "copy",
        )

    def _without_alpha(
        self, path: Path, watched: Path, image: np.ndarray
    ) -> tuple[np.ndarray, str]:
        """``image`` (read from ``path``, the copy of ``watched``) with a TIFF's extra samples
        (alpha) dropped, and the notice saying so ("" when it had none); refused when the
        alpha is premultiplied (associated).

        Why: a tethering program may save grey + alpha (2 samples) or RGBA (4); grey + alpha
        had stopped the run with "expected an H×W or H×W×3 image". Unassociated alpha carries
        no light, so the grey or colour samples are the shot. Premultiplied alpha has scaled
        every sample by it: dropped, the pixels would be darker wherever alpha is below full,
        and nothing would say so. Which samples are the grey or colour ones is the header's
        count (SamplesPerPixel less ExtraSamples), never the array's: grey with two extra
        samples has three per pixel and had been recorded as an RGB of grey and extras."""
        if png_colour_type(path) in PNG_ALPHA_TYPES:  # its reader dropped the alpha
            return image, self._alpha_note("PNGs", "an alpha channel, which carries no light")
        extra = tiff_extra_samples(path)
        if not extra or image.ndim != 3:
            return image, ""
        colour = image.shape[2] - len(extra)
        if colour not in (1, 3):
            raise CaptureError(
                self.name,
                f"{watched.name} has {image.shape[2]} samples per pixel, {len(extra)} of them "
                f"extra (ExtraSamples), which leaves {colour} for the picture: neither grey (1) "
                "nor RGB (3); save it as grey or RGB without extra channels, then run again "
                "(a --resume of a session with images shoots this light again)",
                "decode",
            )
        if "associated" in extra:
            raise CaptureError(
                self.name,
                f"{watched.name} has premultiplied (associated) alpha: its grey or colour "
                "samples were multiplied by the alpha, so they are not the light the camera "
                "measured, and dropping the alpha would not give them back; save it without "
                "alpha (turn the alpha channel or transparency off in the tethering program's "
                "TIFF settings), then run again (a --resume of a session with images shoots "
                "this light again)",
                "decode",
            )
        # unassociated alpha carries no light; an unspecified extra sample is, by the TIFF's
        # own header, no part of its grey or colour picture: what it holds is not claimed
        kind = (
            "an alpha channel (ExtraSamples), which carries no light"
            if set(extra) == {"unassociated"}
            else "an extra channel of no stated use (ExtraSamples), which its header does not "
            "count as part of the grey or colour picture"
        )
        kept = image[..., :3] if colour == 3 else image[..., 0]
        return np.ascontiguousarray(kept), self._alpha_note("TIFFs", kind)

    @staticmethod
    def _alpha_note(files: str, kind: str) -> str:
        """The notice that ``kind`` (an alpha channel, or an extra one) of the watched
        ``files`` was dropped; each step's journal names its own file.

        Why: one wording for every image of every run, so the session says it once, with how
        many images it concerns (a PNG's alpha had been dropped unsaid; each run had named
        its own first file, so a resumed session said it twice, calling two files the
        first)."""
        return (
            f"the watched {files} have {kind}: it was dropped and the grey or colour samples "
            "recorded"
        )

    def _decode(
        self, path: Path, exposure_s: float, started: float, watched: Path | None = None
    ) -> Frame:
        """Decode ``path`` (the session's copy of ``watched``, the folder's file).

        Its refusals name ``watched`` (the file the user's program saved, left in the folder),
        never the copy, whose name may differ (``IMG_0001_2.dng`` beside an earlier copy)."""
        s = self.settings
        watched = watched or path
        if is_raw_file(path):
            decoded = decode_raw(path, s.decode, timestamp_s=started)
            pixels, white = decoded.pixels, decoded.white_level
            file_exposure = decoded.exposure_s or None
            gain = decoded.gain or s.gain
            metadata: dict[str, Any] = dict(decoded.metadata)
        else:
            image = read_image_file(path, self.name)
            # an 8-bit file whose ICC profile says a linear curve is linear data, as it says
            # (it had been refused as gamma-encoded, or read through the sRGB table)
            if (
                image.dtype == np.uint8
                and s.eight_bit_response == "refuse"
                and not file_colour(path).linear_curve
            ):
                raw = [x for x in s.patterns if Path(x).suffix.lower() in RAW_SUFFIXES]
                # patterns matching RAWs too: a camera saving RAW+JPEG whose JPEG came first
                # and was whole before its RAW appeared (being told to "save RAW" it already
                # did, the owner had nothing to change)
                fix = (
                    f"patterns {list(s.patterns)} match RAW files too: a camera saving RAW+JPEG "
                    f"may write its JPEG first, so match only the RAW (keep {raw} in patterns "
                    "in [camera.device])"
                    if raw
                    # the key's table named: "set eight_bit_response" alone left the owner
                    # to guess which of the config's tables takes it
                    else "save RAW or 16-bit TIFF, or, for a camera's sRGB JPEGs, add "
                    'eight_bit_response = "srgb" under [camera.device] in the rig config'
                )
                raise CaptureError(
                    self.name,
                    f"{watched.name} is 8-bit (gamma-encoded), not linear data: {fix}; "
                    f"{watched.name} is left in {shown_path(s.folder)}, and no image was "
                    "recorded for this light",
                    "decode",
                )
            image, alpha_note = self._without_alpha(path, watched, image)
            response = "linear" if s.eight_bit_response == "refuse" else s.eight_bit_response
            # what the file says of its colours (every file had been declared sRGB, an Adobe
            # RGB JPEG or a ProPhoto TIFF too); a grey image has no primaries to say: its TIFF
            # says linear grey
            colour = file_colour(path) if image.ndim == 3 and image.shape[2] >= 3 else None
            notices = [alpha_note] if alpha_note else []
            converted = None
            if colour is not None and needs_conversion(colour, image.dtype):
                # its own curve undone and its primaries made sRGB's: a 16-bit file had been
                # taken as linear whatever its curve (a ProPhoto TIFF's gamma 1.8)
                encoded = image.dtype == np.uint16 or response == "srgb"
                converted = to_linear_srgb(image, colour, encoded=encoded)
            if converted is not None:
                pixels, white = converted.pixels, 65535
            else:
                try:
                    pixels, white = to_linear_uint16(image, response, order="rgb")
                except ValueError as exc:
                    raise CaptureError(self.name, f"{watched.name}: {exc}", "decode") from exc
            file_exposure, gain = None, s.gain
            metadata = {"source_file": str(path), "bit_depth": 8 * image.dtype.itemsize}
            metadata.update(exposure_stats(pixels, white, s.decode.underexposed_level))
            if colour is not None:
                metadata["file_colour"] = colour.as_dict()
                said = file_colour_notice(colour, bits=8 * image.dtype.itemsize)
                if converted is not None:
                    metadata["file_colour"].update(converted.record)
                    if colour.space != "srgb":  # an sRGB file's own words stand (Exif-only)
                        said = converted_notice(colour)
                    if converted.clipped:
                        notices.append(clipped_notice(colour))
                if said:
                    notices.append(said)
            suffix = path.suffix.lower()
            turned = (
                jpeg_orientation(path)
                if suffix in JPEG_SUFFIXES
                else tiff_orientation(path)
                if suffix in TIFF_SUFFIXES
                else None
            )
            if turned not in (None, 1):
                kind = "JPEG" if suffix in JPEG_SUFFIXES else "TIFF"
                happened, undone = orientation_words(turned)
                notices.append(
                    f"{happened} (Orientation tag {turned}: "
                    f"{ORIENTATION_NAMES.get(turned, 'not a known value')}): rti-rig keeps "
                    f"the {kind}'s pixels as stored, so these images are not {undone} as "
                    "a viewer shows the watched folder's files; the .lp light directions "
                    "are in the same (stored) frame, so fitting is unaffected "
                    "(docs/cameras.md)"
                )
            if notices:
                metadata["notices"] = notices
        if file_exposure is not None and s.exposure_tolerance is not None:
            rel = abs(file_exposure - exposure_s) / exposure_s
            if rel > s.exposure_tolerance:
                raise CaptureError(
                    self.name,
                    f"{watched.name} was exposed {file_exposure:g} s but {exposure_s:g} s was "
                    "asked: set the camera to manual at the session exposure",
                    "check exposure",
                )
        metadata.update(
            {
                "camera": self.name,
                # the session copies the file under raw/ with its own name (the watched
                # folder belongs to another program)
                "originals": [{"path": str(path), "name": watched.name}],
                "watched_file": str(watched),
                "exposure_requested_s": exposure_s,
                "exposure_source": "file" if file_exposure else "requested",
                "capture_started_s": started,
                "capture_finished_s": self._clock.now(),
            }
        )
        return Frame(
            pixels=pixels,
            exposure_s=file_exposure or exposure_s,
            gain=float(gain),
            white_level=white,
            timestamp_s=started,
            metadata=metadata,
        )
