"""A text as a TOML 1.0 basic string, for a line the user is told to paste into a rig config.

Why: calibrate-lights printed ``intensity_correction_file = "{rel}"`` as it was; a name with a
quote or a backslash made a line TOML refuses (or reads as another name), and a name whose
bytes are not UTF-8 (held by Python as lone surrogates) cannot be in a TOML file at all.
"""

from __future__ import annotations

#: TOML 1.0's short escapes; any other control character is written ``\\uXXXX``.
_SHORT = {'"': '\\"', "\\": "\\\\", "\b": "\\b", "\t": "\\t", "\n": "\\n", "\f": "\\f", "\r": "\\r"}


class NotTomlText(ValueError):
    """The text holds what no TOML string can: a name whose bytes are not UTF-8."""


def toml_basic_string(text: str) -> str:
    """``text`` as a double-quoted TOML basic string that ``tomllib`` reads back as ``text``.

    Raises :class:`NotTomlText` when ``text`` holds a lone surrogate (``os.fsdecode`` of bytes
    that are not UTF-8): a TOML document is UTF-8, so no escape names those bytes."""
    chars = []
    for ch in text:
        code = ord(ch)
        if 0xD800 <= code <= 0xDFFF:
            raise NotTomlText("not UTF-8 text, which a TOML file cannot hold")
        if ch in _SHORT:
            chars.append(_SHORT[ch])
        elif code < 0x20 or code == 0x7F:
            chars.append(f"\\u{code:04X}")
        else:
            chars.append(ch)
    return '"' + "".join(chars) + '"'
