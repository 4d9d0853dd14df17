"""Write one benchmark's figures into its own section of ``docs/benchmarks.md``, when asked.

Each benchmark owns a section delimited by HTML comment markers, so benchmarks can be rerun
independently without clobbering each other's figures. A benchmark prints its figures; it
writes them into the repository's committed docs only when its command line says ``--write``,
so a quick or exploratory run never replaces the committed results.
"""

from __future__ import annotations

import platform
import re
import sys
from datetime import UTC, datetime
from pathlib import Path

DOCS = Path(__file__).resolve().parent.parent / "docs" / "benchmarks.md"
HEADER = (
    "# Benchmarks\n\n"
    "Figures written by the scripts in `benchmarks/`; each section names the command that "
    "measured it. A script prints its figures; rerun it with `--write` to refresh its section.\n"
)


def machine_line() -> str:
    """One line describing where and when the figures were measured."""
    import os

    cores = os.cpu_count()
    when = datetime.now(UTC).strftime("%Y-%m-%d %H:%M UTC")
    py = platform.python_version()
    return f"Measured {when} on {platform.machine()}, {cores} cores, Python {py}."


def write_asked(argv: list[str] | None = None) -> bool:
    """Whether the command line asked for the figures to be written (``--write``)."""
    return "--write" in (sys.argv[1:] if argv is None else argv)


def exit_on_help(doc: str | None, argv: list[str] | None = None, *, writes: bool = True) -> None:
    """For a script without an argument parser: ``-h``/``--help`` prints its docstring and
    exits, instead of running the whole benchmark (minutes) as an unknown argument would.

    ``writes=False``: the script only prints (its figures in docs/ are recorded by hand). Its
    help says so, and a ``--write`` is refused before the run. Why: every script's help had
    offered ``--write``, and three that write nothing ran for minutes with it and left the
    recorded table as it was, the user believing it refreshed."""
    args = sys.argv[1:] if argv is None else argv
    if "-h" in args or "--help" in args:
        print((doc or "").strip())
        if writes:
            print(WRITES)
        else:
            print(PRINTS_ONLY)
        raise SystemExit(0)
    if not writes and "--write" in args:
        print(f"--write: {PRINTS_ONLY.strip()}", file=sys.stderr)
        raise SystemExit(2)


#: What a script that writes its figures into docs/ says of ``--write``.
WRITES = "\nOptions: --write  update the figures in docs/ (otherwise they are only printed)"

#: What a script that writes nothing into docs/ says of ``--write``.
PRINTS_ONLY = (
    "\nThis benchmark only prints its figures: it has no --write. The figures recorded in "
    "docs/ from it were copied there by hand, with the date and command they came from."
)


def positional_args(argv: list[str] | None = None) -> list[str]:
    """The command line's arguments without ``--write`` (for scripts that read positionals)."""
    return [a for a in (sys.argv[1:] if argv is None else argv) if a != "--write"]


def write_section(name: str, markdown: str, path: Path = DOCS) -> Path | None:
    """Replace (or append) the section ``name`` of ``path`` with ``markdown`` — only when the
    command line says ``--write``; otherwise say how to, and write nothing (returns None)."""
    if not write_asked():
        print(f"(figures not written to {path.name}: rerun with --write to update it)")
        return None
    begin, end = f"<!-- BEGIN {name} -->", f"<!-- END {name} -->"
    block = f"{begin}\n{markdown.rstrip()}\n{end}"
    text = path.read_text(encoding="utf-8") if path.exists() else HEADER
    pattern = re.compile(re.escape(begin) + r".*?" + re.escape(end), re.DOTALL)
    if pattern.search(text):
        text = pattern.sub(lambda _m: block, text)
    else:
        text = text.rstrip() + "\n\n" + block + "\n"
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text if text.endswith("\n") else text + "\n", encoding="utf-8")
    return path
