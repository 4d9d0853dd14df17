"""Which of a real dome's LEDs spoil a sparse acquisition: per-LED effect on random subsets.

For neuralrti-example (72 LEDs), draws ``DRAWS`` random subsets of N lights, fits plain
least-squares photometric stereo on each (sampled pixels) and scores it against robust
photometric stereo on all 72 lights. An LED's *effect* is the median error of subsets that
contain it minus the median of those that do not. Its *excess* is how much brighter its image
is than the all-light Lambertian fit predicts (median relative residual over the sampled pixels:
highlights and inter-reflections are positive). The planner's docs use this to explain why
near-equivalent layouts differ by degrees on this glossy object.

Run: ``python -m benchmarks.real_led_effects`` (reads ../shared/data/neuralrti-example; prints,
writes nothing).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from benchmarks.planner_real_data import DATA, load
from rti_rig.core.geometry import az_el_from_direction
from rti_rig.reconstruct import fit_photometric_stereo

DRAWS = 3000
PIXELS = 4000


def led_effects(data: Path = DATA, n: int = 12, seed: int = 0) -> list[tuple]:
    """(name, elevation, azimuth, effect in degrees, excess) per LED, worst effect last."""
    dome, images, _ = load(data)
    dirs = dome.directions
    ref_fit = fit_photometric_stereo(images, dirs, robust=True)
    ref = ref_fit.normals
    alb = np.asarray(ref_fit.albedo).reshape(ref.shape[:2])
    mask = ref_fit.valid & (alb > 0.1 * np.percentile(alb[ref_fit.valid], 99))
    rng = np.random.default_rng(seed)
    idx = rng.choice(np.flatnonzero(mask.ravel()), PIXELS, replace=False)
    obs = images.reshape(len(dirs), -1)[:, idx]
    r = ref.reshape(-1, 3)[idx]
    b_ref = r * alb.ravel()[idx, None]
    pred = np.clip(dirs @ b_ref.T, 0.0, None)
    excess = np.median((obs - pred) / np.maximum(pred, 1e-3), axis=1)

    def err(sel: np.ndarray) -> float:
        b = (np.linalg.pinv(dirs[sel]) @ obs[sel]).T
        nb = b / np.maximum(np.linalg.norm(b, axis=1, keepdims=True), 1e-12)
        return float(np.degrees(np.arccos(np.clip(np.sum(nb * r, axis=1), -1, 1))).mean())

    member = np.zeros((DRAWS, len(dirs)), dtype=bool)
    errors = np.empty(DRAWS)
    for i in range(DRAWS):
        sel = rng.choice(len(dirs), n, replace=False)
        member[i, sel] = True
        errors[i] = err(sel)
    az, el = az_el_from_direction(dirs)
    rows = []
    for k in range(len(dirs)):
        effect = float(np.median(errors[member[:, k]]) - np.median(errors[~member[:, k]]))
        rows.append((dome.names[k], float(el[k]), float(az[k]), effect, float(excess[k])))
    rows.sort(key=lambda t: t[3])
    return rows


def main() -> None:
    for n in (12, 18):
        rows = led_effects(n=n)
        eff = np.array([t[3] for t in rows])
        el = np.array([t[1] for t in rows])
        print(
            f"N = {n}: {DRAWS} random subsets; correlation of effect with elevation "
            f"{np.corrcoef(eff, el)[0, 1]:.2f}"
        )
        for name, e, a, effect, ex in rows[:5] + rows[-7:]:
            print(
                f"  {name:12s} el {e:4.0f}° az {a:4.0f}°  effect {effect:+.2f}°  "
                f"excess {100 * ex:+.0f} %"
            )


if __name__ == "__main__":
    from benchmarks.report import exit_on_help

    exit_on_help(__doc__, writes=False)
    main()
