"""What a fit was made from, recorded in its ``fit.json``, and how a source differs from it.

Why: a batch took any session whose output folder existed for "finished earlier". A session
fitted while interrupted (11 images), then continued with ``run --resume`` (48 images) or
mended with ``--reshoot-lost``, kept its out-of-date fit in the batch, reported as done. The
record is what the fit reads: each image's file (its size and modification time, which a
resumed or reshot session changes) and the lights, so a batch can tell that an earlier fit no
longer matches its session and say how.
"""

from __future__ import annotations

import hashlib
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

#: The key of ``fit.json`` that holds the record.
INPUTS_KEY = "inputs"


def inputs_record(
    lights: np.ndarray, paths: Sequence[Path], names: Sequence[str]
) -> dict[str, Any]:
    """The record of an acquisition as the fit reads it: each image (name, size in bytes,
    modification time in ns) in its ``.lp``'s order, and a digest of its lights (to 1e-6, the
    precision an ``.lp`` is written in). Raises OSError when a file cannot be stat'ed."""
    images = []
    for name, path in zip(names, paths, strict=True):
        st = Path(path).stat()
        images.append([str(name), int(st.st_size), int(st.st_mtime_ns)])
    rounded = np.round(np.asarray(lights, dtype=np.float64), 6) + 0.0  # no -0.0
    return {
        "images": images,
        "lights_sha256": hashlib.sha256(rounded.tobytes()).hexdigest(),
    }


def change_since(earlier: Any, now: dict[str, Any]) -> str | None:
    """How the acquisition recorded ``now`` differs from the ``earlier`` record, in words
    ("11 → 48 images"; "2 of 8 images changed: image_003, image_005"), or None when it
    matches. An ``earlier`` record that is not one (a damaged ``fit.json``) differs."""
    try:
        before = [(str(n), int(s), int(t)) for n, s, t in earlier["images"]]
        lights_before = str(earlier["lights_sha256"])
    except (TypeError, KeyError, ValueError):
        return "its fit.json's record of what it was fitted from cannot be read"
    after = [(str(n), int(s), int(t)) for n, s, t in now["images"]]
    said = []
    if len(before) != len(after):
        said.append(f"{len(before)} → {len(after)} images")
    elif [b[0] for b in before] != [a[0] for a in after]:
        said.append("its images are not the ones fitted")
    else:
        changed = [a[0] for a, b in zip(after, before, strict=True) if a != b]
        if changed:
            shown = ", ".join(changed[:5]) + (" …" if len(changed) > 5 else "")
            said.append(f"{len(changed)} of {len(after)} images changed: {shown}")
    if lights_before != now["lights_sha256"] and len(before) == len(after):
        said.append("its lights changed")
    return "; ".join(said) or None
