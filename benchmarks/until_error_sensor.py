"""How much of the gap between the ``--until-error`` stop's upper estimate and the measured
error on the shipped simulated arm is the camera's sensor?

The arm (``rig_configs/simulated_arm.toml`` with its point lamps dropped: directional lights,
as the calibration's) measured 2–3× its upper estimate over every elevation, where the
calibration's tablet measures under it (``benchmarks.until_error_configs``). This runs one
session through the CLI as a user does (``--lights 12 --until-error 1e-6``: it never stops
early, and every decision records its estimates), then measures after k lights, on the lights
the session recorded (``lights.lp``), the robust fit's mean normal error against the scene's
true normals three ways:

* on the camera's own linear images (what the user gets);
* on the same lights rendered by the scene's renderer without any sensor (noise-free);
* on that rendering with Poisson-like noise of the level the camera's images show (variance
  proportional to the signal, its slope fitted on camera − rendering).

Printed beside them: the point and upper estimates the session recorded after k lights. The
estimate fits 128-px images (``FIT_PX``); the measurement is at the camera's 256 px.

Run: ``python -m benchmarks.until_error_sensor [--write]`` (``--write`` puts the table into
docs/adaptive.md).
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from benchmarks.adaptive import DOC
from benchmarks.report import machine_line, write_section
from benchmarks.tradeoff import normal_error
from benchmarks.until_error_configs import Case, run_cli, session_stack, truth_normals

COUNTS = (4, 6, 8, 12)


def _noisy(clean: NDArray[np.float32], camera: NDArray[np.float32]) -> NDArray[np.float32]:
    """``clean`` scaled to the camera's level, with noise of variance ∝ signal fitted on the
    camera's images (the same seed every run)."""
    lit = clean > 0.02
    scale = float(np.median(camera[lit] / clean[lit]))
    level = scale * clean
    slope = float(np.mean((camera[lit] - level[lit]) ** 2) / np.mean(level[lit]))
    rng = np.random.default_rng(0)
    noise = rng.standard_normal(level.shape).astype(np.float32)
    return (level + noise * np.sqrt(slope * np.maximum(level, 0.0))).astype(np.float32)


def measure() -> list[dict]:  # type: ignore[type-arg]
    from rti_rig.simulator.sim_scene import renderer_for

    # directional lights (as the calibration's), to the cap: every decision records its estimates
    case = Case("simulated_arm.toml", True, None, 1e-6)
    with tempfile.TemporaryDirectory() as tmp:
        session, cfg = run_cli(case, Path(tmp), "--lights", str(max(COUNTS)))
        steps, camera, lights = session_stack(session)
        result = json.loads((session / "manifest.json").read_text())["adaptive"]["result"]
    h, w = int(cfg["camera"]["height"]), int(cfg["camera"]["width"])
    render = renderer_for(cfg["scene"]["name"], h, w, int(cfg["scene"].get("seed", 0)), None)
    clean = np.stack([render.rows(d, 1.0, 0, h) for d in lights]).astype(np.float32)
    noisy = _noisy(clean, camera)
    truth = truth_normals(cfg)
    rows = []
    for k in COUNTS:
        rec = steps[k]["decision"] if k < len(steps) else result
        rows.append(
            {
                "k": k,
                "estimate": float(rec["estimated_error_deg"]),
                "upper": float(rec["upper_error_deg"]),
                "camera": normal_error(truth, camera[:k], lights[:k])[0],
                "clean": normal_error(truth, clean[:k], lights[:k])[0],
                "noisy": normal_error(truth, noisy[:k], lights[:k])[0],
            }
        )
    return rows


def table(rows: list[dict]) -> str:  # type: ignore[type-arg]
    lines = [
        "| lights | estimate ° | upper ° | measured: noise-free rendering ° | rendering + "
        "camera-level noise ° | camera's images ° | camera / upper |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        lines.append(
            f"| {r['k']} | {r['estimate']:.2f} | {r['upper']:.2f} | {r['clean']:.2f} | "
            f"{r['noisy']:.2f} | {r['camera']:.2f} | {r['camera'] / r['upper']:.1f}× |"
        )
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--write", action="store_true", help="write the table to docs/")
    parser.parse_args(argv)
    t0 = time.perf_counter()
    rows = measure()
    seconds = time.perf_counter() - t0
    text = (
        f"Command: `python -m benchmarks.until_error_sensor --write` ({seconds:.0f} s). "
        f"{machine_line()}\n\n" + table(rows)
    )
    print(text)
    write_section("until_error_sensor", text, DOC)  # only with --write (it says so otherwise)


if __name__ == "__main__":
    main()
