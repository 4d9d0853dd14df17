"""The fault kinds the docs tell a user to pass to ``python -m rti_rig.simulator.dome_firmware
--fault K:KIND`` are the emulators' own: docs/domes.md's rehearsal (a real firmware's
emulator) lists :data:`BOARD_FAULT_KINDS`, docs/protocols/led-dome.md's (the own protocols')
every :class:`FaultKind`, and docs/domes.md names every real firmware the emulator serves.

Why: ``blank_line_before_reply`` was added to the emulator and the config without a word in
domes.md, which a reader took for the whole list; a kind added or renamed now fails here."""

from __future__ import annotations

import re
from pathlib import Path

from rti_rig.simulator.dome_firmware import FaultKind
from rti_rig.simulator.domes import SERIAL_FIRMWARES
from rti_rig.simulator.domes.board import BOARD_FAULT_KINDS

DOCS = Path(__file__).resolve().parents[2] / "docs"
KINDS = {k.value for k in FaultKind}


def _paragraph(path: Path, starts: str) -> str:
    """The paragraph (or bullet) of ``path`` that begins with ``starts``."""
    text = path.read_text(encoding="utf-8")
    at = text.index(starts)
    end = re.compile(r"\n\s*\n|\n\* ").search(text, at + len(starts))
    return text[at : end.start() if end else len(text)]


def _kinds_in(paragraph: str) -> set[str]:
    return {word for word in re.findall(r"`([a-z_]+)`", paragraph) if word in KINDS}


def test_domes_md_lists_the_kinds_a_real_firmwares_emulator_takes() -> None:
    paragraph = _paragraph(DOCS / "domes.md", "To rehearse a failure, add `--fault K:KIND`")
    listed = _kinds_in(paragraph.split("These are the kinds")[0])
    assert listed == {k.value for k in BOARD_FAULT_KINDS}, paragraph
    # the others are pointed to where they are listed
    assert "protocols/led-dome.md" in paragraph, paragraph


def test_led_dome_md_lists_every_kind_of_the_own_protocols_emulator() -> None:
    bullet = _paragraph(DOCS / "protocols" / "led-dome.md", "* deterministic faults")
    assert _kinds_in(bullet) == KINDS, bullet


def test_domes_md_names_every_firmware_the_emulator_serves() -> None:
    paragraph = _paragraph(DOCS / "domes.md", "To rehearse it without a dome")
    named = set(re.findall(r"`([a-z0-9-]+)`", paragraph))
    assert set(SERIAL_FIRMWARES) <= named, paragraph
