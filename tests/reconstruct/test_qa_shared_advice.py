"""The verdict says advice shared by many images once, in the problems' order, and only where
one word names the problems (an overexposed session had said the same advice 48 times)."""

from __future__ import annotations

from rti_rig.reconstruct.qa import _shared_advice, _without_advice
from rti_rig.reconstruct.qa_repeated import repeated_problem

LESS = "a session keeps one exposure: shoot it again as a new session"
OTHER = "check the lens cap"


def test_advice_of_three_images_is_shared_in_the_problems_order() -> None:
    images = [
        [f"saturated: {k}% of pixels clipped; {LESS}", f"darkened: {k}%; {OTHER}"]
        for k in (9, 75, 90)
    ]
    shared = _shared_advice(images)
    assert list(shared) == [LESS, OTHER]  # the problems' order, not a set's
    assert shared[LESS] == (3, "saturated") and shared[OTHER] == (3, "darkened")
    assert _without_advice(images[0][0], shared) == "saturated: 9% of pixels clipped"
    assert _shared_advice(images[:2]) == {}  # two images: each says its own


def test_problems_led_by_several_words_keep_their_advice() -> None:
    # "the same picture as image_001, though … (…: …); reshoot it": no one-word label
    images = [[repeated_problem("image_001")] for _ in range(4)]
    assert _shared_advice(images) == {}


def test_a_problem_of_several_words_keeps_advice_said_once_for_another_kind() -> None:
    """Advice said once "for the 3 saturated images" is taken off those alone: a problem of
    several words with the same advice ("a flat frame: …; LESS") is not counted in the 3, and
    had lost its advice all the same."""
    images = [[f"saturated: {k}% of pixels clipped; {LESS}"] for k in (9, 75, 90)]
    flat = f"a flat frame: one level throughout; {LESS}"
    shared = _shared_advice([*images, [flat]])
    assert shared[LESS] == (3, "saturated")
    assert _without_advice(flat, shared) == flat
    assert _without_advice(images[1][0], shared) == "saturated: 75% of pixels clipped"
