"""Where a key is written in a TOML file: the line a config error names beside the key.

Why by hand: :mod:`tomllib` keeps no positions, and the libraries that keep a document's layout
(tomlkit) expose none either; a user told "key 'camera.device.gain'" of a 90-line config had
to search for it. This reads only what locates a key: table headers (``[a.b]``, ``[[a.b]]``,
counted per array so that ``emulator.faults[1].kind`` is the second table's) and assignments
(``key =``, ``a.b =``, quoted parts), skipping comments and multi-line strings. It never
judges the file: tomllib has read it before any key is refused.
"""

from __future__ import annotations

import re
from pathlib import Path

_PART = r"""(?:[A-Za-z0-9_-]+|"(?:[^"\\]|\\.)*"|'[^']*')"""
_DOTTED = rf"{_PART}(?:\s*\.\s*{_PART})*"
_HEADER = re.compile(rf"^\s*(\[\[?)\s*({_DOTTED})\s*\]\]?\s*(?:#.*)?$")
_ASSIGN = re.compile(rf"^\s*({_DOTTED})\s*=")
_ONE_PART = re.compile(_PART)
#: A key's parts as an error names them: ``dome.rings[2].count`` → dome, rings, [2], count.
_KEY_PARTS = re.compile(r"\[\d+\]|[^.\[]+")

#: Past this size a file is no rig config: not read for a line.
_MAX_BYTES = 1 << 20


def _parts(dotted: str) -> list[str]:
    """The parts of a dotted TOML key, quotes removed (escapes are left as written: a key
    that needs one is matched as written, or not at all)."""
    return [p[1:-1] if p[:1] in "\"'" else p for p in _ONE_PART.findall(dotted)]


def _indexed(parts: list[str], arrays: dict[str, int]) -> str:
    """``parts`` as an error names the key, each array of tables among its prefixes given the
    index of its latest table (``[emulator.faults.x]`` after two ``[[emulator.faults]]`` is
    ``emulator.faults[1].x``)."""
    out = ""
    for part in parts:
        out = f"{out}.{part}" if out else part
        if out in arrays:
            out += f"[{arrays[out]}]"
    return out


def _structure(value: str) -> str:
    """The brackets, braces and commas of ``value`` (the rest of a line), strings and a
    comment skipped."""
    out, quote, i = [], "", 0
    while i < len(value):
        c = value[i]
        if quote:
            if c == "\\" and quote == '"':
                i += 1
            elif c == quote:
                quote = ""
        elif c in "\"'":
            quote = c
        elif c == "#":
            break
        elif c in "[]{},":
            out.append(c)
        i += 1
    return "".join(out)


class _OpenArray:
    """A value that goes on over several lines, read line by line for the inline tables of
    an array (``rings = [`` then ``{ elevation_deg = 10.0, count = 12 },`` per line): each
    written whole on its line is found as ``rings[i]``, so a key refused in it (a negative
    elevation) is named with that line. Why: the shipped configs write their rings so, and
    their errors had named no line at all."""

    def __init__(self, key: str) -> None:
        self.key = key
        self.depth = 0
        self.element = 0  # commas at the array's own depth: the index of the next element
        self.table_from: int | None = None  # the line an element's inline table opened on

    def read(self, line: str, n: int, found: dict[str, tuple[int, bool]]) -> None:
        for c in _structure(line):
            if c in "[{":
                if c == "{" and self.depth == 1:
                    self.table_from = n
                self.depth += 1
            elif c in "]}":
                self.depth -= 1
                if c == "}" and self.depth == 1 and self.table_from is not None:
                    name = f"{self.key}[{self.element}]"
                    found.setdefault(name, (self.table_from, self.table_from == n))
                    self.table_from = None
            elif self.depth == 1:
                self.element += 1

    @property
    def open(self) -> bool:
        return self.depth > 0


def key_lines(text: str) -> dict[str, tuple[int, bool]]:
    """Each key and table of a TOML text, by the name an error gives it, with its first line
    (from 1) and whether its whole value is on that line (False: a table header, or a value
    that goes on over more lines, whose keys are on lines of their own; an inline table of
    such an array, written on one line, is found by its index: ``rings[2]``)."""
    found: dict[str, tuple[int, bool]] = {}
    arrays: dict[str, int] = {}
    table = ""
    closing: str | None = None  # the quotes that end a multi-line string being skipped
    value: _OpenArray | None = None  # a value that goes on over the lines being read
    for n, line in enumerate(text.removeprefix("\ufeff").splitlines(), 1):
        if closing is not None:
            if closing in line:
                closing = None
            continue
        if value is not None and value.open:
            value.read(line, n, found)
            continue
        header = _HEADER.match(line)
        if header:
            parts = _parts(header[2])
            if header[1] == "[[":  # one more table of the array: its own name not indexed
                above = _indexed(parts[:-1], arrays)
                path = f"{above}.{parts[-1]}" if above else parts[-1]
                arrays[path] = arrays.get(path, -1) + 1
                path += f"[{arrays[path]}]"
            else:
                path = _indexed(parts, arrays)
            table = path
            found.setdefault(table, (n, False))
            continue
        assign = _ASSIGN.match(line)
        if assign is None:
            continue
        key = ".".join(_parts(assign[1]))
        rest = line[assign.end() :]
        for quotes in ('"""', "'''"):
            if rest.count(quotes) == 1:
                closing = quotes
        name = f"{table}.{key}" if table else key
        value = None if closing else _OpenArray(name)
        if value is not None:
            value.read(rest, n, found)
        whole = value is None or not value.open
        found.setdefault(name, (n, whole))
    return found


def key_line(text: str, key: str) -> int | None:
    """The line ``key`` (as an error names it) is written on in ``text``, or None.

    A key inside a value written whole on one line (an inline table or array: ``decode = {
    white_balance = [0, 1, 1, 1] }``) is on that assignment's line, and one inside an inline
    table of an array written over several lines (``rings = [`` then a table per line) is on
    that table's line; a key elsewhere in such a value has none, nor has a key its table
    lacks (a table header, or the first line of such a value, is never named as the line of
    a key it does not hold: a wrong line is worse than none)."""
    found = key_lines(text)
    parts = _KEY_PARTS.findall(key)
    for end in range(len(parts), 0, -1):
        name = "".join(p if p.startswith("[") else f".{p}" for p in parts[:end]).lstrip(".")
        if name in found:
            line, assigned = found[name]
            return line if end == len(parts) or assigned else None
    return None


def key_line_in_file(path: Path | str, key: str) -> int | None:
    """:func:`key_line` of a TOML file; None when it cannot be read (gone, too large, not
    text): a line is a help to the message, never a reason for another error."""
    file = Path(path)
    if file.suffix.lower() != ".toml":
        return None
    try:
        if file.stat().st_size > _MAX_BYTES:
            return None
        text = file.read_text(encoding="utf-8-sig")  # a byte-order mark, as tomllib takes
    except (OSError, UnicodeDecodeError):
        return None
    return key_line(text, key)
