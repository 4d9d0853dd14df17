"""The end-of-run proof of a camera-triggered dome's order, on rendered images with noise that
differs from frame to frame (pure: no device, no model of the object)."""

from __future__ import annotations

import numpy as np
import pytest

from rti_rig.core.geometry import direction_from_az_el
from rti_rig.reconstruct.run_out_proof import (
    CANNOT,
    DOUBLE,
    MIN_DIFFERENCE,
    PROVED,
    prove_run_out,
    relative_difference,
)
from rti_rig.reconstruct.sequence_check import reduce_image
from rti_rig.simulator.sim_scene import renderer_for

# the shipped order's last ring: 16 LEDs at 10 deg elevation, from azimuth 45 deg
ORDER = direction_from_az_el(45 + 360 * np.arange(16) / 16, np.full(16, 10.0))


def shots(scene: str, leds: list[int], noise: float, seed: int = 1) -> list[np.ndarray]:
    """One reduced image per entry of ``leds`` (an LED index of ORDER), each with its own noise
    (``noise``: standard deviation as a fraction of full scale, per pixel)."""
    render = renderer_for(scene, 64, 64, 0)
    rng = np.random.default_rng(seed)
    out = []
    for led in leds:
        rgb = render(ORDER[led], 1.0) * 0.75
        rgb = rgb + rng.normal(0.0, noise, rgb.shape)
        pixels = np.round(np.clip(rgb, 0, 1) * 65535).astype(np.uint16)
        out.append(reduce_image(pixels, 65535))
    return out


@pytest.mark.parametrize("scene", ["relief", "coin", "painting", "tablet"])
@pytest.mark.parametrize("noise", [0.0, 0.002, 0.005])
def test_a_clean_run_is_proved_whatever_the_noise(scene: str, noise: float) -> None:
    """Without a slip the proof frame re-lights the last LED: same as the last image up to
    noise, and the image before (its neighbour) differs."""
    *images, proof = shots(scene, [10, 11, 12, 13, 14, 15, 15], noise)
    verdict = prove_run_out(images, proof)
    assert verdict.kind == PROVED, verdict.reason
    assert verdict.neighbours > 3 * verdict.same


@pytest.mark.parametrize("scene", ["relief", "coin", "painting", "tablet"])
@pytest.mark.parametrize("noise", [0.0, 0.002, 0.005])
def test_a_double_step_anywhere_leaves_the_last_two_images_alike(scene: str, noise: float) -> None:
    """After an unseen double step the dome reached its last LED one image early: the last two
    images and the proof frame are all the same LED."""
    *images, proof = shots(scene, [11, 12, 13, 14, 15, 15, 15], noise)
    verdict = prove_run_out(images, proof)
    assert verdict.kind == DOUBLE, verdict.reason
    assert "stepped twice" in verdict.reason


@pytest.mark.parametrize("scene", ["relief", "coin", "painting", "tablet"])
@pytest.mark.parametrize(
    "leds",
    [
        [9, 10, 11, 12, 13, 14, 0],  # the proof frame lit by a far LED
        [8, 9, 10, 11, 12, 13, 14],  # a step lost unseen: image n was LED n-1, the proof LED n
    ],
)
def test_a_dome_that_had_not_run_out_is_not_proved(scene: str, leds: list[int]) -> None:
    """A proof frame lit by another LED than the last image's never passes, even though the
    last two images differ."""
    *images, proof = shots(scene, leds, 0.005)
    verdict = prove_run_out(images, proof)
    assert verdict.kind != PROVED, verdict.reason


@pytest.mark.parametrize("scene", ["relief", "coin", "painting", "tablet"])
def test_noise_as_large_as_the_leds_difference_is_cannot_verify_never_proved(scene: str) -> None:
    """At 2 % of full scale per reduced pixel the noise rivals what tells the last two LEDs
    apart: a double step is not proved, and neither is a clean run (a false alarm, said as
    "cannot be verified", rather than silence)."""
    *images, proof = shots(scene, [11, 12, 13, 14, 15, 15, 15], 0.02)
    assert prove_run_out(images, proof).kind == CANNOT
    *images, proof = shots(scene, [10, 11, 12, 13, 14, 15, 15], 0.02)
    assert prove_run_out(images, proof).kind == CANNOT


def test_an_object_that_looks_alike_under_every_led_cannot_be_verified() -> None:
    """A featureless object: neighbouring LEDs give the same image, so 'alike' proves nothing
    either way; the verdict says so instead of 'double step' or 'ok'."""
    rng = np.random.default_rng(0)
    flat = [np.full((64, 64), 0.5) + rng.normal(0, 0.002, (64, 64)) for _ in range(8)]
    verdict = prove_run_out(flat[:7], flat[7])
    assert verdict.kind == CANNOT, verdict.reason
    assert "cannot be verified" in verdict.reason


def test_the_difference_is_scale_free_and_zero_for_the_same_image() -> None:
    a = shots("relief", [3], 0.0)[0]
    assert relative_difference(a, a) == 0.0
    b = shots("relief", [4], 0.0)[0]
    assert relative_difference(a, b) == pytest.approx(relative_difference(4 * a, 4 * b))
    assert relative_difference(a, b) > MIN_DIFFERENCE


def test_the_proof_needs_two_images() -> None:
    with pytest.raises(ValueError):
        prove_run_out([np.zeros((4, 4))], np.zeros((4, 4)))
