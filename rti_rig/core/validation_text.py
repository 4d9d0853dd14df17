"""A validation error of a config table in the user's words: the full key and what is wrong.

Why here: the rig config loader (app) and a driver's own nested table (``[dome.serial.protocol]``
is validated by the LED dome driver's settings) must word the same slip the same way, and the
drivers may stand on the core alone. The functions read pydantic's error dicts, so the core
needs no pydantic import.
"""

from __future__ import annotations

from typing import Any

#: what every table says of a key it does not know
UNKNOWN_KEY = "unknown key (check its spelling and the table it is in)"


def key_of(loc: tuple[Any, ...]) -> str:
    """A pydantic location as the dotted TOML key a user wrote (``dome.rings[2].count``)."""
    out = ""
    for part in loc:
        if isinstance(part, int):
            out += f"[{part}]"
        else:
            out += ("." if out else "") + str(part)
    return out


def error_text(err: Any) -> str:
    """One pydantic error in a user's words: what is wrong, the value given, and for a number
    where the driver wants the camera's own text (``iso = 100``), how to write it."""
    msg = str(err["msg"]).removeprefix("Value error, ")
    if err["type"] == "extra_forbidden":
        return UNKNOWN_KEY
    if err["type"] in ("value_error", "missing") or "input" not in err:
        return msg
    got = err["input"]
    if err["type"] == "string_type" and isinstance(got, int | float) and not isinstance(got, bool):
        return f'{msg} (got {got!r}: write it in quotes, "{got}", as the camera names it)'
    return f"{msg} (got {got!r})"
