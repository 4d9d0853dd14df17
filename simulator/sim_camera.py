"""The simulated camera: renders what the simulated light state shows, through a sensor model.

Signal scales with exposure; shot (Poisson) and read (Gaussian) noise and saturation are applied
in electrons, then scaled to a 16-bit linear container. Capturing advances the injected clock by
exposure + readout + transfer, so a dry run reports the session time the real rig would take.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from rti_rig.core.clock import Clock
from rti_rig.core.devices import Frame
from rti_rig.core.errors import CaptureError
from rti_rig.simulator.sim_lights import LightState

#: A renderer maps (light direction or None, intensity) to linear radiance (H, W, 3) in [0, ~1].
Renderer = Callable[[NDArray[np.float64] | None, float], NDArray[np.float64]]


class SimulatedCamera:
    """A noisy linear camera looking at a rendered scene."""

    def __init__(
        self,
        render: Renderer,
        state: LightState,
        clock: Clock,
        *,
        reference_exposure_s: float,
        readout_s: float = 0.3,
        transfer_s: float = 0.7,
        full_well_e: float = 20000.0,
        read_noise_e: float = 3.0,
        ambient: float = 0.0,
        noise: bool = True,
        seed: int = 0,
        raw: bool = False,
    ) -> None:
        self.name = "simulated camera"
        self._render = render
        self._state = state
        self._clock = clock
        # White (albedo 1) at normal incidence fills 75 % of the well at the reference exposure.
        self._e_per_radiance_s = 0.75 * full_well_e / reference_exposure_s
        self._readout_s = readout_s
        self._transfer_s = transfer_s
        self._full_well = full_well_e
        self._read_noise = read_noise_e
        self._ambient = ambient
        self._noise = noise
        self._seed = seed
        self._raw = raw
        self._count = 0
        self._connected = False

    def connect(self) -> None:
        self._connected = True

    def close(self) -> None:
        self._connected = False

    def _noise_key(self, exposure_s: float) -> list[int]:
        """Noise depends on the scene seed and what is lit, not on how many frames came before.

        A session that is interrupted and resumed therefore yields bit-identical images to an
        uninterrupted one, which is what lets the tests compare the two folders file by file.
        """
        d = self._state.direction
        light = [0, 0, 0] if d is None else [round(c * 1e6) + 2_000_000 for c in d]
        return [
            self._seed,
            *light,
            round(self._state.intensity * 1e6),
            round(exposure_s * 1e9),
        ]

    def capture(self, exposure_s: float) -> Frame:
        if not self._connected:
            raise CaptureError(self.name, "not connected; call connect() first", "capture")
        if not exposure_s > 0:
            raise CaptureError(self.name, f"exposure must be positive, got {exposure_s}", "capture")
        t0 = self._clock.now()
        radiance = self._render(self._state.direction, self._state.intensity) + self._ambient
        electrons = radiance * (self._e_per_radiance_s * exposure_s)
        rng = np.random.default_rng(self._noise_key(exposure_s))
        self._count += 1
        if self._noise:
            electrons = rng.poisson(np.clip(electrons, 0.0, None)).astype(np.float64)
            electrons += rng.normal(0.0, self._read_noise, electrons.shape)
        electrons = np.clip(electrons, 0.0, self._full_well)
        self._clock.sleep(exposure_s + self._readout_s + self._transfer_s)
        if self._raw:
            return self._through_raw(electrons / self._full_well, exposure_s, t0)
        white = 65535
        pixels = np.round(electrons * (white / self._full_well)).astype(np.uint16)
        return Frame(
            pixels=pixels,
            exposure_s=exposure_s,
            gain=1.0,
            white_level=white,
            timestamp_s=t0,
            metadata={"source": "simulated", "capture_index": self._count - 1},
        )

    def _through_raw(self, linear: NDArray[np.float64], exposure_s: float, t0: float) -> Frame:
        """Deliver the frame as a DSLR would: Bayer mosaic → DNG → the real rawpy decode path."""
        from rti_rig.drivers.cameras.raw_roundtrip import encode_decode
        from rti_rig.drivers.cameras.settings import RawDecodeSettings

        frame = encode_decode(
            linear, exposure_s, RawDecodeSettings(mode="demosaic"), timestamp_s=t0
        )
        meta = {**frame.metadata, "source": "simulated-raw"}
        return Frame(frame.pixels, exposure_s, frame.gain, frame.white_level, t0, meta)
