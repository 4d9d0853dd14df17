"""How long ``rti-rig probe`` takes on each emulated dome firmware, and where the time goes.

Each firmware's emulator (``rti_rig.simulator.domes``, written from its source: its bootloader
time, baud-paced output, framing by silence) is served on a pseudo-terminal, and the ``probe``
command is run on it in this process (the CLI's own command, through typer's runner: a child
interpreter's start, seconds on a loaded machine, would swamp the figures), timed on the wall
clock. ``silent`` is a board that never answers (the hadrian2/RTI_Dome firmware), which every
protocol is tried on. Each probe's time (each opening of the port: its wait, its send, its
listen) is timed too, and printed under its label; ``nab all-off`` is the Nab sketch's
switching off (its own opening, its boot listened out, ``<0>``).

Run: ``python -m benchmarks.probe_time [-v] [CASE ...]`` (prints; ``-v`` adds what the probe
printed).
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable
from typing import Any

from typer.testing import CliRunner

from rti_rig.app.usecases import probe as probe_module
from rti_rig.cli import app
from rti_rig.core.clock import SystemClock
from rti_rig.drivers.led_dome.settings import DomeSerialSettings
from rti_rig.simulator.dome_firmware import firmware_for
from rti_rig.simulator.domes import board_for
from rti_rig.simulator.domes.nichlock import NichlockBoard
from rti_rig.simulator.pty_link import serve_on_pty

CASES = ["nab-rti-v1", "rtipy", "minirti", "elexol-24r1", "nichlock", "nichlock@9600"]
CASES += ["nichlock@19200", "default", "silent"]


def board(case: str) -> Any:
    if case == "silent":
        return board_for("rti-dome-m")
    if case.startswith("nichlock@"):
        return NichlockBoard(baudrate=int(case.split("@")[1]))
    if case == "default":
        settings = DomeSerialSettings(port="pty", profile="default")
        return firmware_for(settings, led_count=48, clock=SystemClock())
    return board_for(case)


def timed(steps: list[tuple[str, float]], label: Callable[..., str], f: Callable[..., Any]) -> Any:
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        t0 = time.perf_counter()
        try:
            return f(*args, **kwargs)
        finally:
            steps.append((label(*args), time.perf_counter() - t0))

    return wrapper


def measure(case: str) -> tuple[float, int, list[tuple[str, float]], str]:
    """(seconds, exit code, [(probe, seconds)], output) of one probe."""
    steps: list[tuple[str, float]] = []
    exchange, nab_found = probe_module._exchange, probe_module._nab_found
    probe_module._exchange = timed(steps, lambda _r, what, *a: what, exchange)
    probe_module._nab_found = timed(steps, lambda *a: "nab all-off", nab_found)
    try:
        with serve_on_pty(board(case), case) as link:
            t0 = time.perf_counter()
            r = CliRunner().invoke(app, ["probe", link.port], terminal_width=400)
            seconds = time.perf_counter() - t0
    finally:
        probe_module._exchange, probe_module._nab_found = exchange, nab_found
    return seconds, r.exit_code, steps, r.output


def main(argv: list[str]) -> None:
    import argparse

    parser = argparse.ArgumentParser(
        prog="python -m benchmarks.probe_time", description=__doc__.split("\n\n")[0]
    )
    parser.add_argument("cases", nargs="*", help=f"of {', '.join(CASES)} (default: all)")
    parser.add_argument("-v", action="store_true", help="print what the probe printed")
    args = parser.parse_args(argv)
    unknown = [case for case in args.cases if case not in CASES]
    if unknown:
        parser.error(f"unknown case {', '.join(unknown)}: give some of {', '.join(CASES)}")
    for case in args.cases or CASES:
        seconds, code, steps, output = measure(case)
        print(f"{case:16s} {seconds:6.2f} s  exit {code}", flush=True)
        for what, s in steps:
            print(f"    {s:6.2f}  {what}", flush=True)
        for line in output.splitlines() if args.v else []:
            print(f"    | {line[:110]}", flush=True)


if __name__ == "__main__":
    main(sys.argv[1:])
