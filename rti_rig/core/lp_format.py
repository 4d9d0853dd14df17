"""Reading and writing `.lp` light-position files.

The writer emits the one profile every known reader accepts (see docs/conventions.md): a count
line (at most 1000), then ``name x y z`` with one space, LF endings, unit vectors in fixed point as
``0.xxxxxx`` / ``-0.xxxxxx`` (RTIBuilder finds numbers with the regex ``-?0\\.[0-9]+``, so ``1``,
``1.0`` and exponents are never written; components are clamped to ±0.999999).

The reader is tolerant of what real files contain (tabs, CRLF, trailing blanks, blank lines, a
missing count line, non-unit vectors, which are renormalised; a UTF-8 or UTF-16 byte-order mark;
names that are not UTF-8, read as Latin-1, with or without a mark; DOS's end-of-file mark, Ctrl-Z,
after the last line) and precise about what it rejects: every error names the file, the line and
the reason, and where a known tool writes such a file (relight's "0 0 0" for a light it did not
find, a dome's nameless "skeleton" list, relight's JSON dome) the error says which, so the fix is
plain.

Two flaws of real calibrated files are kept and *reported* (appended to ``notes``, each naming
the file and line) rather than refused:

* a count line that disagrees with the lines listed (one real dome file says 47 above 48
  lights): the listed lines are used;
* a light a hair below the object plane where lights must be above it (``upper_hemisphere``):
  calibration noise at the horizon (one real file has z = -0.0012). A normalised z in
  (-HORIZON_TOLERANCE, 0) is clamped to the horizon (z = 0, x and y renormalised); anything
  lower is still refused.
"""

from __future__ import annotations

import codecs
import contextlib
import math
import os
import re
import unicodedata
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path, PurePosixPath, PureWindowsPath

import numpy as np
from numpy.typing import NDArray

from rti_rig.core.errors import LpFormatError
from rti_rig.core.image_files import looks_like_image
from rti_rig.core.shell_words import shown_path

#: relight refuses files with more lights than this.
MAX_LIGHTS = 1000
#: relight rejects directions shorter than this; so do we.
MIN_NORM = 1e-4
#: a light this little below the object plane (normalised z) is calibration noise at the
#: horizon: kept, clamped to z = 0 and reported where lights must be above the plane.
HORIZON_TOLERANCE = 0.01
_CLAMP = 0.999999
_NAME_OK = re.compile(r"^[^\s]+$")


@dataclass(frozen=True)
class LpEntry:
    """One line of an `.lp` file: an image name and the unit direction to its light.

    ``line`` is the line of the file it was read from (1-based; None for an entry made in
    code), so that a refusal about a light can name the line a user opens the file at. It
    takes no part in equality: the same light read from another file, or written by us, is
    the same entry."""

    name: str
    direction: tuple[float, float, float]
    line: int | None = field(default=None, compare=False)


def lights_said(entries: Sequence[LpEntry], indexes: Sequence[int]) -> str:
    """``lights 3 (line 4: image09.jpg) and 7 (line 8: IMAGE09.jpg)``: lights of one ``.lp``
    named as a refusal names them — their number in the file (a dome's user thinks in
    lights), the line to correct (past a count line and comments it is not the number) and
    the image name."""
    said = [
        f"{i + 1} ({'' if entries[i].line is None else f'line {entries[i].line}: '}"
        f"{entries[i].name})"
        for i in indexes
    ]
    return f"lights {', '.join(said[:-1])} and {said[-1]}"


def format_component(value: float) -> str:
    """A direction component in the safe fixed-point form ``0.xxxxxx`` or ``-0.xxxxxx``."""
    if not math.isfinite(value):
        raise ValueError(f"cannot write non-finite component {value!r}")
    v = min(max(value, -_CLAMP), _CLAMP)
    text = f"{v:.6f}"
    return "0.000000" if text == "-0.000000" else text


def format_lp(entries: Sequence[LpEntry]) -> str:
    """The text of an `.lp` file for ``entries``, in the safe profile."""
    if not entries:
        raise ValueError("an .lp file needs at least one light")
    if len(entries) > MAX_LIGHTS:
        raise ValueError(
            f"{len(entries)} lights: readers such as relight accept at most {MAX_LIGHTS}"
        )
    lines = [str(len(entries))]
    for e in entries:
        if not _NAME_OK.match(e.name):
            raise ValueError(f"image name {e.name!r} is empty or contains whitespace")
        if not e.name.isascii() or e.name.startswith("#"):  # written as ASCII; '#' a comment
            raise ValueError(f"image name {e.name!r} is not ASCII or starts with '#'")
        d = np.asarray(e.direction, dtype=np.float64)
        n = float(np.linalg.norm(d))
        if not math.isfinite(n) or n < MIN_NORM:
            raise ValueError(f"direction of {e.name} is zero or not finite: {e.direction}")
        d = d / n
        lines.append(f"{e.name} " + " ".join(format_component(float(c)) for c in d))
    return "\n".join(lines) + "\n"


def write_lp(path: Path, entries: Sequence[LpEntry]) -> Path:
    """Write ``entries`` to ``path`` atomically (temporary file, then rename)."""
    path = Path(path)
    text = format_lp(entries)
    tmp = path.with_name(f".{path.name}.tmp")
    try:
        with open(tmp, "w", encoding="ascii", newline="\n") as fh:
            fh.write(text)
        tmp.replace(path)
    except BaseException as exc:  # the temporary file never outlives a failed write
        with contextlib.suppress(OSError):
            tmp.unlink()
        if not isinstance(exc, OSError):
            raise
        # a read-only or missing folder, a full disk: say which file
        raise LpFormatError(
            path, None, f"cannot write: {exc.strerror or exc}; choose a folder you can write to"
        ) from None
    return path


def lp_files_in(folder: Path) -> list[Path]:
    """The ``.lp`` files of ``folder``, by name, whatever the case of their extension.

    Why: Windows tools and FAT cards write ``DIRS.LP``; ``glob("*.lp")`` does not match it
    on Linux, so ``fit FOLDER`` and ``bench tradeoff --from FOLDER`` had said the folder
    "holds no .lp file" while ``run FOLDER`` named DIRS.LP in it."""
    try:
        found = [p for p in Path(folder).iterdir() if p.suffix.lower() == ".lp" and p.is_file()]
    except OSError:
        return []
    return sorted(found)


#: The subfolder of an RTIBuilder project that holds its ``.lp`` (its images are in
#: ``jpeg-exports/`` beside it).
ASSEMBLY_FILES = "assembly-files"


def acquisition_lp_files(folder: Path) -> list[Path]:
    """The ``.lp`` files of a folder given as an acquisition: its own (:func:`lp_files_in`),
    or, where it holds none, those of RTIBuilder's ``assembly-files/``: the folder's own
    (the project folder, what a user sees as the acquisition) or, for a ``jpeg-exports``
    folder (the project's images), the one beside it.

    Why: ``fit PROJECT`` and ``bench tradeoff --from PROJECT`` had said the project "holds no
    .lp file", and ``run PROJECT`` named none, where RTIBuilder had put it one folder down."""
    folder = Path(folder)
    own = lp_files_in(folder)
    if own:
        return own
    if folder.name.casefold() == "jpeg-exports":
        return lp_files_in(folder.parent / ASSEMBLY_FILES)
    return lp_files_in(folder / ASSEMBLY_FILES)


def lp_name_from(folder: Path, lp: Path) -> str:
    """``lp`` (:func:`acquisition_lp_files`), or an image it lists, as named from ``folder``:
    ``dirs.lp``, ``assembly-files/proj.lp`` or ``../assembly-files/proj.lp`` (``/`` on every
    system, as a manifest records it)."""
    return Path(os.path.relpath(lp, folder)).as_posix()


def is_absolute_name(name: str) -> bool:
    """An image name that is a path from the root, on either system's rules."""
    return any(
        pure.is_absolute() or bool(pure.drive) or bool(pure.anchor)
        for pure in (PurePosixPath(name), PureWindowsPath(name))
    )


def image_file_name(name: str) -> str:
    """The file name alone of an image an `.lp` line names, whichever system wrote the path
    (``H:\\RTI\\jpeg-exports\\a_01.jpg`` -> ``a_01.jpg``, ``C:IMG.JPG`` -> ``IMG.JPG``)."""
    return _pure_name(name).name


def _pure_name(name: str) -> PurePosixPath | PureWindowsPath:
    """``name`` as the system that wrote it reads it: Windows' where it has a ``\\`` or a
    drive (``C:IMG.JPG``, ``C:sub/IMG.JPG``, ``//server/share/IMG.JPG``), POSIX otherwise.

    Why the drive: a drive-relative name without a ``\\`` had been read as POSIX, whose one
    component ``C:IMG.JPG`` was looked for as such beside the .lp and said to be missing."""
    windows = PureWindowsPath(name)
    return windows if "\\" in name or windows.drive else PurePosixPath(name)


def image_path(lp_dir: Path, name: str) -> Path:
    """Where the image an `.lp` line names is, for an `.lp` in ``lp_dir``.

    A relative name is read relative to the `.lp`'s folder (``\\`` as a folder separator, as
    Windows tools write it). An absolute name — what RTIBuilder writes, the project's path on
    the machine that built it (``H:\\RTI_Data\\proj\\jpeg-exports\\proj_01.jpg``) — is looked
    for by its trailing path components under the `.lp`'s folder, longest first
    (``C:\\captures\\sub\\IMG.JPG`` in ``captures/sub/IMG.JPG``, then ``sub/IMG.JPG``, then
    ``IMG.JPG`` beside the `.lp`), then in a ``jpeg-exports`` folder beside it or beside its
    folder (RTIBuilder keeps the `.lp` in ``assembly-files/``); never at the path itself,
    which is another machine's (and would let an `.lp` read any file, where a relative name
    that climbs out with ``..`` is refused; a ``..`` in the name ends the components tried).
    The first that exists is returned; none existing, the file beside the `.lp` (for the
    caller's "missing" message). Why the folders: an acquisition copied with its subfolders
    (``sub/IMG.JPG``) had been looked for only as ``IMG.JPG`` and said to be missing. A bare
    relative name not beside an `.lp` in ``assembly-files/`` is looked for in the project's
    ``jpeg-exports/`` too (:func:`_in_project_exports`)."""
    lp_dir = Path(lp_dir)
    if not is_absolute_name(name):
        literal = lp_dir / name
        portable = lp_dir / PureWindowsPath(name).as_posix() if "\\" in name else literal
        beside = literal if _exists(literal) and not _exists(portable) else portable
        return beside if _exists(beside) else _in_project_exports(lp_dir, name) or beside
    candidates = _absolute_name_candidates(lp_dir, name)
    return next((c for c in candidates if _is_file(c)), lp_dir / image_file_name(name))


def _exists(path: Path) -> bool:
    """``path.exists()``, False where the system cannot look it up (a name too long for it:
    Python raises there, where it answers False for a name that is not there)."""
    try:
        return path.exists()
    except OSError:
        return False


def _is_file(path: Path) -> bool:
    """``path.is_file()``, False where the system cannot look it up (as :func:`_exists`)."""
    try:
        return path.is_file()
    except OSError:
        return False


def _in_project_exports(lp_dir: Path, name: str) -> Path | None:
    """Where a bare file name listed by an `.lp` in an RTIBuilder project's
    ``assembly-files/`` is, when not beside the `.lp`: the project's ``jpeg-exports/``, if
    the file is there; None otherwise (a name with folders in it is the user's path, read as
    written).

    Why: the guide's own recipe for RTIBuilder (a session's ``lights.lp``, whose names are
    bare, copied into ``assembly-files/``, its JPEGs into ``jpeg-exports/``) made a project
    that ``fit``, ``run``, ``check`` and ``bench`` refused as "12 of 12 image(s) missing",
    though an absolute name of that project was found there."""
    if lp_dir.name.casefold() != ASSEMBLY_FILES or len(_pure_name(name).parts) != 1:
        return None
    exported = lp_dir.parent / "jpeg-exports" / name
    return exported if _is_file(exported) else None


def _trailing_parts(name: str) -> list[str]:
    """The plain folder and file names at the end of an absolute image name, outermost first,
    stopping at its root or at a ``.``/``..`` (never followed out of the `.lp`'s folder)."""
    pure = _pure_name(name)
    parts: list[str] = []
    for part in reversed(pure.parts[1:] if pure.anchor else pure.parts):
        if part in ("", ".", "..") or "/" in part or "\\" in part:
            break
        if _name_bytes(part) > NAME_MAX_BYTES:  # no folder here has it: looked up, it raised
            break
        parts.insert(0, part)
    return parts


def _under_lp_dir(lp_dir: Path, parts: list[str]) -> list[Path]:
    """The files ``parts`` (:func:`_trailing_parts`) name under the `.lp`'s folder, longest
    first (``sub/IMG.JPG``, then ``IMG.JPG``): one order for where a name is looked for and
    for which of them make it ambiguous, so the two never judge different files."""
    return [lp_dir.joinpath(*parts[k:]) for k in range(len(parts))]


def _absolute_name_candidates(lp_dir: Path, name: str) -> list[Path]:
    """Where :func:`image_path` looks for an absolute name, in order (no duplicates)."""
    parts = _trailing_parts(name) or [image_file_name(name)]
    base = parts[-1]
    tails = _under_lp_dir(lp_dir, parts)
    found: list[Path] = []
    for c in [*tails, lp_dir / "jpeg-exports" / base, lp_dir.parent / "jpeg-exports" / base]:
        if c not in found:
            found.append(c)
    return found


def image_name_ambiguity(lp_dir: Path, name: str) -> str | None:
    """Why an absolute image name cannot be read without a guess, or None: two of the files
    its trailing components name under the `.lp`'s folder exist and differ
    (``C:\\captures\\sub\\IMG.JPG`` with both ``sub/IMG.JPG`` and ``IMG.JPG`` beside the `.lp`,
    not copies of one image). The longest is the likelier, but reading it where the other was
    meant would put one light's photograph under another's: the user says which."""
    if not is_absolute_name(name):
        return None
    lp_dir = Path(lp_dir)
    existing = [c for c in _under_lp_dir(lp_dir, _trailing_parts(name)) if _is_file(c)]
    if len(existing) < 2:
        return None
    chosen, others = existing[0], existing[1:]
    differ = [c for c in others if not _same_bytes(chosen, c)]
    if not differ:
        return None
    listed = ", ".join(str(c.relative_to(lp_dir)) for c in (chosen, *differ))
    return (
        f"'{name}' could be {listed} under the .lp's folder, which are different files: "
        "move away the ones that are not this light's image, or write the name relative to "
        "the .lp's folder (e.g. " + chosen.relative_to(lp_dir).as_posix() + ")"
    )


def _same_bytes(a: Path, b: Path) -> bool:
    """Whether two files hold the same bytes (a copy of one image is no ambiguity)."""
    import filecmp

    try:
        return filecmp.cmp(a, b, shallow=False)
    except OSError:
        return False


def image_paths(lp_path: Path, entries: Sequence[LpEntry]) -> list[Path]:
    """:func:`image_path` of every entry of the `.lp` at ``lp_path``; two lines that come to
    one file (absolute names in two folders with one file name) are refused, naming them, and
    so is a name that could be either of two different files
    (:func:`image_name_ambiguity`)."""
    lp_dir = Path(lp_path).parent
    for e in entries:  # before any is looked up: no file here can have such a name
        _refuse_long_parts(e.name, str(lp_path), e.line)
    for e in entries:
        why = image_name_ambiguity(lp_dir, e.name)
        if why is not None:
            raise LpFormatError(lp_path, None, why)
    paths = [image_path(lp_dir, e.name) for e in entries]
    first: dict[Path, tuple[int, str]] = {}
    for number, (e, p) in enumerate(zip(entries, paths, strict=True), start=1):
        if p in first:
            earlier, name = first[p]
            # './image02.jpg' beside 'image02.jpg' had been told its names "differ only in
            # folders the .lp's machine had", with no word of which lights they were
            why = (
                "their names differ only in folders the .lp's machine had"
                if is_absolute_name(name) or is_absolute_name(e.name)
                else "the two names are one path written two ways"
            )
            raise LpFormatError(
                lp_path,
                None,
                f"lights {earlier} and {number} of the file, {name!r} and {e.name!r}, are both "
                f"read from {shown_path(p)} ({why}): two lights cannot share an image; remove "
                "the line that is not this image's light, or correct its name",
            )
        first[p] = (number, e.name)
    return paths


def case_hint(missing: Sequence[Path]) -> str:
    """What to say of images not found whose folder holds a file of the same name in another
    case (``image01.JPG`` listed, ``image01.jpg`` there), or of the same name with another
    image extension (``image01.jpg`` listed, ``image01.jpeg`` or ``image01.JPEG`` there): ""
    when none does.

    Windows and macOS find such a file, so an `.lp` written there reads there; Linux tells
    the two names apart (and a FAT card mounted with ``shortname=lower`` shows a camera's
    ``IMG_0001.JPG`` as ``img_0001.jpg``). The file is not read in its place — which of two
    names differing only in case is meant is not ours to guess — but named, since "missing"
    of a file the user sees in the folder is no help. Likewise another extension: an `.lp`
    written for the camera's files (``.tif``, ``.CR2``) beside the JPEGs exported from them,
    or an export that wrote ``.jpeg``, had been told to "copy them where their names point",
    beside the very files; a file of another kind is never read as the one named (a RAW and
    its JPEG are not the same data), only named."""
    twins, kin = _name_twins(missing)
    hidden = _invisible_names(missing)
    return (
        _not_files_said(_not_files(missing))
        + _twins_said(twins, len(missing))
        + _kin_said(kin, len(missing))
        + _invisible_said(hidden)
        + _other_encoding_said(_other_encodings(missing))
    )


#: The byte encodings a file name written by an older Windows tool, or on a card or share
#: mounted without UTF-8, is found in when the `.lp` names it in UTF-8 characters.
_NAME_ENCODINGS = ("cp1252", "latin-1")


def _other_encodings(missing: Sequence[Path]) -> list[tuple[str, str]]:
    """The missing images whose file is there with the same characters in another encoding's
    bytes (``pièce.jpg`` listed, its name's bytes Windows-1252 on disk), each with that
    encoding."""
    found: list[tuple[str, str]] = []
    for path in missing:
        for encoding in _NAME_ENCODINGS:
            try:
                other = os.fsdecode(path.name.encode(encoding))
            except (UnicodeEncodeError, UnicodeDecodeError):
                continue
            if other != path.name and (path.parent / other).is_file():
                found.append((path.name, encoding))
                break
    return found


def _other_encoding_said(found: list[tuple[str, str]]) -> str:
    """:func:`case_hint`'s clause for :func:`_other_encodings`.

    Why: such a file had been called missing, as the user sees ``pièce.jpg`` in a file
    manager that shows the bytes decoded its own way (QA, 2026-12-05). The file is not read in
    its place (a name's bytes are the name), but named, with the rename that fixes it."""
    if not found:
        return ""
    named = ", ".join(name for name, _ in found[:3]) + (
        f" and {len(found) - 3} more" if len(found) > 3 else ""
    )
    encoding = "Windows-1252" if found[0][1] == "cp1252" else "Latin-1"
    return (
        f"; {named} {'is' if len(found) == 1 else 'are'} there with {encoding} bytes in the "
        "file name, not UTF-8 (copied from an older Windows tool, or a card or share mounted "
        "without UTF-8): rename the files to UTF-8 names, e.g. convmv -f cp1252 -t utf-8 "
        "--notest on them, or mount the card with iocharset=utf8"
    )


def _not_files(missing: Sequence[Path]) -> dict[str, str]:
    """The listed names that are there but are no file to read (a folder, a link whose target
    does not exist, a device or pipe), each with the words that say what it is.

    Why: such an entry had been named "the same name in other upper/lower case" of itself,
    with the advice to rename it; "missing" alone is no help either when the user sees the
    name in the folder."""
    said: dict[str, str] = {}
    for path in missing:
        if not os.path.lexists(path) or path.is_file():
            continue
        if path.is_dir():
            what = "a folder"
        elif path.is_symlink() and not path.exists():
            what = f"a link to {os.readlink(path)}, which does not exist"
        else:
            what = "not a regular file"
        said[path.name] = f"{path.name} is {what}"
    return said


def _not_files_said(not_files: dict[str, str]) -> str:
    """:func:`case_hint`'s clause for :func:`_not_files`."""
    said = list(not_files.values())
    if not said:
        return ""
    more = f" and {len(said) - 3} more" if len(said) > 3 else ""
    return f"; {', '.join(said[:3])}{more}: put the image file itself there"


def _invisible_names(missing: Sequence[Path]) -> list[str]:
    """The missing images' names that hold a character no one sees (a zero-width space, a
    byte-order mark, a soft hyphen pasted with the name), each said with the characters'
    code points and names, and whether the name without them is there."""
    said: list[str] = []
    for path in missing:
        name = path.name
        if name.isprintable():
            continue
        hidden = sorted({c for c in name if not c.isprintable()})
        chars = ", ".join(f"U+{ord(c):04X} {unicodedata.name(c, 'unnamed')}" for c in hidden)
        visible = "".join(c for c in name if c.isprintable())
        there = f", and {visible} is there" if (path.parent / visible).is_file() else ""
        said.append(f"{name!r} holds {chars}{there}")
    return said


_RUN_OF_SPACES = re.compile(r"[ \t]{2,}|\t")


def _spaced_names(missing: Sequence[Path]) -> list[tuple[str, str]]:
    """``(listed, there)`` for missing images with a space in their name where a file is there
    whose name has a run of spaces (or a tab) at that place: ``img  00.jpg`` listed in an .lp
    is read ``img 00.jpg``, as relight reads it."""
    found: list[tuple[str, str]] = []
    listings: dict[Path, list[str]] = {}
    for path in missing:
        if " " not in path.name:
            continue
        if path.parent not in listings:
            try:
                listings[path.parent] = [
                    e.name for e in path.parent.iterdir() if any(c.isspace() for c in e.name)
                ]
            except OSError:
                listings[path.parent] = []
        # a run of two or more spaces or tabs, read as one: not a no-break space, nor a space
        # at the name's end, which the .lp's reading does not make (they are missing otherwise)
        there = [n for n in listings[path.parent] if _RUN_OF_SPACES.sub(" ", n) == path.name]
        if there and there[0] != path.name:
            found.append((path.name, there[0]))
    return found


def _spaced_said(spaced: list[tuple[str, str]]) -> str:
    """The clause for names read with one space where the file's has a run of them.

    Why: a file named with two spaces in a row, listed so in the .lp, had been said missing
    under the name with one (QA, 2026-12-06), with the advice to copy it where it was."""
    if not spaced:
        return ""
    more = f" and {len(spaced) - 3} more" if len(spaced) > 3 else ""
    pairs = ", ".join(f"{listed!r} is there as {there!r}" for listed, there in spaced[:3])
    return (
        f"; {pairs}{more}: an .lp's names are read with each run of spaces as one space (as "
        "relight reads them); rename the files with single spaces, and write the names so"
    )


def _invisible_said(hidden: list[str]) -> str:
    """:func:`case_hint`'s clause for names holding invisible characters.

    Why: a zero-width space pasted into a name had been told "image05.jpg missing" beside
    the image05.jpg the user sees, the name printed with its invisible character in it."""
    if not hidden:
        return ""
    more = f" and {len(hidden) - 3} more" if len(hidden) > 3 else ""
    return (
        f"; {'; '.join(hidden[:3])}{more}: an invisible character in the .lp's name (pasted "
        "text?); delete it from the .lp"
    )


def _name_twins(missing: Sequence[Path]) -> tuple[list[str], list[str]]:
    """The files :func:`case_hint` names, as ``"listed -> there"``: those differing only in
    upper/lower case, and those with the same name and another image extension."""
    listings: dict[Path, tuple[dict[str, list[str]], dict[str, list[str]]]] = {}
    twins: list[str] = []
    kin: list[str] = []
    other_cases: dict[Path, Path | None] = {}
    for path in missing:
        folder = path.parent
        # a folder named in other case (JPEGS\image01.jpg, the images in jpegs/): its files
        # are the twins, as Windows and macOS would find them ("missing" had been said of
        # every image, with the advice to copy them where they already were)
        if folder not in other_cases:  # one look per folder (600 images: 1 s, not 5)
            other_cases[folder] = _folder_in_other_case(folder)
        other_case = other_cases[folder]
        listed = path.name
        if other_case is not None:
            folder, listed = other_case, f"{folder.name}/{path.name}"
        if folder not in listings:
            by_case: dict[str, list[str]] = {}
            by_stem: dict[str, list[str]] = {}
            with contextlib.suppress(OSError):
                for child in sorted(folder.iterdir()):
                    by_case.setdefault(child.name.casefold(), []).append(child.name)
                    if child.suffix.lower() in _IMAGE_ENDINGS and child.is_file():
                        by_stem.setdefault(child.stem.casefold(), []).append(child.name)
            listings[folder] = (by_case, by_stem)
        by_case, by_stem = listings[folder]
        # the entry of the very same name is no twin: a folder or a dead link there
        # (:func:`_not_files_said`) had been called "the same name in other case" of itself
        found = [n for n in by_case.get(path.name.casefold(), []) if n != listed]
        there = f"{folder.name}/" if other_case is not None else ""
        if found:
            twins.append(f"{listed} -> {there}{found[0]}")
            continue
        other = [n for n in by_stem.get(path.stem.casefold(), []) if n != listed]
        if other:
            kin.append(f"{listed} -> {there}{other[0]}")
    return twins, kin


def _folder_in_other_case(folder: Path) -> Path | None:
    """The folder that ``folder``, which is not there, names in other upper/lower case (each
    missing component matched case-blind, from the nearest folder that is there), or None."""
    if folder.is_dir():
        return None
    base, parts = folder, []
    while not base.is_dir():
        if base.parent == base:
            return None
        parts.insert(0, base.name)
        base = base.parent
    for part in parts:
        try:
            match = [
                c
                for c in sorted(base.iterdir())
                if c.is_dir() and c.name.casefold() == part.casefold()
            ]
        except OSError:
            return None
        if not match:
            return None
        base = match[0]
    return base


def _twins_said(twins: list[str], missing: int) -> str:
    """:func:`case_hint`'s clause for names that differ only in upper/lower case."""
    if not twins:
        return ""
    folders = any("/" in t.split(" -> ")[0] for t in twins)  # a folder named in other case
    why = (
        ": Windows and macOS ignore the case of file names, this system does not; rename the "
        + ("folder" if folders else "files")
        + " or correct the names in the .lp"
    )
    if missing == 1:
        return (
            f"; {twins[0].split(' -> ')[1]} is there, the same name in other upper/lower case{why}"
        )
    more = f" and {len(twins) - 3} more" if len(twins) > 3 else ""
    return (
        f"; {len(twins)} of them differ only in upper/lower case from a file there "
        f"({', '.join(twins[:3])}{more}){why}"
    )


def _kin_said(kin: list[str], missing: int) -> str:
    """:func:`case_hint`'s clause for names whose file is there with another extension."""
    if not kin:
        return ""
    why = (
        ": an image is read only by the name the .lp gives it; rename the files or correct "
        "the names in the .lp"
    )
    if missing == 1:
        return f"; {kin[0].split(' -> ')[1]} is there, the same name with another extension{why}"
    more = f" and {len(kin) - 3} more" if len(kin) > 3 else ""
    are = "is" if len(kin) == 1 else "are"
    return (
        f"; {len(kin)} of them {are} there with another extension ({', '.join(kin[:3])}{more}){why}"
    )


def exports_folder(lp_dir: Path, found: Sequence[Path]) -> Path | None:
    """The ``jpeg-exports`` folder that every image ``found`` for an `.lp` in ``lp_dir`` was
    read from (RTIBuilder's layout: see :func:`image_path`), or None.

    Why: an image missing from such a project had been said to be missing "in" the `.lp`'s
    ``assembly-files/`` and to be copied there, away from its eleven siblings; any absolute
    name is looked for in this folder too, so a file copied beside its siblings is found."""
    folders = {p.parent for p in found}
    if len(folders) != 1:
        return None
    (folder,) = folders
    lp_dir = Path(lp_dir)
    exports = (lp_dir / "jpeg-exports", lp_dir.parent / "jpeg-exports")
    return folder if folder in exports else None


def missing_images_advice(
    names: Sequence[str],
    paths: Sequence[Path],
    lp_dir: Path,
    use: str,
    *,
    total: int,
    into: Path | None = None,
) -> str:
    """What to say after "N image(s) missing" of the images an `.lp` in ``lp_dir`` lists as
    ``names``, looked for at ``paths`` (:func:`image_path`): where an absolute name is looked
    for, and what to do; ``use`` is the verb of what is done with the others ("replay", "fit"),
    of the ``total`` images the `.lp` lists.

    Why: an absolute name whose file exists at that very path had been called "missing" and
    the user told to "copy them where their names point", where they already were. It is
    read beside the `.lp` by design (see :func:`image_path`), so that is said, with the two
    ways out. One wording for ``run``, ``fit`` (of an `.lp`, not a session: a session's lost
    images are said from its journal) and ``bench tradeoff --from``, all three through
    :func:`rti_rig.core.acquisition_images.check_image_files`.

    An absolute name at no such path had been told both that it is looked for beside the
    `.lp` and to "copy them where their names point" (which leads only to the "exists at the
    path the .lp names" refusal): it is told to copy them into ``lp_dir``. "Remove their lines
    from the .lp to fit the others" is offered only when there are others (it had been said
    with every image missing).

    ``into``: where an absolute name's file is to be copied, when not ``lp_dir``: the
    :func:`exports_folder` its siblings were read from."""
    into = lp_dir if into is None else into
    absolute = [n for n in names if is_absolute_name(n)]
    where = (
        "an absolute name (a path on the machine that wrote the .lp) is looked for by its "
        "trailing folders and file name under the .lp's folder (sub/IMG.JPG, then IMG.JPG), "
        "then in a jpeg-exports folder beside it or beside its folder"
    )
    there = [n for n in absolute if _is_file_at(n)]
    if there:
        more = f" and {len(there) - 3} more" if len(there) > 3 else ""
        which = (
            ("it exists" if len(names) == 1 else "all of them exist")
            if len(there) == len(names)
            else f"{len(there)} of them exist ({', '.join(there[:3])}{more})"
        )
        return (
            f"; {which} at the path the .lp names, but an .lp's images are read beside it: "
            f"{where}; "
            f"copy them into {shown_path(into)}, or write an .lp whose names are relative to its "
            "folder"
        )
    if not absolute:
        copy = "copy them where their names point"
    elif len(absolute) == len(names):
        copy = f"copy them into {shown_path(into)}"
    else:  # a relative name may name a subfolder; an absolute one is read by its file name
        copy = (
            "copy them where their names point, an absolute name's file by its file name "
            f"into {shown_path(into)}"
        )
    others = f", or remove their lines from the .lp to {use} the others"
    plain = f"; {copy}{others if len(names) < total else ''}"
    quoted = quote_hint(names, lp_dir)
    if quoted and (rest := len(names) - len(_quoted_names(names, lp_dir))):
        # the images not quoted are missing all the same: their way out is said too (it had
        # been left out, the quotes' edit alone offered for every image)
        tail = others if len(names) < total else ""
        quoted += f"; for the other {rest} not found, {copy}{tail}"
    twins, kin = _name_twins(paths)  # listed once (case_hint's own, which had listed again)
    hidden = _invisible_names(paths)
    not_files = _not_files(paths)
    encoded = _other_encodings(paths)
    spaced = _spaced_names(paths)
    named = (
        _not_files_said(not_files)
        + _spaced_said(spaced)
        + _twins_said(twins, len(paths))
        + _kin_said(kin, len(paths))
        + _invisible_said(hidden)
        + _other_encoding_said(encoded)
    )
    # each missing image counted once, whatever clauses name it (a folder image05.jpg beside
    # image05.png is both "a folder" and "another extension": "the other -1" had been said)
    covered = set(not_files)
    covered |= {t.split(" -> ")[0] for t in [*twins, *kin]}
    covered |= {p.name for p in paths if not p.name.isprintable()}
    covered |= {name for name, _ in encoded}
    covered |= {name for name, _ in spaced}
    if named and (rest := max(0, len(names) - len(covered))):
        # the images with no such file are missing all the same: their way out is said too
        tail = others if len(names) < total else ""
        named += f"; for the other {rest} not found, {copy}{tail}"
    return ("; " + where if absolute else "") + (named or quoted or plain)


def quote_hint(names: Sequence[str], lp_dir: Path) -> str:
    """What to say of images not found whose names are in quotes (``"my image 01.jpg"``, as a
    script's CSV writer quotes a field with spaces) when the file without them is there: ""
    when none is.

    Why: an `.lp` does not quote its names (relight, like this reader, takes the quotes as
    part of the name), so such images had been told to be copied "where their names point",
    beside files the user sees are there. Named, not read in their place: the fix is one
    edit of the `.lp`, and then every reader finds them."""
    quoted = _quoted_names(names, lp_dir)
    if not quoted:
        return ""
    more = f" and {len(quoted) - 3} more" if len(quoted) > 3 else ""
    if len(names) == 1:
        which = "its name is in quotes and the file without them is there"
    elif len(quoted) == 1:
        which = f"1 of them is named in quotes ({quoted[0]}) and its file without them is there"
    else:
        which = (
            f"{len(quoted)} of them are named in quotes ({', '.join(quoted[:3])}{more}) and "
            "their files without the quotes are there"
        )
    return (
        f"; {which}: an .lp does not quote its names (a name may hold spaces: the last three "
        "fields are the light), so remove the quotes from the .lp"
    )


def _quoted_names(names: Sequence[str], lp_dir: Path) -> list[str]:
    """The ``names`` in quotes whose file without the quotes is in ``lp_dir`` (see
    :func:`quote_hint`)."""
    return [
        n
        for n in names
        if len(n) > 2
        and n[0] == n[-1]
        and n[0] in "\"'"
        and image_path(Path(lp_dir), n[1:-1]).is_file()
    ]


def _is_file_at(name: str) -> bool:
    """Whether an absolute image name is a file at that path on this machine (only looked at,
    never read: an `.lp` does not read files outside its folder)."""
    path = Path(name)
    try:
        return path.is_absolute() and path.is_file()
    except OSError:
        return False


#: The longest file or folder name, in bytes, that Linux's file systems hold (ext4, XFS, Btrfs:
#: NAME_MAX); NTFS counts 255 UTF-16 units instead, so a name a Windows tool wrote can be longer
#: in UTF-8 than any file a Linux machine can look up.
NAME_MAX_BYTES = 255


def _refuse_long_parts(name: str, source: str, lineno: int) -> None:
    """Refuse a name one of whose parts no file here can have: looked up, it had raised
    "File name too long" as a traceback (``check``, ``fit``, ``bench``) or an "unexpected
    OSError" (``run``). 94 CJK characters are a legal NTFS name and 274 bytes in UTF-8."""
    pure = _pure_name(name)
    # an absolute name's folders are another machine's, looked for only where they fit
    # (:func:`_trailing_parts`): only its file name must be one a file here can have
    parts = [pure.name] if is_absolute_name(name) else list(pure.parts)
    for part in parts:
        size = _name_bytes(part)
        if size > NAME_MAX_BYTES:
            shown = part if len(part) <= 40 else f"{part[:20]}…{part[-12:]}"
            raise LpFormatError(
                source,
                lineno,
                f"image name part {shown!r} is {size} bytes long: no file or folder on this "
                f"machine's file systems can have a name over {NAME_MAX_BYTES} bytes (a name a "
                "Windows tool wrote may be longer in UTF-8 than there); rename it shorter and "
                "write the new name on this line",
            )


def _name_bytes(part: str) -> int:
    """The bytes a file name takes on this machine (UTF-8 where the locale cannot say)."""
    try:
        return len(os.fsencode(part))
    except UnicodeEncodeError:
        return len(part.encode("utf-8", "surrogatepass"))


def _check_name(name: str, source: str, lineno: int) -> None:
    """Reject relative names that would resolve outside the `.lp` file's own folder (an
    absolute name is a tool's path on its own machine: see :func:`image_path`)."""
    if is_absolute_name(name):
        return
    # read as the .lp's readers read it: "\\" a folder separator wherever it appears
    pure = PureWindowsPath(name) if "\\" in name else PurePosixPath(name)
    if ".." in pure.parts:
        raise LpFormatError(source, lineno, _dot_dot_refusal(name, pure))


def _dot_dot_refusal(name: str, pure: PurePosixPath | PureWindowsPath) -> str:
    """Why a relative name holding ``..`` is refused, and what to write instead.

    Why two cases: ``imgs/../image01.jpg`` was told it "climbs out of the .lp file's folder",
    though written out it stays inside; it is still refused (``imgs`` may be a link, and
    ``..`` from a link's target is elsewhere), but said so, with the name to write."""
    depth, kept = 0, []
    for part in pure.parts:
        if part == "..":
            depth -= 1
            if depth < 0:
                return (
                    f"image name {name!r} climbs out of the .lp file's folder with '..'; "
                    "move the .lp next to the images and use bare file names"
                )
            kept.pop()
        elif part not in ("", "."):
            depth += 1
            kept.append(part)
    if not kept:
        return f"image name {name!r} names the .lp file's folder itself, not an image file"
    return (
        f"image name {name!r} steps back with '..' (an .lp's image names are read without "
        f"following '..', which from a linked folder would lead elsewhere); write it as "
        f"{'/'.join(kept)!r}"
    )


#: A spreadsheet's CSV export of a light list: fields split by ',' or ';' (with or without
#: spaces after them), four or more of them on the line.
_CSV_FIELDS = re.compile(r"\s*[,;]\s*|\s+")


def _csv_hint(line: str) -> str:
    """What to say of a line whose fields are split by ',' or ';' (Excel's "Save as CSV", in
    locales whose decimal separator is ',' with ';'): "" for any other line. Such lines had
    been refused as one field, or with "use '.' as the decimal separator" of a file whose
    decimals were '.' already and whose commas split the fields."""
    if not re.search(r"[,;]", line) or len([f for f in _CSV_FIELDS.split(line) if f]) < 4:
        return ""
    return (
        " (fields separated by ',' or ';': a spreadsheet's CSV export? an .lp separates the "
        "image name and x y z with spaces or tabs, and writes decimals with '.')"
    )


def _heading_hint(line: str) -> str:
    """What to say of a line that holds no number at all where a count or a light goes: a
    title (``LP file``, ``RTI dome A``) or a row of column headings (``image x y z``, as a
    spreadsheet or a script's table writes above the lights): "" for any other line, and for
    one naming an image file (a light line that lost its numbers).

    Why: such a line had been refused as "x component 'x' is not a number" or "expected 'name
    x y z', found 2 field(s)", a reason with nothing to do; the fix is one edit, said here,
    and a line marked with '#' is read as a comment (:func:`parse_lp`)."""
    tokens = line.split()
    if not tokens or any(_is_number(t.strip(",;")) for t in tokens):
        return ""
    if any(t.lower().endswith(_IMAGE_ENDINGS) for t in tokens):
        return ""
    return TITLE_HINT


#: What a line of words where a light goes is taken for, and its mend (not said of a session's
#: own lights.lp, whose line is a light cut short: its mend is a listing written again).
TITLE_HINT = (
    " (a title or a row of column headings? an .lp has none: delete the line, or start "
    "it with '#' to keep it as a comment)"
)


#: A number as C's ``strtod`` and Qt's ``toDouble`` read one (relight, RTIBuilder): ASCII
#: digits, an optional sign, point and exponent, or a word for infinity or NaN (refused as not
#: finite, by name). Python's ``float`` also takes ``1_0`` (as 10) and other scripts' digits
#: (full-width ``０.5``), which those readers refuse: such a file had passed ``check``.
_C_NUMBER = re.compile(
    r"[+-]?(?:(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?|inf(?:inity)?|nan)", re.ASCII | re.IGNORECASE
)


def _c_float(token: str) -> float:
    """``float(token)`` for a number C's and Qt's readers take; ValueError for the rest."""
    if not _C_NUMBER.fullmatch(token):
        raise ValueError(token)
    return float(token)


def _parse_float(token: str, source: str, lineno: int, axis: str, line: str = "") -> float:
    try:
        value = _c_float(token)
    except ValueError:
        hint = _csv_hint(line) if token.endswith((",", ";")) or ";" in token else ""
        if not hint and "," in token:
            hint = " (use '.' as the decimal separator)"
        raise LpFormatError(
            source, lineno, f"{axis} component {token!r} is not a number{hint}"
        ) from None
    if not math.isfinite(value):
        raise LpFormatError(source, lineno, f"{axis} component {token!r} is not finite")
    return value


#: File name endings of the images an ``.lp`` lists (to tell a name from a stray column).
_IMAGE_ENDINGS = (
    ".jpg", ".jpeg", ".tif", ".tiff", ".png", ".dng", ".cr2", ".nef", ".arw",
    ".tga", ".ppm",  # HP's PTMfitter reads .jpg, .tga and .ppm
)  # fmt: skip


#: A light vector further than this from unit length is noted (normalised all the same).
UNIT_TOLERANCE = 0.05


def _is_number(token: str) -> bool:
    try:
        _c_float(token)
    except ValueError:
        return False
    return True


def _refuse_extra_columns(tokens: list[str], line: str, source: str, lineno: int) -> None:
    """Refuse a line whose image name is followed by a number before the vector: a fourth
    column (an intensity, a weight), not a name with spaces. It had been read as the name
    ``image01.jpg 0.2051`` and reported as a missing image.

    Why the hint says what the line has: it had asked "an extra column after the name?" of
    ``a.jpg 0.6 0 0.8 1.0`` too, whose extra number is the last; which one is extra is named
    only where exactly one run of three is a unit vector (the light's direction)."""
    if len(tokens) < 5:
        return
    # a comment after the light ('image02.jpg 0.1 0.2 0.97 # LED 2 weak') had been told "7
    # fields after the name", with nothing of the '#': a '#' line is a comment, its tail not
    mark = next((i for i, t in enumerate(tokens) if i >= 4 and t.startswith("#")), None)
    if mark is not None and all(_is_number(t) for t in tokens[mark - 3 : mark]):
        raise LpFormatError(
            source,
            lineno,
            f"a comment after the light: {' '.join(tokens[mark:])!r}; an .lp has no "
            "end-of-line comments (relight and RTIBuilder read every field of a light line): "
            "move it to a line of its own starting with '#'",
        )
    named_image = tokens[0].lower().endswith(_IMAGE_ENDINGS)
    if (named_image and any(_is_number(t) for t in tokens[1:-3])) or _columns_after_light(tokens):
        raise LpFormatError(
            source,
            lineno,
            f"expected 'name x y z', found {len(tokens)} fields: {line.strip()!r} "
            f"({_extra_columns_hint(tokens[1:])}; an .lp line is the image name and the "
            "light's x y z only)",
        )
    if not named_image and (reading := _name_or_column(tokens)):
        raise LpFormatError(
            source,
            lineno,
            f"{line.strip()!r} reads two ways: {reading}; an .lp cannot quote a name, so if the "
            "name holds a space, replace the space (and rename its image), or else delete the "
            "column after the light",
        )


def _columns_after_light(tokens: list[str]) -> bool:
    """Whether a line whose first field is no image file name (a dome's ``led01``, ``img_a``)
    has columns after its light: every field after the first is a number, the last three are
    no unit vector and exactly one earlier run of three is (``img_a 0 0 1 255 255 255``, a
    colour after the direction).

    Why: read the way relight reads a line (the last three fields the vector), such a line had
    been taken as the image ``img_a 0 0 1`` lit from (255, 255, 255) normalised, every light
    of the file from one direction, with only a note of the vectors' length; a name with a
    number in it whose last three fields are the unit vector (``scan 2 0 0 1``) still reads."""
    after = tokens[1:]
    if not all(_is_number(t) for t in after):
        return False
    units = [i for i in range(len(after) - 2) if _is_unit(after[i : i + 3])]
    return len(units) == 1 and units[0] != len(after) - 3


#: A zero-padded whole number (``01``, ``007``): how a name numbers its lights, never how a
#: vector's component is written.
_PADDED = re.compile(r"^[+-]?0\d+$")


def _name_or_column(tokens: list[str]) -> str:
    """The two readings of a line whose first field is no image file name, every field after
    it a number, and both its last three and an earlier run of three a unit vector: a name
    with numbers in it (``led01 0`` from (0, 1, 0)) or a column after the light (``led01``
    from (0, 0, 1), intensity 0); "" for any other line.

    Why: ``led01 0 0 1 0`` (an LED's intensity 0) had been read relight's way, the light
    ``led01 0`` from (0, 1, 0), with nothing noted: the unit vector at the end was taken as
    telling a name from a column, but here both runs are unit vectors and nothing in the line
    says which is meant. ``scan 2 0 0 1`` (only the last three a unit vector) still reads, and
    so does ``led 01 0 0 1``: a zero-padded ``01`` is a name's number, which no writer of a
    vector's component writes.

    The name is every field before the line's closing run of numbers, so a name with spaces
    (``my scan 2 0 0 1 0``) reads two ways as ``led01 0 0 1 0`` does: it had been read as the
    light ``my scan 2 0`` with nothing noted."""
    k = len(tokens)
    while k > 1 and _is_number(tokens[k - 1]):
        k -= 1
    after = tokens[k:]
    if len(after) < 4:
        return ""
    last = len(after) - 3
    if not _is_unit(after[last:]):
        return ""
    earlier = [
        i
        for i in range(last)
        if _is_unit(after[i : i + 3]) and not any(_PADDED.match(t) for t in after[i : i + 3])
    ]
    if not earlier:
        return ""
    i = earlier[0]
    as_name = f"the light {' '.join(tokens[: k + last])!r} from ({', '.join(after[last:])})"
    later = after[i + 3 :]
    as_column = (
        f"the light {' '.join(tokens[: k + i])!r} from ({', '.join(after[i : i + 3])}) with "
        f"{' '.join(later)} after it"
    )
    return f"{as_name}, or {as_column}"


def _is_unit(fields: list[str]) -> bool:
    """Whether three number fields are a unit vector, within :data:`UNIT_TOLERANCE`."""
    return abs(math.sqrt(sum(float(t) ** 2 for t in fields)) - 1.0) <= UNIT_TOLERANCE


def _extra_columns_hint(after: list[str]) -> str:
    """What the fields after an image name are, and which are extra where the line shows it
    (exactly one run of three numbers is a unit vector)."""
    if not all(_is_number(t) for t in after):
        return f"{len(after)} fields after the name where an .lp line has 3 numbers"
    said = f"{len(after)} numbers after the name where an .lp line has 3"
    units = [i for i in range(len(after) - 2) if _is_unit(after[i : i + 3])]
    if len(units) != 1:
        return said
    i = units[0]
    before, vector, later = after[:i], after[i : i + 3], after[i + 3 :]
    where = " and ".join(
        part
        for part in (
            f"before it {' '.join(before)}" if before else "",
            f"after it {' '.join(later)}" if later else "",
        )
        if part
    )
    extra = "is an extra column" if len(before) + len(later) == 1 else "are extra columns"
    return f"{said}: {' '.join(vector)} is a unit vector, and {where} {extra}"


def _refuse_non_lp_text(content: list[tuple[int, str]], source: str) -> None:
    """Refuse, saying what it is, a file that is no ``.lp`` text at all, before its first line
    is read as a count: NUL bytes (UTF-16 saved without a byte-order mark, or a file cut off
    while being written, which FAT cards fill with zeros) had been shown as
    ``count line '1\\x008\\x00'``; relight's JSON dome (``.dome``, or a ``.relight`` project)
    as ``count line '{' is not a whole number``."""
    for lineno, line in content:
        if "\x00" in line:
            raise LpFormatError(
                source,
                lineno,
                "the line holds NUL bytes: not plain text (UTF-16 without a byte-order mark?) "
                "or cut off while being written (a power loss, a full card?); save it again as "
                "UTF-8 or ASCII text, or copy it again from where it was written",
            )
    first_no, first = content[0]
    tokens = first.split()
    # an image named '{001}.jpg' on a count-less file's first line is a light, not JSON
    light = len(tokens) >= 4 and all(_is_number(t) for t in tokens[1:4])
    if first.startswith("{") and not light:
        raise LpFormatError(
            source,
            first_no,
            "this is a JSON file, not an .lp (relight's .dome or .relight project?); give the "
            "lights as an .lp: a count line, then 'image-name x y z' per image (relight can "
            "save one from a project)",
        )


#: DOS's end-of-file mark (Ctrl-Z, SUB): what old Windows tools end a text file with
DOS_EOF = "\x1a"


def _without_dos_eof(text: str) -> str:
    """``text`` without the DOS end-of-file marks (Ctrl-Z, 0x1A) after its last line, and the
    blanks around them.

    Why: DOS's ``COPY /A`` and editors of its time end a text file with a Ctrl-Z (CP/M padded
    a file's last 128-byte record with them), where DOS and Windows text readers stop: it is
    no content, like a final CRLF, and is dropped without a note as a CRLF is. It had been
    refused as a light line ("expected 'name x y z', found 1 field(s): '\\x1a'"), or, after
    the last number with no line end, as "z component '0.8\\x1a' is not a number". One inside
    the file is left for the line that holds it to be refused: what follows it may be a
    light."""
    stripped = text.rstrip()
    return stripped.rstrip(DOS_EOF + " \t\r\n") if stripped.endswith(DOS_EOF) else text


#: Words that may follow the number on a count line (``2 lights``, ``48 LEDs``): read as the
#: count alone, since they say what is counted and nothing else.
_COUNT_WORDS = frozenset(
    ("light", "lights", "led", "leds", "image", "images", "direction", "directions",
     "entries", "entry", "photos", "shots", "lamps")
)  # fmt: skip


def _count_with_words(tokens: list[str]) -> bool:
    """Whether a first line is a whole number followed by words and no number (``2 lights``,
    ``48 LEDs in dome A``): a count line with words, never a light (which ends in numbers),
    nor a light that lost its numbers (``1 image01.jpg``, left to the light's own error).

    Numbers among the words (``2 of 3 lights``) keep it a count line unless the line ends in
    three numbers, as a light does (``2 lights 0 0 1`` is a light named ``2 lights``): it had
    been read as the light ``2`` and refused as "x component 'of' is not a number"."""
    if len(tokens) < 2 or not re.fullmatch(r"[+-]?\d+", tokens[0]):
        return False
    rest = tokens[1:]
    if any(t.lower().endswith(_IMAGE_ENDINGS) for t in rest):
        return False
    if all(_is_number(t) for t in rest):
        return False
    return len(tokens) < 4 or not all(_is_number(t) for t in tokens[-3:])


def _count_line_words(
    first: str, tokens: list[str], source: str, lineno: int, notes: list[str]
) -> list[str]:
    """The count of a count line with a count word after it (``2 lights``, ``48 LEDs``), said
    in ``notes``; any other words refused, saying what the first line must be.

    Why: ``2 lights`` had been read as a light line and refused as "expected 'name x y z',
    found 2 field(s)", with nothing to do. One count word says only what is counted, so it is
    read (and noted: relight's parseLP reads the line with ``QString::toInt``, which refuses
    it); other words may say anything (``48 of 50 LEDs``), so the user says the count."""
    word = tokens[1].strip(":,.;").lower() if len(tokens) == 2 else ""
    if word in _COUNT_WORDS:
        notes.append(
            f"{shown_path(source)}, line {lineno}: count line {first!r} read as the count "
            f"{tokens[0]}; relight reads only a number alone there (write '{tokens[0]}')"
        )
        return tokens[:1]
    raise LpFormatError(
        source,
        lineno,
        f"count line {first!r} holds words after its number: the first line of an .lp is the "
        f"number of lights alone (e.g. '{tokens[0]}'), or, without a count line, the first "
        "light 'name x y z'; delete the words, or start the line with '#' and write the count "
        "on a line of its own",
    )


def _whole_count(token: str, first: str, source: str, lineno: int, notes: list[str]) -> int:
    """The count of a count line; a whole number written with a decimal point (``72.0``, as a
    spreadsheet or a script's float writes it) read as that number and said in ``notes``
    (relight's ``QString::toInt`` reads only digits there). Raises ValueError for anything
    else (``72.5``, a word).

    Why: ``72.0`` had been refused as "not a whole number" with nothing to do."""
    if re.fullmatch(r"[+-]?\d+", token, re.ASCII):  # not int()'s '7_2' or other scripts' digits
        return int(token)
    value = _c_float(token)  # ValueError for a word: the caller's refusal
    if not value.is_integer():
        raise ValueError(token)
    notes.append(
        f"{shown_path(source)}, line {lineno}: count line {first!r} read as the count "
        f"{int(value)}; relight reads only a whole number there (write '{int(value)}')"
    )
    return int(value)


def _refuse_name_last(tokens: list[str], line: str, source: str, lineno: int) -> None:
    """Refuse a line in the order ``x y z name`` (three numbers, then an image name).

    Why: such a file (a script's columns in another order) had been refused as "z component
    'image01.jpg' is not a number", as if one number were wrong, with no word of the order."""
    if (
        len(tokens) == 4
        and all(_is_number(t) for t in tokens[:3])
        and tokens[3].lower().endswith(_IMAGE_ENDINGS)
    ):
        raise LpFormatError(
            source,
            lineno,
            f"the line {line!r} gives the light before the image name ('x y z name'): an .lp's "
            "lines are 'name x y z', the order relight and RTIBuilder read; move each name to "
            "the front of its line (e.g. awk 'NR == 1 && NF == 1 {print; next} {print $4, $1, "
            "$2, $3}' in.lp > out.lp)",
        )


def parse_lp(
    text: str,
    source: str = "<lp>",
    upper_hemisphere: bool = False,
    notes: list[str] | None = None,
) -> list[LpEntry]:
    """Parse `.lp` text; ``source`` names the file in errors and notes.

    ``upper_hemisphere`` refuses lights below the object plane (z < 0), naming the line: every
    command that lights, plans or fits from a file asks for it (``plan``, ``run``, ``check``,
    ``fit``, a rig's ``dome.lp_file``), since no such light can have lit the object; without it
    (a session's own ``lights.lp`` read back, the benchmarks) a direction is read as written. A
    light less than :data:`HORIZON_TOLERANCE` below is clamped to the horizon instead. What was
    tolerated is appended to ``notes`` (``"FILE, line N: what and what was done"``) for the
    caller to show.

    Refused as well, though each line alone reads: a lone light vector far from unit length in
    a file of unit vectors (:func:`_refuse_lone_off_unit`), and a line starting with '#' that
    the count line counts as a light (:func:`_refuse_counted_comment`).
    """
    notes = notes if notes is not None else []
    lines = _without_dos_eof(text).splitlines()  # handles LF, CRLF and CR
    numbered = [(i + 1, ln.strip()) for i, ln in enumerate(lines)]
    content = [(n, ln) for n, ln in numbered if ln]
    comments = [n for n, ln in content if ln.startswith("#")]
    # '#05.jpg 0 0 1' may be an image named '#05.jpg'; '# 05.jpg 0 0 1' is a light commented out
    light_like = [(n, ln) for n, ln in content if ln.startswith("#") and _reads_as_light(ln)]
    if comments:
        # cceh/rti's image-filer.py wrote a '# run of <date>' line above the count, and a
        # hand-annotated file is no wrong file: skipped, and said (a '# LP file from RTIBuilder,
        # dome A' header had been refused as "x component 'RTIBuilder,' is not a number"; one
        # ending in three numbers would have been read as a light)
        content = [(n, ln) for n, ln in content if not ln.startswith("#")]
        notes.append(
            f"{shown_path(source)}, line{'s' if len(comments) > 1 else ''} "
            f"{', '.join(map(str, comments[:5]))}{' ...' if len(comments) > 5 else ''}: "
            "comment line(s) starting with '#' skipped"
            + (
                f"; line {light_like[0][0]} ({light_like[0][1]!r}) reads as a light: if "
                f"{light_like[0][1].split()[0]!r} is an image, rename it and its line (an .lp "
                "cannot name an image starting with '#')"
                if light_like
                else ""
            )
        )
    if not content:
        raise LpFormatError(source, None, "the file is empty; expected a count line and lights")
    _refuse_non_lp_text(content, source)

    declared: int | None = None
    first_no, first = content[0]
    first_tokens = first.split()
    if _count_with_words(first_tokens):
        first_tokens = _count_line_words(first, first_tokens, source, first_no, notes)
    if len(first_tokens) == 1:
        try:
            declared = _whole_count(first_tokens[0], first, source, first_no, notes)
        except ValueError:
            raise LpFormatError(
                source,
                first_no,
                f"count line {first!r} is not a whole number"
                + (
                    " (a spreadsheet's column headings? an .lp has none: a count line, then "
                    "'image-name x y z' per image, separated by spaces or tabs)"
                    if _csv_hint(first)
                    else _heading_hint(first)
                ),
            ) from None
        # a count of 0 or below disagrees with the lines as 47 above 48 does: noted below and
        # the lines used (it had been refused, "count 0 must be positive", with nothing to do)
        content = content[1:]

    entries: list[LpEntry] = []
    seen: dict[str, int] = {}
    off_unit: list[tuple[int, float]] = []
    below: list[tuple[int, str, float, float]] = []
    for lineno, line in content:
        tokens = line.split()
        if len(tokens) == 3 and all(_is_number(t) for t in tokens):
            # cceh/rti's lp-builder.py writes a dome's lights as bare 'x y z' lines (its
            # "skeleton" .lp, filled with names by its image-filer.py): no image to pair
            raise LpFormatError(
                source,
                lineno,
                f"expected 'name x y z', found three numbers and no image name: {line!r} (a "
                "dome's light list without image names, such as the 'skeleton' .lp of cceh/rti's "
                "lp-builder.py?); put each image's file name before its light, in shooting order",
            )
        if len(tokens) < 4:
            # the file's last line short of its fields: a copy or a save cut short (the
            # refusal had said what was found and nothing to do)
            cut = (
                " (the last line: the file cut short? copy it again from where it came from, "
                "or remove the line and leave its image out)"
                if lineno == content[-1][0] and not (_csv_hint(line) or _heading_hint(line))
                else ""
            )
            raise LpFormatError(
                source,
                lineno,
                f"expected 'name x y z', found {len(tokens)} field(s): {line!r}"
                + (_csv_hint(line) or _heading_hint(line))
                + cut,
            )
        if hint := _heading_hint(line):
            # a heading row ('image x y z', 'filename\tlx\tly\tlz'): no light, and no number to
            # blame (it had been told "x component 'x' is not a number" and nothing to do)
            raise LpFormatError(
                source, lineno, f"expected 'name x y z', found no number: {line!r}{hint}"
            )
        # As relight's parseLP reads a line (cnr-isti-vclab/relight, src/lp.cpp at commit
        # 74b352a02e66: the last three fields are the vector, the fields before them joined
        # with single spaces are the name), where the line is not refused above or here.
        # Older relight (its QRegExp-split parseLP) refused any line of other than 4 fields,
        # so a name with spaces reads in only some relight versions.
        name = " ".join(tokens[:-3])
        _refuse_name_last(tokens, line, source, lineno)
        _refuse_extra_columns(tokens, line, source, lineno)
        x, y, z = (
            _parse_float(t, source, lineno, axis, line)
            for t, axis in zip(tokens[-3:], "xyz", strict=True)
        )
        norm = math.hypot(x, y, z)  # no overflow: 1e308 squared is inf, and x / inf is 0
        if norm < MIN_NORM:
            # relight's saveLP writes '0 0 0' for an image whose light its sphere did not find
            # (it warns "Missing N light directions" and saves all the same): say so
            raise LpFormatError(
                source,
                lineno,
                f"direction ({x}, {y}, {z}) of {name!r} is (nearly) zero: it has no orientation "
                "(a light the writing tool did not find? relight saves a missing direction as "
                "'0 0 0'); find that light again, or remove the line and leave its image out",
            )
        # the length as written: a clamped light is still checked as a unit vector (a clamp
        # had hidden a mistyped line that the same line a hair above the plane is refused for)
        length = norm
        if upper_hemisphere and -HORIZON_TOLERANCE < z / norm < -1e-9:
            flat = math.hypot(x, y)
            # the file's z, and the direction's where the vector is not of unit length
            unit_z = f" ({z / norm:.4f} as a direction)" if f"{z:.4f}" != f"{z / norm:.4f}" else ""
            notes.append(
                f"{shown_path(source)}, line {lineno}: light z = {z:.4f}{unit_z} is a hair below "
                "the object plane (calibration noise at the horizon?); clamped to z = 0"
            )
            x, y, z, norm = x / flat, y / flat, 0.0, 1.0
        elif upper_hemisphere and z < 0.0 and z / norm >= -1e-9:
            # float noise (-1e-16, -1e-10) is the horizon, set there without a word: left
            # negative, the light had passed here and then fallen out of every elevation
            # band (a 72-image replay refused "has only 71 images")
            flat = math.hypot(x, y)
            x, y, z, norm = x / flat, y / flat, 0.0, 1.0
        if upper_hemisphere and z / norm < -1e-9:
            below.append((lineno, name, z / norm, z))
        _check_name(name, source, lineno)
        if name in seen:
            # what to do, not only what is wrong: a line repeated (a paste) or two lights
            # given one image's name
            first_entry = next(e for e in entries if e.name == name)
            same = all(
                abs(a - b) < 1e-6
                for a, b in zip(first_entry.direction, (x / norm, y / norm, z / norm), strict=True)
            )
            raise LpFormatError(
                source,
                lineno,
                f"image name {name!r} already used on line {seen[name]}"
                + (
                    f", with the same light: the line repeated? delete line {lineno}"
                    if same
                    else ", with another light: each image has one light; give this line the "
                    "name of the image it lit, or delete the line that is wrong"
                ),
            )
        seen[name] = lineno
        if abs(length - 1.0) > UNIT_TOLERANCE:
            off_unit.append((lineno, length))
        entries.append(LpEntry(name, (x / norm, y / norm, z / norm), lineno))

    if not entries:
        raise LpFormatError(source, None, "no light lines after the count line")
    if below:
        _refuse_below_plane(below, len(entries), source)
    _refuse_lone_off_unit(off_unit, content, len(entries), source, text)
    _refuse_counted_comment(light_like, declared, len(entries), first_no, source)
    if off_unit:
        # rounding noise is no news; vectors of length 3 may be lamp positions read as
        # directions, which is worth a line (they are normalised either way)
        lengths = [n for _, n in off_unit]
        shortest, longest = f"{min(lengths):.3g}", f"{max(lengths):.3g}"
        # one length when they all print alike: a file scaled by 3 had been told "length 3–3"
        span = shortest if shortest == longest else f"{shortest}–{longest}"
        notes.append(
            f"{shown_path(source)}, line {off_unit[0][0]}"
            + (f" and {len(off_unit) - 1} more" if len(off_unit) > 1 else "")
            + f": light vector length {span}"
            + ", not 1; read as directions (normalised). If the file gives lamp positions "
            "rather than directions, they are only right for a distant lamp"
        )
    if declared is None:
        # read all the same (the lines say what they are), but said: the profile every known
        # reader accepts opens with the count, so another tool may refuse the file as it is
        notes.append(
            f"{shown_path(source)}, line {first_no}: no count line (the .lp every known reader "
            f"accepts opens with the number of lights); the {len(entries)} listed lights are "
            f"used. To give it to another tool, add a first line '{len(entries)}'"
        )
    elif declared != len(entries):
        notes.append(
            f"{shown_path(source)}, line {first_no}: count line says {declared} lights but the "
            f"file lists {len(entries)}; the {len(entries)} listed lights are used"
        )
    return entries


def _reads_as_light(line: str) -> bool:
    """Whether a line is an image name and three numbers (a comment line: one whose name
    starts with '#', the '#' touching it)."""
    tokens = line.split()
    return (
        len(tokens) >= 4
        and tokens[0].lower().endswith(_IMAGE_ENDINGS)
        and all(_is_number(t) for t in tokens[-3:])
    )


def _refuse_below_plane(
    below: list[tuple[int, str, float, float]], lights: int, source: str
) -> None:
    """Refuse lights below the object plane, saying which way out fits the file.

    Why two messages: most of a file's lights below the plane is a z axis pointing the other
    way (another tool's convention), one of 72 is not, yet it had been told "check the sign
    convention" too, with no word of how far below it was or what to do with that one line."""
    lineno, name, z, written = below[0]
    more = len(below) - 1
    others = (
        f" ({more} more line{'s' if more > 1 else ''} below the plane: "
        f"{', '.join(str(n) for n, *_ in below[1:6])}{' ...' if more > 5 else ''})"
        if more
        else ""
    )
    if 2 * len(below) > lights:
        raise LpFormatError(
            source,
            lineno,
            f"{len(below)} of the file's {lights} lights point below the object plane (z < 0), "
            f"{name!r} first: the file's z axis points the other way? rti-rig's z points up, "
            "towards the camera (docs/conventions.md); negate the z column",
        )
    elevation = math.degrees(math.asin(max(-1.0, z)))
    # the file's z, and the direction's where the vector is not of unit length (the
    # direction's alone had quoted a z of -0.0101 for a line written -0.0099)
    as_unit = f" ({z:.4f} as a direction)" if f"{written:.4f}" != f"{z:.4f}" else ""
    raise LpFormatError(
        source,
        lineno,
        f"the light of {name!r} is {-elevation:.1f}° below the object plane (z = "
        f"{written:.4f}{as_unit}; "
        f"less than {HORIZON_TOLERANCE} below is read as the horizon): no light there can have lit "
        "the object. If it is a light at the horizon whose calibration is off, set its z to 0; "
        f"otherwise remove the line and leave its image out{others}",
    )


#: A light vector this far from unit length, in a file of unit vectors, is a mistyped number.
FAR_FROM_UNIT = 0.2


def _refuse_lone_off_unit(
    off_unit: list[tuple[int, float]],
    content: list[tuple[int, str]],
    lights: int,
    source: str,
    text: str,
) -> None:
    """Refuse a light vector far from unit length where nearly all others are unit vectors.

    Why: a z of 0.0949 typed for 0.949 (length 0.33) had been normalised with a note and used
    about 55° from where the light was, ``check`` saying PASS; so had a last line cut off at
    ``0.`` (a zenith light made a horizon light). A file of lamp positions (every length
    alike, or all spread about 1) is still read as directions with a note; the rule fires
    only when at least three lines, and three quarters of them, are unit vectors."""
    far = [(n, length) for n, length in off_unit if abs(length - 1.0) > FAR_FROM_UNIT]
    unit = lights - len(off_unit)
    if not far or unit < 3 or 4 * unit < 3 * lights:
        return
    lineno, length = far[0]
    line = dict(content)[lineno]
    z = float(line.split()[-1])
    elevation = math.degrees(math.asin(max(-1.0, min(1.0, z / length))))
    last = lineno == content[-1][0] and not text.endswith(("\n", "\r"))
    more = len(far) - 1
    raise LpFormatError(
        source,
        lineno,
        f"light vector {' '.join(line.split()[-3:])} has length {length:.3g}, where {unit} of "
        f"the file's {lights} lights are unit vectors (length 1 ± {UNIT_TOLERANCE}): a "
        f"mistyped number? Read as a direction (normalised) it lights from {round(elevation)}° "
        "elevation"
        + (
            "; the file ends on this line without a line break: cut off while written or "
            "copied? Copy it again from its source"
            if last
            else "; correct the numbers on that line"
        )
        + (
            f" ({more} more such line{'s' if more > 1 else ''}: "
            f"{', '.join(str(n) for n, _ in far[1:6])}{' ...' if more > 5 else ''})"
            if more
            else ""
        ),
    )


def _refuse_counted_comment(
    light_like: list[tuple[int, str]],
    declared: int | None,
    lights: int,
    first_no: int,
    source: str,
) -> None:
    """Refuse comment lines that read as lights when the count line counts them.

    Why: an image named ``#05.jpg`` had its line skipped as a comment, the count mismatch
    was only a note, and ``check`` passed with one light fewer. A commented-out light and an
    image whose name starts with '#' look the same; the count line tells them apart."""
    if declared is None or declared == lights or declared != lights + len(light_like):
        return
    lineno, line = light_like[0]
    name = line.split()[0]
    raise LpFormatError(
        source,
        lineno,
        f"{line!r} starts with '#' and is read as a comment, but the count line (line "
        f"{first_no}) says {declared} lights and the file lists {lights} without "
        f"{'it' if len(light_like) == 1 else f'its {len(light_like)} such lines'}: is "
        f"{name!r} an image? An .lp cannot name an image starting with '#': rename the image "
        f"and its line (e.g. {name.lstrip('#') or 'image.jpg'!r}); if the line was commented "
        f"out on purpose, write the count {lights}",
    )


#: What a reader wants where it is given no ``.lp``, unless its command says it in its own words.
LP_WANTED = "give the .lp light list (a count line, then 'name x y z' per image)"


def read_lp(
    path: Path | str,
    upper_hemisphere: bool = False,
    notes: list[str] | None = None,
    *,
    wanted: str = LP_WANTED,
) -> list[LpEntry]:
    """Read an `.lp` file tolerantly; errors and ``notes`` name the file and line (see
    :func:`parse_lp`).

    A folder, an image or a TOML file given where an `.lp` goes (``run --plan``, ``bench
    tradeoff --from``) is said to be one: they had been told "cannot read: Is a directory",
    "line 1: the line holds NUL bytes … save it again as UTF-8" and "line 4: expected 'name x
    y z'". ``wanted`` says what the command reading it takes, in its words: a TOML file had
    been asked "(a rig config?)" by every reader, ``--plan`` and a rig's ``dome.lp_file``
    included, where no rig config is meant."""
    path = Path(path)
    if path.is_dir():
        raise LpFormatError(path, None, f"is a folder, not an .lp file: {wanted}")
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise LpFormatError(path, None, f"cannot read: {exc.strerror or exc}") from None
    if looks_like_image(raw):
        raise LpFormatError(path, None, f"this is an image, not an .lp file: {wanted}")
    if path.suffix.lower() == ".toml":
        raise LpFormatError(path, None, f"this is a TOML file, not an .lp: {wanted}")
    if _is_binary(raw):
        raise LpFormatError(path, None, f"this is a binary file (not text), not an .lp: {wanted}")
    return parse_lp(_decode(raw), str(path), upper_hemisphere, notes)


def _is_binary(raw: bytes) -> bool:
    """Whether ``raw`` is no text in any form an `.lp` is met in: not a file with a byte-order
    mark, not text up to a run of zeros (a file cut off while being written, which FAT cards
    fill with zeros), not UTF-16 without a mark (in any script), each of which the reader
    reads or names as such.

    Why: random bytes named ``.lp`` were told "line 6: the line holds NUL bytes … (UTF-16
    without a byte-order mark?) or cut off while being written", guesses that fit a text file
    and a line number that means nothing; a rig config of the same bytes was called binary."""
    if raw.startswith((codecs.BOM_UTF8, codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE)):
        return False
    head = raw[:4096]
    if _text_like(head) or _text_like(head.rstrip(b"\x00")):
        return False  # text, or text then zeros (cut off)
    for encoding in ("utf-16-le", "utf-16-be"):
        try:
            text = head[: len(head) // 2 * 2].decode(encoding)
        except UnicodeDecodeError:
            continue
        unprintable = sum(1 for c in text if not c.isprintable() and c not in "\t\n\r\f\x1a")
        if unprintable <= len(text) // 20:
            return False  # UTF-16 without its mark
    return True


def _text_like(data: bytes) -> bool:
    """No NUL byte, and control characters (but tab, line ends, form feed, DOS's end of file)
    in at most 1 byte of 20."""
    controls = sum(1 for b in data if b < 0x20 and b not in b"\t\n\r\f\x1a")
    return b"\x00" not in data and controls <= len(data) // 20


def _decode(raw: bytes) -> str:
    """The text of an `.lp`'s bytes. A byte-order mark says the encoding: UTF-8 (Notepad's
    "UTF-8 with BOM") or UTF-16 (Notepad's "Unicode"; what Windows PowerShell 5.1's ``>`` and
    ``Out-File`` write by default), which relight reads (Qt's QTextStream detects the mark) and
    which had been refused as ``count line 'ÿþ1\\x008\\x00'``. Without a mark, UTF-8, else
    Latin-1 (a Windows tool's ANSI names), which never fails.

    A UTF-8 mark before names that are not UTF-8 (ANSI names added to a file an editor had
    saved as "UTF-8 with BOM") is read as each is alone: the mark dropped, the rest Latin-1. It
    had been kept as Latin-1 text and the file refused at its ``count line 'ï»¿48'``, a reason
    that was not the file's; no Latin-1 file begins with those three letters."""
    if raw.startswith((codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE)):
        with contextlib.suppress(UnicodeDecodeError):  # cut off mid-character: NULs, said
            return raw.decode("utf-16")
    try:
        return raw.decode("utf-8-sig")
    except UnicodeDecodeError:
        return raw.removeprefix(codecs.BOM_UTF8).decode("latin-1")


def directions_of(entries: Iterable[LpEntry]) -> NDArray[np.float64]:
    """The (N, 3) array of the entries' unit directions."""
    return np.array([e.direction for e in entries], dtype=np.float64).reshape(-1, 3)
