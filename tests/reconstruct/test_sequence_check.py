"""The online slip check of a camera-triggered dome, on rendered images (pure: no device)."""

from __future__ import annotations

import numpy as np

from rti_rig.core.geometry import direction_from_az_el
from rti_rig.reconstruct.sequence_check import DOUBLE, MISSED, OK, SHIFT_UNTIL, SequenceChecker
from rti_rig.simulator.sim_scene import renderer_for

ORDER = np.concatenate(
    [
        direction_from_az_el(45 + 360 * np.arange(c) / c, np.full(c, e))
        for e, c in ((79.4, 4), (62.0, 8), (44.7, 16))
    ]
)
RENDER = renderer_for("relief", 64, 64, 0)


def frame(direction) -> np.ndarray:  # type: ignore[no-untyped-def]
    rgb = RENDER(None if direction is None else direction, 1.0)
    return np.round(np.clip(rgb * 0.75, 0, 1) * 65535).astype(np.uint16)


def test_a_clean_sequence_is_accepted_image_by_image() -> None:
    chk = SequenceChecker(ORDER)
    verdicts = [chk.check(i, frame(d), 65535) for i, d in enumerate(ORDER)]
    assert [v.kind for v in verdicts] == [OK] * len(ORDER)
    assert sum(v.fitted for v in verdicts) >= len(ORDER) - 4  # the neighbour test ran
    assert chk.accepted == len(ORDER)


def test_a_dark_image_is_a_missed_step_even_before_any_fit() -> None:
    chk = SequenceChecker(ORDER)
    chk.check(0, frame(ORDER[0]), 65535)
    v = chk.check(1, frame(None), 65535)
    assert v.kind == MISSED and "dark" in v.reason and not v.fitted
    assert chk.accepted == 1  # never joins the fit


def test_an_image_lit_by_the_next_led_is_a_double_step() -> None:
    chk = SequenceChecker(ORDER)
    for i in range(10):
        assert chk.check(i, frame(ORDER[i]), 65535).kind == OK
    v = chk.check(10, frame(ORDER[11]), 65535)
    assert v.kind == DOUBLE and v.best_position == 11 and v.fitted
    # named as the CLI names LEDs: 0-based, with its direction (it said "position 12")
    assert "next LED of the order, LED 11 (az " in v.reason and "not LED 10 (az " in v.reason


def test_an_image_lit_by_the_previous_led_is_a_missed_step() -> None:
    chk = SequenceChecker(ORDER)
    for i in range(10):
        chk.check(i, frame(ORDER[i]), 65535)
    v = chk.check(10, frame(ORDER[9]), 65535)
    assert v.kind == MISSED and v.best_position == 9 and "previous LED" in v.reason


def test_a_shift_from_the_first_images_is_found_by_the_whole_set_test() -> None:
    """Double step at image 2: every later image is lit one LED later, so the images explain
    one another and the neighbour test sees nothing; the whole-set test names where it began."""
    chk = SequenceChecker(ORDER)
    verdicts = []
    for i in range(25):
        v = chk.check(i, frame(ORDER[i if i < 1 else i + 1]), 65535)
        verdicts.append(v)
        if v.slip:
            break
    v = verdicts[-1]
    assert v.slip and v.kind == DOUBLE and v.since in (0, 1)
    assert v.index <= SHIFT_UNTIL and "stepped twice" in v.reason


def test_a_slip_found_late_is_traced_back_to_the_image_it_began_at() -> None:
    """Test 4 (white-box): images 8-10 were lit one LED later but accepted (as under grazing
    light, where the neighbour test sees a slip only once it grows); when the slip is found at
    image 11 the whole set says it began at image 8."""
    from rti_rig.reconstruct.sequence_check import SequenceVerdict, reduce_image

    chk = SequenceChecker(ORDER)
    for i in range(7):
        assert chk.check(i, frame(ORDER[i]), 65535).kind == OK
    for i in range(7, 10):  # accepted although lit by the next LED
        chk._images.append(reduce_image(frame(ORDER[i + 1]), 65535))
        chk._lights.append(ORDER[i])
    found = SequenceVerdict(10, DOUBLE, "lit by the next LED", 11, True)
    located = chk._locate_start(found, reduce_image(frame(ORDER[11]), 65535))
    assert located.since == 7 and "beginning at image 8" in located.reason
    # ...and a slip at its own image is left as it is
    chk2 = SequenceChecker(ORDER)
    for i in range(10):
        chk2.check(i, frame(ORDER[i]), 65535)
    v = chk2.check(10, frame(ORDER[11]), 65535)
    assert v.kind == DOUBLE and v.since is None


def test_a_missed_step_shot_again_with_its_own_noise_is_still_named() -> None:
    """A real camera's second exposure of the previous LED has noise of its own (the
    simulator's is keyed by the light, so there it is the image before bit for bit): the
    "that image again" condition must hold at shot noise, not only at equality. Poisson noise
    of a 20000 e- full well, drawn afresh for every shot."""
    rng = np.random.default_rng(1)

    def shot(direction) -> np.ndarray:  # type: ignore[no-untyped-def]
        electrons = rng.poisson(np.clip(RENDER(direction, 1.0) * 0.75, 0, None) * 20000.0)
        return np.round(np.clip(electrons / 20000.0, 0, 1) * 65535).astype(np.uint16)

    chk = SequenceChecker(ORDER)
    for i in range(10):
        assert chk.check(i, shot(ORDER[i]), 65535).kind == OK
    v = chk.check(10, shot(ORDER[9]), 65535)
    assert v.kind == MISSED and v.best_position == 9 and "previous LED" in v.reason
