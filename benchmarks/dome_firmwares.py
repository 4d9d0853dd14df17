"""Time per light on each real dome firmware profile, against its emulator on a pty.

For each built-in firmware profile the emulator (``rti_rig.simulator.domes``, written from the
firmware's source: baud-paced output, blocking commands, framing by silence) is served on a
pseudo-terminal, and the real scripted driver under the runtime policy lights LEDs one after
another. Timed on the wall clock per light: ``light`` (until the LED is known lit) + ``all_off``
(until it is known off, or the firmware's on-window ended). That is the link's share of each
image: settle, exposure and camera transfer come on top. Connecting (boot wait) is timed once.

Run: ``python -m benchmarks.dome_firmwares`` (prints; ``--write`` updates docs/benchmarks.md).
"""

from __future__ import annotations

import statistics
import sys
import time

from benchmarks.report import machine_line, write_section
from rti_rig.app.dome_factory import build_dome
from rti_rig.core.clock import VirtualClock
from rti_rig.drivers.led_dome.dome_profiles import described_profiles
from rti_rig.drivers.led_dome.settings import DomeSerialSettings
from rti_rig.simulator.domes import board_for
from rti_rig.simulator.pty_link import serve_on_pty

LIGHTS = 8
OVERRIDES = {"rtipy": {"light_on_s": 1.0}}


def measure(profile: str) -> tuple[float, list[float], int]:
    """(connect seconds, seconds per light = light + all_off, resends) on the wall clock."""
    board = board_for(profile)
    with serve_on_pty(board, profile) as link:
        settings = DomeSerialSettings(
            port=link.port, profile=profile, protocol=OVERRIDES.get(profile)
        )
        dome = build_dome(settings, VirtualClock())
        t0 = time.perf_counter()
        dome.connect()
        connect_s = time.perf_counter() - t0
        per_light = []
        try:
            for i in range(LIGHTS):
                t0 = time.perf_counter()
                dome.light(2 * i + 1)
                dome.all_off()
                per_light.append(time.perf_counter() - t0)
        finally:
            dome.close()
    return connect_s, per_light, dome.stats.retries


def main(argv: list[str]) -> str:
    rows = []
    for profile in described_profiles():
        connect_s, per, retries = measure(profile)
        med = statistics.median(per)
        rows.append(f"| {profile} | {connect_s:.2f} | {med:.3f} | {max(per):.3f} | {retries} |")
        print(
            f"{profile:12s} connect {connect_s:.2f} s, per light median {med:.3f} s, "
            f"max {max(per):.3f} s",
            flush=True,
        )
    md = "\n".join(
        [
            "## Dome firmwares: time per light (`python -m benchmarks.dome_firmwares --write`)",
            "",
            machine_line(),
            "",
            f"Scripted driver + runtime policy + pyserial against each firmware's emulator on a "
            f"pty; LEDs 1, 3, …, {2 * LIGHTS - 1}; wall-clock seconds. *Per light* = `light` "
            "(until the LED is known lit) + `all_off` (until it is known off, or a timed LED's "
            "window ended): the link's share of each image, before settle, exposure and transfer. "
            "What dominates: rtipy, the 1 s of silence that frames a command plus its whole-second "
            "on-window (`light_on_s = 1` here); rti-dome-m, parseInt's 1 s timeout twice (light, "
            "then `M99`); nichlock, stepping up from LED 0 after each all-off (grows with the LED "
            "index); nab-rti-v1, ~100 reply characters at 9600 baud. *Connect* includes the boot "
            "wait after the port opens (Arduino auto-reset).",
            "",
            "| profile | connect s | per light median s | per light max s | resends |",
            "|---|---|---|---|---|",
            *rows,
        ]
    )
    if "--write" in argv:
        write_section("dome_firmwares", md)
    return md


if __name__ == "__main__":
    from benchmarks.report import exit_on_help

    exit_on_help(__doc__)
    main(sys.argv[1:])
