"""The highlight method's pure part: a highlight's position gives l = 2(n·v)n − v in the
project's frame (y up, rows down), sub-pixel; what gives no direction is rejected with why."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rti_rig.reconstruct.sphere_lights import (
    Circle,
    Highlight,
    Rejected,
    SphereCircleError,
    angle_deg,
    direction_at,
    find_highlight,
)

CIRCLE = Circle(60.0, 50.0, 40.0)
SHAPE = (100, 120)


def _image(column: float, row: float, sigma: float = 1.2, peak: float = 3000.0) -> np.ndarray:
    """A highlight of ``peak`` above a sphere at 10, unclipped at the white level 65535 (a
    highlight must stand 2.5 % of it above the sphere)."""
    rows, cols = np.mgrid[0 : SHAPE[0], 0 : SHAPE[1]].astype(float)
    spot = peak * np.exp(-((cols - column) ** 2 + (rows - row) ** 2) / (2 * sigma**2))
    return 10.0 + spot


def test_centre_is_the_camera_and_up_the_image_is_plus_y() -> None:
    assert np.allclose(direction_at(CIRCLE, 60.0, 50.0), (0.0, 0.0, 1.0))
    # a highlight above the centre (a smaller row) is a light towards the image's top: +y
    up = direction_at(CIRCLE, 60.0, 50.0 - 40.0 * math.sin(math.radians(20)))
    assert up[1] > 0 and abs(up[0]) < 1e-12
    assert math.isclose(math.degrees(math.asin(up[2])), 50.0, abs_tol=1e-9)  # 90 − 2·20
    right = direction_at(CIRCLE, 60.0 + 10.0, 50.0)
    assert right[0] > 0 and abs(right[1]) < 1e-12


def test_a_sub_pixel_highlight_gives_its_direction() -> None:
    column, row = 71.3, 38.6
    found = find_highlight(_image(column, row), CIRCLE, 65535)
    assert isinstance(found, Highlight)
    assert abs(found.column - column) < 0.05 and abs(found.row - row) < 0.05
    assert angle_deg(found.direction, direction_at(CIRCLE, column, row)) < 0.2


@pytest.mark.parametrize(
    ("image", "words"),
    [
        (np.full(SHAPE, 10.0), "no highlight"),
        (_image(60.0, 50.0, sigma=8.0, peak=60000.0), "blob of"),
        (_image(60.0 + 39.0, 50.0), "rim"),
        (_image(60.0 + 34.0, 50.0), "below the object plane"),
    ],
)
def test_what_gives_no_direction_is_rejected_with_why(image: np.ndarray, words: str) -> None:
    found = find_highlight(image, CIRCLE, 65535)
    assert isinstance(found, Rejected) and words in found.reason


def test_a_clipped_highlight_gives_its_centre() -> None:
    """The usual case on a chrome sphere at a real exposure: the highlight's core is clipped
    flat at the white level; the plateau's middle is the highlight, sub-pixel."""
    column, row = 52.4, 61.7
    image = np.minimum(_image(column, row, sigma=1.5, peak=1e6), 65535.0)
    assert (image >= 65535).sum() > 20  # a clipped plateau, not a peak
    found = find_highlight(image, CIRCLE, 65535)
    assert isinstance(found, Highlight), found
    assert abs(found.column - column) < 0.05 and abs(found.row - row) < 0.05


def _dark_jpeg() -> np.ndarray:
    """An LED that did not light, on a black sphere in 8 bits: 0 but for a few counts of noise
    (the disc's median and its median absolute deviation are both 0)."""
    rng = np.random.default_rng(3)
    image = np.zeros(SHAPE)
    image[rng.integers(35, 65, 40), rng.integers(45, 75, 40)] = rng.integers(1, 4, 40)
    return image


def _two_spots() -> np.ndarray:
    return _image(50.0, 45.0) + _image(72.0, 58.0, peak=2500.0) - 10.0


@pytest.mark.parametrize(
    ("image", "white", "words"),
    [
        (_dark_jpeg(), 255, "no highlight"),
        (_image(70.0, 40.0, sigma=0.01), 65535, "single pixel (column 70, row 40)"),
        (_two_spots(), 65535, "2 bright spots on the sphere (column 50, row 45 and column 72"),
    ],
    ids=["dark-8-bit", "hot-pixel", "two-spots"],
)
def test_no_direction_is_invented_from_noise_a_hot_pixel_or_two_spots(
    image: np.ndarray, white: float, words: str
) -> None:
    found = find_highlight(image, CIRCLE, white)
    assert isinstance(found, Rejected) and words in found.reason, found


def test_a_circle_outside_the_frame_is_refused() -> None:
    with pytest.raises(SphereCircleError, match="inside"):
        find_highlight(np.zeros(SHAPE), Circle(100.0, 50.0, 40.0), 65535)


def _disc(circle: Circle, inside: float = 0.02, ground: float = 0.6) -> np.ndarray:
    """A dark disc on a lit ground, antialiased over a pixel (8×8 samples per pixel)."""
    fine = 8
    rows, cols = np.mgrid[0 : SHAPE[0] * fine, 0 : SHAPE[1] * fine].astype(float)
    rows, cols = (rows + 0.5) / fine - 0.5, (cols + 0.5) / fine - 0.5
    hit = np.hypot(cols - circle.x, rows - circle.y) < circle.radius
    cover = hit.reshape(SHAPE[0], fine, SHAPE[1], fine).mean(axis=(1, 3))
    return ground + (inside - ground) * cover


@pytest.mark.parametrize(("dx", "dy", "dr"), [(0, 0, 0), (3, 0, 0), (0, -2.5, 0), (1, 1, -4)])
def test_the_outline_is_found_where_the_disc_is_wherever_the_circle_given(
    dx: float, dy: float, dr: float
) -> None:
    from rti_rig.reconstruct.sphere_lights import outline_circle

    truth = Circle(60.3, 49.6, 38.7)
    rng = np.random.default_rng(4)
    image = _disc(truth) + rng.normal(0.0, 0.01, SHAPE)
    given = Circle(truth.x + dx, truth.y + dy, truth.radius + dr)
    found = outline_circle(image, given)
    assert found is not None
    assert math.hypot(found.x - truth.x, found.y - truth.y) < 0.15, found
    assert abs(found.radius - truth.radius) < 0.15, found


@pytest.mark.parametrize("ground", ["noise", "ramp", "same as the sphere"])
def test_no_outline_is_invented_where_there_is_none(ground: str) -> None:
    from rti_rig.reconstruct.sphere_lights import outline_circle

    rng = np.random.default_rng(1)
    _rows, cols = np.mgrid[0 : SHAPE[0], 0 : SHAPE[1]].astype(float)
    image = {
        "noise": 0.1 + rng.normal(0.0, 0.01, SHAPE),
        "ramp": cols / SHAPE[1],
        "same as the sphere": _disc(CIRCLE, 0.02, 0.02) + rng.normal(0.0, 0.002, SHAPE),
    }[ground]
    assert outline_circle(image, CIRCLE) is None


@pytest.mark.parametrize("ring", ["bright rim", "chrome band", "shadow halo"])
def test_rings_about_the_sphere_move_the_radius_found_not_its_centre(ring: str) -> None:
    """A glossy sphere's bright rim, a chrome sphere's band mirroring the ground, a shadow's
    halo: rings about the sphere that the steepest step may take for its outline. The radius
    found is then no evidence (the use case says nothing of it); the centre stays."""
    from rti_rig.reconstruct.sphere_lights import outline_circle

    truth = Circle(60.3, 49.6, 36.0)
    rows, cols = np.mgrid[0 : SHAPE[0], 0 : SHAPE[1]].astype(float)
    rho = np.hypot(cols - truth.x, rows - truth.y)
    image = _disc(truth)
    if ring == "bright rim":
        image = np.where((rho < truth.radius) & (rho > truth.radius - 3), 1.0, image)
    elif ring == "chrome band":
        image = np.where((rho < truth.radius) & (rho > truth.radius - 6), 0.55, image)
    else:
        image = np.where((rho >= truth.radius) & (rho < truth.radius + 5), 0.1, image)
    given = Circle(truth.x + 3.0, truth.y - 2.0, truth.radius)
    found = outline_circle(image, given)
    assert found is not None
    assert math.hypot(found.x - truth.x, found.y - truth.y) < 0.3, found
