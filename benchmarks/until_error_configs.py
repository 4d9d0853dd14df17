"""``--until-error`` through the front door on the shipped simulated rigs: is the stop's claim
true where the benchmarks that calibrated it never looked?

The stop's estimate and its upper factor were calibrated on the simulator's scenes at 96 px
under directional lights, over every elevation (``benchmarks.adaptive_until_sim``,
``benchmarks.adaptive``). A user runs ``rti-rig run rig_configs/simulated_arm.toml
--until-error T``: 256 px, point lamps at 400 mm, perhaps under an elevation band. Each case
here is that command, run as a user runs it (a subprocess of ``python -m rti_rig``), and the
session's images then measured as the calibration measures them (robust photometric stereo on
the session's linear images and its ``lights.lp``, the mean angle to the scene's true normals
over every pixel, an unsolved pixel counted as facing the camera:
``benchmarks.tradeoff.normal_error``). Printed per case: the lights used, the estimate, the
upper estimate the stop compares with the target (the larger of the estimate × the factor and
the images' misfit bound, plus the unsolved term), whether the target was claimed, the
measured error, and whether the claim holds (measured ≤ target).

A variant of a config with its point lamps removed (``light_distance_mm`` dropped: directional
lights, as the calibration's) separates the lamps' nearness from the band's and the
resolution's share.

Run: ``python -m benchmarks.until_error_configs [--targets 1.5,0.8] [--write]`` (``--write``
puts the table into docs/adaptive.md).
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
import tomllib
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from benchmarks.adaptive import DOC
from benchmarks.report import machine_line, write_section

REPO = Path(__file__).resolve().parent.parent
CONFIGS = REPO / "rig_configs"


@dataclass(frozen=True)
class Case:
    """One front-door session: a shipped config (``directional``: its point lamps dropped),
    an elevation ceiling (None: every elevation) and a target (°)."""

    config: str
    directional: bool
    ceiling_deg: float | None
    target_deg: float

    def label(self) -> str:
        lamps = "directional" if self.directional else "as shipped"
        band = "every elevation" if self.ceiling_deg is None else f"≤ {self.ceiling_deg:g}°"
        return f"{self.config} ({lamps}) | {band} | {self.target_deg:g}°"


def cases(targets: tuple[float, ...]) -> list[Case]:
    """The default cases: the arm as shipped and with directional lights, over every elevation
    and under two low ceilings; the dome as shipped over every elevation and under ceilings of
    45° and 15° (its relief leaves pixels unsolved under four low lights)."""
    out = []
    for target in targets:
        for directional in (False, True):
            for ceiling in (None, 15.0, 5.0):
                out.append(Case("simulated_arm.toml", directional, ceiling, target))
        for ceiling in (None, 45.0, 15.0):
            out.append(Case("simulated_dome.toml", False, ceiling, target))
    return out


def truth_normals(config: dict) -> NDArray[np.float64]:  # type: ignore[type-arg]
    """The true normals of a simulated config's scene at its camera's size."""
    from rti_rig.simulator.scenes import make_scene
    from rti_rig.simulator.sim_scene import relief_scene

    scene = config["scene"]
    h, w = int(config["camera"]["height"]), int(config["camera"]["width"])
    seed = int(scene.get("seed", 0))
    if scene["name"] == "relief":
        return relief_scene(h, w, seed).normals
    return make_scene(scene["name"], h, w, seed=seed).normals


def config_text(case: Case) -> str:
    """The config's text, its point lamps dropped for a directional case."""
    text = (CONFIGS / case.config).read_text(encoding="utf-8")
    if not case.directional:
        return text
    return "\n".join(
        line for line in text.splitlines() if not line.strip().startswith("light_distance_mm")
    )


def session_stack(session: Path) -> tuple[list[dict], NDArray[np.float32], NDArray[np.float64]]:  # type: ignore[type-arg]
    """A session's journal steps, its linear images (units of white) and each image's light
    as lights.lp records it, in shooting order."""
    from rti_rig.core.image_files import read_linear_tiff
    from rti_rig.core.lp_format import read_lp

    steps = [json.loads(line) for line in (session / "journal.jsonl").read_text().splitlines()]
    images = np.stack(
        [read_linear_tiff(session / s["linear_image"]).astype(np.float32) / 65535 for s in steps]
    )
    by_name = {e.name: e.direction for e in read_lp(session / "lights.lp")}
    return steps, images, np.array([by_name[s["image"]] for s in steps])


def measured_error(session: Path, truth: NDArray[np.float64]) -> tuple[float, float]:
    """Mean and median angle (°) of robust photometric stereo on the session's linear images
    and lights.lp to ``truth``, as the calibration measures it."""
    from benchmarks.tradeoff import normal_error

    _, images, lights = session_stack(session)
    mean, median, _ = normal_error(truth, images, lights)
    return mean, median


def session_error_deg(config: Path, session: Path) -> float:
    """The mean normal error (°) of ``session``, shot on the simulated rig ``config`` (a TOML
    file), as the stop's calibration measures it (:func:`measured_error` against the
    config's scene's true normals): what the front-door tests compare a claim with."""
    cfg = tomllib.loads(Path(config).read_text(encoding="utf-8"))
    return measured_error(session, truth_normals(cfg))[0]


def run_cli(case: Case, folder: Path, *options: str) -> tuple[Path, dict]:  # type: ignore[type-arg]
    """``rti-rig run`` on ``case``'s config (written to ``folder``) with ``--until-error``,
    its ceiling and ``options``, as a user runs it (a subprocess): the session and the
    config read."""
    config = folder / case.config
    text = config_text(case)
    config.write_text(text, encoding="utf-8")
    session = folder / "s"
    argv = [sys.executable, "-m", "rti_rig", "run", str(config), "--out", str(session)]
    argv += ["--until-error", f"{case.target_deg:g}", "--no-verdict", *options]
    if case.ceiling_deg is not None:
        argv += ["--max-elevation-deg", f"{case.ceiling_deg:g}"]
    done = subprocess.run(argv, capture_output=True, text=True, cwd=REPO)
    if done.returncode != 0:
        raise SystemExit(f"{case.label()}: the session failed:\n{done.stderr[-2000:]}")
    return session, tomllib.loads(text)


def run_case(case: Case, folder: Path) -> dict:  # type: ignore[type-arg]
    """Run ``case`` through the CLI in ``folder`` and measure it."""
    session, cfg = run_cli(case, folder)
    result = json.loads((session / "manifest.json").read_text())["adaptive"]["result"]
    mean, median = measured_error(session, truth_normals(cfg))
    return {
        "case": case,
        "lights": int(result["lights_used"]),
        "estimate": float(result["estimated_error_deg"]),
        "upper": float(result["upper_error_deg"]),
        "unsolved": float(result.get("unsolved_fraction") or 0.0),
        "misfit": result.get("misfit_deg"),
        "claimed": bool(result["target_claimed"]),
        "mean": mean,
        "median": median,
    }


def table(rows: list[dict]) -> str:  # type: ignore[type-arg]
    """The markdown table of the cases' rows."""
    lines = [
        "| config (lamps) | band | target | lights | estimate ° | misfit bound ° | unsolved | "
        "upper ° | claimed | measured mean ° (median) | measured / upper | claim true |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        c: Case = r["case"]
        holds = "—" if not r["claimed"] else ("yes" if r["mean"] <= c.target_deg else "**no**")
        misfit = "—" if r.get("misfit") is None else f"{float(r['misfit']):.2f}"
        lines.append(
            f"| {c.label()} | {r['lights']} | {r['estimate']:.2f} | {misfit} | "
            f"{100 * r['unsolved']:.1f} % | "
            f"{r['upper']:.2f} | "
            f"{'yes' if r['claimed'] else 'no'} | {r['mean']:.2f} ({r['median']:.2f}) | "
            f"{r['mean'] / r['upper']:.1f}× | {holds} |"
        )
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--targets", default="1.5", help="comma-separated targets (°)")
    parser.add_argument("--write", action="store_true", help="write the table to docs/")
    args = parser.parse_args(argv)
    targets = tuple(float(t) for t in args.targets.split(","))
    t0 = time.perf_counter()
    rows = []
    for case in cases(targets):
        with tempfile.TemporaryDirectory() as tmp:
            rows.append(run_case(case, Path(tmp)))
        print(table(rows[-1:]).splitlines()[-1], flush=True)
    text = (
        f"Command: `python -m benchmarks.until_error_configs --targets {args.targets} --write` "
        f"({time.perf_counter() - t0:.0f} s). {machine_line()}\n\n{table(rows)}"
    )
    print("\n" + text)
    write_section("until_error_configs", text, DOC)


if __name__ == "__main__":
    main()
