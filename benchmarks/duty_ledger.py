"""What the dome's duty ledger costs a command: one write and one read of a full ledger.

The ledger (``rti_rig.runtime.duty_ledger``) is read when a dome connects and written when it
closes, and at an all-off at most every ``SAVE_EVERY_S`` of rig time: never more than once per
image. The worst case is every LED lit several times within the duty window (metering lights
the same LEDs again and again): here a 48-LED dome with each LED lit ``LIGHTINGS`` times in the
window. Timed on the wall clock per call: ``save`` (JSON, a temporary file, ``os.replace``; no
fsync) and ``load`` (read, parse, check, drop the old), in a temporary folder.

Run: ``python -m benchmarks.duty_ledger`` (``--write`` writes its section of docs/benchmarks.md).
"""

from __future__ import annotations

import os
import statistics
import tempfile
import time

from benchmarks.report import machine_line, write_section
from rti_rig.runtime.duty_ledger import LEDGER_DIR_ENV, DutyLedger

LEDS = 48
LIGHTINGS = 10
REPEATS = 300
WINDOW_S = 60.0


def measure() -> tuple[list[float], list[float], int]:
    """Wall-clock seconds of each ``save`` and ``load``, and the ledger's size in bytes."""
    before = os.environ.get(LEDGER_DIR_ENV)
    try:
        with tempfile.TemporaryDirectory() as folder:
            os.environ[LEDGER_DIR_ENV] = folder
            return _measure_in_folder()
    finally:  # the variable named a folder that no longer exists
        if before is None:
            os.environ.pop(LEDGER_DIR_ENV, None)
        else:
            os.environ[LEDGER_DIR_ENV] = before


def _measure_in_folder() -> tuple[list[float], list[float], int]:
    """The measurement, in the ledger folder the caller set."""
    ledger = DutyLedger("port:/dev/ttyACM0")
    now = time.time()
    step = WINDOW_S / (LEDS * LIGHTINGS)
    spans = {
        i: [
            (
                now - WINDOW_S + (k * LEDS + i) * step,
                now - WINDOW_S + (k * LEDS + i + 0.8) * step,
            )
            for k in range(LIGHTINGS)
        ]
        for i in range(LEDS)
    }
    save_s, load_s = [], []
    for _ in range(REPEATS):
        t0 = time.perf_counter()
        ledger.save(spans, now, WINDOW_S)
        t1 = time.perf_counter()
        read = ledger.load(WINDOW_S)
        t2 = time.perf_counter()
        save_s.append(t1 - t0)
        load_s.append(t2 - t1)
    assert len(read.spans) == LEDS
    size = ledger.path.stat().st_size
    return save_s, load_s, size


def main() -> str:
    save_s, load_s, size = measure()
    sm, lm = statistics.median(save_s), statistics.median(load_s)
    print(
        f"{LEDS} LEDs x {LIGHTINGS} lightings ({size} bytes): save median {1e3 * sm:.3f} ms "
        f"(max {1e3 * max(save_s):.3f}), load median {1e3 * lm:.3f} ms "
        f"(max {1e3 * max(load_s):.3f})"
    )
    md = "\n".join(
        [
            "Command: `python -m benchmarks.duty_ledger`. " + machine_line(),
            "",
            f"A full duty ledger ({LEDS} LEDs, each lit {LIGHTINGS} times in the window, "
            f"{size} bytes), {REPEATS} writes and reads; wall-clock milliseconds per call. A "
            "command writes it at most once per 10 s of rig time, and at close.",
            "",
            "| call | median ms | max ms |",
            "|---|---|---|",
            f"| save | {1e3 * sm:.3f} | {1e3 * max(save_s):.3f} |",
            f"| load | {1e3 * lm:.3f} | {1e3 * max(load_s):.3f} |",
        ]
    )
    write_section("duty_ledger", md)
    return md


if __name__ == "__main__":
    from benchmarks.report import exit_on_help

    exit_on_help(__doc__)
    main()
