"""A camera sensor model: radiance in, linear 16-bit-container raw out, plus the sRGB JPEG.

Why a sensor model and not just "add Gaussian noise": photometric stereo and RTI fitting are
weighted by signal-dependent noise (shot noise grows with √signal), dark pixels are clipped at
zero, highlights saturate, and a dataset quantised to 8 bits behaves differently from 14-bit
raw. A benchmark that skips these looks better than any real rig.

Pipeline per pixel and channel (EMVA 1288-style linear model):

1. electrons expected   Φ = q · E_rel · t · V(x, y)
   (q = ``electrons_per_unit_s``: electrons per second for π·radiance 1, i.e. a white card
   facing a unit light; V = optional radial vignetting 1 - v·(r / r_corner)²)
2. shot noise           e ~ Poisson(Φ), clipped at the full well
3. read noise           e + N(0, σ_r²)
4. ADC                  DN = round(K·e) + black level, clipped to [0, 2^bits - 1];
                        K = gain · (2^bits - 1 - black) / full_well (at gain 1 the full well
                        just fills the ADC range)
5. black subtraction    pixels = max(DN - black, 0), clipped at ``white_level`` (uint16);
                        a full well reads exactly ``white_level``

so, away from the clips, mean = K·Φ and variance = K²·(Φ + σ_r²) + 1/12 (quantisation).
``white_level`` = min(2^bits - 1 - black, round(K · full_well)): the code at which the pixel
saturates, whichever of the well or the ADC clips first.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np
from numpy.typing import ArrayLike, NDArray


@dataclass(frozen=True)
class CameraModel:
    """Sensor parameters. Defaults: a 14-bit camera with a 20 ke⁻ well and 3 e⁻ read noise."""

    full_well_e: float = 20_000.0
    read_noise_e: float = 3.0
    bit_depth: int = 14
    gain: float = 1.0
    black_level_dn: int = 512
    electrons_per_unit_s: float = 200_000.0
    vignetting: float = 0.0

    def __post_init__(self) -> None:
        problems = []
        if not self.full_well_e > 0:
            problems.append(f"full_well_e must be > 0, got {self.full_well_e}")
        if not self.read_noise_e >= 0:
            problems.append(f"read_noise_e must be >= 0, got {self.read_noise_e}")
        if not 8 <= int(self.bit_depth) <= 16:
            problems.append(f"bit_depth must be in 8..16 (16-bit container), got {self.bit_depth}")
        if not self.gain > 0:
            problems.append(f"gain must be > 0, got {self.gain}")
        if not 0 <= int(self.black_level_dn) < (1 << int(self.bit_depth)) // 2:
            problems.append(
                f"black_level_dn must be in [0, 2^bit_depth/2), got {self.black_level_dn}"
            )
        if not self.electrons_per_unit_s > 0:
            problems.append(f"electrons_per_unit_s must be > 0, got {self.electrons_per_unit_s}")
        if not 0 <= self.vignetting < 1:
            problems.append(f"vignetting must be in [0, 1), got {self.vignetting}")
        if problems:
            raise ValueError("CameraModel: " + "; ".join(problems))

    @property
    def adc_max_dn(self) -> int:
        return (1 << int(self.bit_depth)) - 1

    @property
    def dn_per_electron(self) -> float:
        """Conversion gain K at the current ``gain``."""
        return self.gain * (self.adc_max_dn - self.black_level_dn) / self.full_well_e

    @property
    def white_level(self) -> int:
        """Code (black removed) at which pixels saturate."""
        well = round(self.dn_per_electron * self.full_well_e)
        return int(min(self.adc_max_dn - self.black_level_dn, well))

    def vignetting_map(self, rows: int, cols: int) -> NDArray[np.float64]:
        """Relative illumination (rows, cols): 1 at the centre, 1 - vignetting at the corners."""
        if self.vignetting == 0:
            return np.ones((rows, cols))
        y = np.arange(rows) - (rows - 1) / 2.0
        x = np.arange(cols) - (cols - 1) / 2.0
        r2 = y[:, None] ** 2 + x[None, :] ** 2
        corner2 = ((rows - 1) / 2.0) ** 2 + ((cols - 1) / 2.0) ** 2
        return 1.0 - self.vignetting * r2 / max(corner2, 1e-12)

    def expected_electrons(self, radiance: ArrayLike, exposure_s: float) -> NDArray[np.float64]:
        """Mean photo-electrons Φ per pixel (before noise and clipping)."""
        rad = np.asarray(radiance, dtype=np.float64)
        if rad.ndim < 2:
            raise ValueError(f"radiance must be (H, W) or (H, W, C), got shape {rad.shape}")
        if not (math.isfinite(exposure_s) and exposure_s > 0):
            raise ValueError(f"exposure_s must be a finite number > 0, got {exposure_s}")
        if not np.all(np.isfinite(rad)) or np.any(rad < 0):
            raise ValueError("radiance must be finite and >= 0")
        vig = self.vignetting_map(rad.shape[0], rad.shape[1])
        if rad.ndim == 3:
            vig = vig[..., None]
        return rad * (self.electrons_per_unit_s * exposure_s) * vig

    def expose(
        self, radiance: ArrayLike, exposure_s: float, rng: np.random.Generator
    ) -> tuple[NDArray[np.uint16], int]:
        """Linear raw pixels (uint16, black level removed) and the white level."""
        phi = self.expected_electrons(radiance, exposure_s)
        # Anything above a few wells saturates anyway; capping keeps Poisson in its valid range.
        phi = np.minimum(phi, 4.0 * self.full_well_e)
        electrons = rng.poisson(phi).astype(np.float64)
        full = electrons >= self.full_well_e
        np.minimum(electrons, self.full_well_e, out=electrons)
        if self.read_noise_e > 0:
            electrons += rng.normal(0.0, self.read_noise_e, size=electrons.shape)
        dn = np.rint(electrons * self.dn_per_electron) + self.black_level_dn
        np.clip(dn, 0, self.adc_max_dn, out=dn)
        dn -= self.black_level_dn
        white = self.white_level
        np.clip(dn, 0, white, out=dn)
        dn[full] = white  # a full well reads white exactly, so saturation is detectable
        return dn.astype(np.uint16), white

    def exposure_for(self, radiance_level: float, fraction_of_white: float = 0.8) -> float:
        """Exposure (s) putting π·radiance ``radiance_level`` at ``fraction_of_white`` of white."""
        if not (radiance_level > 0 and 0 < fraction_of_white <= 1):
            raise ValueError("radiance_level must be > 0 and fraction_of_white in (0, 1]")
        target_e = fraction_of_white * self.white_level / self.dn_per_electron
        return target_e / (self.electrons_per_unit_s * radiance_level)


def _srgb_oetf(x: NDArray[np.float64]) -> NDArray[np.float64]:
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)


def to_srgb8(pixels: ArrayLike, white_level: int) -> NDArray[np.uint8]:
    """8-bit sRGB for viewers: linear pixels / white level, sRGB transfer curve, rounded.

    The export a real camera writes next to its raw file; never used for fitting.
    """
    if not white_level > 0:
        raise ValueError(f"white_level must be > 0, got {white_level}")
    x = np.clip(np.asarray(pixels, dtype=np.float64) / float(white_level), 0.0, 1.0)
    return np.rint(255.0 * _srgb_oetf(x)).astype(np.uint8)


def encode_jpeg(srgb8: ArrayLike, quality: int = 92) -> bytes:
    """JPEG bytes of an 8-bit sRGB image (H, W, 3) RGB or (H, W) grey."""
    img = np.asarray(srgb8)
    if img.dtype != np.uint8:
        raise ValueError(f"encode_jpeg expects uint8 sRGB, got {img.dtype}")
    if img.ndim == 3:
        img = np.ascontiguousarray(img[..., ::-1])  # RGB -> BGR for OpenCV
    ok, buf = cv2.imencode(".jpg", img, [cv2.IMWRITE_JPEG_QUALITY, int(quality)])
    if not ok:
        raise ValueError("OpenCV could not encode the image as JPEG")
    return buf.tobytes()
