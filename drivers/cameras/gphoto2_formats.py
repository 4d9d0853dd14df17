"""Whether a camera's image-format choice, as libgphoto2 names it, gives a RAW file.

Why: every decode mode reads the shot's RAW (``collect`` refuses a shot without one), and a
JPEG-only ``image_format`` had passed ``rti-rig check``, to be refused at the first shot with
its LED already lit. The camera's choices are read at connect; this judges them by the names
libgphoto2 publishes for the common bodies (camlibs/ptp2/config.c):

* Canon EOS (``imageformat``): "RAW", "mRAW", "sRAW", "cRAW", "RAW + Large Fine JPEG" …, and
  the JPEG-only "Large Fine JPEG", "Medium Normal JPEG", "S1 Fine JPEG", "Smaller JPEG" ….
* Nikon (``imagequality``, the compression table): "NEF (Raw)", "NEF+Basic", "NEF+Normal",
  "NEF+Fine", and the RAW-less "JPEG Basic", "JPEG Normal", "JPEG Fine", "TIFF (RGB)".
* Fuji: "RAW", "RAW + JPEG Fine" …, "JPEG Fine", "JPEG Normal".
* Sony (``imagequality``): "RAW", "RAW+JPEG" …, and the JPEG-only "Standard", "Fine",
  "Extra Fine".

A name none of these rules covers (libgphoto2's "Unknown value 0007" for a code its table
lacks, a vendor's own word) is *not judged*: None, said so at check, never guessed.
"""

from __future__ import annotations

import re

#: a RAW in the name: Canon's RAW/mRAW/sRAW/cRAW, Nikon's NEF, or a RAW file's suffix
_RAW = re.compile(r"(raw|\bnef\b|\b(cr2|cr3|crw|arw|srf|sr2|raf|orf|rw2|pef|dng|3fr|iiq)\b)", re.I)
#: a JPEG-only (or other RAW-less) format named as such: JPEG, TIFF, HEIF
_NOT_RAW = re.compile(r"\b(jpe?g|tiff?|heif|heic)\b", re.I)
#: whole names of JPEG-only qualities that say no "JPEG" (Sony's; Minolta-heritage bodies)
_NOT_RAW_NAMES = frozenset({"standard", "fine", "extra fine", "economy"})


def gives_raw(choice: str) -> bool | None:
    """True when the choice gives a RAW file (alone or with a JPEG), False when libgphoto2's
    name says it gives none (JPEG or TIFF only), None when the name cannot be judged."""
    name = choice.strip()
    if _RAW.search(name):
        return True
    if _NOT_RAW.search(name) or name.lower() in _NOT_RAW_NAMES:
        return False
    return None


def raw_choices(choices: list[str]) -> list[str]:
    """The offered choices known to give a RAW file, in the camera's order."""
    return [c for c in choices if gives_raw(c)]
