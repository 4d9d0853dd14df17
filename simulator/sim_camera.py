"""The simulated camera: renders what the simulated light state shows, through a sensor model.

Signal scales with exposure; shot (Poisson) and read (Gaussian) noise and saturation are applied
in electrons, then scaled to a 16-bit linear container. Capturing advances the injected clock by
exposure + readout + transfer, so a dry run reports the session time the real rig would take.

The exposure starts at the trigger and lasts exactly ``exposure_s`` on the clock, as a real
camera's does: the light is read at the trigger, and the image is rendered only after the
exposure, in the time the modelled readout and transfer take. Rendering is the simulator's cost,
not the camera's; before 2026-12-01 it came first and, on the real clock of a self-timed dome
(RTIPy), pushed the whole exposure ~0.1 s later into the LED's window, so a capture that fits
the window on the real dome was refused as outlasting it.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from rti_rig.core.clock import Clock
from rti_rig.core.devices import Frame
from rti_rig.core.errors import CaptureError
from rti_rig.simulator.sim_lights import LightState
from rti_rig.simulator.sim_scene import row_bands

#: Poisson counts are kept as float32, exact up to here; anything above reads full well anyway.
_COUNT_CAP = float(2**24)
_WHITE = 65535

#: A renderer maps (light direction or None, intensity) to linear radiance (H, W, 3) in [0, ~1].
#: One that also has ``shape`` and ``rows(direction, intensity, start, stop)`` (the relief's
#: :class:`~rti_rig.simulator.sim_scene.ReliefRenderer`) is pulled band by band, so the camera
#: never holds the whole float64 radiance; the returned arrays are only read, never modified.
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
        #: (trigger, exposure end, delivery) of every capture on the camera's clock: the
        #: interval the light must be on is [trigger, exposure end]; delivery is later by the
        #: modelled readout and transfer, or by the render if that took longer.
        self.exposures: list[tuple[float, float, float]] = []

    def connect(self) -> None:
        self._connected = True

    def close(self) -> None:
        self._connected = False

    def _noise_key(
        self,
        exposure_s: float,
        d: NDArray[np.float64] | None = None,
        intensity: float | None = None,
    ) -> list[int]:
        """Noise depends on the scene seed and what is lit, not on how many frames came before.

        A session that is interrupted and resumed therefore yields bit-identical images to an
        uninterrupted one, which is what lets the tests compare the two folders file by file.
        ``d`` / ``intensity``: the light read at the trigger (without them, the light now).
        """
        if intensity is None:
            d, intensity = self._state.direction, self._state.intensity
        light = [0, 0, 0] if d is None else [round(c * 1e6) + 2_000_000 for c in d]
        return [
            self._seed,
            *light,
            round(intensity * 1e6),
            round(exposure_s * 1e9),
        ]

    def capture(self, exposure_s: float) -> Frame:
        if not self._connected:
            raise CaptureError(self.name, "not connected; call connect() first", "capture")
        if not exposure_s > 0:
            raise CaptureError(self.name, f"exposure must be positive, got {exposure_s}", "capture")
        t0 = self._clock.now()
        # The light as it is at the trigger is what this exposure sees: read it now, since on
        # a self-timed dome it may be dark by the time the image is rendered.
        direction, intensity = self._state.direction, self._state.intensity
        rng = np.random.default_rng(self._noise_key(exposure_s, direction, intensity))
        self._count += 1
        # Deadlines, not durations: the time reading the light took (an emulated board's link
        # is first run up to now) lies inside the exposure, not after it.
        self._sleep_until(t0 + exposure_s)
        exposed = self._clock.now()
        out = self._expose(exposure_s, rng, direction, intensity)
        # Render time counts towards the readout and transfer; only beyond them does it delay
        # the frame (on a virtual clock the render takes none, so this is readout + transfer).
        self._sleep_until(exposed + self._readout_s + self._transfer_s)
        self.exposures.append((t0, exposed, self._clock.now()))
        if self._raw:
            return self._through_raw(out, exposure_s, t0)
        return Frame(
            pixels=out,
            exposure_s=exposure_s,
            gain=1.0,
            white_level=_WHITE,
            timestamp_s=t0,
            metadata={"source": "simulated", "capture_index": self._count - 1},
        )

    def _sleep_until(self, deadline: float) -> None:
        self._clock.sleep(max(0.0, deadline - self._clock.now()))

    def _expose(
        self,
        exposure_s: float,
        rng: np.random.Generator,
        direction: NDArray[np.float64] | None,
        intensity: float,
    ) -> NDArray[np.generic]:
        """The sensor's output (uint16 codes, or linear float in [0, 1] for ``raw``) under the
        light ``direction`` / ``intensity`` read at the trigger, a band of rows at a time.

        Why bands: whole-image float64 temporaries of a 24 MP frame are 0.6 GB each, and the
        sensor chain made half a dozen. Every pixel still goes through the same arithmetic,
        and the generator draws the same numbers in the same order (all the Poisson draws,
        then all the read-noise draws, each in row order), so the image is bit for bit the one
        a whole-image pass gives. Only the Poisson counts are kept between the two passes, as
        float32 capped at 2**24 (exact below the cap; a count that high is clipped to the full
        well whatever read noise is added).
        """
        band_of = getattr(self._render, "rows", None)
        if band_of is None:
            whole = self._render(direction, intensity)
            shape = whole.shape

            def band(start: int, stop: int) -> NDArray[np.float64]:
                return whole[start:stop]
        else:
            shape = tuple(self._render.shape)  # type: ignore[attr-defined]

            def band(start: int, stop: int) -> NDArray[np.float64]:
                return band_of(direction, intensity, start, stop)  # type: ignore[no-any-return]

        scale = self._e_per_radiance_s * exposure_s
        out = np.empty(shape, dtype=np.float64 if self._raw else np.uint16)
        bands = row_bands(shape[0], shape[1] if len(shape) > 1 else 1)
        counts = np.empty(shape, dtype=np.float32) if self._noise else None
        for a, b in bands:
            # in place, on the band's own new array (the renderer's is only read): one
            # temporary a band where there were four, the same arithmetic
            electrons = np.add(band(a, b), self._ambient)
            electrons *= scale
            if counts is None:
                self._finish(electrons, out[a:b])
            else:
                np.clip(electrons, 0.0, None, out=electrons)
                drawn = rng.poisson(electrons)
                np.minimum(drawn, _COUNT_CAP, out=counts[a:b], casting="unsafe")
        if counts is not None:
            for a, b in bands:
                electrons = rng.normal(0.0, self._read_noise, counts[a:b].shape)
                electrons += counts[a:b]  # count + noise: the same sum, in either order
                self._finish(electrons, out[a:b])
        return out

    def _finish(self, electrons: NDArray[np.float64], out: NDArray[np.generic]) -> None:
        """Clip ``electrons`` (the band's own array: it is overwritten) to the well and write
        the band's output codes into ``out``."""
        np.clip(electrons, 0.0, self._full_well, out=electrons)
        if self._raw:
            np.divide(electrons, self._full_well, out=out)
        else:
            electrons *= _WHITE / self._full_well
            np.rint(electrons, out=electrons)  # np.round to 0 decimals, without its copy
            out[...] = electrons  # whole codes in [0, 65535]: the cast is exact

    def _through_raw(self, linear: NDArray[np.float64], exposure_s: float, t0: float) -> Frame:
        """Deliver the frame as a DSLR would: Bayer mosaic → DNG → the real rawpy decode path."""
        from rti_rig.drivers.cameras.raw_roundtrip import encode_decode
        from rti_rig.drivers.cameras.settings import RawDecodeSettings

        frame = encode_decode(
            linear, exposure_s, RawDecodeSettings(mode="demosaic"), timestamp_s=t0
        )
        meta = {**frame.metadata, "source": "simulated-raw"}
        return Frame(frame.pixels, exposure_s, frame.gain, frame.white_level, t0, meta)
