"""The images of a recorded acquisition (an `.lp` with its images beside it), checked before
anything is done with them.

Why one module: ``run ACQ/dirs.lp`` (the replay rig) and ``bench tradeoff --from`` read the
same acquisitions; the trade-off had checked only that the files exist, and so read every
image before stopping at "all input arrays must have the same shape" (naming no file), or
scaled one image of another size in silence and printed a full table of results from it.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from rti_rig.core.errors import ConfigError, SessionError
from rti_rig.core.image_files import (
    header_bit_depth,
    header_layout,
    image_truncation,
    is_camera_raw,
    read_image_any,
    tiff_sample_problem,
    tiff_several_images,
)
from rti_rig.core.lp_format import (
    LpEntry,
    exports_folder,
    image_paths,
    missing_images_advice,
)
from rti_rig.core.shell_words import shown_path


@dataclass(frozen=True)
class AcquisitionImages:
    """Where every image of an acquisition is (in the `.lp`'s order), and their one layout."""

    paths: list[Path]
    height: int
    width: int
    colour: bool


class AcquisitionImagesError(ConfigError):
    """What is wrong with an acquisition's images: every problem found (``problems``, each a
    sentence naming the images and what to do), the first one as the message.

    Why a kind of its own: ``check ACQ/dirs.lp`` checks exactly these, and says them as a
    failed check (each one, RESULT: FAIL, exit 1), where ``run``, ``fit`` and ``bench`` refuse
    to start (the first one, as before). The check had said the first one as a usage error
    (exit 2), the others unsaid."""

    def __init__(self, lp_path: Path | str, problems: Sequence[str]) -> None:
        super().__init__(lp_path, None, problems[0])
        self.problems = tuple(problems)
        #: what the `.lp`'s tolerant reader noted of the file (set by the loader that read
        #: it), said with the refusal: the user mending the images learns of the rest too
        self.reader_notes: tuple[str, ...] = ()


def check_acquisition_images(
    lp_path: Path,
    entries: Sequence[LpEntry],
    *,
    lead: str = "",
    use: str = "replay",
    pixels: str = "a replay cannot give as a frame",
) -> AcquisitionImages:
    """The images ``entries`` (read from ``lp_path``) name, each found, whole, readable, and
    all of one size and one kind (colour or grey); else an :class:`AcquisitionImagesError`
    naming the `.lp`, the images and what to do (every problem found, the first as its
    message).

    From the files' headers where they say (decoding only those whose header does not, as a
    capture or a read would), so that a fault is said before minutes of work, not part-way.
    ``lead`` opens the message of missing images (the replay says what an `.lp` is as a rig);
    ``use`` is the verb of what is done with the others ("replay", "measure"); ``pixels``
    says who cannot read a float or many-paged TIFF."""
    names = [e.name for e in entries]
    return check_image_files(
        lp_path,
        names,
        image_paths(lp_path, entries),
        lead=lead,
        use=use,
        pixels=pixels,
    )


def check_image_files(
    lp_path: Path,
    names: Sequence[str],
    files: Sequence[Path],
    *,
    lead: str = "",
    use: str = "replay",
    pixels: str = "a replay cannot give as a frame",
    headers_only: bool = False,
) -> AcquisitionImages:
    """:func:`check_acquisition_images` of the files that will actually be read for the images
    ``lp_path`` lists as ``names`` (``files[i]`` for ``names[i]``).

    Why split out: ``fit`` reads a ``linear/<stem>.tif`` beside the `.lp` in place of the file
    it names when there is one; it checks those files, in the words ``run`` and ``bench
    tradeoff --from`` use (it had stopped at the first missing image, and said a size apart
    as numpy shapes).

    ``headers_only``: decode nothing, and leave an image that is damaged, of samples ``pixels``
    names, or whose header does not say its size out of the comparison, to the reader that
    names its fault (the fit's own read says "cannot be read as a TIFF" where a decode here
    would say "index 0 out of range"); the size and kind then are 0 and colour when no header
    says them."""
    paths = dict(zip(names, files, strict=True))
    problems: list[str] = []
    missing = [n for n in names if not paths[n].is_file()]
    if missing:
        more = f" and {len(missing) - 5} more" if len(missing) > 5 else ""
        # a name with an invisible character in it is shown escaped ('ima\u200bge05.jpg')
        shown = ", ".join(n if n.isprintable() else repr(n) for n in missing[:5]) + more
        lp_dir = Path(lp_path).parent
        # an RTIBuilder project's others are in its jpeg-exports/: said, and copied, there
        exports = exports_folder(lp_dir, [paths[n] for n in names if n not in missing])
        problems.append(
            f"{lead}{len(missing)} of {len(names)} image(s) missing in "
            f"{shown_path(exports or lp_dir)} ({shown})"
            + missing_images_advice(
                missing,
                [paths[m] for m in missing],
                lp_dir,
                use,
                total=len(names),
                into=exports,
            )
        )
    gone = set(missing)
    # a camera's RAW files, from their names (no read decodes them): a DNG is a TIFF to the
    # header reader, so they had passed as "undamaged and readable" and stopped the replay at
    # its first capture, the fit at its first read, behind an OpenCV warning line
    raw = [n for n in names if n not in gone and is_camera_raw(paths[n])]
    if raw:
        more = f" and {len(raw) - 5} more" if len(raw) > 5 else ""
        problems.append(
            f"{len(raw)} of {len(names)} image(s) beside it are camera RAW files "
            f"({', '.join(raw[:5])}{more}), which rti-rig does not read as an acquisition's "
            "images: develop them to 16-bit linear TIFFs (dcraw -4 -T, or RawTherapee or "
            "darktable with a linear output profile) and list those in the .lp, or list the "
            "camera's JPEGs"
        )
        gone.update(raw)
    present = [n for n in names if n not in gone]
    why_cut = {n: image_truncation(paths[n]) for n in present}
    damaged = [f"{name}: {why}" for name, why in why_cut.items() if why is not None]
    # OpenCV would decode a JPEG with its missing part grey, and say nothing
    if damaged and not headers_only:
        jpegs = all(
            paths[name].suffix.lower() in (".jpg", ".jpeg")
            for name, why in why_cut.items()
            if why is not None
        )
        problems.append(
            f"{len(damaged)} of {len(names)} image(s) beside it are damaged "
            f"{'JPEGs' if jpegs else 'images'} "
            f"({'; '.join(damaged[:5])}{' ...' if len(damaged) > 5 else ''}); copy them again "
            "from the camera or card"
        )
    layouts: dict[str, tuple[int, int, bool]] = {}
    unreadable: list[str] = []
    unsupported: list[str] = []
    several: list[str] = []
    for n in present:
        path = paths[n]
        if why_cut[n] is not None:
            continue  # said above (or, headers_only, by the reader)
        many = tiff_several_images(path)  # whole and readable: not "copy it again"
        if many is not None:
            if not headers_only:
                several.append(many)
            continue
        problem = tiff_sample_problem(path)  # a float TIFF has a header like any other
        if problem is not None:
            if not headers_only:
                unsupported.append(problem)
            continue
        layout = header_layout(path)
        if layout is None:
            if headers_only:
                continue
            try:
                img = read_image_any(path)
            except SessionError as exc:
                unreadable.append(str(exc))
                continue
            layout = (int(img.shape[0]), int(img.shape[1]), img.ndim == 3)
        layouts[n] = layout
    if unreadable:
        problems.append(
            f"{len(unreadable)} of {len(names)} image(s) beside it cannot be read "
            f"({'; '.join(unreadable[:5])}{' ...' if len(unreadable) > 5 else ''}); copy them "
            "again from the camera or card, or list only the others"
        )
    if several:
        problems.append(
            f"{len(several)} of {len(names)} image(s) beside it are whole TIFFs of more than "
            f"one full-size image, not damaged ({'; '.join(several[:3])}"
            f"{' ...' if len(several) > 3 else ''}), or list only the others"
        )
    if unsupported:
        problems.append(
            f"{len(unsupported)} of {len(names)} image(s) beside it hold pixels {pixels} "
            f"({'; '.join(unsupported[:3])}"
            f"{' ...' if len(unsupported) > 3 else ''}), or list only the others"
        )
    if not layouts:  # (headers_only) no header said a size, or no image could say one
        if problems:
            raise AcquisitionImagesError(lp_path, problems)
        return AcquisitionImages([paths[n] for n in names], 0, 0, True)
    first = next(iter(layouts))  # the first image listed, unless left to its reader
    height, width, colour = layouts[first]
    odd = [f"{n} is {w}x{h}" for n, (h, w, _) in layouts.items() if (h, w) != (height, width)]
    if odd:
        problems.append(
            f"the images beside it differ in size: {first} is {width}x{height} but "
            f"{'; '.join(odd[:5])}{' ...' if len(odd) > 5 else ''}; an acquisition has one "
            "image size (replace or resize those images, or list only the others)"
        )
    kind = "colour" if colour else "greyscale"
    other = [n for n, (_, _, c) in layouts.items() if c != colour]
    if other:
        problems.append(
            f"the images beside it are not all {kind}: {first} is {kind} but "
            f"{', '.join(other[:5])}{' ...' if len(other) > 5 else ''} "
            f"{'is' if len(other) == 1 else 'are'} {'greyscale' if colour else 'colour'}; an "
            "acquisition has one kind of image (convert those images, or list only the others)"
        )
    if problems:
        raise AcquisitionImagesError(lp_path, problems)
    return AcquisitionImages([paths[n] for n in names], height, width, colour)


def mixed_depth_note(lp_path: Path, names: Sequence[str], paths: Sequence[Path], use: str) -> str:
    """A note when the images ``lp_path`` lists (``names``, read from ``paths``) mix 8-bit
    files, read as sRGB, with 16-bit ones, read as linear (their headers say which); "" when
    they do not. ``use`` is what is done with them ("replayed").

    Why: ``fit`` of such an `.lp` says so (a gamma-encoded 16-bit export beside JPEGs is
    wrong in its mid-tones), but its replay, whose session holds them all as linear TIFFs,
    and the check before it had said nothing."""
    depths = [header_bit_depth(p) for p in paths]
    eight = [n for n, d in zip(names, depths, strict=True) if d == 8]
    # a TIFF of 10, 12 or 14 bits a sample is decoded to 16-bit codes and taken as linear too
    sixteen = [n for n, d in zip(names, depths, strict=True) if d is not None and d > 8]
    return mixed_depth_words(lp_path, eight, sixteen, use)


def mixed_depth_words(lp_path: Path, eight: Sequence[str], sixteen: Sequence[str], use: str) -> str:
    """The words of :func:`mixed_depth_note` for the images named ``eight`` (8-bit) and
    ``sixteen`` (16-bit); "" unless both are some. ``fit``, which knows each image's depth
    from its frames, says it in these words too (one wording, one place)."""
    if not eight or not sixteen:
        return ""
    shown = ", ".join(sixteen[:3]) + (" ..." if len(sixteen) > 3 else "")
    return (
        f"{shown_path(lp_path)} mixes {len(eight)} 8-bit image(s), decoded as sRGB, with "
        f"{len(sixteen)} 16-bit one(s), taken as linear ({shown}): if the 16-bit files are "
        f"gamma-encoded exports, not linear data, they are {use} wrongly; export every image of "
        "the acquisition alike"
    )
