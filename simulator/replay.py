"""A recorded acquisition replayed: the camera returns the image recorded for the light fired.

With the simulated dome of the same `.lp`, a real acquisition becomes a rig, so that every
planner (adaptive or not) can be rehearsed on real data. What the session then holds:

* **The recorded files, byte for byte**: each frame hands its recorded file to the session as
  the step's camera original (``metadata["originals"]``, marked ``"copy"``: the user's file is
  copied, never moved), which the session keeps under ``raw/`` with the step's name and its
  sha256 journaled, as a watched folder's or a DSLR's files. Whatever its format, the session
  holds the real image; the files below are the session's own, made from its pixels.
* **16-bit sources** (linear TIFF or PNG): the frame *is* the recorded pixels, so the session's
  linear TIFF holds exactly the source's pixels (and, for a source written by rti-rig, the same
  bytes: same writer, same settings).
* **8-bit sources** (JPEG): a JPEG cannot be re-encoded to the same bytes, and the session's
  Frame is linear 16-bit. The decoded 8-bit pixels are mapped through :data:`SRGB8_TO_LINEAR16`,
  a table chosen so that the session's own sRGB encoding
  (:func:`rti_rig.core.image_files.linear_to_srgb8`) gives back exactly the decoded pixels: the
  session's linear TIFF, encoded as the session encodes it, is pixel-identical to the decoded
  source JPEG. The session's JPEG is a re-encoding (quality 95) and is not byte-identical
  (the source's bytes are its copy in ``raw/``).
* **Sources in another known space** (an Adobe RGB, ProPhoto or Display P3 file, or a 16-bit
  file said to be sRGB-encoded): their curve is undone and their primaries converted to sRGB's
  (:mod:`~rti_rig.drivers.cameras.colour_convert`), so the frames the fits read are linear
  sRGB as the session says; the byte-for-byte copies under ``raw/`` are untouched. Untagged or
  sRGB sources (and rti-rig's own linear TIFFs, whose profile is linear) are replayed as above.

**The recorded codes' own white**: 16-bit files of 10- or 12-bit camera data (white 4095,
or 65520 shifted up) are handed over as recorded, with the white level the application reads
from the acquisition as the camera connects (``white_reading``, :func:`rti_rig.app.usecases.
fit_full_scale.recorded_full_scale`; the simulator may not import the reading itself). The
session's labels, previews, QA and fit then judge them against it; each frame says so among
its notices. A resumed session keeps the white its images so far are labelled with
(:meth:`ReplayCamera.bind_session`), unread: one session, one white level.

Exposure is not modelled: the recorded image is returned whatever exposure is asked (it is
noted in the frame's metadata). Capturing advances the injected clock as a camera would.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Protocol

import numpy as np
from numpy.typing import NDArray

from rti_rig.core.clock import Clock
from rti_rig.core.devices import Frame
from rti_rig.core.errors import CaptureError, SessionError
from rti_rig.core.image_files import linear_tiff_white_level, linear_to_srgb8, read_image_any
from rti_rig.core.shell_words import shown_path
from rti_rig.drivers.cameras.colour_convert import (
    Converted,
    clipped_notice,
    converted_notice,
    needs_conversion,
    to_linear_srgb,
)
from rti_rig.drivers.cameras.file_colour import FileColour, file_colour, file_colour_notice

WHITE = 65535


def _srgb8_to_linear16() -> NDArray[np.uint16]:
    """For each 8-bit code, the middle 16-bit linear value that the session encodes back to it
    (the white level for 255: clipped stays clipped)."""
    codes = linear_to_srgb8(np.arange(WHITE + 1, dtype=np.uint16), WHITE)
    table = np.zeros(256, dtype=np.uint16)
    for v in range(256):
        hits = np.flatnonzero(codes == v)
        if hits.size == 0:  # pragma: no cover - the sRGB curve reaches every code at 16 bits
            raise AssertionError(f"8-bit code {v} has no 16-bit linear value")
        table[v] = hits[hits.size // 2]
    # A clipped 8-bit pixel stays clipped: the top code maps to the white level (which encodes
    # back to 255 too), not to the middle of its range, where it would pass for a valid
    # reading and the fit's saturation masks and the QA's "saturated" check would miss it.
    table[255] = WHITE
    return table


#: 8-bit sRGB code → 16-bit linear value that ``linear_to_srgb8`` maps back to the same code.
SRGB8_TO_LINEAR16 = _srgb8_to_linear16()


def recorded_frame_pixels(path: Path) -> NDArray[np.uint8] | NDArray[np.uint16]:
    """The recorded image's values as its file stores them (8- or 16-bit, RGB order): made
    linear by :func:`linear_frame`, by what the file says of its colours."""
    return read_image_any(path)


def linear_frame(
    img: NDArray[np.uint8] | NDArray[np.uint16], colour: FileColour | None
) -> tuple[NDArray[np.uint16], Converted | None]:
    """The recorded values as a linear 16-bit frame (see the module docstring), and the
    conversion made (None: none). A file in a known space other than sRGB, or a 16-bit one
    said to be sRGB-encoded, is converted by its own curve and primaries (an Adobe RGB JPEG
    had been undone by the sRGB curve, a ProPhoto TIFF taken as linear); an sRGB or untagged
    8-bit one goes through :data:`SRGB8_TO_LINEAR16`, a 16-bit one untagged or with a linear
    profile (a session's own) is taken as stored, so those replay pixel-identical."""
    if colour is not None and needs_conversion(colour, img.dtype):
        converted = to_linear_srgb(img, colour)
        return converted.pixels, converted
    if img.dtype == np.uint8:
        return SRGB8_TO_LINEAR16[img], None
    return img.astype(np.uint16, copy=False), None


def session_white_level(root: Path) -> int | None:
    """The white level a session's linear TIFFs so far are labelled with (the first that says
    one), or None for a session with none yet."""
    for tiff in sorted((root / "linear").glob("*.tif")):
        level = linear_tiff_white_level(tiff)
        if level is not None:
            return level
    return None


def _sha256(path: Path) -> str | None:
    """The file's SHA-256, or None where it cannot be read."""
    import hashlib

    try:
        with open(path, "rb") as fh:
            return hashlib.file_digest(fh, "sha256").hexdigest()
    except OSError:
        return None


def _stamp(path: Path) -> tuple[int, int, int] | None:
    """A file's size, mtime and ctime (ns), or None where it cannot be read."""
    try:
        st = path.stat()
    except OSError:
        return None
    return st.st_size, st.st_mtime_ns, st.st_ctime_ns


class LitLed(Protocol):
    """What the replay camera needs of the dome: which LED is lit (``None`` when all are off)."""

    lit: int | None


class ReplayCamera:
    """Returns the recorded image of the LED the dome has lit (one image per LED, in order)."""

    def __init__(
        self,
        images: Sequence[Path],
        dome: LitLed,
        clock: Clock,
        *,
        shape: tuple[int, ...],
        readout_s: float = 0.3,
        transfer_s: float = 0.7,
        names: Sequence[str] | None = None,
        digests: Sequence[str | None] | None = None,
        white_reading: Callable[[], tuple[int, str | None]] | None = None,
    ) -> None:
        self.name = "replay camera"
        #: the recorded codes' white (65535 unless read otherwise) and what says so, read as
        #: the camera connects by ``white_reading`` unless a resumed session's labels said it
        self._white = WHITE
        self._white_notice: str | None = None
        self._white_reading = white_reading
        #: each recorded file's SHA-256 as the run began (None: not known)
        self._digests = list(digests) if digests is not None else [None] * len(images)
        self._images = [Path(p) for p in images]
        # each image's name as the session records it: its path relative to the .lp (two
        # files of one name in two subfolders had both been recorded by their file name)
        self._names = [str(n) for n in names] if names is not None else None
        self._dome = dome
        self._clock = clock
        self._shape = shape
        self._readout_s = readout_s
        self._transfer_s = transfer_s
        self._connected = False
        #: each recorded file's (size, mtime_ns, ctime_ns) as the run opened the camera
        self._stamps: list[tuple[int, int, int] | None] = []

    def bind_session(self, root: Path) -> None:
        """A resumed session keeps the white level its images so far are labelled with (the
        acquisition is not read again): its fit and verdict judge every image against one."""
        kept = session_white_level(Path(root))
        if kept is None:
            return
        self._white_reading = None
        self._white = kept
        self._white_notice = (
            None
            if kept == WHITE
            else f"replayed with white level {kept}, not 65535, as this session's images so far "
            "are labelled; if the camera's white level is another, fit the session with "
            "--white-level N"
        )

    def connect(self) -> None:
        # taken as the rig opens, just after the session hashed the acquisition for its
        # manifest: a file rewritten since then is told at its step
        self._stamps = [_stamp(p) for p in self._images]
        if self._white_reading is not None:
            self._white, self._white_notice = self._white_reading()
            self._white_reading = None
        self._connected = True

    def _refuse_changed(self, lit: int) -> None:
        """Refuse the step of a recorded file changed since the run began: it had been
        copied into the session as it was then, the manifest still recording the file the run
        began with, and nothing said (QA, 2026-12-06). A resume hashes the whole acquisition
        and refuses a changed one; within a run, a file whose stamp moved (a write, a
        replacement; also a chmod, a sync client's tag, a backup's hard link, which change
        nothing in it) is hashed and judged by its bytes against the digest of the run's
        start."""
        path = self._images[lit]
        before = self._stamps[lit] if lit < len(self._stamps) else None
        now = _stamp(path)
        if before is None or now in (before, None):  # a file gone: _recorded says so
            return
        expected = self._digests[lit] if lit < len(self._digests) else None
        if expected is None or _sha256(path) in (expected, None):
            self._stamps[lit] = now  # the same bytes: not hashed again
            return
        raise CaptureError(
            self.name,
            f"the recorded file {shown_path(path)} was changed since this run began (its bytes "
            "differ from those the run began with: written or replaced while the acquisition "
            "was replayed): the session would mix two "
            "versions of the acquisition. Put the file back as it was, from a copy, and "
            "resume; or start a new session from the acquisition as it is now",
            "capture",
        )

    def close(self) -> None:
        self._connected = False

    def _recorded(self, path: Path) -> NDArray[np.uint8] | NDArray[np.uint16]:
        """The recorded image at ``path``; one gone since the run began (its drive unplugged,
        the file moved or deleted) is the camera's failure, naming the file and what brings
        it back (it had been a bare "cannot read image …: there is no such file")."""
        try:
            return recorded_frame_pixels(path)
        except (OSError, SessionError) as exc:
            if path.is_file():
                if not isinstance(exc, OSError):
                    raise  # there, but not readable as an image: the reader's words say why
                # there, but the system refused its read: its own reason, not "moved or
                # deleted?" of a file still in its place (a permission, a failing drive's EIO)
                raise CaptureError(
                    self.name,
                    f"cannot read the recorded file {shown_path(path)}: "
                    f"{exc.strerror or exc}; make it readable (for an I/O error, check the "
                    "drive that holds it), then resume",
                    "capture",
                ) from None
            raise CaptureError(
                self.name,
                f"cannot read the recorded file {shown_path(path)}, there when the run began "
                "(its drive unplugged, or the file moved or deleted?): re-attach the drive "
                "that holds it, or put the file back there, then resume",
                "capture",
            ) from None

    def capture(self, exposure_s: float) -> Frame:
        if not self._connected:
            raise CaptureError(self.name, "not connected; call connect() first", "capture")
        t0 = self._clock.now()
        lit = self._dome.lit
        if lit is None:  # no recorded dark frame: a black one
            pixels = np.zeros(self._shape, dtype=np.uint16)
            source = None
        else:
            path = self._images[lit]
            self._refuse_changed(lit)
            stored = self._recorded(path)
            self._refuse_changed(lit)  # and not while it was read
            colour = file_colour(path) if stored.ndim == 3 else None
            pixels, converted = linear_frame(stored, colour)
            if pixels.shape[:2] != self._shape[:2]:
                raise CaptureError(
                    self.name,
                    f"{shown_path(path)} is {pixels.shape[1]}x{pixels.shape[0]} but the "
                    f"acquisition's first image is {self._shape[1]}x{self._shape[0]}: one "
                    "acquisition, one size",
                    "capture",
                )
            source = str(path)
        self._clock.sleep(exposure_s + self._readout_s + self._transfer_s)
        metadata: dict[str, object] = {
            "source": "replay",
            "replayed_image": source,
            "exposure_modelled": False,
        }
        if source is not None:
            # the recorded file is the step's camera file: the session copies it whole under
            # raw/ with its checksum, as a watched folder's or a DSLR's (an 8-bit JPEG's own
            # bytes cannot be re-encoded: without this a replay held only a re-encoding)
            # ("copy": the user's file, never moved, wherever it lies)
            name = self._names[lit] if self._names is not None else path.name
            metadata["originals"] = [{"path": source, "name": name, "copy": True}]
            notices: list[str] = []
            if colour is not None:  # what the recorded file says of its colours, as said
                metadata["file_colour"] = colour.as_dict()
                said = file_colour_notice(
                    colour, "the replayed files", bits=8 * stored.dtype.itemsize
                )
                if converted is not None:
                    metadata["file_colour"].update(converted.record)
                    if colour.space != "srgb":
                        said = converted_notice(colour, "the replayed files")
                    if converted.clipped:
                        notices.append(clipped_notice(colour))
                if said:
                    notices.insert(0, said)
            if self._white_notice:
                notices.append(self._white_notice)
            if notices:
                metadata["notices"] = notices
        return Frame(
            pixels=pixels,
            exposure_s=exposure_s,
            gain=1.0,
            white_level=self._white,
            timestamp_s=t0,
            metadata=metadata,
        )
