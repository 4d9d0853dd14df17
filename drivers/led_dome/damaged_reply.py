"""Whether an unmatched reply is the expected one with a single byte damaged, lost or added.

Why: a board without a boot banner (the Elexol 24R1 answers only its ``?``) has shown nothing
of its protocol when its first reply is unreadable, so a failed handshake there had been read
as a wrong port, baud rate or profile: no resend, and that advice. A wrong baud rate or another
firmware gives bytes that are nowhere near the reply; a reply one byte off it (``USB I/\\x0e
24R1``) is the board answering in its profile over a line that damaged a byte, which a resend
survives and whose advice is the cable, not the config.
"""

from __future__ import annotations

import re
import string

#: The bytes tried in place of a damaged or lost one: what the replies of the described
#: firmwares are written in (printable ASCII and line ends).
_CANDIDATES = tuple(string.printable)
#: A match shorter than this is too weak to tell one edit from chance (a one-character
#: acknowledgement is one substitution away from almost any text).
_MIN_MATCH = 6
#: Longer text is a stream of some other kind (a banner, another firmware's chatter), not a
#: damaged reply; it also bounds the search.
_MAX_TEXT = 200


def one_byte_off(wanted: re.Pattern[str], text: str) -> bool:
    """The text would match ``wanted`` (over at least :data:`_MIN_MATCH` characters, the edit
    inside the match) with one character replaced, put back or taken out."""
    if not text or len(text) > _MAX_TEXT:
        return False
    for i in range(len(text) + 1):
        edits = [text[:i] + text[i + 1 :]] if i < len(text) else []
        edits += [text[:i] + c + text[i + 1 :] for c in _CANDIDATES if i < len(text)]
        edits += [text[:i] + c + text[i:] for c in _CANDIDATES]
        for edited in edits:
            m = wanted.search(edited)
            if m and m.end() - m.start() >= _MIN_MATCH and m.start() <= i <= m.end():
                return True
    return False
