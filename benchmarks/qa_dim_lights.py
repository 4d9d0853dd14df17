"""How well the QA names a dim LED on a real acquisition, and whether it accuses good images.

Why: a misfiring or ageing LED is a common real fault, and on a glossy object the Lambertian
prediction the QA compares each image with is off by a different factor light by light, so a
fixed limit on image / prediction cannot see a 1-stop dim light there. The QA also compares
each image with its nearest lights' (``NEIGHBOUR_DIM_RATIO`` in
:mod:`rti_rig.reconstruct.qa`). This script runs the QA on an acquisition as it is (every
image flagged dim there is a false alarm), then with each of ``--count`` random images scaled
by ``--factor`` in turn, and prints per case the bright-end gain, the ratio to the nearest
lights and whether the image was named (dim, or a wrong light).

Run: ``python -m benchmarks.qa_dim_lights --data ../shared/data/neuralrti-example
[--step 1] [--count 12] [--factor 0.5] [--seed 0]`` (``--step 2`` uses every second light;
about 10 min for 12 cases of the 72-light acquisition on 2 cores). It prints only.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from rti_rig.app.usecases.fit import load_acquisition
from rti_rig.reconstruct.qa import assess


def _named(problems: tuple[str, ...]) -> str:
    if any("dim" in p or "misfired" in p for p in problems):
        return "dim"
    if any("wrong light" in p for p in problems):
        return "wrong light"
    return ""


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--data", type=Path, required=True, help="acquisition folder (with its .lp)")
    ap.add_argument("--step", type=int, default=1, help="use every STEP-th light")
    ap.add_argument("--count", type=int, default=12, help="images dimmed, one at a time")
    ap.add_argument("--factor", type=float, default=0.5, help="the dim image's brightness")
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    lp = args.data if args.data.suffix == ".lp" else next(iter(sorted(args.data.glob("*.lp"))))
    frames, lights, names, _ = load_acquisition(lp, [])
    sel = np.arange(0, len(frames), args.step)
    frames = [np.asarray(frames[i][0 : frames[i].shape[0]]) for i in sel]
    lights, names = lights[sel], [names[i] for i in sel]
    n = len(frames)
    clean = assess(frames, lights, names)
    alarms = [c.name for c in clean.images if _named(c.problems)]
    ratio = np.array([c.neighbour_gain_ratio for c in clean.images])
    judged = np.isfinite(ratio)
    low = f"{np.min(ratio[judged]):.3f}" if judged.any() else "-"
    print(f"{lp} every {args.step}: {n} lights; as recorded: named dim or wrong {alarms or 'none'}")
    print(f"  ratio to the nearest lights judged on {int(judged.sum())}/{n}, lowest {low}")
    rng = np.random.default_rng(args.seed)
    named = 0
    for i in rng.choice(n, min(args.count, n), replace=False):
        dimmed = list(frames)
        dimmed[i] = (frames[i].astype(np.float64) * args.factor).astype(frames[i].dtype)
        c = assess(dimmed, lights, names).images[i]
        what = _named(c.problems)
        named += bool(what)
        print(
            f"  {names[i]} x{args.factor:g}: bright-end gain {c.bright_end_gain:.2f}, "
            f"ratio {c.neighbour_gain_ratio:.2f}: {what or 'missed'}"
        )
    print(f"  named {named} of {min(args.count, n)}")


if __name__ == "__main__":
    main()
