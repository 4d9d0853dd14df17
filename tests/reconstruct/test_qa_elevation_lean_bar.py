"""One image's edges are claimed moved only beyond the still images' bar plus how far the
session's edges lean with the light's elevation (``rti_rig.reconstruct.qa``).

The case that made the rule, held as numbers rather than as a rendered session (whose QA
branch moved with the dependencies installed: tests/cli/test_qa_still_step_by_elevation.py): the
emulated Nab dome's brushed-steel part, still, uneven LEDs, seed 8 — a (-1.0, +0.9) px step
refused for the lights' elevation, and image_009 alone 2.9 px off the others with the still
images' bar at 2.6 px, which had been called "object or camera moved"."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from rti_rig.reconstruct import qa

#: the still images' edge noise that puts the bar at 2.6 px (EDGE_NOISE_FACTOR × noise)
NOISE_PX = 2.6 / qa.EDGE_NOISE_FACTOR


def test_an_image_off_by_more_than_the_bar_is_claimed_without_a_lean() -> None:
    assert qa._claim_bar_px(NOISE_PX, 0.0) == pytest.approx(2.6)
    assert qa._edges_agree((2.9, 0.0), np.array([2.9, 0.0]), NOISE_PX, 0.0)


def test_the_lean_of_a_refused_step_raises_the_bar_past_that_image() -> None:
    refused = [SimpleNamespace(shift=(-1.0, 0.9))]
    lean = qa._elevation_lean_px(refused)  # type: ignore[arg-type]
    assert lean == math.hypot(-1.0, 0.9)
    assert qa._claim_bar_px(NOISE_PX, lean) == pytest.approx(2.6 + lean)
    assert not qa._edges_agree((2.9, 0.0), np.array([2.9, 0.0]), NOISE_PX, lean)
    # a real move beyond the raised bar is still claimed
    assert qa._edges_agree((4.5, 0.0), np.array([4.5, 0.0]), NOISE_PX, lean)


def test_no_refused_step_no_lean() -> None:
    assert qa._elevation_lean_px([]) == 0.0
