"""A session's QA verdict also names the files lost since capture.

Why: the QA judges the pixels it can read, and ``fit`` reads a session's linear TIFFs; a JPEG
deleted or truncated since capture went unseen, the verdict said "good", while ``lights.lp``
still listed it, so relight and RTIBuilder (which pair the ``.lp`` with the JPEGs in order)
gave every later image the wrong light. The journal's checksums say what was captured.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

from rti_rig.reconstruct.qa import QAReport
from rti_rig.runtime.session import LP_NAME, files_lost_since_capture, read_manifest


def with_lost_files(qa: QAReport, source: Path) -> QAReport:
    """``qa`` with a problem added to each image of session ``source`` whose files are gone or
    changed since capture (unchanged for an ``.lp`` acquisition, which has no journal)."""
    source = Path(source)
    if not source.is_dir():
        if source.name != LP_NAME:  # an .lp of its own, not a session's lights.lp
            return qa
        source = source.parent
    lost = files_lost_since_capture(source)
    if not lost:
        return qa
    adaptive = bool(read_manifest(source).get("adaptive"))
    todo = (
        "put the original back from a copy (an adaptive session cannot reshoot one image: "
        "the lights after it were chosen from it)"
        if adaptive
        else f"reshoot it with: rti-rig run --resume {source} (the object where it was), or "
        "put the original back from a copy"
    )
    images = []
    for check in qa.images:
        gone = lost.get(check.name)
        if gone:
            pairing = (
                f"; {LP_NAME} still lists it, so relight and RTIBuilder pair the images after "
                "it with the wrong lights"
                if any(g.endswith(".jpg missing") or g.endswith(".jpg changed") for g in gone)
                else ""
            )
            problem = f"{', '.join(gone)} since capture{pairing}; {todo}"
            check = replace(check, problems=(*check.problems, problem))
        images.append(check)
    return replace(qa, images=tuple(images))
