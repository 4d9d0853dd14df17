"""Serial LED-dome round trips through the real driver, real pyserial and a pseudo-terminal.

For each protocol profile (default line ASCII with checksum, framed ``<cmd,…>``, binary with a
one-byte ack) and two line speeds, the firmware emulator serves a 48-LED dome on a pty and the
real driver stack (``rti_rig.app.dome_factory.build_dome``: codec, pyserial, retry/thermal policy)
lights LEDs one after another. Timed per call, on the wall clock: ``light`` (command, wait for
the acknowledgement) and ``all_off``. The emulator delays each reply by the bytes' time on the
wire at the configured baud rate, so the figures are protocol + line time + pty + Python — not a
real dome's firmware or USB latency, which a hardware run has to measure.

Run: ``python -m benchmarks.dome_roundtrip`` (writes its section of docs/benchmarks.md).
"""

from __future__ import annotations

import statistics
import time

import numpy as np

from benchmarks.report import machine_line, write_section
from rti_rig.app.dome_factory import build_dome
from rti_rig.core.clock import SystemClock
from rti_rig.drivers.led_dome.settings import DomeSerialSettings
from rti_rig.simulator.dome_firmware import emulated_dome_on_pty, firmware_for

LEDS = 48
REPEATS = 200
PROFILES = ("default", "framed", "binary")
BAUDS = (115_200, 1_000_000)


def measure(profile: str, baud: int) -> tuple[list[float], list[float]]:
    """Wall-clock seconds of each ``light`` and ``all_off`` call, ``REPEATS`` of each."""
    settings = DomeSerialSettings(port="unused", baudrate=baud, profile=profile)
    firmware = firmware_for(settings, led_count=LEDS, clock=SystemClock())
    with emulated_dome_on_pty(firmware) as link:
        dome = build_dome(settings.model_copy(update={"port": link.port}), SystemClock())
        dome.connect()
        try:
            light_s, off_s = [], []
            for i in range(REPEATS + 5):
                t0 = time.perf_counter()
                dome.light(i % LEDS, 0.2)
                t1 = time.perf_counter()
                dome.all_off()
                t2 = time.perf_counter()
                if i >= 5:  # the first calls warm up pyserial and the codec
                    light_s.append(t1 - t0)
                    off_s.append(t2 - t1)
        finally:
            dome.all_off()
            dome.close()
    return light_s, off_s


def main() -> str:
    rows = []
    for profile in PROFILES:
        for baud in BAUDS:
            light_s, off_s = measure(profile, baud)
            lm, om = statistics.median(light_s), statistics.median(off_s)
            l95 = float(np.percentile(light_s, 95))
            rows.append(
                f"| {profile} | {baud} | {1e3 * lm:.2f} | {1e3 * l95:.2f} | {1e3 * om:.2f} |"
            )
            print(
                f"{profile:8s} {baud:8d} baud: light median {1e3 * lm:.2f} ms "
                f"(p95 {1e3 * l95:.2f}), all_off median {1e3 * om:.2f} ms"
            )
    md = "\n".join(
        [
            "Command: `python -m benchmarks.dome_roundtrip`. " + machine_line(),
            "",
            f"Real driver + pyserial against the firmware emulator on a pseudo-terminal, {LEDS} "
            f"LEDs, {REPEATS} calls each after 5 warm-up calls; wall-clock milliseconds per call "
            "(command sent → acknowledgement parsed). The emulator holds each reply for the "
            "bytes' time on the wire; real firmware and USB-serial adapters add their own "
            "latency (USB full-speed frames are 1 ms; FTDI adapters' default latency timer is "
            "16 ms), which only a hardware run measures.",
            "",
            "| profile | baud | light median ms | light p95 ms | all_off median ms |",
            "|---|---|---|---|---|",
            *rows,
        ]
    )
    write_section("dome_roundtrip", md)
    return md


if __name__ == "__main__":
    from benchmarks.report import exit_on_help

    exit_on_help(__doc__)
    main()
