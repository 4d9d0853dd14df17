"""A small height-field scene for the walking skeleton's simulated camera.

A central hemispherical boss, a few seeded bumps and an engraved ring on a flat ground, with a
patchy colour albedo. It is enough for the brightest region to follow the light, which is what a
dry run and the skeleton's tests need; the full scene library and light transport (shadows,
specular, point lights) live in the renderer modules.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from rti_rig.simulator.scenes import normals_from_height


@dataclass(frozen=True, eq=False)
class HeightFieldScene:
    """Ground truth: height in pixel units, unit normals (frame: docs/conventions.md), albedo."""

    name: str
    height: NDArray[np.float64]
    normals: NDArray[np.float64]
    albedo: NDArray[np.float64]


#: Pixels rendered at a time. Whole-image temporaries of a 24 MP frame are 0.2-0.6 GB each; a
#: band of rows this size keeps them to a few MB while each pixel is computed exactly as for the
#: whole image.
BAND_PIXELS = 1 << 18


#: Images up to this many pixels keep their normals and albedo (48 bytes a pixel: 96 MB at
#: this bound), made once instead of for every light: the normals were 60 % of a 512 x 512
#: dry run's render. They are the very planes the bands make (bit for bit), so the images are
#: the same; a larger image makes them band by band, as its memory needs.
CACHED_PIXELS = 1 << 21


def row_bands(height_px: int, width_px: int) -> list[tuple[int, int]]:
    """``(start, stop)`` of the bands of whole rows an image is computed in, top to bottom."""
    step = max(1, BAND_PIXELS // max(width_px, 1))
    return [(a, min(a + step, height_px)) for a in range(0, height_px, step)]


def _relief_parts(
    height_px: int, width_px: int, seed: int
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.intp], NDArray[np.intp]]:
    """The relief's height field and its albedo as 4x4 colour patches: ``(height, patch colours
    (4, 4, 3), patch row of each image row, patch column of each image column)``.

    The height is computed a band of rows at a time from open row/column grids: the same
    arithmetic per pixel as on whole coordinate planes, without their half-dozen image-sized
    temporaries (1 GB at 24 MP).
    """
    rng = np.random.default_rng(seed)
    cy, cx = (height_px - 1) / 2.0, (width_px - 1) / 2.0
    size = float(min(height_px, width_px))
    bumps = []
    for _ in range(6):
        by, bx = rng.uniform(0.1, 0.9, 2) * (height_px, width_px)
        s = rng.uniform(0.03, 0.06) * size
        bumps.append((by, bx, s, rng.uniform(0.2, 0.5) * s))
    boss_r = 0.22 * size
    ring_r, ring_w = 0.36 * size, 0.012 * size
    cols = np.arange(width_px, dtype=np.float64)[None, :]
    height = np.empty((height_px, width_px))
    for start, stop in row_bands(height_px, width_px):
        rows = np.arange(start, stop, dtype=np.float64)[:, None]
        r = np.hypot(rows - cy, cols - cx)
        band = np.sqrt(np.clip(boss_r**2 - r**2, 0.0, None))
        for by, bx, s, amplitude in bumps:
            band += amplitude * np.exp(-((rows - by) ** 2 + (cols - bx) ** 2) / s**2)
        band -= 0.02 * size * np.exp(-(((r - ring_r) / ring_w) ** 2))
        height[start:stop] = band

    base = rng.uniform(0.35, 0.85, size=(4, 4, 3))
    iy = np.minimum(np.arange(height_px) * 4 // height_px, 3)
    ix = np.minimum(np.arange(width_px) * 4 // width_px, 3)
    return height, base, iy, ix


def relief_scene(height_px: int, width_px: int, seed: int = 0) -> HeightFieldScene:
    """The skeleton's default scene (see the module docstring)."""
    height, base, iy, ix = _relief_parts(height_px, width_px, seed)
    return HeightFieldScene("relief", height, normals_from_height(height), base[iy][:, ix])


def _normals_rows(height: NDArray[np.float64], start: int, stop: int) -> NDArray[np.float64]:
    """Rows ``start:stop`` of ``normals_from_height(height)``, bit for bit, from those rows and
    one neighbour on each side (central differences need them; the image's own first and last
    rows stay one-sided)."""
    lo, hi = max(start - 1, 0), min(stop + 1, height.shape[0])
    return normals_from_height(height[lo:hi])[start - lo : stop - lo]


class BandedRenderer:
    """A renderer that computes an image a band of rows at a time (``rows``); called, it
    assembles the whole image from its bands (the wrong-light check and tests want whole
    images; the simulated camera pulls the bands itself)."""

    shape: tuple[int, int, int]

    def rows(
        self, direction: NDArray[np.float64] | None, intensity: float, start: int, stop: int
    ) -> NDArray[np.float64]:
        raise NotImplementedError

    def __call__(
        self, direction: NDArray[np.float64] | None, intensity: float
    ) -> NDArray[np.float64]:
        out = np.empty(self.shape)
        for start, stop in row_bands(*self.shape[:2]):
            out[start:stop] = self.rows(direction, intensity, start, stop)
        return out


class ReliefRenderer(BandedRenderer):
    """The relief scene under a directional light, rendered a band of rows at a time.

    Holds the height field (8 bytes a pixel); above ``CACHED_PIXELS`` normals and albedo are
    made per band, so a 24 MP simulated camera does not keep 1.3 GB of scene planes; a small
    image keeps them, since they are the same for every light. ``rows`` lets the simulated
    camera pull the image band by band; calling the renderer gives the whole image, equal to
    :func:`lambert_radiance` on :func:`relief_scene` bit for bit.
    """

    def __init__(self, height_px: int, width_px: int, seed: int = 0) -> None:
        self._height, self._base, self._iy, self._ix = _relief_parts(height_px, width_px, seed)
        self.shape = (height_px, width_px, 3)
        #: The whole image's normals and albedo, made once, when they fit ``CACHED_PIXELS``.
        self._planes: tuple[NDArray[np.float64], NDArray[np.float64]] | None = None
        if height_px * width_px <= CACHED_PIXELS:
            self._planes = (normals_from_height(self._height), self._base[self._iy][:, self._ix])

    def rows(
        self, direction: NDArray[np.float64] | None, intensity: float, start: int, stop: int
    ) -> NDArray[np.float64]:
        """Radiance of image rows ``start:stop``."""
        if direction is None:
            return np.zeros((stop - start, *self.shape[1:]))
        if self._planes is not None:
            normals, albedo = self._planes[0][start:stop], self._planes[1][start:stop]
        else:
            normals = _normals_rows(self._height, start, stop)
            albedo = self._base[self._iy[start:stop]][:, self._ix]
        band = HeightFieldScene("relief", self._height[start:stop], normals, albedo)
        return lambert_radiance(band, direction, intensity)


def lambert_radiance(
    scene: HeightFieldScene, direction: NDArray[np.float64], irradiance: float = 1.0
) -> NDArray[np.float64]:
    """Radiance of a Lambertian surface under a directional light (attached shadows only)."""
    cos = np.clip(scene.normals @ np.asarray(direction, dtype=np.float64), 0.0, None)
    return scene.albedo * (irradiance * cos)[..., None]


def field_width_mm(width_px: int) -> float:
    """The width (mm) of the object field a library scene spans at ``width_px`` pixels (what
    :func:`renderer_for` renders: the library's default pixel size)."""
    from rti_rig.simulator.scenes import DEFAULT_PIXEL_SIZE_MM

    return float(width_px) * DEFAULT_PIXEL_SIZE_MM


def renderer_for(
    name: str,
    height_px: int,
    width_px: int,
    seed: int = 0,
    light_distance_mm: float | None = None,
):  # type: ignore[no-untyped-def]
    """``render(direction | None, intensity) -> (H, W, 3)`` radiance for a named scene.

    ``relief`` is this module's simple Lambertian scene; every other name is a scene of the
    library (:mod:`rti_rig.simulator.scenes`), rendered with the passes it needs (cast shadows, GGX
    specular) under a directional light, or a point lamp at ``light_distance_mm`` (the dome's
    radius or the arm's reach) when given. The simulated camera and the wrong-light check both
    render through this one function, so they cannot disagree about what a light looks like.
    """
    if name == "relief":
        return ReliefRenderer(height_px, width_px, seed)

    return LibraryRenderer(name, height_px, width_px, seed, light_distance_mm)


class LibraryRenderer(BandedRenderer):
    """A library scene (:mod:`rti_rig.simulator.scenes`) under one light, with the passes it
    declares, rendered a band of rows at a time.

    Why: at 24 MP a whole-image render held the scene's float64 planes (2 GB), their float32
    copies and a dozen whole-frame temporaries, near 9 GB for one light. The renderer keeps
    only the float32 copies the shading reads (:class:`PreparedScene`, about 1.3 GB at 24 MP);
    the cast-shadow sweep, which needs the whole height field, runs once per light and its
    visibility (4 bytes a pixel) is kept while that light's bands are pulled. Every pixel is
    computed exactly as in :func:`render_radiance` on the whole scene (tested).
    """

    def __init__(
        self,
        name: str,
        height_px: int,
        width_px: int,
        seed: int = 0,
        light_distance_mm: float | None = None,
    ) -> None:
        from rti_rig.simulator.light_transport import PreparedScene
        from rti_rig.simulator.scenes import make_scene

        scene = make_scene(name, height_px, width_px, seed=seed)
        self._prep = PreparedScene(scene)
        self._passes = scene.passes
        self._distance = light_distance_mm
        self.shape = (height_px, width_px, 3)
        self._vis_key: tuple[tuple[float, ...], float] | None = None
        self._vis: NDArray[np.float32] | None = None

    def _light(self, direction: NDArray[np.float64], intensity: float):  # type: ignore[no-untyped-def]
        from rti_rig.simulator.light_transport import light_at

        return light_at(direction, self._distance, irradiance=float(intensity))

    def _visibility(self, light, key: tuple[tuple[float, ...], float]):  # type: ignore[no-untyped-def]
        """The light's whole-frame cast-shadow visibility, swept once per light."""
        from rti_rig.simulator.light_transport import visibility

        if "shadows" not in self._passes:
            return None
        if self._vis_key != key:
            self._vis = None  # the previous light's, released before the sweep
            self._vis = visibility(self._prep, light)
            self._vis_key = key
        return self._vis

    def rows(
        self, direction: NDArray[np.float64] | None, intensity: float, start: int, stop: int
    ) -> NDArray[np.float64]:
        """Radiance (float64) of image rows ``start:stop``."""
        from rti_rig.simulator.light_transport import shade

        if direction is None or intensity <= 0:
            return np.zeros((stop - start, *self.shape[1:]))
        light = self._light(direction, intensity)
        key = (tuple(float(c) for c in np.ravel(direction)), float(intensity))
        vis = self._visibility(light, key)
        band = shade(
            self._prep.band(start, stop),
            light,
            self._passes,
            None if vis is None else vis[start:stop],
        )
        return band.astype(np.float64)
