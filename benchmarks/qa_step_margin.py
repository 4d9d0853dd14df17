"""The shifts the QA's step search places between the two sides of a session, still and moved.

Why: a move part-way through is claimed when the two sides' median edge images lie more than
``STEP_PX`` (1 px) apart (:func:`rti_rig.reconstruct.qa_drift.step_candidates`). The sides
were placed by OpenCV's 5 x 5 signed centroid, which on the virtual arm's 256 px industrial
part (48 lights, the arm's move-time order, moved (1, 2) px from image 25) lay more than a
pixel off a clear (1, 2) peak and was refused, and which on still sessions read up to about
1.3 px. The alternative measured here places the same peak by its upsampled maximum
(:func:`upsampled_peak_shift`). Not adopted: used where the centroid is refused it found
the industrial part's move, but it also added a step on the emulated Nab dome's still
brushed-steel part (tests/cli/test_qa_still_step_by_elevation.py, seed 2, uneven LEDs), and
used everywhere it also broke two glossy-coin moves (test_qa_move_start_glossy.py).
What was adopted instead (rti_rig.reconstruct.qa_drift.lit_alike): the sides are compared on
their images lit alike, since in the arm's order they are lit from opposite halves of the
hemisphere; the two columns now place that pair's peak.
This script shoots simulated sessions through the CLI in their default order (every one
still, and some copies moved part-way through), runs ``fit`` on each and prints, per
session, the largest sides' shift each estimator places over every split the search judged
(old: the centroid the QA uses; new: the upsampled peak on the same pair), the steps the
search yields, and whether the QA names any image "moved". Still rows: every shift is a
false one. Moved rows: the step found.

Run: ``python -m benchmarks.qa_step_margin [--quick] [--seed N] [--keep DIR]`` (about 12 min
for the full list on 2 cores; ``--quick`` shoots 4 still and 2 moved sessions; ``--seed``: the
scene's seed, 0 as shipped). It prints only.
"""

from __future__ import annotations

import argparse
import json
import shutil
import tempfile
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from rti_rig.reconstruct.synthetic import moved_session_copy

REPO = Path(__file__).resolve().parents[1]
#: (rig, scene, side px, lights)
STILL = [
    ("arm", "industrial", 256, 12),
    ("arm", "industrial", 256, 24),
    ("arm", "industrial", 256, 48),
    ("arm", "industrial", 512, 24),
    ("arm", "coin", 256, 24),
    ("arm", "coin", 512, 24),
    ("arm", "painting", 256, 48),
    ("arm", "relief", 256, 24),
    ("arm", "tablet", 256, 12),
    ("arm", "tablet", 256, 24),
    ("dome", "industrial", 256, 12),
    ("dome", "industrial", 256, 24),
    ("dome", "industrial", 512, 12),
    ("dome", "painting", 256, 48),
    ("dome", "painting", 512, 12),
    ("dome", "relief", 256, 24),
    ("dome", "tablet", 256, 48),
    ("arm", "tilted", 256, 24),
    ("arm", "flat", 256, 24),
    ("dome", "coin", 256, 24),
    ("dome", "tilted", 256, 24),
]
#: (rig, scene, side px, lights, first moved image (1-based), dx, dy): x right, y down
MOVED = [
    ("arm", "industrial", 256, 48, 25, 1, 2),
    ("arm", "industrial", 256, 24, 12, 1, 2),
    ("arm", "coin", 512, 24, 13, 2, 0),
    ("arm", "tablet", 256, 24, 12, 2, 2),
    ("dome", "painting", 512, 12, 7, 1, 2),
    ("dome", "industrial", 512, 12, 5, 2, 0),
    # the smaller and the earlier moves of the arm-order industrial part (lit_alike)
    ("arm", "industrial", 256, 48, 25, 1, 1),
    ("arm", "industrial", 256, 48, 25, 1, 0),
    ("arm", "industrial", 256, 48, 13, 1, 2),
]
#: The alternative's grid: 1 / this of a pixel.
UPSAMPLE = 20
QUICK_STILL = [STILL[2], STILL[1], STILL[11], STILL[13]]
QUICK_MOVED = MOVED[:2]


def upsampled_peak_shift(
    ref: NDArray[np.float64], img: NDArray[np.float64], window: NDArray[np.float64]
) -> tuple[tuple[float, float], float]:
    """The alternative measured: ``(dx, dy)`` of the same whole-pixel peak as the
    centroid's, placed by the phase correlation's own maximum on a 1 / UPSAMPLE px grid
    within a pixel of it (a matrix-product inverse DFT), not by the 5 x 5 centroid."""
    import rti_rig.reconstruct.qa_drift as qd

    corr = qd._correlation(qd._spectrum(ref, window), img, window)
    peak, total = qd.whole_pixel_peak(corr)
    if peak is None:
        return (float("nan"), float("nan")), total
    y, x = peak
    h, w = corr.shape
    cy, cx = h // 2, w // 2
    cross = np.conj(np.fft.fft2(ref * window)) * np.fft.fft2(img * window)
    cross /= np.maximum(np.abs(cross), 1e-30)
    steps = np.arange(-UPSAMPLE, UPSAMPLE + 1) / UPSAMPLE
    oy, ox = (y - cy) + steps, (x - cx) + steps
    rows = np.exp(2j * np.pi * np.outer(oy, np.fft.fftfreq(h)))
    cols = np.exp(2j * np.pi * np.outer(np.fft.fftfreq(w), ox))
    fine = (rows @ cross @ cols).real
    jy, jx = np.unravel_index(int(np.argmax(fine)), fine.shape)
    return (float(ox[jx]), float(oy[jy])), total


def _config(root: Path, rig: str, scene: str, side: int, seed: int = 0) -> Path:
    shipped = "virtual_arm.toml" if rig == "arm" else "simulated_dome.toml"
    text = (REPO / "rig_configs" / shipped).read_text(encoding="utf-8")
    text = text.replace("width = 512\nheight = 512", f"width = {side}\nheight = {side}")
    text = text.replace('name = "relief"', f'name = "{scene}"')
    assert "\nseed = 0\n" in text, shipped
    text = text.replace("\nseed = 0\n", f"\nseed = {seed}\n")
    path = root / f"{rig}.toml"
    path.write_text(text, encoding="utf-8")
    return path


def _row(session: Path, out: Path) -> tuple[float, float, list[str], bool]:
    """Largest old and new sides' shift, the steps yielded, "moved" in the verdict."""
    from typer.testing import CliRunner

    import rti_rig.reconstruct.qa as qa
    import rti_rig.reconstruct.qa_drift as qd
    from rti_rig.cli import app

    placed: dict[str, list[float]] = {"old": [], "new": []}
    steps: list[str] = []
    old, candidates = qd.local_phase_correlation, qa.step_candidates

    def spy(ref, img, window):  # type: ignore[no-untyped-def]
        (ox, oy), _ = upsampled_peak_shift(ref, img, window)
        if np.isfinite(ox):
            placed["new"].append(float(np.hypot(ox, oy)))
        got = old(ref, img, window)
        if np.isfinite(got[0][0]):
            placed["old"].append(float(np.hypot(*got[0])))
        return got

    def spy_steps(*a, **k):  # type: ignore[no-untyped-def]
        for s in candidates(*a, **k):
            steps.append(f"{s.first + 1}:({s.shift[0]:+.2f},{s.shift[1]:+.2f})")
            yield s

    qd.local_phase_correlation, qa.step_candidates = spy, spy_steps
    try:
        args = ["fit", str(session), "--out", str(out), "--no-ptm", "--no-hsh"]
        r = CliRunner().invoke(app, args)
    finally:
        qd.local_phase_correlation, qa.step_candidates = old, candidates
    if r.exit_code != 0:
        raise SystemExit(f"fit {session} failed: {r.output[-500:]}")
    images = json.loads((out / "qa.json").read_text())["images"]
    said = any("moved" in p for c in images for p in c["problems"])
    return max(placed["old"], default=0.0), max(placed["new"], default=0.0), steps, said


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="4 still and 2 moved sessions")
    ap.add_argument("--keep", type=Path, help="shoot into this folder and keep it")
    ap.add_argument("--seed", type=int, default=0, help="the scenes' seed (0 as shipped)")
    args = ap.parse_args()
    from typer.testing import CliRunner

    from rti_rig.cli import app

    still, moved = (QUICK_STILL, QUICK_MOVED) if args.quick else (STILL, MOVED)
    base = args.keep or Path(tempfile.mkdtemp(prefix="qa_step_margin_"))
    print(f"{'session':40s} {'old max':>8s} {'new max':>8s}  QA says  steps")
    worst_still, least_moved = 0.0, np.inf
    try:
        shot: dict[tuple, Path] = {}
        for case in [*still, *((m[:4]) for m in moved)]:
            if case in shot:
                continue
            root = base / "_".join(map(str, case))
            root.mkdir(parents=True, exist_ok=True)
            config = _config(root, *case[:3], seed=args.seed)
            r = CliRunner().invoke(
                app,
                [
                    "run",
                    str(config),
                    "--out",
                    str(root / "s"),
                    "--lights",
                    str(case[3]),
                    "--no-verdict",
                ],
            )
            if r.exit_code != 0:
                raise SystemExit(f"run {case} failed: {r.output[-500:]}")
            shot[case] = root / "s"
        for case in still:
            old, new, steps, said = _row(shot[case], shot[case].parent / "fit")
            worst_still = max(worst_still, new) if not steps else worst_still
            name = "still " + " ".join(map(str, case))
            print(f"{name:40s} {old:8.2f} {new:8.2f}  {'MOVED' if said else 'still':7s}  {steps}")
        for m in moved:
            session = moved_session_copy(shot[m[:4]], shot[m[:4]].parent / f"moved_{m[4]}", *m[4:])
            old, new, steps, said = _row(session, session.parent / f"fit_moved_{m[4]}")
            name = "moved " + " ".join(map(str, m))
            print(f"{name:40s} {old:8.2f} {new:8.2f}  {'MOVED' if said else 'still':7s}  {steps}")
            if steps:
                least_moved = min(
                    least_moved,
                    float(np.hypot(*map(float, steps[0][steps[0].index("(") + 1 : -1].split(",")))),
                )
    finally:
        if args.keep is None:
            shutil.rmtree(base, ignore_errors=True)
    print(f"largest new sides' shift on a still session with no step yielded: {worst_still:.2f} px")
    print(f"smallest first step found on a moved session: {least_moved:.2f} px (STEP_PX 1.0)")


if __name__ == "__main__":
    main()
