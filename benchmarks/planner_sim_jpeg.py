"""Is ``--signal-noise`` the setting for JPEG cameras? The simulator's scenes shot as 8-bit JPEGs.

The one real dome we can test on (neuralrti-example) delivers 8-bit sRGB JPEGs from LEDs whose
intensities are not calibrated, and there the planner told that the noise grows with the signal
(``--signal-noise 0.05``) beats the tuned homogeneous layout at every N. The simulator's camera
is a 14-bit raw with exact LEDs, where the same option loses on three scenes. This benchmark
asks what each of the two differences does, so the advice can follow the rig and the object:

* **JPEG**: every image of ``benchmarks.planner_sim_draws``'s scenes (its candidates and its
  preview) goes through what an 8-bit camera does — the sRGB curve, clipping at white, rounding
  to 8 bits, JPEG compression at :data:`JPEG_QUALITY` — and is decoded and linearised again
  before it is planned on or fitted;
* **JPEG and LED spread**: the same, with each candidate light's irradiance off by a fixed
  random factor (log-normal, :data:`LED_SPREAD` RMS) before the camera exposes, so a brighter
  LED saturates as it would. One draw of the factors (one simulated dome) serves every scene.

The draw design, the strategies' planning and the scoring are ``benchmarks.planner_sim_draws``'s
(same seed, so the same out-of-service lights and the same sensor-noise stream); plans depend on
the preview only, so both camera variants score the same plans. The homogeneous floor is tuned
with hindsight per scene and variant.

Run: ``python -m benchmarks.planner_sim_jpeg`` (writes its section of docs/research/planner.md).
"""

from __future__ import annotations

import sys
import time

import cv2
import numpy as np
from numpy.typing import NDArray

from benchmarks.planner_real_data import DOC, planned_leds, srgb_to_linear
from benchmarks.planner_sim_draws import (
    COUNTS,
    DRAWS,
    FLOORS,
    REMOVED,
    cell,
    paired_draws,
    scene_floor,
    table_head,
)
from benchmarks.report import write_section
from benchmarks.tradeoff import TradeoffSettings, normal_error, render_scene_data
from rti_rig.planner.objectives import SIGNAL_NOISE_JPEG_DOME
from rti_rig.planner.uniform import select_uniform_leds
from rti_rig.simulator.camera_model import encode_jpeg, to_srgb8

#: JPEG quality of the simulated 8-bit camera (the simulator's ``encode_jpeg`` default; the
#: real dome's is not recorded).
JPEG_QUALITY = 92
#: RMS of the candidate lights' intensity errors (log-normal) in the "LED spread" variant: the
#: size of the spread ``SIGNAL_NOISE_JPEG_DOME`` stands for.
LED_SPREAD = 0.05
#: Added to the settings' seed for the LED factors, so they are drawn apart from the draws'
#: and the sensor noise's streams (which must stay those of ``planner_sim_draws``).
SPREAD_SEED_OFFSET = 7
#: Variants: (label, LED spread).
VARIANTS = (("JPEG", 0.0), (f"JPEG + {100 * LED_SPREAD:g} % LED spread", LED_SPREAD))


def jpeg_round_trip(linear: NDArray) -> tuple[NDArray[np.uint8], NDArray[np.float32]]:
    """What an 8-bit JPEG camera keeps of a linear image (units of the white level).

    Returns the decoded 8-bit sRGB image (what a planner reads as the preview) and its
    linearised float32 copy (what photometric stereo fits). Values above white clip.
    """
    srgb8 = to_srgb8(np.asarray(linear, dtype=np.float64), 1)
    buf = np.frombuffer(encode_jpeg(srgb8, JPEG_QUALITY), dtype=np.uint8)
    flag = cv2.IMREAD_COLOR if srgb8.ndim == 3 else cv2.IMREAD_GRAYSCALE
    decoded = cv2.imdecode(buf, flag)
    if decoded.ndim == 3:
        decoded = np.ascontiguousarray(decoded[..., ::-1])  # BGR -> RGB
    return decoded, srgb_to_linear(decoded / 255.0).astype(np.float32)


def led_factors(count: int, spread: float, seed: int) -> NDArray[np.float64]:
    """Each light's fixed intensity factor: ``exp`` of a normal draw with SD ``spread``."""
    if spread == 0:
        return np.ones(count)
    return np.exp(np.random.default_rng(seed).normal(0.0, spread, count))


def scene_errors(
    scene: str, settings: TradeoffSettings, rng: np.random.Generator
) -> dict[tuple[str, int, str], list[float]]:
    """Normal error per (variant, N, strategy) over the paired draws of one scene."""
    data = render_scene_data(scene, settings)
    cand = data.candidate_dirs
    images = {}
    for label, spread in VARIANTS:
        factors = led_factors(len(cand), spread, settings.seed + SPREAD_SEED_OFFSET)
        shot = (
            data.candidate_images
            if spread == 0
            else render_scene_data(scene, settings, factors).candidate_images
        )
        images[label] = np.stack([jpeg_round_trip(im)[1] for im in shot])
    preview, _ = jpeg_round_trip(data.preview)
    light = settings.preview_light_az_el_deg
    err: dict[tuple[str, int, str], list[float]] = {}
    for n, keep, sub in paired_draws(cand, COUNTS, DRAWS, REMOVED, rng):
        chosen = {f"uniform {f:g}": keep[select_uniform_leds(sub, n, f)] for f in FLOORS}
        chosen["optimal"] = keep[planned_leds(preview, sub, n, light)]
        chosen["signal"] = keep[planned_leds(preview, sub, n, light, SIGNAL_NOISE_JPEG_DOME)]
        for variant, imgs in images.items():
            for label, idx in chosen.items():
                e = normal_error(data.normals, imgs[idx], cand[idx])[0]
                err.setdefault((variant, n, label), []).append(e)
    return err


def variant_rows(scene: str, variant: str, err: dict, seed: int) -> list[str]:
    """Three table rows for one scene and camera variant (floor tuned on this variant)."""
    mine = {(n, label): v for (var, n, label), v in err.items() if var == variant}
    floor = scene_floor(mine)

    def cells(bar: str, plan: str) -> str:
        return " | ".join(
            cell(np.array(mine[(n, bar)]), np.array(mine[(n, plan)]), seed) for n in COUNTS
        )

    head = f"| {scene} | {variant} | {floor:g}° |"
    bar = f"uniform {floor:g}"
    return [
        f"{head} tuned homogeneous → `optimal` | {cells(bar, 'optimal')} |",
        f"{head} tuned homogeneous → with `--signal-noise` | {cells(bar, 'signal')} |",
        f"{head} `optimal` → with `--signal-noise` | {cells('optimal', 'signal')} |",
    ]


def main(seed: int = 0) -> str:
    """Run every scene, print its rows as they come, and write the docs section."""
    t0 = time.perf_counter()
    settings = TradeoffSettings(held_out_lights=1, ground_truth_lights=50)
    rng = np.random.default_rng(seed)
    rows: list[str] = []
    for scene in settings.scenes:
        err = scene_errors(scene, settings, rng)
        scene_rows = [r for variant, _ in VARIANTS for r in variant_rows(scene, variant, err, seed)]
        rows.extend(scene_rows)
        print(f"{scene}: done ({time.perf_counter() - t0:.0f} s)")
        print("\n".join(scene_rows))
        sys.stdout.flush()
    md = "\n".join(
        [
            "Command: `python -m benchmarks.planner_sim_jpeg` "
            f"(total {time.perf_counter() - t0:.0f} s, seed {seed}).",
            "",
            f"The draws of `benchmarks.planner_sim_draws` ({DRAWS} per scene and N, {REMOVED} of "
            "the 240 candidate lights out of service), every image shot as an 8-bit sRGB JPEG "
            f"(quality {JPEG_QUALITY}) and linearised; in the second variant each light's "
            f"irradiance is also off by a fixed random factor ({100 * LED_SPREAD:g} % RMS, one "
            "draw for all scenes). "
            f"`--signal-noise {SIGNAL_NOISE_JPEG_DOME:g}` is the setting for the real JPEG dome. "
            "Cells: mean normal error (°) of the first strategy → of the second, and (draws "
            "the second won, verdict as in the tables above).",
            "",
            *table_head("scene", "camera", "tuned floor", "comparison"),
            *rows,
        ]
    )
    write_section("planner_sim_jpeg", md, DOC)
    return md


if __name__ == "__main__":
    from benchmarks.report import exit_on_help

    exit_on_help(__doc__)
    main()
