"""Synthetic RTI scenes with dense ground truth: height, normals, albedo, material, passes.

Why synthetic scenes at all: the planner and the speed/accuracy benchmark need surfaces whose
true normals are known exactly. Why *these* scenes: they are what RTI is used for, and each
stresses something different — fine relief under grazing light (painting, tablet), glossy
highlights on metal (coin, industrial), normals far from the camera axis (tilted), and the
degenerate flat plate on which every method must be perfect.

Conventions (docs/conventions.md): frame x right, y **up** (towards image row 0), z towards the
camera.
``height`` is in *pixel units* (unit pixel pitch), so normals follow from finite differences:
``n ∝ (-∂h/∂x, -∂h/∂y, 1)`` with ``∂/∂y = -∂/∂row``. Depth from the camera is ``-height``.
Shapes are defined in coordinates normalised by the image size and heights scale with it, so
slopes — and so normals and shadow lengths relative to the image — do not depend on resolution.

Each scene says which render passes it needs (``passes``): a matte scene does not pay for the
specular lobe and the flat plate pays for neither shadows nor specular.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from pathlib import Path

import cv2
import numpy as np
from numpy.typing import ArrayLike, NDArray

from rti_rig.core import opencv_files
from rti_rig.core.errors import RtiRigError
from rti_rig.core.shell_words import shown_path

#: Render passes a scene may ask for. Diffuse (Lambertian) shading is always rendered.
KNOWN_PASSES = frozenset({"shadows", "specular"})

#: Default physical size of one pixel on the object (mm): a 50 mm field over 1000 pixels.
DEFAULT_PIXEL_SIZE_MM = 0.05


#: The smallest image side a library scene is built at (its shapes scale with the image).
MIN_SIZE_PX = 8


class SceneError(RtiRigError, ValueError):
    """A scene cannot be built: unknown name, bad size, or an unreadable map file."""


@dataclass(frozen=True, eq=False)
class Scene:
    """A height-field scene with its ground truth. Arrays are read-only.

    ``eq=False``: scenes compare (and hash) by identity, so renderers can cache per scene.
    """

    name: str
    seed: int
    height: NDArray[np.float64]  # (H, W) pixel units, larger = nearer the camera
    normals: NDArray[np.float64]  # (H, W, 3) unit, frame of docs/conventions.md
    albedo: NDArray[np.float64]  # (H, W, 3) linear diffuse albedo in [0, 1]
    specular_albedo: NDArray[np.float64]  # (H, W, 3) Fresnel F0 of the GGX lobe, [0, 1]
    roughness: NDArray[np.float64]  # (H, W) GGX roughness r in (0, 1]; alpha = r²
    passes: frozenset[str]
    pixel_size_mm: float = DEFAULT_PIXEL_SIZE_MM
    material: str = ""
    description: str = ""
    metadata: dict[str, object] = field(default_factory=dict)

    def __post_init__(self) -> None:
        h = self.height
        if h.ndim != 2 or h.shape[0] < 2 or h.shape[1] < 2:
            raise SceneError(f"scene '{self.name}': height must be (H, W) with H, W >= 2")
        shape = h.shape
        checks = {
            "normals": (self.normals, (*shape, 3)),
            "albedo": (self.albedo, (*shape, 3)),
            "specular_albedo": (self.specular_albedo, (*shape, 3)),
            "roughness": (self.roughness, shape),
        }
        for key, (arr, want) in checks.items():
            if arr.shape != want:
                raise SceneError(f"scene '{self.name}': {key} has shape {arr.shape}, want {want}")
            if not np.all(np.isfinite(arr)):
                raise SceneError(f"scene '{self.name}': {key} contains NaN or infinity")
        unknown = set(self.passes) - KNOWN_PASSES
        if unknown:
            raise SceneError(
                f"scene '{self.name}': unknown passes {sorted(unknown)}; "
                f"known: {sorted(KNOWN_PASSES)}"
            )
        if not self.pixel_size_mm > 0:
            raise SceneError(f"scene '{self.name}': pixel_size_mm must be > 0")
        for arr in (self.height, self.normals, self.albedo, self.specular_albedo, self.roughness):
            arr.flags.writeable = False

    @property
    def shape(self) -> tuple[int, int]:
        """(H, W) in pixels."""
        return (int(self.height.shape[0]), int(self.height.shape[1]))

    @property
    def depth(self) -> NDArray[np.float64]:
        """Depth below the highest point, in pixel units (0 at the top, positive into it)."""
        return self.height.max() - self.height


# --------------------------------------------------------------------------------------------
# Geometry helpers (pure functions)


def normals_from_height(height: ArrayLike) -> NDArray[np.float64]:
    """Unit normals (H, W, 3) of a height field with unit pixel pitch, y up (rows run down).

    Central differences inside, one-sided at the border (``np.gradient``).
    """
    h = np.asarray(height, dtype=np.float64)
    d_row, d_col = np.gradient(h)
    n = np.empty((*h.shape, 3))
    n[..., 0] = -d_col  # -∂h/∂x
    n[..., 1] = d_row  # -∂h/∂y, and ∂/∂y = -∂/∂row
    n[..., 2] = 1.0
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    return n


def height_from_normals(normals: ArrayLike) -> NDArray[np.float64]:
    """Integrate a normal map into a height field (Frankot–Chellappa, least squares in Fourier).

    Used only to give normal-map scenes a height for shadows and point-light geometry; the
    normals themselves stay exactly as given. Mean height is 0.
    """
    n = np.asarray(normals, dtype=np.float64)
    nz = np.maximum(n[..., 2], 1e-3)
    p = -n[..., 0] / nz  # ∂h/∂x = ∂h/∂col
    q = n[..., 1] / nz  # ∂h/∂row = -∂h/∂y
    rows, cols = p.shape
    # Mirror-extend so the periodic FFT does not see jumps at the border.
    pe = np.block([[p, -p[:, ::-1]], [p[::-1, :], -p[::-1, ::-1]]])
    qe = np.block([[q, q[:, ::-1]], [-q[::-1, :], -q[::-1, ::-1]]])
    wx = 2 * np.pi * np.fft.fftfreq(2 * cols)[None, :]
    wy = 2 * np.pi * np.fft.fftfreq(2 * rows)[:, None]
    denom = wx**2 + wy**2
    denom[0, 0] = 1.0
    hz = (-1j * wx * np.fft.fft2(pe) - 1j * wy * np.fft.fft2(qe)) / denom
    hz[0, 0] = 0.0
    h = np.real(np.fft.ifft2(hz))[:rows, :cols]
    return h - h.mean()


def _frame_grid(rows: int, cols: int) -> tuple[NDArray[np.float64], NDArray[np.float64], float]:
    """Normalised frame coordinates (u right, v up) with the image centre at 0, and the scale.

    ``u = x / s`` where ``s = min(rows, cols)``, so the shorter side spans [-0.5, 0.5].
    """
    s = float(min(rows, cols))
    x = (np.arange(cols) - (cols - 1) / 2.0) / s
    y = ((rows - 1) / 2.0 - np.arange(rows)) / s
    u, v = np.meshgrid(x, y)
    return u, v, s


def _smoothstep(e0: float, e1: float, x: NDArray[np.float64]) -> NDArray[np.float64]:
    t = np.clip((x - e0) / (e1 - e0), 0.0, 1.0)
    return t * t * (3 - 2 * t)


def _value_noise(rng: np.random.Generator, rows: int, cols: int, cells: int) -> NDArray[np.float64]:
    """Smooth random field in [-1, 1] with about ``cells`` features across the short side."""
    s = min(rows, cols)
    gr = max(2, math.ceil(cells * rows / s) + 2)
    gc = max(2, math.ceil(cells * cols / s) + 2)
    coarse = rng.uniform(-1.0, 1.0, size=(gr, gc)).astype(np.float32)
    return cv2.resize(coarse, (cols, rows), interpolation=cv2.INTER_CUBIC).astype(np.float64)


def _fill(shape: tuple[int, int], value: Iterable[float]) -> NDArray[np.float64]:
    return np.broadcast_to(np.asarray(tuple(value), np.float64), (*shape, 3)).copy()


def _build(
    name: str,
    seed: int,
    height: NDArray[np.float64],
    albedo: NDArray[np.float64],
    specular: NDArray[np.float64],
    roughness: NDArray[np.float64],
    passes: Iterable[str],
    material: str,
    description: str,
    pixel_size_mm: float,
) -> Scene:
    return Scene(
        name=name,
        seed=seed,
        height=height,
        normals=normals_from_height(height),
        # in place: the builders hand over arrays of their own, and a copy of each would
        # hold 7 more frame-sized planes at the build's peak
        albedo=np.clip(albedo, 0.0, 1.0, out=albedo),
        specular_albedo=np.clip(specular, 0.0, 1.0, out=specular),
        roughness=np.clip(roughness, 0.02, 1.0, out=roughness),
        passes=frozenset(passes),
        pixel_size_mm=pixel_size_mm,
        material=material,
        description=description,
    )


# --------------------------------------------------------------------------------------------
# The scene library


def _painting(rows: int, cols: int, seed: int, pixel_mm: float) -> Scene:
    """Oil painting: canvas weave, impasto brush strokes with bristle grooves, pigment patches."""
    rng = np.random.default_rng(seed)
    u, v, s = _frame_grid(rows, cols)
    period = 1.0 / 70.0  # canvas threads across the short side
    weave = np.sin(2 * np.pi * u / period) * np.sin(2 * np.pi * v / period)
    height = 0.06 * period * s * weave / (2 * np.pi) * 2.0  # max weave slope ~0.12
    ground = np.array([0.82, 0.78, 0.68])
    albedo = _fill((rows, cols), ground)
    palette = np.array(
        [
            [0.60, 0.12, 0.08],
            [0.10, 0.18, 0.45],
            [0.75, 0.60, 0.15],
            [0.15, 0.35, 0.15],
            [0.85, 0.83, 0.80],
            [0.05, 0.05, 0.06],
            [0.55, 0.30, 0.15],
        ]
    )
    flow = rng.uniform(0, np.pi)  # strokes follow a dominant direction, as a painter's do
    for _ in range(220):
        cu, cv_ = rng.uniform(-0.6, 0.6), rng.uniform(-0.6, 0.6)
        ang = flow + 0.8 * math.sin(3 * cu + 2 * cv_) + rng.normal(0, 0.25)
        half_len = rng.uniform(0.05, 0.18)
        half_w = rng.uniform(0.012, 0.04)
        thick = rng.uniform(0.0015, 0.005) * s  # impasto thickness, pixel units
        colour = palette[rng.integers(len(palette))] * rng.uniform(0.85, 1.1)
        r = half_len + half_w
        c0 = max(0, int((cu - r) * s + (cols - 1) / 2))
        c1 = min(cols, int((cu + r) * s + (cols - 1) / 2) + 2)
        r0 = max(0, int((rows - 1) / 2 - (cv_ + r) * s))
        r1 = min(rows, int((rows - 1) / 2 - (cv_ - r) * s) + 2)
        if c0 >= c1 or r0 >= r1:
            continue
        du, dv = u[r0:r1, c0:c1] - cu, v[r0:r1, c0:c1] - cv_
        along = du * math.cos(ang) + dv * math.sin(ang)
        across = -du * math.sin(ang) + dv * math.cos(ang)
        a, b = along / half_len, across / half_w
        body = np.clip(1 - b * b, 0, None) * _smoothstep(1.0, 0.7, np.abs(a))
        ridge = 1.0 + 0.5 * _smoothstep(0.6, 1.0, a)  # paint piles up where the stroke ends
        bristles = 1.0 + 0.25 * np.sin(b * 9 * np.pi + rng.uniform(0, 6.3))
        height[r0:r1, c0:c1] += thick * body * ridge * bristles
        cover = _smoothstep(0.0, 0.3, body)[..., None]
        albedo[r0:r1, c0:c1] = albedo[r0:r1, c0:c1] * (1 - cover) + colour * cover
    albedo *= (1.0 + 0.08 * _value_noise(rng, rows, cols, 12))[..., None]
    spec = _fill((rows, cols), (0.04, 0.04, 0.04))  # varnish (n ≈ 1.5)
    rough = np.full((rows, cols), 0.35)  # varnish over rough paint: broad lobe
    return _build(
        "painting",
        seed,
        height,
        albedo,
        spec,
        rough,
        {"shadows", "specular"},
        "varnished oil paint on canvas",
        "Canvas weave plus impasto brush strokes (bristle grooves, piled ends) with varied "
        "pigments; a thin varnish gives a weak, broad highlight; strokes cast short shadows.",
        pixel_mm,
    )


def _tablet(rows: int, cols: int, seed: int, pixel_mm: float) -> Scene:
    """Clay tablet: pillow-shaped surface with lines of wedge-shaped (cuneiform) impressions."""
    rng = np.random.default_rng(seed)
    u, v, s = _frame_grid(rows, cols)
    height = 0.04 * s * (1.0 - (u / 0.9) ** 2 - (v / 0.9) ** 2)  # gently convex
    height += 0.002 * s * _value_noise(rng, rows, cols, 25)  # hand-smoothed clay
    wedge_len, wedge_w, depth = 0.045, 0.012, 0.012 * s
    impressions = np.zeros((rows, cols))
    n_lines = 8
    for line in range(n_lines):
        v0 = 0.4 - 0.8 * (line + 0.5) / n_lines
        u_pos = -0.42
        while u_pos < 0.42:
            n_wedges = int(rng.integers(1, 4))
            for _ in range(n_wedges):
                ang = float(rng.choice([0.0, -np.pi / 2, -np.pi / 4, np.pi / 4]))
                ang += rng.normal(0, 0.08)
                cu = u_pos + rng.uniform(0, 0.03)
                cv_ = v0 + rng.uniform(-0.015, 0.015)
                r = wedge_len + 0.02
                c0 = max(0, int((cu - r) * s + (cols - 1) / 2))
                c1 = min(cols, int((cu + r) * s + (cols - 1) / 2) + 2)
                r0 = max(0, int((rows - 1) / 2 - (cv_ + r) * s))
                r1 = min(rows, int((rows - 1) / 2 - (cv_ - r) * s) + 2)
                if c0 >= c1 or r0 >= r1:
                    continue
                du, dv = u[r0:r1, c0:c1] - cu, v[r0:r1, c0:c1] - cv_
                a = du * math.cos(ang) + dv * math.sin(ang)
                b = -du * math.sin(ang) + dv * math.cos(ang)
                head = 0.25 * wedge_len
                # Pyramid-like: deepest at the head, straight walls tapering along the tail.
                prof = np.minimum((a + head) / head, (wedge_len - a) / wedge_len)
                cut = np.clip(prof - np.abs(b) / wedge_w, 0.0, None)
                np.maximum(impressions[r0:r1, c0:c1], depth * cut, out=impressions[r0:r1, c0:c1])
            u_pos += rng.uniform(0.07, 0.11)
    height -= impressions
    clay = np.array([0.62, 0.47, 0.33])
    tone = 1.0 + 0.12 * _value_noise(rng, rows, cols, 6) + 0.04 * _value_noise(rng, rows, cols, 60)
    albedo = clay * tone[..., None]
    albedo *= (1.0 - 0.25 * np.clip(impressions / depth, 0, 1))[..., None]  # dirt in the cuts
    zeros = np.zeros((rows, cols, 3))
    return _build(
        "tablet",
        seed,
        height,
        albedo,
        zeros,
        np.ones((rows, cols)),
        {"shadows"},
        "matte fired clay",
        "Convex clay tablet with lines of sharp wedge impressions; matte (no specular pass); "
        "the wedges cast shadows under raking light.",
        pixel_mm,
    )


#: The coin's legend: strokes in the ring between these radii (frame units, see _frame_grid),
#: each within this many radians of its letter's angle and this wide (a V groove's half-width).
_LEGEND_RING = (0.30, 0.355)
_LEGEND_SECTOR_RAD = 0.1
_LEGEND_HALF_WIDTH = 0.0035


def _stroke_box(a0: float, s: float, rows: int, cols: int) -> tuple[slice, slice]:
    """Rows and columns of the box that holds every pixel a legend stroke at angle ``a0`` can
    touch: the ring's sector within ``_LEGEND_SECTOR_RAD`` of ``a0`` (a stroke reaches at most
    0.072 rad from it: 0.008 of offset plus its tilted half-length over the inner radius),
    widened by 2 px."""
    inner, outer = _LEGEND_RING
    angles = a0 + np.linspace(-_LEGEND_SECTOR_RAD, _LEGEND_SECTOR_RAD, 41)
    radii = np.array([inner - 0.01, outer + 0.01])
    u = (radii[:, None] * np.cos(angles)[None, :]).ravel()
    v = (radii[:, None] * np.sin(angles)[None, :]).ravel()
    col = u * s + (cols - 1) / 2.0
    row = (rows - 1) / 2.0 - v * s
    r0, r1 = max(0, math.floor(row.min()) - 2), min(rows, math.ceil(row.max()) + 3)
    c0, c1 = max(0, math.floor(col.min()) - 2), min(cols, math.ceil(col.max()) + 3)
    return slice(r0, max(r0, r1)), slice(c0, max(c0, c1))


def _coin_legend(
    rng: np.random.Generator,
    u: NDArray[np.float64],
    v: NDArray[np.float64],
    rad: NDArray[np.float64],
    s: float,
) -> NDArray[np.float64]:
    """The coin's legend: short engraved strokes (sharp V grooves) around the rim, in [0, 1].

    Each stroke is computed only in the box it can reach (:func:`_stroke_box`): outside it a
    stroke's groove is exactly 0, so the legend is the one a whole-frame evaluation gives, at
    a few hundredths of its cost (at 24 MP the whole-frame strokes took minutes and a dozen
    frame-sized temporaries).
    """
    rows, cols = rad.shape
    legend = np.zeros((rows, cols))
    # Once over the frame and then sliced, not per box: a transcendental's vectorised and
    # element-wise paths may round differently, and the legend must not depend on the boxes.
    ang_frame = np.arctan2(v, u)
    inner, outer = _LEGEND_RING
    for k in range(28):
        a0 = -np.pi + 2 * np.pi * (k + 0.5) / 28
        if abs(a0 + np.pi / 2) < 0.35:
            continue  # leave a gap at the bottom, as coins do
        box = _stroke_box(a0, s, rows, cols)
        r_box = rad[box]
        ang = ang_frame[box]
        ring = (r_box > inner) & (r_box < outer)
        for _ in range(int(rng.integers(2, 4))):
            tilt = rng.uniform(-0.8, 0.8)
            da = (ang - a0 + np.pi) % (2 * np.pi) - np.pi
            x_loc = da * r_box - rng.uniform(-0.008, 0.008)
            y_loc = r_box - 0.3275
            dist = np.abs(x_loc * math.cos(tilt) - y_loc * math.sin(tilt) * 0.3)
            groove = np.clip(1 - dist / _LEGEND_HALF_WIDTH, 0, None) * ring
            np.maximum(legend[box], groove, out=legend[box])
    return legend


def _coin(rows: int, cols: int, seed: int, pixel_mm: float) -> Scene:
    """Silver coin on dark cloth: raised rim, relief portrait, engraved legend, sharp edges."""
    rng = np.random.default_rng(seed)
    u, v, s = _frame_grid(rows, cols)
    rad = np.hypot(u, v)
    radius = 0.42
    on_coin = _smoothstep(radius + 0.002, radius - 0.002, rad)
    thickness = 0.03 * s
    rim = 0.012 * s * _smoothstep(radius - 0.05, radius - 0.035, rad)
    # Relief portrait: an ellipsoidal bust with a steep (sharp) edge and some inner modelling.
    eu, ev = (u + 0.03) / 0.17, (v - 0.01) / 0.23
    e = np.hypot(eu, ev)
    bust = 0.014 * s * np.sqrt(np.clip(1 - e * e, 0, None)) * _smoothstep(1.0, 0.93, e)
    bust *= 1.0 + 0.25 * _value_noise(rng, rows, cols, 14)
    legend = _coin_legend(rng, u, v, rad, s)
    height = on_coin * (thickness + rim + bust - 0.006 * s * legend)
    # frame-sized planes no longer needed, let go before the next ones are made (a 24 MP
    # coin peaked at 6 GB while building; the values are unchanged)
    del u, v, rad, rim, eu, ev, e, bust
    cloth = (
        _fill((rows, cols), (0.05, 0.06, 0.09))
        * (1 + 0.3 * _value_noise(rng, rows, cols, 80))[..., None]
    )
    metal_diffuse = np.array([0.04, 0.04, 0.035])
    oc = on_coin[..., None]
    albedo = cloth * (1 - oc) + metal_diffuse * oc
    silver = np.array([0.95, 0.93, 0.88])
    tarnish = 1.0 - 0.15 * np.clip(legend, 0, 1)[..., None]
    spec = silver * tarnish * oc
    del cloth, tarnish, legend, oc
    rough = 0.25 + 0.05 * _value_noise(rng, rows, cols, 30)
    rough = rough * on_coin + 1.0 * (1 - on_coin)
    return _build(
        "coin",
        seed,
        height,
        albedo,
        spec,
        rough,
        {"shadows", "specular"},
        "polished silver (GGX, low roughness) on matte cloth",
        "Silver coin standing on cloth: a step at its edge, raised rim, relief portrait, "
        "engraved legend; glossy metal needs the specular pass, edges and rim cast shadows.",
        pixel_mm,
    )


def _tilted(rows: int, cols: int, seed: int, pixel_mm: float) -> Scene:
    """Sculpted stone relief on a plane tilted 50° from the camera axis."""
    rng = np.random.default_rng(seed)
    u, v, s = _frame_grid(rows, cols)
    tilt_deg = 50.0
    azim = rng.uniform(0, 2 * np.pi)
    plane = math.tan(math.radians(tilt_deg)) * (u * math.cos(azim) + v * math.sin(azim)) * s
    sculpt = np.zeros((rows, cols))
    for _ in range(9):
        cu, cv_ = rng.uniform(-0.4, 0.4, size=2)
        su, sv = rng.uniform(0.05, 0.15, size=2)
        sculpt += rng.uniform(-1, 1) * np.exp(-0.5 * (((u - cu) / su) ** 2 + ((v - cv_) / sv) ** 2))
    folds = np.sin(2 * np.pi * (u * 3 + v * 2) + 2 * _value_noise(rng, rows, cols, 3))
    height = plane + 0.06 * s * sculpt + 0.006 * s * folds
    del u, v, plane, sculpt, folds  # let go before the next planes (values unchanged)
    veins = np.abs(_value_noise(rng, rows, cols, 8))
    tone = 0.72 + 0.08 * _value_noise(rng, rows, cols, 20) - 0.2 * _smoothstep(0.08, 0.0, veins)
    albedo = np.array([1.0, 0.97, 0.92]) * tone[..., None]
    del veins, tone
    return _build(
        "tilted",
        seed,
        height,
        albedo,
        np.zeros((rows, cols, 3)),
        np.ones((rows, cols)),
        {"shadows"},
        "matte limestone",
        "Sculpted relief on a plane tilted 50°: normals far from the camera axis, large "
        "attached and cast shadows for lights on the far side; matte.",
        pixel_mm,
    )


def _industrial(rows: int, cols: int, seed: int, pixel_mm: float) -> Scene:
    """Machined steel: brushed finish, long scratches, dents."""
    rng = np.random.default_rng(seed)
    u, v, s = _frame_grid(rows, cols)
    # Brushing: fine grooves along x (random per row, slowly varying along the row).
    brush = rng.normal(0, 1, size=(rows, 1)) * (1 + 0.2 * _value_noise(rng, rows, cols, 3))
    brush = cv2.GaussianBlur(brush.astype(np.float32), (1, 3), 0.8).astype(np.float64)
    height = 0.15 * brush
    for _ in range(14):  # scratches: V grooves, 2–5 px wide, up to a few px deep
        p0 = rng.uniform(-0.5, 0.5, size=2)
        ang = rng.uniform(0, np.pi)
        d = np.array([math.cos(ang), math.sin(ang)])
        half = rng.uniform(0.15, 0.5)
        along = (u - p0[0]) * d[0] + (v - p0[1]) * d[1]
        across = np.abs(-(u - p0[0]) * d[1] + (v - p0[1]) * d[0]) * s
        width = rng.uniform(1.0, 2.5)
        depth = rng.uniform(0.8, 3.0)
        fade = _smoothstep(half, half * 0.8, np.abs(along))
        height -= depth * np.clip(1 - across / width, 0, None) * fade
    for _ in range(6):  # dents: smooth spherical-cap depressions with a slight raised lip
        c = rng.uniform(-0.4, 0.4, size=2)
        r = rng.uniform(0.02, 0.06)
        dist = np.hypot(u - c[0], v - c[1]) / r
        depth = rng.uniform(0.08, 0.15) * r * s
        height -= depth * np.clip(1 - dist**2, 0, None) ** 2
        height += 0.1 * depth * np.exp(-(((dist - 1.1) / 0.12) ** 2))
    # the last stroke's and dent's planes, let go before the next ones (values unchanged)
    del u, v, brush, along, across, fade, dist
    albedo = (
        _fill((rows, cols), (0.10, 0.10, 0.11))
        * (1 + 0.1 * _value_noise(rng, rows, cols, 10))[..., None]
    )
    spec = _fill((rows, cols), (0.56, 0.57, 0.58))  # steel F0
    rough = 0.3 + 0.05 * _value_noise(rng, rows, cols, 10)
    return _build(
        "industrial",
        seed,
        height,
        albedo,
        spec,
        rough,
        {"shadows", "specular"},
        "brushed steel (GGX, medium roughness)",
        "Machined steel with a brushed finish, thin deep scratches and shallow dents: defects "
        "show in the highlight and in grazing-light shadows.",
        pixel_mm,
    )


def _flat(rows: int, cols: int, seed: int, pixel_mm: float) -> Scene:
    """Flat matte plate of uniform albedo: every method must be exact here."""
    return _build(
        "flat",
        seed,
        np.zeros((rows, cols)),
        _fill((rows, cols), (0.5, 0.5, 0.5)),
        np.zeros((rows, cols, 3)),
        np.ones((rows, cols)),
        set(),
        "matte grey card",
        "Flat uniform Lambertian plate (degenerate case): no relief, so no shadows pass; "
        "matte, so no specular pass.",
        pixel_mm,
    )


#: The calibration sphere's radius, as a fraction of the image's shorter side.
SPHERE_RADIUS = 0.3


def sphere_circle(rows: int, cols: int) -> tuple[float, float, float]:
    """The ``sphere`` scene's circle in image pixels: centre column, centre row, radius.

    Pixel centres are at integer coordinates (column 0 is the first pixel's centre), as an
    image viewer and OpenCV report them; what ``rti-rig lights-from-sphere --sphere`` takes."""
    return ((cols - 1) / 2.0, (rows - 1) / 2.0, SPHERE_RADIUS * float(min(rows, cols)))


def _sphere(rows: int, cols: int, seed: int, pixel_mm: float) -> Scene:
    """Black glossy calibration sphere on a matte grey ground: the highlight method's target.

    Why analytic normals (not finite differences of the height, as the other scenes): the
    scene is the truth a light-direction calibration is measured against, and differenced
    normals are off by up to a degree where the sphere curves fastest."""
    u, v, s = _frame_grid(rows, cols)
    rad = np.hypot(u, v) / SPHERE_RADIUS  # 1 on the rim
    on = rad < 1.0
    nz = np.sqrt(np.clip(1.0 - rad * rad, 0.0, 1.0))
    normals = np.zeros((rows, cols, 3))
    normals[..., 0] = np.where(on, u / SPHERE_RADIUS, 0.0)
    normals[..., 1] = np.where(on, v / SPHERE_RADIUS, 0.0)
    normals[..., 2] = np.where(on, nz, 1.0)
    normals /= np.linalg.norm(normals, axis=-1, keepdims=True)
    height = np.where(on, SPHERE_RADIUS * s * nz, 0.0)
    oc = on[..., None].astype(np.float64)
    albedo = _fill((rows, cols), (0.35, 0.35, 0.35)) * (1 - oc) + 0.01 * oc
    spec = _fill((rows, cols), (0.04, 0.04, 0.04)) * oc  # black glass: F0 of n = 1.5
    # roughness 0.2: a highlight a couple of pixels wide at 160 px, as a real camera's optics
    # spread one; at 0.12 the lobe fell between the renderer's point samples (0.36° median
    # error at 160 px against 0.03° at 320 px)
    rough = np.where(on, 0.2, 1.0)
    cx, cy, r = sphere_circle(rows, cols)
    return Scene(
        name="sphere",
        seed=seed,
        height=height,
        normals=normals,
        albedo=albedo,
        specular_albedo=spec,
        roughness=rough,
        passes=frozenset({"specular"}),
        pixel_size_mm=pixel_mm,
        material="black glass sphere (GGX, sharp lobe) on matte grey",
        description="A black glossy sphere of radius 0.3 of the short side at the image "
        "centre, for light calibration by its highlight (rti-rig lights-from-sphere): the "
        "highlight sits where the sphere's normal is the half-vector of light and view.",
        metadata={"sphere_circle_px": (cx, cy, r)},
    )


_BUILDERS: dict[str, Callable[[int, int, int, float], Scene]] = {
    "painting": _painting,
    "tablet": _tablet,
    "coin": _coin,
    "tilted": _tilted,
    "industrial": _industrial,
    "flat": _flat,
    "sphere": _sphere,
}

#: Names accepted by :func:`make_scene`.
SCENE_NAMES: tuple[str, ...] = tuple(_BUILDERS)


def make_scene(
    name: str,
    height_px: int,
    width_px: int,
    seed: int = 0,
    pixel_size_mm: float = DEFAULT_PIXEL_SIZE_MM,
) -> Scene:
    """Build the named library scene at the given size; same (name, size, seed) → same scene."""
    if name not in _BUILDERS:
        raise SceneError(f"unknown scene '{name}'; choose one of: {', '.join(SCENE_NAMES)}")
    if int(height_px) < MIN_SIZE_PX or int(width_px) < MIN_SIZE_PX:
        raise SceneError(
            f"scene '{name}': size {height_px}x{width_px} too small "
            f"(min {MIN_SIZE_PX}x{MIN_SIZE_PX})"
        )
    if not pixel_size_mm > 0:
        raise SceneError(f"scene '{name}': pixel_size_mm must be > 0, got {pixel_size_mm}")
    return _BUILDERS[name](int(height_px), int(width_px), int(seed), float(pixel_size_mm))


# --------------------------------------------------------------------------------------------
# Scenes from files


def _read_map(path: Path) -> NDArray:
    if not path.is_file():
        raise SceneError(f"{shown_path(path)}: no such file")
    suffix = path.suffix.lower()
    try:
        if suffix == ".npy":
            data = np.load(path, allow_pickle=False)
        elif suffix in {".tif", ".tiff"}:
            import tifffile

            data = tifffile.imread(path)
        else:
            data = opencv_files.imread(path)
            if data is None:
                raise SceneError(
                    f"{shown_path(path)}: not an image OpenCV can read (try .npy, .tif, .png)"
                )
            if data.ndim == 3:
                data = data[..., 2::-1] if data.shape[2] >= 3 else data  # BGR(A) -> RGB
    except SceneError:
        raise
    except Exception as exc:  # unreadable file: say which and why
        raise SceneError(f"{shown_path(path)}: cannot read map ({exc})") from exc
    return np.asarray(data)


def _albedo_array(albedo: float | ArrayLike, shape: tuple[int, int]) -> NDArray[np.float64]:
    a = np.asarray(albedo, dtype=np.float64)
    if a.ndim == 0:
        a = np.full((*shape, 3), float(a))
    elif a.shape == (3,):
        a = np.broadcast_to(a, (*shape, 3)).copy()
    elif a.shape == shape:
        a = np.repeat(a[..., None], 3, axis=-1)
    if a.shape != (*shape, 3):
        raise SceneError(f"albedo of shape {a.shape} does not fit a {shape} map")
    return np.clip(a, 0.0, 1.0)


def scene_from_depth_file(
    path: str | Path,
    *,
    scale_px: float = 1.0,
    relief_px: float | None = None,
    is_depth: bool = False,
    albedo: float | ArrayLike = 0.6,
    pixel_size_mm: float = 0.05,
    passes: Iterable[str] = ("shadows",),
    name: str | None = None,
) -> Scene:
    """A matte scene from a height (or depth) map file: .npy, .tif/.tiff, or an image (.png…).

    Values become pixel units by ``scale_px`` (value × scale_px), or, if ``relief_px`` is given,
    are min–max rescaled to [0, relief_px]. ``is_depth=True`` means larger = farther (negated).
    Row 0 of the file is the top of the image. Colour images use their first channel.
    """
    p = Path(path)
    raw = _read_map(p)
    if raw.ndim == 3:
        raw = raw[..., 0]
    if raw.ndim != 2 or raw.shape[0] < 2 or raw.shape[1] < 2:
        raise SceneError(f"{shown_path(p)}: expected a 2-D height map, got shape {raw.shape}")
    h = raw.astype(np.float64)
    if not np.all(np.isfinite(h)):
        raise SceneError(f"{shown_path(p)}: height map contains NaN or infinity")
    if is_depth:
        h = -h
    if relief_px is not None:
        span = float(h.max() - h.min())
        h = (h - h.min()) * (relief_px / span if span > 0 else 0.0)
    else:
        h = h * float(scale_px)
    return _matte_from_file(
        name or p.stem,
        h,
        normals_from_height(h),
        albedo,
        pixel_size_mm,
        passes,
        "depth file",
        f"height field from {p.name}",
    )


def scene_from_normal_file(
    path: str | Path,
    *,
    green_up: bool = True,
    albedo: float | ArrayLike = 0.6,
    pixel_size_mm: float = 0.05,
    passes: Iterable[str] = (),
    name: str | None = None,
) -> Scene:
    """A matte scene from a normal map: .npy/.tif float in [-1, 1], or an 8/16-bit RGB image.

    Integer images encode ``n = 2·value/max - 1`` (the usual RGB normal-map convention).
    ``green_up=True`` is the OpenGL convention (green = +y = image top), the frame of this
    project; ``False`` flips y (DirectX maps). Normals are kept exactly (renormalised; z ≥ 1e-3);
    a height is integrated from them only for shadows and point-light geometry, which is why
    ``passes`` defaults to none: integrated heights of non-integrable maps are approximate.
    """
    p = Path(path)
    raw = _read_map(p)
    if raw.ndim != 3 or raw.shape[2] < 3:
        raise SceneError(
            f"{shown_path(p)}: expected an RGB normal map (H, W, 3), got shape {raw.shape}"
        )
    raw = raw[..., :3]
    if np.issubdtype(raw.dtype, np.integer):
        n = 2.0 * raw.astype(np.float64) / float(np.iinfo(raw.dtype).max) - 1.0
    else:
        n = raw.astype(np.float64)
    if not np.all(np.isfinite(n)):
        raise SceneError(f"{shown_path(p)}: normal map contains NaN or infinity")
    if not green_up:
        n[..., 1] = -n[..., 1]
    n[..., 2] = np.maximum(n[..., 2], 1e-3)
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    return _matte_from_file(
        name or p.stem,
        height_from_normals(n),
        n,
        albedo,
        pixel_size_mm,
        passes,
        "normal file",
        f"normal map from {p.name}",
    )


def _matte_from_file(
    name: str,
    height: NDArray[np.float64],
    normals: NDArray[np.float64],
    albedo: float | ArrayLike,
    pixel_size_mm: float,
    passes: Iterable[str],
    source: str,
    description: str,
) -> Scene:
    """A matte scene (no specular lobe) from a height and its normals read from a file."""
    shape = (height.shape[0], height.shape[1])
    return Scene(
        name=name,
        seed=0,
        height=height,
        normals=normals,
        albedo=_albedo_array(albedo, shape),
        specular_albedo=np.zeros((*shape, 3)),
        roughness=np.ones(shape),
        passes=frozenset(passes),
        pixel_size_mm=pixel_size_mm,
        material=f"matte (from {source})",
        description=description,
    )
