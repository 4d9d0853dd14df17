"""The slip check's statistics over clean runs and real slips: the margins its rules have.

Frames come from the shipped ``rig_configs/emulated_cceh_rti.toml`` (every object scene,
scene seeds ``0..--seeds``) through the product's own path (:func:`benchmarks.flash_sync_slips.
run_once`), with the guard's judgement set aside so that every image is kept; each image is
then checked against the images before it, labelled with their true LEDs. Printed per
statistic: percentiles 0, 1, 5, 50 and the worst (scene, seed, image). A slip is named when
the statistic is at most ``SLIP_RATIO`` (0.5):

* ``missed, model`` — residual under the previous LED / under its own, from the fit of all
  images before (the old rule; the previous LED lit the last image of that fit);
* ``missed, fair`` — the rule now: the larger of that ratio from a fit without the last image
  and the image's pixel residual against the last image / its own LED's residual;
* ``double`` — residual under the next LED / under its own;
* slips: a ``double_step`` fault (the ``double`` statistic at its image) and the LED of the
  image before lit again (the firmware's run-out; in the simulator that exposure is the
  image before, bit for bit) under ``missed, fair``;
* ``power cycle before image 4`` — image 2 or 3 against image 1 (pixel residual up to a
  gain) in clean runs and with the power cycled there (lit by LED 0 again).

Run: ``python -m benchmarks.flash_sync_statistics [--seeds 12]`` (a few minutes).
"""

from __future__ import annotations

import contextlib
import sys
import tempfile
from collections.abc import Iterator
from pathlib import Path

import numpy as np

import benchmarks.flash_sync_slips as slips
import rti_rig.app.flash_sync as fs
from rti_rig.app.config import load_rig_config, rig_geometry
from rti_rig.reconstruct.sequence_check import SequenceChecker, pixel_residual, reduce_image
from rti_rig.simulator.scenes import SCENE_NAMES

DIRS = rig_geometry(load_rig_config(slips.CONFIG)).directions
#: The objects measured: every library scene but the calibration sphere (a target for
#: ``lights-from-sphere``), as docs/domes.md's figures were recorded before the sphere was
#: added (7 scenes × 12 seeds × 56 images = 4704 clean images).
SCENES = ("relief", *(name for name in SCENE_NAMES if name != "sphere"))


@contextlib.contextmanager
def _unjudged(seed: int, got: list[np.ndarray]) -> Iterator[None]:
    """The run keeps every frame (reduced) and judges none; the scene's seed is ``seed``."""
    call, end, load = fs.SlipGuard.__call__, fs.SlipGuard.end_of_run, slips.load_rig_config

    def keep(self, index, frame, actual, root):  # type: ignore[no-untyped-def]
        got.append(reduce_image(frame.pixels, frame.white_level))

    def seeded(path):  # type: ignore[no-untyped-def]
        loaded = load(path)
        c = loaded.config
        scene = c.scene.model_copy(update={"seed": seed})
        return loaded.model_copy(update={"config": c.model_copy(update={"scene": scene})})

    fs.SlipGuard.__call__, fs.SlipGuard.end_of_run = keep, lambda *_a: []  # type: ignore[method-assign]
    slips.load_rig_config = seeded
    try:
        yield
    finally:
        fs.SlipGuard.__call__, fs.SlipGuard.end_of_run = call, end  # type: ignore[method-assign]
        slips.load_rig_config = load


def frames(scene: str, seed: int, fault: tuple[int, str] | None = None) -> list[np.ndarray]:
    got: list[np.ndarray] = []
    with _unjudged(seed, got), tempfile.TemporaryDirectory() as tmp:
        slips.run_once(scene, fault, Path(tmp) / "s")
    return got


def _checker(images: list[np.ndarray]) -> SequenceChecker:
    c = SequenceChecker(DIRS)
    for i, img in enumerate(images):
        c._images.append(img)
        c._lights.append(DIRS[i])
        c._peaks.append(1.0)
    return c


def _fair(c: SequenceChecker, i: int, img: np.ndarray) -> float:
    r = c._previous_judged_fairly(i, img)
    if r is None:
        return float("inf")
    return max(r[i - 1], pixel_residual(img, c._images[-1])) / r[i]


def main(argv: list[str]) -> None:
    seeds = int(argv[argv.index("--seeds") + 1]) if "--seeds" in argv else 12
    stats: dict[str, list[tuple[float, str]]] = {}

    def add(name: str, value: float, where: str) -> None:
        stats.setdefault(name, []).append((value, where))

    for scene in SCENES:
        for seed in range(seeds):
            imgs = frames(scene, seed)
            for k in (1, 2):
                add(f"clean image {k + 1} vs image 1", pixel_residual(imgs[k], imgs[0]), scene)
            for i in range(4, 60):
                c = _checker(imgs[:i])
                r = c._residuals(imgs[i], [i - 1, i, i + 1] if i < 59 else [i - 1, i])
                where = f"{scene} seed {seed} image {i + 1}"
                if r is None:
                    continue
                add("clean: missed, model (old)", r[i - 1] / r[i], where)
                add("clean: missed, fair (now)", _fair(c, i, imgs[i]), where)
                if i + 1 in r:
                    add("clean: double", r[i + 1] / r[i], where)
                if i % 6 == 0:  # the LED of the image before lit again
                    add("slip: LED before lit again, fair", _fair(c, i, imgs[i - 1]), where)
            if seed % 4 == 0:
                for p in (9, 33):
                    d = frames(scene, seed, (p, "double_step"))
                    c = _checker(d[: p - 1])
                    r = c._residuals(d[p - 1], [p - 1, p])
                    if r is not None:
                        add(
                            "slip: double_step, double",
                            r[p] / r[p - 1],
                            f"{scene} seed {seed} at {p}",
                        )
                for p in (2, 3):
                    d = frames(scene, seed, (p, "power_cycle"))
                    add(
                        f"power cycle at image {p}: vs image 1",
                        pixel_residual(d[p - 1], d[0]),
                        scene,
                    )
            print(f"{scene} seed {seed} done", file=sys.stderr, flush=True)
    print("statistic: percentiles 0 1 5 50 100 (n) | lowest at; highest at")
    for name, values in stats.items():
        v = np.array([x for x, _ in values])
        lo, hi = min(values), max(values)
        q = " ".join(f"{x:.3f}" for x in np.percentile(v, [0, 1, 5, 50, 100]))
        print(f"{name}: {q} (n={len(v)}) | {lo[1]}; {hi[1]}")


if __name__ == "__main__":
    from benchmarks.report import exit_on_help

    exit_on_help(__doc__, writes=False)
    main(sys.argv[1:])
