"""The trade on the user's own object: `rti-rig bench tradeoff --from ACQ/dirs.lp --out DIR`.

A conservator runs this once on a dense acquisition of their own (an `.lp` with its images) to
decide how many lights their objects need. Every light of the acquisition is the reference:
robust photometric stereo on all of them gives the reference normals (on the mask of
well-lit pixels), and each plan's relighting is scored on the lights it did not take. For
N lights (those below the acquisition's count among 6, 9, 12, 18, 24, 36, 48):

* `uniform` — the homogeneous layout, at floor 0° and at the floor that does best here
  (tuned with hindsight, which a user without this dense acquisition could not do);
* `optimal` — `plan --rig ACQ/dirs.lp --method optimal` (no preview: a level surface);
* `adaptive` — `run ACQ/dirs.lp --adaptive --lights N` (the same chooser, fed these images; one
  run per N, since with N known the design is chosen for N).

Session time: N lights at the replayed dome's ~1.12 s a light (the default dome timing). The
images are read as the replay rig reads them (JPEG decoded and linearised, 16-bit as they are),
averaged to grey, and shrunk to at most ``MAX_PX`` wide for speed.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from pathlib import Path

import cv2
import numpy as np

from benchmarks.tradeoff import Row, plot, write_csv

COUNTS = (6, 9, 12, 18, 24, 36, 48)
FLOORS = (0.0, 10.0, 20.0, 30.0)
MAX_PX = 256
PER_LIGHT_S = 0.02 + 0.1 + 0.05 + 0.3 + 0.7  # the default dome timing and exposure


def load_acquisition(lp: Path) -> tuple[np.ndarray, np.ndarray, list[str]]:
    """(grey linear images (N, H, W) float32, directions (N, 3), names) of an acquisition."""
    from rti_rig.core.image_files import read_image_any
    from rti_rig.core.lp_format import read_lp

    entries = read_lp(lp, upper_hemisphere=True)
    images = []
    for e in entries:
        img = read_image_any(lp.parent / e.name)
        x = img.astype(np.float32) / (255.0 if img.dtype == np.uint8 else 65535.0)
        if img.dtype == np.uint8:  # sRGB decoding
            x = np.where(x <= 0.04045, x / 12.92, ((x + 0.055) / 1.055) ** 2.4)
        g = x.mean(axis=-1) if x.ndim == 3 else x
        if g.shape[1] > MAX_PX:
            size = (MAX_PX, max(1, round(g.shape[0] * MAX_PX / g.shape[1])))
            g = cv2.resize(g, size, interpolation=cv2.INTER_AREA)
        images.append(g.astype(np.float32))
    dirs = np.array([e.direction for e in entries])
    return np.stack(images), dirs, [e.name for e in entries]


def run_tradeoff_from(lp: Path, progress: Callable[[str], None] = print) -> list[Row]:
    """Rows (one per plan and N) for the acquisition ``lp``; see the module docstring."""
    from benchmarks.planner_real_data import evaluate, planned_leds, reference
    from rti_rig.app.usecases.adaptive import AdaptiveChooser, dome_start
    from rti_rig.core.errors import ScheduleError
    from rti_rig.core.rig_geometry import DomeGeometry
    from rti_rig.planner.adaptive import START_LIGHTS
    from rti_rig.planner.objectives import models_for
    from rti_rig.planner.uniform import select_uniform_leds

    images, dirs, names = load_acquisition(Path(lp))
    dome = DomeGeometry(dirs, tuple(names))
    ref, mask = reference(images, dirs)
    counts = [n for n in COUNTS if n < len(dirs)]
    if not counts:
        raise ValueError(f"{lp}: {len(dirs)} lights; at least 7 are needed for a trade-off")
    name = f"{Path(lp).parent.name}/{Path(lp).name}"

    def adaptive_run(n: int) -> tuple[list[int], float]:
        """`run --adaptive --lights n` on the recorded images: its lights and the mean time of
        a decision (with N known the design is chosen for N, so each N is its own session)."""
        chooser = AdaptiveChooser(dirs, dome_start(dome, START_LIGHTS, n), n, design_lights=n)
        t0 = time.perf_counter()
        for i in range(n):
            c, _ = chooser.decide(i)
            if c is None:
                break
            chooser.observe(c, dirs[c], images[c])
        return chooser.used, (time.perf_counter() - t0) / max(1, n - START_LIGHTS)

    rows: list[Row] = []

    def add(method: str, floor: float, n: int, leds: np.ndarray, plan_s: float) -> None:
        err, psnr, _ = evaluate(np.asarray(leds), images, dirs, ref, mask, models_for(n)[-1])
        t = n * PER_LIGHT_S
        rows.append(
            Row(
                name,
                method,
                "normals",
                n,
                floor,
                err,
                float("nan"),
                float(mask.mean()),
                models_for(n)[-1],
                psnr,
                float("nan"),
                t,
                float("nan"),
                plan_s,
            )
        )

    for n in counts:
        for f in FLOORS:
            try:
                leds = select_uniform_leds(dome, n, f)
            except ScheduleError:  # fewer LEDs above this floor than N: no such layout
                continue
            add("uniform", f, n, leds, 0.0)
        t1 = time.perf_counter()
        opt = planned_leds(None, dome, n, None)
        add("optimal", 0.0, n, opt, time.perf_counter() - t1)
        used, adaptive_s = adaptive_run(n)
        add("adaptive", 0.0, n, np.array(used), adaptive_s)
        progress(f"{name}: N = {n} done")
    return rows


def _best_floor(rows: list[Row]) -> float:
    """The floor with the lowest mean error over the N it could serve (every N for floor 0)."""
    return min(
        FLOORS,
        key=lambda f: float(
            np.mean([r.normal_mean_deg for r in rows if r.method == "uniform" and r.floor_deg == f])
        ),
    )


def summarise_from(rows: list[Row], seconds: float, command: str) -> str:
    floor = _best_floor(rows)
    by = {(r.method, r.floor_deg, r.n): r for r in rows}
    counts = sorted({r.n for r in rows})
    lines = [
        f"# The trade on {rows[0].scene}",
        "",
        f"Command: `{command}` ({seconds:.0f} s). Reference: robust photometric stereo on every "
        "light of the acquisition (normal error on its well-lit pixels); relighting PSNR on the "
        "lights a plan did not take. Session time: "
        f"{PER_LIGHT_S:.2f} s a light (the replayed dome's default timing).",
        "",
        "| N | session s | uniform 0° | uniform, best floor here "
        f"({floor:g}°, hindsight) | optimal | adaptive |",
        "|---|---|---|---|---|---|",
    ]
    for n in counts:
        cells = [
            by[("uniform", 0.0, n)],
            by[("uniform", floor, n)],
            by[("optimal", 0.0, n)],
            by[("adaptive", 0.0, n)],
        ]
        lines.append(
            f"| {n} | {n * PER_LIGHT_S:.0f} | "
            + " | ".join(f"{r.normal_mean_deg:.2f}° / {r.relight_psnr_db:.1f} dB" for r in cells)
            + " |"
        )
    lines += [
        "",
        "Cells: mean normal error against the all-light reference / relighting PSNR. One "
        "acquisition, one layout per cell: differences of a few tenths of a degree between "
        "layouts are within what one layout's luck moves (docs/planner.md); read the trend "
        "with N, not single cells.",
    ]
    return "\n".join(lines)


def bench_from(lp: Path, out_dir: Path | None, progress: Callable[[str], None] = print) -> str:
    """Run, write results.csv, the plots and summary.md into ``out_dir`` (nothing written when
    it is None: the summary is only returned); return the summary."""
    t0 = time.perf_counter()
    rows = run_tradeoff_from(lp, progress)
    command = f"rti-rig bench tradeoff --from {lp}"
    if out_dir is None:
        return summarise_from(rows, time.perf_counter() - t0, command)
    out_dir.mkdir(parents=True, exist_ok=True)
    write_csv(rows, out_dir / "results.csv")
    for path in plot(rows, out_dir):
        if "arm_time" in path.name:  # a replayed acquisition is a dome: no arm time to plot
            path.unlink()
    text = summarise_from(rows, time.perf_counter() - t0, f"{command} --out {out_dir}")
    (out_dir / "summary.md").write_text(text + "\n", encoding="utf-8")
    return text
