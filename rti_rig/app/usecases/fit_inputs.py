"""What a fit was made from, recorded in its ``fit.json``, and how a source differs from it.

Why: a batch took any session whose output folder existed for "finished earlier". A session
fitted while interrupted (11 images), then continued with ``run --resume`` (48 images) or
mended with ``--reshoot-lost``, kept its out-of-date fit in the batch, reported as done. The
record is what the fit reads, so a batch can tell that an earlier fit no longer matches its
session and say how:

- each image by the checksum its session's journal took at capture (a reshot image has a new
  one), read from the journal, not hashed again; only an image the journal does not name (a
  plain ``.lp`` with its images, no journal) by its size and modification time. Sizes and
  times alone had called a session copied without its timestamps (plain ``cp``, rsync
  without ``-t``) changed in every image, and refitted a whole backlog;
  An image whose pixels, as the fit read them, are not those captured (changed on disk
  since) is recorded by what was read instead (:func:`as_read`): a later reshoot that brings
  back the captured image then refits it;
- the lights themselves, compared with the tolerance a resume uses
  (:func:`rti_rig.app.rig_identity.moved_lights`): a digest of them rounded to 6 decimals
  had called an ``.lp`` written again with 5 decimals "its lights changed", and could not
  say which.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from rti_rig.app.rig_identity import degrees_text, moved_lights

#: The key of ``fit.json`` that holds the record.
INPUTS_KEY = "inputs"

#: The most images or lights a change names before "…".
_SHOWN = 5


def inputs_record(
    lights: np.ndarray,
    paths: Sequence[Path],
    names: Sequence[str],
    root: Path,
    journaled: Mapping[str, tuple[str, str | None]] | None,
) -> dict[str, Any]:
    """The record of an acquisition as the fit reads it: each image in its ``.lp``'s order,
    by name and the sha256 ``journaled`` (:func:`rti_rig.runtime.session.journaled_checksums`
    of session ``root``) holds for its file, or its size in bytes and modification time in ns
    when none; and its lights' directions. Raises OSError when a file to stat cannot be."""
    images: list[dict[str, Any]] = []
    for name, path in zip(names, paths, strict=True):
        sums = None
        if journaled is not None:
            try:
                sums = journaled.get(Path(path).relative_to(root).as_posix())
            except ValueError:  # an image outside the session folder
                sums = None
        st = Path(path).stat()
        image: dict[str, Any] = {"name": str(name)}
        if sums is not None:
            image["sha256"] = sums[0]
            if sums[1] is not None:
                image["pixels_sha256"] = sums[1]  # what :func:`as_read` compares
        # kept beside a checksum too: a batch tells an image unchanged since the fit by them
        # without reading it, and one edited in place (or a session whose journal is lost
        # since) by them first (:func:`change_since`)
        image["size"], image["mtime_ns"] = int(st.st_size), int(st.st_mtime_ns)
        images.append(image)
    directions = [[float(x) for x in d] for d in np.asarray(lights, dtype=np.float64)]
    return {"images": images, "lights": directions}


def as_read(record: dict[str, Any], read_pixels: Sequence[str | None]) -> dict[str, Any]:
    """``record`` with each image whose pixels the fit read (``read_pixels``, in the record's
    order: their checksum, None when not taken) differ from the pixels its journal recorded
    at capture, recorded by what was read rather than by the journal's checksum.

    Why: the journal's checksum says what was captured, not what the fit read; a fit made
    while an image was damaged, then mended by ``run --resume --reshoot-lost`` (which brings
    back the same bytes), would have stood, fitted from the damaged image."""
    images = []
    for image, got in zip(record["images"], read_pixels, strict=True):
        captured = image.get("pixels_sha256")
        if got is not None and captured is not None and got != captured:
            kept = {k: image[k] for k in ("size", "mtime_ns") if k in image}
            image = {"name": image["name"], "read_pixels_sha256": got, **kept}
        elif got is not None and got == captured:
            # the fit read the captured pixels, whatever file holds them (a TIFF re-saved
            # with zlib has other bytes): a batch may then confirm a file of other bytes by
            # its pixels (:func:`_image_change`)
            image = {**image, PIXELS_AS_CAPTURED: True}
        images.append(image)
    return {**record, "images": images}


#: Set on an image of the record whose pixels the fit read and found those captured.
PIXELS_AS_CAPTURED = "pixels_as_captured"
#: The sha256 of an image's file as a batch found it holding the pixels the fit read, when
#: that is not the journal's (a TIFF re-saved with the same pixels): set by a batch
#: (:func:`confirmed_update`), so that a later ``touch`` or copy of it is not a change.
READ_SHA256 = "read_sha256"


def is_record(earlier: Any) -> bool:
    """Whether ``earlier`` is a record in this form (one kept by a fit before it, a digest of
    the lights and each image's size and time, is not: its fit is treated as one that records
    nothing, rather than every such session refitted)."""
    return isinstance(earlier, dict) and "lights" in earlier


#: Hashes an image of the acquisition now, by its name in the record: the sha256 of its file
#: (or of its pixels, :func:`rti_rig.core.image_files.tiff_pixels_sha256`), or None when it
#: cannot be read.
Digest = Callable[[str], "str | None"]


def _same_stat(before: Mapping[str, Any], now: Mapping[str, Any]) -> bool:
    """Whether an image's size and modification time are those ``before`` recorded."""
    try:
        return (int(before["size"]), int(before["mtime_ns"])) == (
            int(now["size"]),
            int(now["mtime_ns"]),
        )
    except (KeyError, TypeError, ValueError):  # a record that kept no size or time
        return False


def _image_change(
    before: Mapping[str, Any],
    now: Mapping[str, Any],
    digest: Digest | None,
    pixels: Digest | None = None,
    confirmed: dict[str, dict[str, Any]] | None = None,
) -> str | None:
    """How one image differs from the fit's record of it: ``"changed"`` (a new capture or other
    file), ``"edited"`` (its file is no longer what its journal took at capture: edited or
    damaged in place since the fit), or None when it is the image fitted.

    Size and time first, which cost no read: an image the journal vouches for whose size or
    time differ is hashed (a copy without timestamps then stands; an image edited in place
    had stood too, found by the fit's QA only). A hash that matches neither the journal's nor
    the one a batch recorded for the file the fit read (:data:`READ_SHA256`) is an edit,
    unless the fit read the captured pixels and the file still holds them (``pixels``: a TIFF
    re-saved with zlib had been refitted after every ``touch``, "changed since its
    capture"). An image so confirmed is put in ``confirmed`` by name, with its size, time and
    file hash now, for the record to be brought up to date (a copied session had been read
    in full on every batch). Without a journal's checksum now (a plain ``.lp``, or a session
    whose journal is lost since the fit) size and time decide."""
    if "sha256" in now:
        if "sha256" in before:
            if str(before["sha256"]) != str(now["sha256"]):
                return "changed"
            if "size" not in before or _same_stat(before, now):
                return None  # a record without size and time: the journal's word, as before
            name = str(now["name"])
            got = digest(name) if digest is not None else None
            if got is None:
                return "edited"
            if got not in (str(now["sha256"]), before.get(READ_SHA256)) and not (
                before.get(PIXELS_AS_CAPTURED) is True
                and before.get("pixels_sha256") is not None
                and pixels is not None
                and pixels(name) == str(before["pixels_sha256"])
            ):
                return "edited"
            if confirmed is not None:
                update = {"size": now["size"], "mtime_ns": now["mtime_ns"]}
                if got != str(now["sha256"]):
                    update[READ_SHA256] = got
                confirmed[name] = update
            return None
        if "read_pixels_sha256" in before:  # fitted from an image not as captured
            return None if _same_stat(before, now) else "changed"
    return None if _same_stat(before, now) else "changed"


def _shown_names(images: Sequence[Mapping[str, Any]]) -> list[str]:
    return [str(i["name"]) for i in images]


def _shown(items: Sequence[str]) -> str:
    return ", ".join(items[:_SHOWN]) + (" …" if len(items) > _SHOWN else "")


def change_since(
    earlier: Any,
    now: dict[str, Any],
    digest: Digest | None = None,
    pixels: Digest | None = None,
    confirmed: dict[str, dict[str, Any]] | None = None,
) -> str | None:
    """How the acquisition recorded ``now`` differs from the ``earlier`` record, in words
    ("11 → 48 images"; "2 of 8 images changed: image_003, image_005"; "1 of 8 images changed
    on disk since its capture …: image_003"; "1 of 8 lights moved: image_004's by 0.20°"), or
    None when it matches. ``digest`` hashes an image whose size or time changed, ``pixels``
    hashes its pixels, and ``confirmed`` collects the images a hash confirmed (see
    :func:`_image_change`). An ``earlier`` record that cannot be read (a damaged ``fit.json``)
    differs."""
    try:
        before = list(earlier["images"])
        names_before = _shown_names(before)
        lights_before = np.asarray(earlier["lights"], dtype=np.float64)
    except (TypeError, KeyError, ValueError):
        return "its fit.json's record of what it was fitted from cannot be read"
    after = list(now["images"])
    names = _shown_names(after)
    lights_now = np.asarray(now["lights"], dtype=np.float64)
    said = []
    if len(before) != len(after):
        said.append(f"{len(before)} → {len(after)} images")
    elif names_before != names:
        said.append("its images are not the ones fitted")
    else:
        kinds = [
            _image_change(b, a, digest, pixels, confirmed)
            for b, a in zip(before, after, strict=True)
        ]
        changed = [n for n, k in zip(names, kinds, strict=True) if k == "changed"]
        edited = [n for n, k in zip(names, kinds, strict=True) if k == "edited"]
        if changed:
            said.append(f"{len(changed)} of {len(after)} images changed: {_shown(changed)}")
        if edited:
            said.append(
                f"{len(edited)} of {len(after)} images changed on disk since their capture "
                f"(same name, not the checksum their journal took): {_shown(edited)}"
            )
    if len(before) == len(after) and lights_before.shape == lights_now.shape:
        moved = moved_lights(lights_before, lights_now)
        if moved:
            order = sorted(moved, key=lambda i: -moved[i])
            each = [f"{names[i]}'s by {degrees_text(moved[i])}" for i in order]
            said.append(f"{len(moved)} of {len(after)} lights moved: {_shown(each)}")
    return "; ".join(said) or None


def journal_lost(earlier: Any, now: dict[str, Any]) -> bool:
    """Whether the ``earlier`` record named images by their journal's checksums and ``now``
    names none so (the session's journal is gone, or cannot be read, since the fit)."""
    try:
        had = any("sha256" in i or "read_pixels_sha256" in i for i in earlier["images"])
    except (TypeError, KeyError):
        return False
    return had and not any("sha256" in i for i in now["images"])


def judged_by_stat(earlier: Any) -> bool:
    """Whether the ``earlier`` record kept each image's size and time (records before they
    were kept beside a journal's checksum did not: such an image cannot be compared without
    its journal)."""
    try:
        return all("size" in i and "mtime_ns" in i for i in earlier["images"])
    except (TypeError, KeyError):
        return False


def confirmed_update(
    earlier: dict[str, Any], confirmed: Mapping[str, Mapping[str, Any]]
) -> dict[str, Any]:
    """The ``earlier`` record with the images a batch's hash confirmed (:func:`change_since`'s
    ``confirmed``) given their size, time and file hash now: the next batch then reads their
    headers only, not every byte again (a session copied without its timestamps had been read
    in full on every batch)."""
    images = []
    for image in earlier["images"]:
        update = confirmed.get(str(image.get("name")))
        images.append(image if update is None else {**image, **update})
    return {**earlier, "images": images}
