"""QA on a session of fewer images than light directions can be judged on: it says so, rather
than calling a matte surface glossy (an `--until-error` session may stop at 4 images)."""

from __future__ import annotations

import numpy as np

from rti_rig.reconstruct.qa import MIN_DIRECTION_IMAGES, assess
from rti_rig.reconstruct.synthetic import fibonacci_lights, render, sphere_normals


def _report(n: int):  # type: ignore[no-untyped-def]
    lights = fibonacci_lights(n)
    normals, _ = sphere_normals(96, 96)
    images = render(normals, 0.6, lights)  # matte: every image a Lambertian rendering
    frames = [np.clip(im * 0.8 * 65535, 0, 65535).astype(np.uint16) for im in images]
    return assess(frames, lights, [f"image{i:02d}.tif" for i in range(n)])


def test_four_images_are_too_few_to_judge_directions_and_it_says_why() -> None:
    report = _report(MIN_DIRECTION_IMAGES - 1)
    assert not report.directions_checked
    assert "too few to tell a wrong light" in report.direction_note
    assert "glossy" not in report.direction_note
    assert not report.reshoot


def test_with_enough_images_the_same_matte_sphere_has_its_directions_judged() -> None:
    report = _report(12)
    assert report.directions_checked and report.direction_note == ""
    assert not report.reshoot
