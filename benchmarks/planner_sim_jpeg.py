"""Is ``--signal-noise`` the setting for JPEG cameras? The simulator's scenes shot as 8-bit JPEGs.

The one real dome we can test on (neuralrti-example) delivers 8-bit sRGB JPEGs from LEDs whose
intensities are not calibrated, and there the planner told that the noise grows with the signal
(``--signal-noise 0.05``) beats the tuned homogeneous layout at every N. The simulator's camera
is a 14-bit raw with exact LEDs, where the same option loses on three scenes. This benchmark
asks which of the two differences decides it, so the advice can follow the rig, not one object:

* **JPEG**: every image of ``benchmarks.planner_sim_draws``'s scenes (its candidates and its
  preview) goes through what an 8-bit camera does — the sRGB curve, rounding to 8 bits, JPEG
  compression at the simulator's quality — and is decoded and linearised again before it is
  planned on or fitted;
* **JPEG and LED spread**: the same, with each candidate light's intensity off by a random
  factor (log-normal, :data:`LED_SPREAD` RMS; fixed per light, as on a real dome).

The draw design, the strategies' planning and the scoring are ``benchmarks.planner_sim_draws``'s
(same seed, so the same out-of-service lights); plans depend on the preview only, so both camera
variants score the same plans. The homogeneous floor is tuned with hindsight per scene and
variant.

Run: ``python -m benchmarks.planner_sim_jpeg`` (writes its section of docs/planner.md).
"""

from __future__ import annotations

import sys
import time

import cv2
import numpy as np
from numpy.typing import NDArray

from benchmarks.planner_real_data import DOC, planned_leds, srgb_to_linear
from benchmarks.planner_sim_draws import COUNTS, DRAWS, FLOORS, REMOVED, _cell, _table_head
from benchmarks.report import write_section
from planner.objectives import SIGNAL_NOISE_JPEG_DOME
from planner.uniform import select_uniform_leds
from rti_rig.bench_tradeoff import TradeoffSettings, normal_error, render_scene_data
from rti_rig.rig_geometry import DomeGeometry
from simulator.camera_model import encode_jpeg, to_srgb8

#: RMS of the candidate lights' intensity errors (log-normal) in the "LED spread" variant: the
#: size of the spread ``SIGNAL_NOISE_JPEG_DOME`` stands for.
LED_SPREAD = 0.05
#: Variants: (label, LED spread).
VARIANTS = (("JPEG", 0.0), (f"JPEG + {100 * LED_SPREAD:g} % LED spread", LED_SPREAD))


def jpeg_round_trip(linear: NDArray, gain: float = 1.0) -> tuple[NDArray[np.uint8], NDArray]:
    """What an 8-bit JPEG camera keeps of a linear image (units of the white level).

    Returns the decoded 8-bit sRGB image (what a planner reads as the preview) and its
    linearised float32 copy (what photometric stereo fits): ``gain`` scales the light first,
    values above white clip, as they would in the camera.
    """
    srgb8 = to_srgb8(np.asarray(linear, dtype=np.float64) * gain, 1)
    buf = np.frombuffer(encode_jpeg(srgb8), dtype=np.uint8)
    flag = cv2.IMREAD_COLOR if srgb8.ndim == 3 else cv2.IMREAD_GRAYSCALE
    decoded = cv2.imdecode(buf, flag)
    if decoded.ndim == 3:
        decoded = np.ascontiguousarray(decoded[..., ::-1])  # BGR -> RGB
    return decoded, srgb_to_linear(decoded / 255.0).astype(np.float32)


def scene_errors(scene: str, settings: TradeoffSettings, rng: np.random.Generator):
    """Normal error per (variant, N, strategy) over the paired draws of one scene."""
    data = render_scene_data(scene, settings)
    cand = data.candidate_dirs
    spread = np.random.default_rng(settings.seed + 7).normal(0.0, 1.0, len(cand))
    images = {
        label: np.stack(
            [
                jpeg_round_trip(im, float(np.exp(s * z)))[1]
                for im, z in zip(data.candidate_images, spread, strict=True)
            ]
        )
        for label, s in VARIANTS
    }
    preview, _ = jpeg_round_trip(data.preview)
    light = settings.preview_light_az_el_deg
    err: dict[tuple[str, int, str], list[float]] = {}
    for n in COUNTS:
        for _ in range(DRAWS):
            keep = np.sort(rng.choice(len(cand), len(cand) - REMOVED, replace=False))
            sub = DomeGeometry(cand[keep], tuple(f"c{i:03d}" for i in keep))
            chosen = {f"uniform {f:g}": keep[select_uniform_leds(sub, n, f)] for f in FLOORS}
            chosen["optimal"] = keep[planned_leds(preview, sub, n, light)]
            chosen["signal"] = keep[planned_leds(preview, sub, n, light, SIGNAL_NOISE_JPEG_DOME)]
            for variant, imgs in images.items():
                for label, idx in chosen.items():
                    e = normal_error(data.normals, imgs[idx], cand[idx])[0]
                    err.setdefault((variant, n, label), []).append(e)
    return err


def main(seed: int = 0) -> str:
    t0 = time.perf_counter()
    settings = TradeoffSettings(held_out_lights=1, ground_truth_lights=50)
    rng = np.random.default_rng(seed)
    rows: list[str] = []
    for scene in settings.scenes:
        err = scene_errors(scene, settings, rng)
        for variant, _ in VARIANTS:

            def mean_over(f: float, variant: str = variant, err=err) -> float:
                return float(
                    np.mean([np.mean(err[(variant, n, f"uniform {f:g}")]) for n in COUNTS])
                )

            floor = min(FLOORS, key=mean_over)

            def cells(bar: str, plan: str, variant: str = variant, err=err) -> str:
                return " | ".join(
                    _cell(np.array(err[(variant, n, bar)]), np.array(err[(variant, n, plan)]), seed)
                    for n in COUNTS
                )

            head = f"| {scene} | {variant} | {floor:g}° |"
            rows.append(
                f"{head} tuned homogeneous → `optimal` | {cells(f'uniform {floor:g}', 'optimal')} |"
            )
            rows.append(
                f"{head} tuned homogeneous → with `--signal-noise` | "
                f"{cells(f'uniform {floor:g}', 'signal')} |"
            )
            rows.append(
                f"{head} `optimal` → with `--signal-noise` | {cells('optimal', 'signal')} |"
            )
        print(f"{scene}: done ({time.perf_counter() - t0:.0f} s)")
        print("\n".join(rows[-3 * len(VARIANTS) :]))
        sys.stdout.flush()
    md = "\n".join(
        [
            "Command: `python -m benchmarks.planner_sim_jpeg` "
            f"(total {time.perf_counter() - t0:.0f} s, seed {seed}).",
            "",
            f"The draws of `benchmarks.planner_sim_draws` ({DRAWS} per scene and N, {REMOVED} of "
            "the 240 candidate lights out of service), every image shot as an 8-bit sRGB JPEG "
            f"(the simulator's quality) and linearised; in the second variant each light's "
            f"intensity is also off by a fixed random factor ({100 * LED_SPREAD:g} % RMS). "
            f"`--signal-noise {SIGNAL_NOISE_JPEG_DOME:g}` is the setting for the real JPEG dome. "
            "Cells: mean normal error (°) of the first strategy → of the second, and (draws "
            "the second won, verdict as in the tables above).",
            "",
            *_table_head("scene", "camera", "tuned floor", "comparison"),
            *rows,
        ]
    )
    write_section("planner_sim_jpeg", md, DOC)
    return md


if __name__ == "__main__":
    main()
