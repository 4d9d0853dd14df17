"""The full scale a fit and its QA judge an acquisition's 16-bit images against.

Why here: the reading itself is pure (:mod:`rti_rig.reconstruct.full_scale`); this module
samples the opened frames in their own codes, decides whether the reading applies (an
acquisition from elsewhere, 16-bit throughout) and checks a ``--white-level`` given by the
user against the images, naming the image that disagrees.
"""

from __future__ import annotations

from collections.abc import Collection, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from rti_rig.core.errors import RtiRigError
from rti_rig.core.shell_words import shown_path
from rti_rig.reconstruct.full_scale import FullScale, full_scale_of
from rti_rig.reconstruct.signal_check import sample_grid, sample_pixels
from rti_rig.runtime.session import JOURNAL, MANIFEST

#: How rti-rig's own linear TIFFs begin their ImageDescription (scaled to 65535 as shot).
OWN_TIFF_LABEL = "rti-rig:"


def sampled_codes(frames: Sequence[Any]) -> NDArray[np.uint16]:
    """The frames' own codes on the fit's sample grid (N, P, C), read a sampled row at a time
    (the frames are row-readable: nothing is read whole)."""
    first = frames[0]
    h, w = int(first.shape[0]), int(first.shape[1])
    channels = int(np.prod(first.shape[2:], dtype=int))
    rows, cols = sample_grid(h, w, sample_pixels(len(frames), channels))
    out = np.empty((len(frames), rows.size * cols.size, channels), np.uint16)
    for i, frame in enumerate(frames):
        for k, r in enumerate(rows):
            row = np.asarray(frame[int(r) : int(r) + 1])[0, cols]
            out[i, k * cols.size : (k + 1) * cols.size] = row.reshape(cols.size, channels)
    return out


def stored_8_bit(frame: Any) -> bool:
    """Whether a frame of the fit's ``_open_frames`` holds 8-bit (sRGB-encoded) pixels."""
    return bool(getattr(frame, "stored", np.dtype(frame.dtype)) == np.uint8)


def _own_session(source: Path, frames: Sequence[Any]) -> bool:
    """An rti-rig session (its record beside the .lp, or its own labelled TIFFs): its camera's
    range was scaled to 65535 as it was shot."""
    folder = source if source.is_dir() else source.parent
    if (folder / JOURNAL).is_file() or (folder / MANIFEST).is_file():
        return True
    return any(str(getattr(f, "description", "")).startswith(OWN_TIFF_LABEL) for f in frames)


def acquisition_full_scale(
    frames: Sequence[Any],
    names: Sequence[str],
    source: Path,
    given: int | None,
    converted: Collection[str] = (),
) -> FullScale | None:
    """The full scale to fit and judge ``frames`` against, or None for the frames' own (65535
    for 16-bit, 255 for 8-bit). ``given``: ``--white-level``, checked against the images;
    ``converted``: the names of images converted from the colour space their file says (their
    values are rti-rig's linear sRGB on 65535, no longer the camera's codes)."""
    eight = [names[i] for i, f in enumerate(frames) if stored_8_bit(f)]
    if given is not None:
        if not 1 <= given <= 65535:
            raise RtiRigError(f"--white-level {given}: give a code value from 1 to 65535")
        if eight or converted:
            name, why = (
                (eight[0], "8-bit (its white is 255, read through the sRGB curve)")
                if eight
                else (
                    sorted(converted)[0],
                    "converted from the colour space its file says (an encoded curve and "
                    "primaries, not a camera's linear codes)",
                )
            )
            raise RtiRigError(
                f"--white-level is for 16-bit linear images; {name} of {shown_path(source)} "
                f"is {why}: leave --white-level out"
            )
        codes = sampled_codes(frames)
        top = codes.reshape(len(frames), -1).max(axis=1)
        over = int(np.argmax(top))
        if int(top[over]) > given:
            raise RtiRigError(
                f"--white-level {given}: {names[over]} of {shown_path(source)} holds "
                f"{int(top[over])}, "
                "above it; give the camera's white level (the largest value its files can "
                "hold), or leave --white-level out to have it read from the images"
            )
        return FullScale(given, "given", None, int(codes.max()))
    if eight or converted or any(np.dtype(f.dtype) != np.uint16 for f in frames):
        return None
    if _own_session(source, frames):
        return None
    return full_scale_of(sampled_codes(frames), names)
