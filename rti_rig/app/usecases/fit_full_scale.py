"""The full scale a fit and its QA judge an acquisition's 16-bit images against.

Why here: the reading itself is pure (:mod:`rti_rig.reconstruct.full_scale`); this module
samples the opened frames in their own codes, decides whether the reading applies (an
acquisition from elsewhere, 16-bit throughout) and checks a ``--white-level`` given by the
user against the images, naming the image that disagrees. An rti-rig session's images are
judged by what their labels say (65535, but the recorded codes' own white for a replay of
camera data: :func:`recorded_full_scale` reads it for the replay rig and ``bench tradeoff
--from``, as the fit reads it here).
"""

from __future__ import annotations

from collections.abc import Collection, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from rti_rig.core.errors import RtiRigError
from rti_rig.core.image_files import OWN_TIFF_LABEL, labelled_white_level
from rti_rig.core.shell_words import shown_path
from rti_rig.reconstruct.full_scale import FullScale, bits_of, full_scale_of
from rti_rig.reconstruct.signal_check import sample_grid, sample_pixels
from rti_rig.runtime.session import JOURNAL, MANIFEST

__all__ = [
    "OWN_TIFF_LABEL",
    "acquisition_full_scale",
    "recorded_full_scale",
    "sampled_codes",
    "stored_8_bit",
]


def _sample_into(out: NDArray[np.uint16], frame: Any, rows: Any, cols: Any) -> None:
    """One frame's codes on the sample grid into ``out`` (P, C), a sampled row at a time."""
    channels = out.shape[-1]
    for k, r in enumerate(rows):
        row = np.asarray(frame[int(r) : int(r) + 1])[0, cols]
        out[k * cols.size : (k + 1) * cols.size] = row.reshape(cols.size, channels)


def _grid(shape: Sequence[int], images: int) -> tuple[Any, Any, int]:
    """The fit's sample grid (rows, cols) of ``images`` images of ``shape``, and channels."""
    channels = int(np.prod(shape[2:], dtype=int))
    rows, cols = sample_grid(int(shape[0]), int(shape[1]), sample_pixels(images, channels))
    return rows, cols, channels


def sampled_codes(frames: Sequence[Any]) -> NDArray[np.uint16]:
    """The frames' own codes on the fit's sample grid (N, P, C), read a sampled row at a time
    (the frames are row-readable: nothing is read whole)."""
    rows, cols, channels = _grid(frames[0].shape, len(frames))
    out = np.empty((len(frames), rows.size * cols.size, channels), np.uint16)
    for i, frame in enumerate(frames):
        _sample_into(out[i], frame, rows, cols)
    return out


def stored_8_bit(frame: Any) -> bool:
    """Whether a frame of the fit's ``_open_frames`` holds 8-bit (sRGB-encoded) pixels."""
    return bool(getattr(frame, "stored", np.dtype(frame.dtype)) == np.uint8)


def _own_session(source: Path, frames: Sequence[Any]) -> bool:
    """An rti-rig session (its record beside the .lp, or its own labelled TIFFs): its camera's
    range was scaled to 65535 as it was shot, but for a replay's codes kept as recorded, whose
    white its labels state (:func:`labelled_full_scale_of`)."""
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
    if eight and given is None and _own_session(source, frames):
        _refuse_mixed_scales(frames, names, eight, source)
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
        return labelled_full_scale(frames, names, source)
    codes = sampled_codes(frames)
    return _with_header(full_scale_of(codes, names), [_stored_bits(f) for f in frames], codes)


def _stored_bits(frame: Any) -> int | None:
    """The bits a sample ``frame``'s file stores, by its header (None: not known)."""
    from rti_rig.core.image_files import header_bit_depth

    where = getattr(frame, "path", None) or getattr(frame, "name", None)
    return header_bit_depth(Path(where)) if where else None


def _with_header(
    full: FullScale | None, bits: Sequence[int | None], codes: NDArray[np.uint16]
) -> FullScale | None:
    """``full``, or the depth the files' headers say where it is below 16 bits and the data
    showed no clip (a TIFF of 12 bits a sample: white 4095, however dark its images; the
    data's own "bits" reading had called a dark one 10-bit)."""
    known = [b for b in bits if b in _WIDE_BITS]
    depth = max(known, default=16)
    if len(known) != len(bits) or depth >= 16 or (full is not None and full.how != "bits"):
        return full
    return FullScale((1 << depth) - 1, "header", depth, int(codes.max()))


def _refuse_mixed_scales(
    frames: Sequence[Any], names: Sequence[str], eight: Sequence[str], source: Path
) -> None:
    """Refuse a session whose TIFFs are labelled with a white below 65535 (a replay of 12-bit
    data) where an image's 8-bit JPEG stands in for its lost linear TIFF: the JPEG was encoded
    against that white and decodes onto 65535, 16× the TIFFs' scale, and one fit of both would
    judge neither right (nor see the clip at 4095)."""
    wide = [(n, f) for n, f in zip(names, frames, strict=True) if not stored_8_bit(f)]
    try:
        level = labelled_full_scale_of([f for _, f in wide], [n for n, _ in wide], source)
    except RtiRigError:
        return  # two levels: said by the reading that follows
    if level is None:
        return
    raise RtiRigError(
        f"{shown_path(source)}: {eight[0]} is read from its 8-bit JPEG (its linear TIFF is "
        f"missing or cut short), but the session's TIFFs hold codes on white {level} (their "
        "labels say so: a replay of camera data kept as recorded), which the JPEG is not on; "
        "put the linear TIFF back from a backup copy of the session, or replay the "
        "acquisition again into a new session"
    )


def labelled_full_scale(
    frames: Sequence[Any], names: Sequence[str], source: Path
) -> FullScale | None:
    """The white level an rti-rig session's TIFF labels state where it is not 65535 (a replay
    of 12-bit camera data keeps the recorded codes, white 4095, and says so in each label), or
    None (:func:`labelled_full_scale_of`)."""
    level = labelled_full_scale_of(frames, names, source)
    if level is None:
        return None
    return _labelled(level, int(sampled_codes(frames).max()))


def _labelled(level: int, brightest: int) -> FullScale:
    """A labelled white level as a reading: its depth where it is one's top code, unscaled or
    shifted up (65520: 12-bit data shifted by 4)."""
    shift = (65536 - level).bit_length() - 1 if level > 4095 else 0
    return FullScale(level, "labelled", bits_of(level, shift), brightest)


def _opened(path: Path, bits: int | None) -> Any:
    """``path`` for sampling: an uncompressed 16-bit TIFF read in place (rows), else decoded
    (a TIFF of 12 bits a sample is packed: its rows cannot be taken in place)."""
    from rti_rig.core.image_files import read_image_any
    from rti_rig.core.tiff_rows import TiffRows

    if path.suffix.lower() in (".tif", ".tiff") and bits == 16:
        rows = TiffRows(path)
        if rows.dtype == np.uint16 and rows.reads_in_place:
            return rows
    return read_image_any(path)


#: The sample depths of files a replay hands over as 16-bit codes (a TIFF may store 10, 12 or
#: 14 bits a sample, decoded to uint16 values up to 2^bits - 1).
_WIDE_BITS = (10, 12, 14, 16)


def recorded_full_scale(
    folder: Path, paths: Sequence[Path], names: Sequence[str]
) -> FullScale | None:
    """The full scale of a recorded acquisition's files as a replay hands them over (their
    own codes, unscaled), or None for 65535 (or 255): read as the fit reads an acquisition's
    (:func:`acquisition_full_scale`), one file at a time (a compressed one decoded, sampled and
    let go). ``folder``: the .lp's (a session's record there makes it rti-rig's own, judged by
    its labels). Not read (None) where any file is 8-bit or converted by the replay from the
    colour space it says (its frame is linear sRGB on 65535), nor where two labels disagree
    (replayed at 65535, as before).

    Why: a replay of 12-bit camera data in 16-bit files handed its codes over as on 65535:
    its session's previews were 16× too dark, its QA and fit read no clip at 4095, and an
    adaptive run weighed clipped highlights as light."""
    from rti_rig.app.config import converted_by_replay
    from rti_rig.core.image_files import header_bit_depth

    bits = [header_bit_depth(p) for p in paths]
    if not paths or any(b not in _WIDE_BITS for b in bits):
        return None
    if any(converted_by_replay(p) for p in paths):
        return None
    first = _opened(paths[0], bits[0])
    rows, cols, channels = _grid(first.shape, len(paths))
    codes = np.empty((len(paths), rows.size * cols.size, channels), np.uint16)
    described: list[Any] = []
    for i, path in enumerate(paths):
        frame = first if i == 0 else _opened(path, bits[i])
        if frame.shape != first.shape or np.dtype(frame.dtype) != np.uint16:
            return None  # the replay refuses such a file at its step, in its own words
        _sample_into(codes[i], frame, rows, cols)
        described.append(_Described(str(getattr(frame, "description", ""))))
    if _own_session(folder, described):
        try:
            said = labelled_full_scale_of(described, names, folder)
        except RtiRigError:
            return None
        return None if said is None else _labelled(said, int(codes.max()))
    return _with_header(full_scale_of(codes, names), bits, codes)


class _Described:
    """A file's label alone, for :func:`_own_session` and the labels' reading."""

    def __init__(self, description: str) -> None:
        self.description = description


def labelled_full_scale_of(frames: Sequence[Any], names: Sequence[str], source: Path) -> int | None:
    """The white level the labels of ``frames`` state where below 65535, else None. Images
    whose label states none (JPEGs, a RAW's TIFFs) say nothing either way; two images labelled
    with two levels are refused by name (``--white-level`` decides)."""
    said: dict[int, str] = {}
    for name, frame in zip(names, frames, strict=True):
        level = labelled_white_level(str(getattr(frame, "description", "")))
        if level is not None:
            said.setdefault(level, name)
    if len(said) > 1:
        (a, first), (b, second) = list(said.items())[:2]
        raise RtiRigError(
            f"{shown_path(source)}: {first} is labelled with white level {a} but {second} with "
            f"{b}; one acquisition has one white level: fit with --white-level N (the "
            "camera's white level) to judge every image against it"
        )
    if not said or next(iter(said)) >= 65535:
        return None
    return next(iter(said))
