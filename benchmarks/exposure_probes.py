"""How many lights --auto-exposure must meter at on a dome whose LEDs were never evened out.

Why: one exposure serves the whole session, so it must keep the *brightest* image under the
saturation limit. With equal LEDs that is the planned light nearest the zenith (a level object
receives most from it); on a real dome whose LEDs differ by tens of percent (no ``rti-rig
calibrate-lights``) another light may be brighter, and metering at the zenith light alone
clipped 7 of 48 images on the shipped ``rig_configs/emulated_dome_card.toml``.
:data:`rti_rig.runtime.exposure_policy.PROBE_LIGHTS` is how many lights metering checks there;
this script measures what each count leaves clipped.

Model (no images rendered): a level Lambertian object under distant lights, so every image is
the same picture scaled by the light it receives, its LED's output × the direction's height ×
the step's intensity. Metering at a set of lights fixes the exposure that puts the brightest of
them ``HEADROOM`` (1.25, as ``fix_exposure``) under the limit; an image clips where its light
exceeds that light × ``HEADROOM``. The LED outputs are the emulator's own draws
(:meth:`rti_rig.app.config.EmulatorConfig.led_powers`: log-normal, ``--spread`` RMS of
ln(output)), one dome per seed, seed 0 being the shipped card config's dome; the layout and
plan are those ``rti-rig run`` uses (``plan_uniform`` on the config's geometry). Strategies:
the ``k`` highest-ranked planned lights (:func:`~rti_rig.runtime.exposure_policy.
metering_steps`, what ``--auto-exposure`` does), and for comparison ``k`` lights spread in
elevation and azimuth (``plan_uniform`` of ``k`` lights, snapped to the planned ones).

Run: ``python -m benchmarks.exposure_probes [--draws 4000] [--spread 0.2] [--write]``
(a few seconds; prints, and with ``--write`` updates its section of docs/benchmarks.md).
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from benchmarks.report import machine_line, write_section
from rti_rig.app.config import EmulatorConfig, load_rig_config, rig_geometry
from rti_rig.core.schedule import LightSchedule
from rti_rig.planner.uniform import plan_uniform
from rti_rig.runtime.exposure_policy import PROBE_LIGHTS, metering_steps

CONFIG = Path(__file__).resolve().parent.parent / "rig_configs" / "emulated_dome_card.toml"
HEADROOM = 1.25  # as rti_rig.app.usecases.session.fix_exposure's rule
COUNTS = (1, 2, 4, PROBE_LIGHTS, 8)


def received(schedule: LightSchedule, powers: np.ndarray) -> np.ndarray:
    """The light a level object receives at each step: LED output × height × intensity."""
    leds = np.array([s.led for s in schedule.steps])
    intensity = np.array([s.intensity for s in schedule.steps])
    return powers[leds] * schedule.directions[:, 2] * intensity


def clipped_steps(light: np.ndarray, metered: list[int], headroom: float = HEADROOM) -> np.ndarray:
    """Indices of the steps whose image clips at the exposure metered at ``metered``."""
    return np.flatnonzero(light > headroom * light[metered].max() * (1 + 1e-12))


def spread_steps(schedule: LightSchedule, geometry, k: int) -> list[int]:  # type: ignore[no-untyped-def]
    """``k`` planned steps spread in elevation and azimuth: a uniform ``k``-light layout, each
    snapped to the nearest planned light not yet taken."""
    planned = schedule.directions
    taken: list[int] = []
    for d in plan_uniform(geometry, k).directions:
        order = np.argsort(-(planned @ d))
        taken.append(int(next(i for i in order if int(i) not in taken)))
    return taken


def run(lights: int | None, draws: int, spread: float) -> dict[str, float]:
    """Percent of the ``draws`` domes left with some clipped image, per strategy."""
    loaded = load_rig_config(CONFIG)
    geometry = rig_geometry(loaded)
    schedule = plan_uniform(geometry, lights or geometry.count)
    emulator = EmulatorConfig(led_power_spread=spread)
    strategies = {f"highest {k}": metering_steps(schedule, k) for k in COUNTS}
    if len(schedule) > PROBE_LIGHTS:
        strategies[f"spread {PROBE_LIGHTS}"] = spread_steps(schedule, geometry, PROBE_LIGHTS)
    over = dict.fromkeys(strategies, 0)
    for seed in range(draws):
        light = received(schedule, emulator.led_powers(geometry.count, seed))
        for name, metered in strategies.items():
            over[name] += bool(clipped_steps(light, metered).size)
    return {name: 100.0 * n / draws for name, n in over.items()}


def shipped_dome() -> str:
    """Seed 0 (the shipped card config's own LEDs): the LEDs the model says clip at one light."""
    loaded = load_rig_config(CONFIG)
    geometry = rig_geometry(loaded)
    schedule = plan_uniform(geometry, geometry.count)
    cfg = loaded.config.emulator
    light = received(schedule, cfg.led_powers(geometry.count, loaded.config.scene.seed))
    lines = []
    for k in (1, PROBE_LIGHTS):
        clipped = clipped_steps(light, metering_steps(schedule, k))
        leds = sorted(int(schedule.steps[i].led) for i in clipped)  # type: ignore[arg-type]
        lines.append(f"metered at {k}: {len(leds)} of {len(schedule)} images clip (LEDs {leds})")
    return "; ".join(lines)


def main(argv: list[str] | None = None) -> str:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--draws", type=int, default=4000, help="domes drawn (one per seed)")
    ap.add_argument("--spread", type=float, default=0.2, help="RMS of ln(LED output)")
    ap.add_argument("--write", action="store_true", help="update docs/benchmarks.md")
    args = ap.parse_args(argv)
    rows = []
    for lights in (None, 8):
        said = "every LED (48)" if lights is None else f"--lights {lights}"
        for name, pct in run(lights, args.draws, args.spread).items():
            rows.append(f"| {said} | {name} | {pct:.1f} |")
            print(f"{said:15s} {name:10s}: {pct:5.1f} % of domes leave some image clipped")
    shipped = shipped_dome()
    print(f"shipped card dome (model): {shipped}")
    md = "\n".join(
        [
            "## Metering lights on an uncalibrated dome "
            "(`python -m benchmarks.exposure_probes --write`)",
            "",
            machine_line(),
            "",
            f"The 48-LED layout of `rig_configs/emulated_dome_card.toml`, {args.draws} domes "
            f"whose LED outputs are the emulator's log-normal draws ({args.spread:g} RMS of "
            "ln(output), one per seed), a level Lambertian object under distant lights, "
            f"headroom {HEADROOM:g}: the share of domes where metering at these lights leaves "
            "some image of the session over the saturation limit. *highest k*: the k planned "
            "lights a level object receives most from (what `--auto-exposure` meters at, "
            f"k = {PROBE_LIGHTS} on an uncalibrated dome); *spread k*: k lights spread in "
            "elevation and azimuth (a uniform k-light layout snapped to the planned lights, "
            "which leaves out the highest ones). Seed 0 is the shipped config's dome (the model "
            "names the LEDs the emulated session clipped): "
            f"{shipped}.",
            "",
            "| session | metered at | % of domes with a clipped image |",
            "|---|---|---|",
            *rows,
        ]
    )
    if args.write:
        write_section("exposure_probes", md)
    return md


if __name__ == "__main__":
    main()
