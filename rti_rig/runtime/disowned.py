"""A session whose image labels are known to be unreliable, marked so that no tool uses them.

Some slips are seen only after images were labelled: a camera-triggered dome (cceh/rti) that
stepped twice where the per-image check could not tell, caught some images later or by the
end-of-run proof (docs/domes.md). Nothing captured is deleted or rewritten, so the session's
``lights.lp`` still lists those images; the marker file beside it says why they must not be
fitted or exported, and :func:`refuse_if_disowned` makes ``rti-rig fit`` and ``export-lp``
refuse the session instead of silently producing a relighting from mislabelled images.
"""

from __future__ import annotations

from pathlib import Path

from rti_rig.core.errors import SessionError
from rti_rig.core.shell_words import shown_path

#: The marker, at the session's root, beside ``lights.lp``; it holds the reason as text.
MARKER = "LABELS_NOT_VERIFIED.txt"


class DisownedSessionError(SessionError):
    """The session's labels were disowned when it was shot (its marker file says why)."""


def disown(root: Path, reason: str) -> Path:
    """Write the marker with ``reason`` (kept whole: several reasons are appended)."""
    marker = Path(root) / MARKER
    with marker.open("a", encoding="utf-8") as fh:
        fh.write(reason.rstrip() + "\n")
    return marker


def refuse_if_disowned(root: Path) -> None:
    """Raise :class:`DisownedSessionError` naming the marker when ``root`` holds one."""
    marker = Path(root) / MARKER
    if marker.is_file():
        reasons = marker.read_text(encoding="utf-8").strip().splitlines()
        last = reasons[-1] if reasons else "(no reason recorded)"  # the most specific one
        raise DisownedSessionError(
            f"{shown_path(root)}: the images of this session may be labelled with the wrong "
            f"lights, so it is not used: {shown_path(marker)} says: {last} — reshoot the object "
            f"(the images are kept; delete {marker.name} only if you have checked every label by "
            "hand)"
        )
