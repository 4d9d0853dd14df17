"""Radiance of a scene under one light: Lambertian + GGX specular, shadows, point-light falloff.

Units: ``render_radiance`` returns π × outgoing radiance, so that a Lambertian surface of albedo
ρ under irradiance E at incidence θ gives exactly ``ρ·E·cos θ`` — the RTI convention in which a
white card facing a unit light reads 1. The specular lobe is scaled the same way.

Models (the *why* of each, in docs/simulator.md):

* Camera: orthographic (telecentric), view direction v = +z everywhere — a camera a metre away
  over a few centimetres of object sees it within a couple of degrees of the axis.
* Diffuse: ρ·E·max(0, n·l) (attached shadows come free from the clamp).
* Specular: Cook–Torrance microfacet lobe with the GGX (Trowbridge–Reitz) distribution,
  α = roughness², separable Smith-GGX masking, Schlick Fresnel with F0 = specular albedo.
  The masking term is written as ``G/(4 n·l n·v)`` in closed form, which stays finite at grazing
  incidence (no 0/0), so grazing and zenith lights give finite, non-negative values.
* Cast shadows: horizon sweep over the height field (``shadows.py``), exact for point lights.
* Directional light: constant direction and irradiance. Point light at the dome's real distance:
  per-pixel direction from the surface point (including its height) to the lamp and inverse-square
  falloff, E = I / r² with I the radiant intensity (``power``, W/sr) and r in metres.

Passes: diffuse is always rendered; "shadows" and "specular" run only when asked for, and by
default (``passes=None``) exactly those the scene declares.
"""

from __future__ import annotations

import copy
import math
import weakref
from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from rti_rig.simulator.scenes import KNOWN_PASSES, Scene, SceneError
from rti_rig.simulator.shadows import directional_visibility, point_visibility


@dataclass(frozen=True)
class DirectionalLight:
    """A light at infinity: ``direction`` from the object towards the light (normalised here)."""

    direction: tuple[float, float, float]
    irradiance: float = 1.0

    def __post_init__(self) -> None:
        d = np.asarray(self.direction, dtype=np.float64).reshape(-1)
        if d.shape != (3,) or not np.all(np.isfinite(d)) or np.linalg.norm(d) < 1e-12:
            raise ValueError(
                f"DirectionalLight: direction must be a finite non-zero 3-vector, "
                f"got {self.direction!r}"
            )
        if not (math.isfinite(self.irradiance) and self.irradiance >= 0):
            raise ValueError(f"DirectionalLight: irradiance must be >= 0, got {self.irradiance}")
        object.__setattr__(self, "direction", tuple(float(x) for x in d / np.linalg.norm(d)))


@dataclass(frozen=True)
class PointLight:
    """An isotropic lamp at ``position_mm`` (frame of docs/conventions.md, origin at the image
    centre on the zero-height plane); ``power`` is its radiant intensity in W/sr, so
    E = power / r[m]²."""

    position_mm: tuple[float, float, float]
    power: float = 1.0

    def __post_init__(self) -> None:
        p = np.asarray(self.position_mm, dtype=np.float64).reshape(-1)
        if p.shape != (3,) or not np.all(np.isfinite(p)):
            raise ValueError(
                f"PointLight: position_mm must be a finite 3-vector, got {self.position_mm!r}"
            )
        if not (math.isfinite(self.power) and self.power >= 0):
            raise ValueError(f"PointLight: power must be >= 0, got {self.power}")
        object.__setattr__(self, "position_mm", tuple(float(x) for x in p))


Light = DirectionalLight | PointLight


def light_at(
    direction: ArrayLike, distance_mm: float | None = None, irradiance: float = 1.0
) -> Light:
    """The light a rig puts at ``direction``: directional if ``distance_mm`` is None, else a point
    lamp at that distance from the object centre, with power chosen so that the irradiance at the
    centre (normal to the beam) equals ``irradiance`` — so both kinds are equally bright there.

    This is what the simulated dome (LED positions = .lp direction × dome radius) and the
    simulated arm (lamp at the arm's radius) call.
    """
    d = np.asarray(direction, dtype=np.float64).reshape(3)
    d = d / np.linalg.norm(d)
    if distance_mm is None:
        return DirectionalLight(tuple(d), irradiance)
    if not distance_mm > 0:
        raise ValueError(f"light_at: distance_mm must be > 0, got {distance_mm}")
    return PointLight(tuple(d * distance_mm), irradiance * (distance_mm / 1000.0) ** 2)


class PreparedScene:
    """Per-scene float32 copies and per-scene constants, computed once and cached.

    Why: a 1-megapixel scene is rendered under hundreds of lights; converting arrays and
    recomputing view-only terms every time would cost as much as the shading itself.
    """

    def __init__(self, scene: Scene) -> None:
        f32 = np.float32
        self.shape = scene.shape
        self.nx, self.ny, self.nz = (
            np.ascontiguousarray(scene.normals[..., k], dtype=f32) for k in range(3)
        )
        self.albedo = scene.albedo.astype(f32)
        self.height = scene.height.astype(f32)
        self.f0 = scene.specular_albedo.astype(f32)
        self.alpha2 = np.empty(self.shape, f32)
        self.vis_view = np.empty(self.shape, f32)
        # In bands of rows: the float64 terms are elementwise, so each pixel is as from whole
        # planes, without half a dozen frame-sized float64 temporaries (1.1 GB at 24 MP).
        step = max(1, (1 << 18) // max(self.shape[1], 1))
        for a in range(0, self.shape[0], step):
            alpha = scene.roughness[a : a + step].astype(np.float64) ** 2
            self.alpha2[a : a + step] = alpha**2
            # View half of the Smith-GGX visibility: 1 / (n·v + sqrt(α² + (1-α²)(n·v)²)), v = +z.
            nz = scene.normals[a : a + step, :, 2]
            self.vis_view[a : a + step] = 1.0 / (nz + np.sqrt(alpha**2 + (1 - alpha**2) * nz**2))
        rows, cols = self.shape
        px = scene.pixel_size_mm
        self.pixel_size_mm = px
        self.x_mm = ((np.arange(cols) - (cols - 1) / 2.0) * px).astype(f32)[None, :]
        self.y_mm = (((rows - 1) / 2.0 - np.arange(rows)) * px).astype(f32)[:, None]
        self.z_mm = (scene.height * px).astype(f32)

    def band(self, start: int, stop: int) -> PreparedScene:
        """The same scene restricted to image rows ``start:stop`` (views, no copies), for
        shading a band of rows at a time: every per-pixel array is sliced, the per-column
        coordinates are shared. Shading is elementwise, so a band's pixels come out exactly
        as in the whole image."""
        part = copy.copy(self)
        for key in ("nx", "ny", "nz", "albedo", "height", "f0", "alpha2", "vis_view", "z_mm"):
            setattr(part, key, getattr(self, key)[start:stop])
        part.y_mm = self.y_mm[start:stop]
        part.shape = (stop - start, self.shape[1])
        return part


_CACHE: weakref.WeakKeyDictionary[Scene, PreparedScene] = weakref.WeakKeyDictionary()


def prepare(scene: Scene) -> PreparedScene:
    """The cached :class:`PreparedScene` of ``scene``."""
    prep = _CACHE.get(scene)
    if prep is None:
        prep = PreparedScene(scene)
        _CACHE[scene] = prep
    return prep


def resolve_passes(scene: Scene, passes: Iterable[str] | None) -> frozenset[str]:
    """The passes to run: the scene's own when ``passes`` is None; unknown names are errors."""
    chosen = scene.passes if passes is None else frozenset(passes)
    unknown = chosen - KNOWN_PASSES
    if unknown:
        raise SceneError(f"unknown render passes {sorted(unknown)}; known: {sorted(KNOWN_PASSES)}")
    return chosen


def _geometry(prep: PreparedScene, light: Light) -> tuple[tuple, NDArray[np.float32] | np.float32]:
    """Per-pixel (or constant) unit light direction components and irradiance."""
    f32 = np.float32
    if isinstance(light, DirectionalLight):
        lx, ly, lz = (f32(c) for c in light.direction)
        return (lx, ly, lz), f32(light.irradiance)
    px, py, pz = (f32(c) for c in light.position_mm)
    dx = px - prep.x_mm  # (1, W)
    dy = py - prep.y_mm  # (H, 1)
    dz = pz - prep.z_mm  # (H, W)
    r2 = dz * dz
    r2 += dx * dx
    r2 += dy * dy
    np.maximum(r2, f32(1e-6), out=r2)  # lamp touching the surface: finite, not inf
    inv_r = 1.0 / np.sqrt(r2)
    lx, ly, lz = dx * inv_r, dy * inv_r, dz * inv_r
    irradiance = f32(light.power * 1e6) / r2  # r in mm -> m: E = I / (r_mm / 1000)²
    return (lx, ly, lz), irradiance


def visibility(prep: PreparedScene, light: Light) -> NDArray[np.float32]:
    """Cast-shadow visibility (H, W) in [0, 1] of the prepared scene from ``light``."""
    if isinstance(light, DirectionalLight):
        return directional_visibility(prep.height, light.direction)
    rows, cols = prep.shape
    px = prep.pixel_size_mm
    x, y, z = light.position_mm
    return point_visibility(
        prep.height, x / px + (cols - 1) / 2.0, (rows - 1) / 2.0 - y / px, z / px
    )


def render_radiance(
    scene: Scene, light: Light, passes: Iterable[str] | None = None
) -> NDArray[np.float32]:
    """π × radiance (H, W, 3) float32 of ``scene`` seen from +z under ``light``; never NaN or < 0.

    ``passes=None`` renders the passes the scene declares; an explicit set overrides them
    (e.g. ``()`` for pure Lambertian, or ``{"shadows"}`` to drop the specular lobe).
    """
    chosen = resolve_passes(scene, passes)
    prep = prepare(scene)
    vis = visibility(prep, light) if "shadows" in chosen else None
    return shade(prep, light, chosen, vis)


def shade(
    prep: PreparedScene,
    light: Light,
    chosen: frozenset[str],
    vis: NDArray[np.float32] | None,
) -> NDArray[np.float32]:
    """π × radiance of ``prep`` (a whole scene or a :meth:`PreparedScene.band` of it) with
    the cast-shadow visibility ``vis`` of the same pixels (None: no shadow pass).

    Why apart from :func:`render_radiance`: the shadow sweep needs the whole height field,
    but the shading does not, so a large frame can take its visibility once and be shaded
    a band of rows at a time (:class:`~rti_rig.simulator.sim_scene.LibraryRenderer`).
    """
    (lx, ly, lz), irradiance = _geometry(prep, light)
    cos_i = prep.nx * lx
    cos_i += prep.ny * ly
    cos_i += prep.nz * lz
    np.maximum(cos_i, 0.0, out=cos_i)
    lit = cos_i * irradiance  # E·cos θ, W/m² on the surface
    if vis is not None:
        lit *= vis
    out = prep.albedo * lit[..., None]
    if "specular" in chosen:
        out += specular_term(prep, (lx, ly, lz), cos_i) * (lit[..., None])
    return out


def specular_term(
    prep: PreparedScene, l_dir: tuple, cos_i: NDArray[np.float32]
) -> NDArray[np.float32]:
    """π·f_spec (H, W, 3): π × GGX microfacet BRDF for view +z, per unit E·cos θ."""
    f32 = np.float32
    lx, ly, lz = l_dir
    # Half vector of l and v = (0, 0, 1).
    hz = lz + f32(1.0)
    inv = 1.0 / np.sqrt(np.maximum(lx * lx + ly * ly + hz * hz, f32(1e-12)))
    n_h = (prep.nx * lx + prep.ny * ly + prep.nz * hz) * inv
    np.clip(n_h, 0.0, 1.0, out=n_h)
    v_h = hz * inv  # v·h = h_z; scalar for directional lights
    a2 = prep.alpha2
    t = n_h * n_h
    t *= a2 - f32(1.0)
    t += f32(1.0)
    d_pi = a2 / (t * t)  # π·D
    vis_light = 1.0 / (cos_i + np.sqrt(a2 + (f32(1.0) - a2) * cos_i * cos_i))
    dv = d_pi * vis_light
    dv *= prep.vis_view
    schlick = np.clip(f32(1.0) - v_h, 0.0, 1.0) ** 5
    if np.ndim(schlick) == 0:
        fresnel = prep.f0 + (f32(1.0) - prep.f0) * f32(schlick)
    else:
        fresnel = prep.f0 + (f32(1.0) - prep.f0) * schlick[..., None]
    return fresnel * dv[..., None]
