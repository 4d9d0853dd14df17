"""How a session's last run ended, as its folder says once the run has stopped.

Why: what ``rti-rig run`` says after a stop (a Ctrl-C, a SIGTERM, an error) depends on some
ten facts of the session folder (are all images in? did this run record its end? is
``lights.lp`` whole? are the labels disowned? …), and these had been read inline, each where
a sentence needed it, in the CLI. Read once here, as typed facts of the folder's manifest,
journal (its committed steps) and files, each can be tested against a folder the real writer
wrote, and the CLI's wording is left a table of (facts → sentence).

Nothing here says anything to the user: the words are the CLI's.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from pathlib import Path
from typing import Any

from rti_rig.runtime.disowned import MARKER
from rti_rig.runtime.session import SessionFolder, holds_no_image


@dataclass(frozen=True)
class RunEnding:
    """What the session folder holds once its run stopped (see :func:`read_run_ending`)."""

    #: committed images in the folder (earlier runs' and this one's)
    images_kept: int
    #: the steps the session plans: its maximum for an adaptive session
    total_steps: int
    #: whether ``lights.lp`` lists exactly the committed images, in step order
    lp_whole: bool
    #: how many images ``lights.lp`` lists (0: missing or unreadable)
    lp_listed: int
    #: whether this run wrote its header to the folder (it began; a resume stopped while it
    #: opened did not)
    begun: bool
    #: whether the manifest's last run entry says the session completed: an earlier run's
    #: while this run has not begun (a --reshoot-lost of a completed session), this run's once
    #: it has
    last_run_completed: bool
    #: whether the session's ``runner`` record says it completed (its end is recorded)
    end_recorded: bool
    #: whether the session is adaptive and its outcome (why it stopped, its error estimate)
    #: is not recorded in the manifest
    adaptive_outcome_unrecorded: bool
    #: the marker disowning the session's labels (None: there is none)
    labels_disowned: Path | None
    #: the session folder (where :attr:`holds_no_image` looks, if asked)
    root: Path

    @cached_property
    def holds_no_image(self) -> bool:
        """Whether the folder holds nothing but an image-less session's own files (False
        while images are kept). Read when first asked, not with the other facts: it walks the
        folder, and a stop with images kept never asks."""
        return self.images_kept == 0 and holds_no_image(self.root)

    @property
    def run_completed(self) -> bool:
        """Whether this run's own entry says the session completed: the capture's end was
        reached before the stop (the manifest is written before the stop acts). Never true
        of a run that did not begin, whose last entry is an earlier run's."""
        return self.begun and self.last_run_completed

    @property
    def every_image_in(self) -> bool:
        """Whether images are kept, ``lights.lp`` lists them all, and the capture had nothing
        left to shoot: every planned image is in, or this run completed (an adaptive session
        its stopping rule ended short of its maximum)."""
        return (
            self.images_kept > 0
            and self.lp_whole
            and (self.images_kept >= self.total_steps or self.run_completed)
        )

    @property
    def stopped_short(self) -> bool:
        """Whether fewer images are kept than the session plans (an adaptive session's
        maximum not reached)."""
        return self.images_kept < self.total_steps


def _last_run_completed(manifest: dict[str, Any]) -> bool:
    runs = manifest.get("runs") or []
    return bool(runs) and runs[-1].get("finish_reason") == "completed"


def read_run_ending(folder: SessionFolder, total_steps: int) -> RunEnding:
    """The facts of ``folder`` once its run stopped, ``total_steps`` being what the run
    planned (an adaptive session's maximum). Read from the folder as it is now: its manifest
    (as the teardown's ``finish`` left it), its committed steps, ``lights.lp`` and the
    disowning marker."""
    manifest = folder.manifest or {}
    kept = folder.images_kept
    whole, listed = folder.lp_listing()
    adaptive = manifest.get("adaptive")
    marker = Path(folder.root) / MARKER
    return RunEnding(
        images_kept=kept,
        total_steps=total_steps,
        lp_whole=whole,
        lp_listed=listed,
        begun=folder.begun,
        last_run_completed=_last_run_completed(manifest),
        end_recorded=(manifest.get("runner") or {}).get("finish_reason") == "completed",
        adaptive_outcome_unrecorded=isinstance(adaptive, dict) and not adaptive.get("result"),
        labels_disowned=marker if marker.is_file() else None,
        root=Path(folder.root),
    )
