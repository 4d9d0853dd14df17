"""Make simulated sensor data RAW-like: encode as DNG, decode through the real rawpy path.

Why: the simulated rig should exercise the same decode code as a real DSLR session (black
level, white level, CFA, saturation pinning, 14-bit quantisation), so a bug there shows up in
dry runs too. The simulator supplies ``render(exposure_s) -> linear image`` in units of the
sensor's full scale (1.0 = white; noise already added); this module does the rest.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from rti_rig.core.clock import Clock, VirtualClock
from rti_rig.core.devices import Frame
from rti_rig.core.errors import CaptureError
from rti_rig.drivers.cameras.dng_writer import dng_bytes, linear_to_mosaic
from rti_rig.drivers.cameras.raw_decode import decode_raw
from rti_rig.drivers.cameras.settings import RawDecodeSettings


def encode_decode(
    linear: NDArray[np.floating],
    exposure_s: float,
    decode: RawDecodeSettings | None = None,
    cfa_pattern: str = "RGGB",
    black_level: int = 512,
    white_level: int = 16383,
    iso: int = 100,
    path: Path | None = None,
    timestamp_s: float = 0.0,
) -> Frame:
    """Linear data → Bayer mosaic → DNG (bytes, or ``path`` if given) → ``decode_raw`` → Frame."""
    mosaic = linear_to_mosaic(linear, cfa_pattern, black_level, white_level)
    data = dng_bytes(
        mosaic,
        cfa_pattern=cfa_pattern,
        black_level=black_level,
        white_level=white_level,
        exposure_s=exposure_s,
        iso=iso,
    )
    if path is not None:
        path.write_bytes(data)
        return decode_raw(path, decode, timestamp_s=timestamp_s)
    return decode_raw(data, decode, timestamp_s=timestamp_s)


class RawRoundTripCamera:
    """A ``Camera`` around a linear renderer whose frames travel through DNG and rawpy.

    ``output_dir`` keeps each DNG (``cap0001.dng`` …) like a real tethered session; ``None``
    decodes from memory. Safe state: nothing held.
    """

    def __init__(
        self,
        name: str,
        render: Callable[[float], NDArray[np.floating]],
        decode: RawDecodeSettings | None = None,
        cfa_pattern: str = "RGGB",
        black_level: int = 512,
        white_level: int = 16383,
        iso: int = 100,
        output_dir: Path | None = None,
        clock: Clock | None = None,
    ) -> None:
        self.name = name
        self._render = render
        self._decode = decode or RawDecodeSettings()
        self._cfa = cfa_pattern
        self._black = black_level
        self._white = white_level
        self._iso = iso
        self.output_dir = output_dir
        self._clock = clock or VirtualClock()
        self._connected = False
        self._count = 0

    def connect(self) -> None:
        self._connected = True

    def close(self) -> None:
        self._connected = False

    def capture(self, exposure_s: float) -> Frame:
        if not self._connected:
            raise CaptureError(
                self.name, "camera is not connected; call connect() first", "capture"
            )
        if exposure_s <= 0:
            raise CaptureError(self.name, f"exposure must be positive, got {exposure_s}", "capture")
        self._count += 1
        path = None
        if self.output_dir is not None:
            self.output_dir.mkdir(parents=True, exist_ok=True)
            path = self.output_dir / f"cap{self._count:04d}.dng"
        frame = encode_decode(
            self._render(exposure_s),
            exposure_s,
            self._decode,
            self._cfa,
            self._black,
            self._white,
            self._iso,
            path,
            self._clock.now(),
        )
        metadata = dict(frame.metadata)
        metadata.update(
            {
                "camera": self.name,
                "exposure_requested_s": exposure_s,
                "gain_unit": "iso",
                "capture_started_s": frame.timestamp_s,
                "capture_finished_s": self._clock.now(),
            }
        )
        # The DNG stores exposure as a float32 rational; the requested value is exact.
        return Frame(
            pixels=frame.pixels,
            exposure_s=exposure_s,
            gain=float(self._iso),
            white_level=frame.white_level,
            timestamp_s=frame.timestamp_s,
            metadata=metadata,
        )
