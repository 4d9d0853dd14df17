"""The QA's "black throughout" and ``fit --no-qa``'s no-signal check judge alike.

The QA had its own rule (each image's brightest 0.1 % of its reduced grey image below 0.2 % of
full scale) restating :mod:`rti_rig.reconstruct.signal_check` by another method, so the two
could disagree about the same images: an object lit in one channel only (a red LED) at 0.4 %
of full scale reads 0.13 % in grey, and the QA called every image "misfired, no light" while
the fit's check saw signal.
"""

from __future__ import annotations

import numpy as np
import pytest

from rti_rig.reconstruct.qa import BLACK_THROUGHOUT, assess
from rti_rig.reconstruct.signal_check import SAMPLE_PIXELS, images_without_signal
from rti_rig.reconstruct.stack import ImageStack
from rti_rig.reconstruct.synthetic import fibonacci_lights, render, sphere_normals

N, SIDE = 12, 96
FULL = 65535


def _black() -> list[np.ndarray]:
    """A capped lens: black, with a few hot pixels (well under 0.1 % of the values)."""
    frames = []
    for _ in range(N):
        f = np.zeros((SIDE, SIDE, 3), np.uint16)
        f[10, 10], f[50, 70] = FULL // 2, FULL // 3
        frames.append(f)
    return frames


def _small_object() -> list[np.ndarray]:
    """A small bright object (a 12 x 12 px sphere, under 2 % of the frame) on black velvet."""
    normals, _ = sphere_normals(12, 12)
    frames = []
    for im in render(normals, 0.8, fibonacci_lights(N)):
        f = np.zeros((SIDE, SIDE, 3), np.uint16)
        f[40:52, 40:52] = (np.clip(im, 0, 1) * 0.8 * FULL).astype(np.uint16)[..., None]
        frames.append(f)
    return frames


def _dim_red_object() -> list[np.ndarray]:
    """An object lit in its red channel only, at 0.4 % of full scale (grey: 0.13 %)."""
    normals, _ = sphere_normals(SIDE, SIDE)
    frames = []
    for im in render(normals, 1.0, fibonacci_lights(N)):
        f = np.zeros((SIDE, SIDE, 3), np.uint16)
        f[..., 0] = np.where(im > 0.05, int(0.004 * FULL), 0)
        frames.append(f)
    return frames


def _qa_black_throughout(frames: list[np.ndarray]) -> bool:
    report = assess(frames, fibonacci_lights(N), [f"image{i:02d}.tif" for i in range(N)])
    said = [" ".join(c.problems) for c in report.images]
    return all(BLACK_THROUGHOUT in s for s in said)


def _check_black_throughout(frames: list[np.ndarray]) -> bool:
    stack = ImageStack(np.stack(frames))
    sample, _ = stack.pixel_sample(SAMPLE_PIXELS)  # as fit --no-qa samples it
    empty = images_without_signal(sample, stack.saturation_level)
    assert empty is not None
    return len(empty.indices) == N and set(empty.kinds) == {"black"}


@pytest.mark.parametrize(
    ("frames", "black"),
    [(_black, True), (_small_object, False), (_dim_red_object, False)],
    ids=["capped lens", "small object on black velvet", "dim red object"],
)
def test_the_qa_and_the_no_signal_check_agree_on_every_image_black(frames, black) -> None:  # type: ignore[no-untyped-def]
    images = frames()
    assert _check_black_throughout(images) is black
    assert _qa_black_throughout(images) is black
