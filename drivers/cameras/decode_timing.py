"""Time DNG writing and RAW decoding per mode: ``python -m drivers.cameras.decode_timing``.

Why: the decode mode decides how long each frame costs after capture (a 24 MP demosaic takes
seconds), so a rig's operator should measure it on the rig's own computer. Prints a markdown
table of medians; ``--sizes 480x640`` restricts the sizes.
"""

from __future__ import annotations

import argparse
import platform
import statistics
import time

import numpy as np

from drivers.cameras.dng_writer import dng_bytes
from drivers.cameras.raw_decode import decode_raw
from drivers.cameras.settings import RawDecodeSettings

MODES = ("mosaic", "half", "demosaic")


def _median_s(fn, repeats: int) -> float:
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def measure(shape: tuple[int, int], repeats: int) -> dict[str, float]:
    """Median seconds for dng_bytes and each decode mode on a random 14-bit mosaic."""
    rng = np.random.default_rng(0)
    mosaic = rng.integers(512, 16383, shape).astype(np.uint16)
    out = {
        "write": _median_s(lambda: dng_bytes(mosaic, black_level=512, white_level=16383), repeats)
    }
    data = dng_bytes(mosaic, black_level=512, white_level=16383)
    for mode in MODES:
        settings = RawDecodeSettings(mode=mode)
        out[mode] = _median_s(lambda s=settings: decode_raw(data, s), repeats)
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--sizes", nargs="+", default=["480x640", "4000x6000"])
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    import rawpy

    print(
        f"{platform.machine()}, Python {platform.python_version()}, rawpy {rawpy.__version__}"
        f", LibRaw {'.'.join(map(str, rawpy.libraw_version))}; median of {args.repeats}"
    )
    print("| size | dng_bytes | mosaic | half | demosaic | demosaic / mosaic |")
    print("|---|---|---|---|---|---|")
    for size in args.sizes:
        h, w = (int(v) for v in size.split("x"))
        r = measure((h, w), args.repeats)
        cells = " | ".join(f"{r[k] * 1000:.1f} ms" for k in ("write", *MODES))
        print(f"| {w}×{h} | {cells} | {r['demosaic'] / r['mosaic']:.0f}× |")


if __name__ == "__main__":
    main()
