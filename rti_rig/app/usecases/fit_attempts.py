"""The hidden folders a batch's attempt at one session leaves in ``--out``, named in one place.

Why a module of its own: an attempt builds its fit in ``.NAME.ATTEMPT.partial`` and, when it
replaces an earlier fit, sets that one aside as ``.NAME.ATTEMPT.earlier`` (``ATTEMPT`` is
``PID-ID``; older runs made ``.NAME.partial``). These names had been written and read in five
places with two differing patterns (an attempt of ``[^.]*`` here, ``[^.]+`` there).
"""

from __future__ import annotations

import os
import re
import uuid
from dataclasses import dataclass, replace
from enum import Enum
from pathlib import Path


class Kind(Enum):
    """What an attempt's folder holds; its value ends the folder's name."""

    #: the attempt's fit, being built (or complete, not yet put in place)
    PARTIAL = "partial"
    #: the earlier fit a refit set aside while it swaps its new fit in
    EARLIER = "earlier"


#: An attempt: the PID of the process that made it, a dash, and an ID of its own.
_ATTEMPT = re.compile(r"(\d+)-[^.]+")


@dataclass(frozen=True)
class AttemptFolder:
    """``.OUTPUT.ATTEMPT.KIND`` beside session output ``OUTPUT`` (``attempt`` None: an older
    run's ``.OUTPUT.partial``)."""

    output: str
    attempt: str | None
    kind: Kind

    @classmethod
    def new(cls, output: str) -> AttemptFolder:
        """A partial folder for a new attempt of this process, unique per attempt, so that a
        retried or orphaned attempt never writes into another's."""
        return cls(output, f"{os.getpid()}-{uuid.uuid4().hex[:8]}", Kind.PARTIAL)

    @property
    def name(self) -> str:
        """The folder's name."""
        attempt = "" if self.attempt is None else f".{self.attempt}"
        return f".{self.output}{attempt}.{self.kind.value}"

    def path(self, root: Path) -> Path:
        """The folder in batch folder ``root``."""
        return root / self.name

    def as_kind(self, kind: Kind) -> AttemptFolder:
        """The same attempt's folder of another kind (a swap's backup ↔ its new fit)."""
        return replace(self, kind=kind)

    @property
    def pid(self) -> int | None:
        """The PID of the process that made the attempt (None for an older run's folder)."""
        found = None if self.attempt is None else _ATTEMPT.fullmatch(self.attempt)
        return int(found.group(1)) if found else None

    @classmethod
    def parse(cls, name: str, output: str | None = None) -> AttemptFolder | None:
        """The attempt folder named ``name``, or None. With ``output``, only one of that
        session output's (matched exactly: a glob ``.s1.*partial`` also matched session
        ``s1.x``'s folders, which a batch may be fitting); without, the output is what
        precedes the attempt (an older run's folder then names no attempt it can be told by).
        """
        for kind in Kind:
            stem = name.removesuffix(f".{kind.value}")
            if stem == name or not stem.startswith("."):
                continue
            if output is not None:
                if stem == f".{output}" and kind is Kind.PARTIAL:
                    return cls(output, None, kind)
                attempt = stem.removeprefix(f".{output}.")
                if attempt != stem and attempt and "." not in attempt:
                    return cls(output, attempt, kind)
                return None
            head, dot, attempt = stem[1:].rpartition(".")
            if dot and head and _ATTEMPT.fullmatch(attempt):
                return cls(head, attempt, kind)
            return None
        return None
