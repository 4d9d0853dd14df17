"""JSON that every reader can parse: no NaN or Infinity.

Python's ``json`` writes ``NaN`` and ``Infinity`` for non-finite floats; they are not JSON
(RFC 8259), and a browser's ``JSON.parse``, ``jq`` and most other readers refuse the whole file.
A measure that could not be taken (NaN) or is unbounded is written as ``null``.
"""

from __future__ import annotations

import json
import math
from typing import Any


def finite_or_null(value: Any) -> Any:
    """``value`` with every non-finite float, in any nesting of dicts, lists and tuples, made
    None."""
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, dict):
        return {k: finite_or_null(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [finite_or_null(v) for v in value]
    return value


def strict_dumps(value: Any, **kwargs: Any) -> str:
    """:func:`json.dumps` of :func:`finite_or_null` (``allow_nan=False``: a non-finite number
    that slipped through raises rather than writing a file no reader parses)."""
    return json.dumps(finite_or_null(value), allow_nan=False, **kwargs)
