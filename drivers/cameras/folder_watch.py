"""A camera fired by someone else: wait for its next file in a folder, with a timeout.

Why: many domes wire the camera's remote-shutter line to the dome controller, and some cameras
are only driven by their vendor's tethering program. rti-rig then cannot *take* a picture, only
*notice* it: the file that appears after the light was switched on is that light's frame.
Files present at ``connect`` are ignored; each file is used once; a file counts only when its
size has stopped changing (the writer may still be copying it). Optionally an injected
``trigger(exposure_s)`` fires the shutter (e.g. the dome driver's shutter-line command).

Safe state: nothing to release (no device handle); ``close`` forgets the seen files.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from rti_rig.core.clock import Clock, SystemClock
from rti_rig.core.devices import Frame
from rti_rig.core.errors import CaptureError, DeviceError
from rti_rig.drivers.cameras.image_io import read_image_file, to_linear_uint16
from rti_rig.drivers.cameras.raw_decode import decode_raw, exposure_stats
from rti_rig.drivers.cameras.settings import FolderWatchSettings

RAW_SUFFIXES = {
    ".dng",
    ".cr2",
    ".cr3",
    ".crw",
    ".nef",
    ".nrw",
    ".arw",
    ".srf",
    ".sr2",
    ".orf",
    ".rw2",
    ".raf",
    ".pef",
    ".srw",
    ".3fr",
    ".iiq",
    ".erf",
    ".kdc",
    ".mos",
    ".x3f",
}


class TriggerUnconfirmed(Exception):
    """The trigger was sent but its confirmation was lost (e.g. the dome's reply to a shutter
    pulse timed out): the camera may well have fired. The pulse is never resent (that could
    take a second picture); the camera waits for the file, and only if none comes is it an
    error."""


def is_raw_file(path: Path) -> bool:
    """True for file names LibRaw should decode (by suffix)."""
    return path.suffix.lower() in RAW_SUFFIXES


class FolderWatchCamera:
    """Implements the ``Camera`` protocol by waiting for new files in a folder."""

    def __init__(
        self,
        settings: FolderWatchSettings,
        clock: Clock | None = None,
        trigger: Callable[[float], None] | None = None,
    ) -> None:
        self.settings = settings
        self.name = settings.name
        self._clock = clock or SystemClock()
        self._trigger = trigger
        self._seen: set[str] | None = None

    def connect(self) -> None:
        folder = self.settings.folder
        if not folder.is_dir():
            raise DeviceError(
                self.name,
                f"watched folder {folder} does not exist or is not a "
                "folder; create it or fix 'folder' in the rig config",
                "connect",
            )
        self._seen = {p.name for p in self._matching()}

    def close(self) -> None:
        self._seen = None

    def __enter__(self) -> FolderWatchCamera:
        self.connect()
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def _matching(self) -> list[Path]:
        found: dict[str, Path] = {}
        for pattern in self.settings.patterns:
            for p in self.settings.folder.glob(pattern):
                if p.is_file():
                    found[p.name] = p
        return list(found.values())

    def _new_files(self, seen: set[str]) -> list[Path]:
        new = []
        for p in self._matching():
            if p.name in seen:
                continue
            try:
                new.append((p.stat().st_mtime_ns, p.name, p))
            except FileNotFoundError:  # removed between glob and stat
                continue
        return [p for _, _, p in sorted(new)]

    def wait_for_file(self) -> Path:
        """Block (on the injected clock) until the next complete new file, or time out."""
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
                    self._seen.add(path.name)
                    return path
            if self._clock.now() - start >= s.timeout_s:
                growing = f"; {last[0]} appeared but was still being written" if last else ""
                raise CaptureError(
                    self.name,
                    f"no new file matching {list(s.patterns)} in {s.folder} within "
                    f"{s.timeout_s:g} s{growing}: is the camera firing and saving there?",
                    "wait for file",
                )
            self._clock.sleep(s.poll_interval_s)

    def capture(self, exposure_s: float) -> Frame:
        """Fire the trigger (if any), wait for the file, decode it to a linear frame."""
        if self._seen is None:
            raise CaptureError(self.name, "not connected; call connect() first", "capture")
        started = self._clock.now()
        unconfirmed: str | None = None
        if self._trigger is not None:
            try:
                self._trigger(exposure_s)
            except TriggerUnconfirmed as exc:
                unconfirmed = str(exc)
        try:
            path = self.wait_for_file()
        except CaptureError as exc:
            if unconfirmed is None:
                raise
            raise CaptureError(
                self.name,
                f"{exc.message}; the trigger was not confirmed either ({unconfirmed})",
                "wait for file",
            ) from exc
        frame = self._decode(path, exposure_s, started)
        if unconfirmed is not None:
            frame.metadata["trigger_unconfirmed"] = unconfirmed
            frame.metadata.setdefault("notices", [])
            frame.metadata["notices"] = [
                *frame.metadata["notices"],
                "the trigger's confirmation was lost but the camera's file arrived",
            ]
        return frame

    def _decode(self, path: Path, exposure_s: float, started: float) -> Frame:
        s = self.settings
        if is_raw_file(path):
            decoded = decode_raw(path, s.decode, timestamp_s=started)
            pixels, white = decoded.pixels, decoded.white_level
            file_exposure = decoded.exposure_s or None
            gain = decoded.gain or s.gain
            metadata: dict[str, Any] = dict(decoded.metadata)
        else:
            image = read_image_file(path, self.name)
            if image.dtype == np.uint8 and s.eight_bit_response == "refuse":
                raise CaptureError(
                    self.name,
                    f"{path.name} is 8-bit (gamma-encoded), not linear data: save RAW or 16-bit "
                    "TIFF, or set eight_bit_response = 'srgb'",
                    "decode",
                )
            response = "linear" if s.eight_bit_response == "refuse" else s.eight_bit_response
            try:
                pixels, white = to_linear_uint16(image, response, order="rgb")
            except ValueError as exc:
                raise CaptureError(self.name, f"{path.name}: {exc}", "decode") from exc
            file_exposure, gain = None, s.gain
            metadata = {"source_file": str(path), "bit_depth": 8 * image.dtype.itemsize}
            metadata.update(exposure_stats(pixels, white, s.decode.underexposed_level))
        if file_exposure is not None and s.exposure_tolerance is not None:
            rel = abs(file_exposure - exposure_s) / exposure_s
            if rel > s.exposure_tolerance:
                raise CaptureError(
                    self.name,
                    f"{path.name} was exposed {file_exposure:g} s but {exposure_s:g} s was "
                    "asked: set the camera to manual at the session exposure",
                    "check exposure",
                )
        metadata.update(
            {
                "camera": self.name,
                # the session copies the file under raw/ with its own name (the watched
                # folder belongs to another program)
                "originals": [{"path": str(path), "name": path.name}],
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
