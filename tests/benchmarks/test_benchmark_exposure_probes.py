"""benchmarks.exposure_probes: its model names the images the emulated card dome clipped, and
checking more of the highest lights never leaves more domes clipped."""

from __future__ import annotations

from benchmarks import exposure_probes as bench


def test_the_model_names_the_shipped_card_domes_clipped_leds() -> None:
    """The emulated session metered at LED 44 alone clipped images 37, 39, 40, 41, 43, 44, 48
    (LEDs 36, 38, 39, 40, 42, 43, 47); checked at 6 lights, none."""
    assert bench.shipped_dome() == (
        "metered at 1: 7 of 48 images clip (LEDs [36, 38, 39, 40, 42, 43, 47]); "
        "metered at 6: 0 of 48 images clip (LEDs [])"
    )


def test_more_of_the_highest_lights_never_leave_more_domes_clipped() -> None:
    pct = bench.run(None, 200, 0.2)
    highest = [pct[f"highest {k}"] for k in bench.COUNTS]
    assert highest == sorted(highest, reverse=True) and highest[0] > highest[-1]
    # equal LEDs: the zenith light is the brightest, and the headroom covers the rest
    assert bench.run(None, 50, 0.0) == dict.fromkeys(pct, 0.0)
