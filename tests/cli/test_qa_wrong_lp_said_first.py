"""Lights that are likely wrong (a shuffled ``.lp``) are said first, not as per-image faults,
through the front door.

Found by an audit: with a session's ``lights.lp`` shuffled the verdict led with "reshoot:
image_012 (wrong light …), image_019 (brighter …)" and only then said that most recorded
lights are likely wrong: every check against the recorded lights points at images one by
one when the lights are not theirs. The likely cause now leads, the images it explains are
counted, not named, and a problem no light can cause (a clipped image) is still named.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
from conftest import qa_of

from rti_rig.core.lp_format import LpEntry, read_lp, write_lp
from rti_rig.reconstruct.qa import MIRRORED_SAID, UNORDERED_SAID

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from fit_sessions import make_session

SATURATED = 4  # 0-based: image_005, six times over its exposure


def test_a_shuffled_lp_is_said_first_and_its_images_not_blamed(tmp_path: Path) -> None:
    session, _, _ = make_session(tmp_path / "s", size=(64, 80), saturate=SATURATED)
    entries = read_lp(session / "lights.lp")
    order = np.random.default_rng(1).permutation(len(entries))
    write_lp(
        session / "lights.lp",
        [LpEntry(e.name, entries[k].direction) for e, k in zip(entries, order, strict=True)],
    )
    text, qa = qa_of(session, tmp_path / "fit")
    verdict = text[text.index("QA verdict: ") :]
    assert verdict.startswith(f"QA verdict: lights likely wrong: {UNORDERED_SAID}"), verdict
    assert verdict.count(UNORDERED_SAID) == 1, verdict
    assert "not named one by one" in verdict, verdict
    # the clipped image is the acquisition's whatever the lights: named, with its advice
    head, _, rest = verdict.partition("; reshoot whatever the lights: ")
    assert rest.startswith("image_005 (saturated"), verdict
    assert "image_" not in head, verdict  # no image blamed before it (caveats may name some)
    assert qa["lights_likely_wrong"] is True and qa["good"] is False
    assert qa["reshoot"] == ["image_005"], qa["reshoot"]


def test_a_y_flipped_lp_is_said_to_be_mirrored(tmp_path: Path) -> None:
    """An .lp whose y is flipped (a tool with y-down image axes) keeps every angle between the
    lights: the fit explained every image and the verdict was "good". The fitted surface, whose
    gradient then curls, tells it."""
    session, _, _ = make_session(tmp_path / "s", size=(64, 80))
    entries = read_lp(session / "lights.lp")
    flipped = [LpEntry(e.name, (e.direction[0], -e.direction[1], e.direction[2])) for e in entries]
    write_lp(session / "lights.lp", flipped)
    text, qa = qa_of(session, tmp_path / "fit")
    assert f"QA verdict: {MIRRORED_SAID}" in text, text
    assert qa["lights_mirrored"] is True and qa["good"] is False, qa["verdict"]


def test_a_flat_plate_with_its_lights_right_is_not_doubted(tmp_path: Path) -> None:
    """A flat plate's images differ by their level alone, so which look alike is noise: with
    every light right it was told "most recorded lights are likely wrong" (likeness 0.53-0.60)."""
    session, _, _ = make_session(tmp_path / "s", scene="flat", size=(64, 80))
    text, qa = qa_of(session, tmp_path / "fit")
    assert "likely wrong" not in text and "mirrored" not in text, text
    assert qa["good"] is True, qa["verdict"]
