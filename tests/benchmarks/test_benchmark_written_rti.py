"""`written_rti_psnr` scores the fit.rti `rti-rig fit` writes, not the richest basis.

Why: the benchmarks' relighting tables had scored the richest basis N lights determine (PTM at
9–12 lights), while `rti-rig fit` writes fit.rti in the HSH order its held-out evidence
chooses (order 1 at 6–11 lights). A user relights the file; the tables now score it too.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from benchmarks.metrics import relight_psnr
from benchmarks.planner_real_data import relight_model, written_rti_order, written_rti_psnr
from rti_rig.app.usecases.fit import FitRequest, run_fit
from rti_rig.core.geometry import direction_from_az_el
from rti_rig.core.image_files import read_image_any
from rti_rig.core.lp_format import read_lp


def _lambert(lights: np.ndarray, size: int = 24) -> np.ndarray:
    """A matte bump lit by ``lights``: (k, size, size) images in [0, 1]."""
    y, x = np.mgrid[-1 : 1 : size * 1j, -1 : 1 : size * 1j]
    h = 0.4 * np.exp(-(x**2 + y**2) * 3)
    gy, gx = np.gradient(h, 2 / size)
    n = np.stack([-gx, -gy, np.ones_like(h)], axis=-1)
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    return np.clip(np.einsum("hwc,kc->khw", n, lights), 0.0, None) * 0.8


def _ring(count: int, el: float) -> np.ndarray:
    az = np.linspace(0.0, 360.0, count, endpoint=False) + 7.0 * el
    return np.array([direction_from_az_el(a, el) for a in az])


def test_the_written_order_is_scored_on_the_held_out_lights() -> None:
    shot = np.concatenate([_ring(5, 30.0), _ring(4, 60.0)])  # 9 lights: PTM is the richest
    held = _ring(12, 45.0)
    basis, psnr = written_rti_psnr(_lambert(shot), shot, _lambert(held), held)
    assert basis == "hsh1"  # 5 folds of 9 lights leave 7 to fit: order 2 cannot be judged
    expected = relight_psnr(relight_model(_lambert(shot), shot, "hsh1"), _lambert(held), held)
    assert psnr == expected
    ptm = relight_psnr(relight_model(_lambert(shot), shot, "ptm"), _lambert(held), held)
    assert psnr != ptm  # a different file from the one the tables scored before


def test_too_few_lights_write_no_file() -> None:
    shot = _ring(4, 40.0)
    held = _ring(8, 50.0)
    assert written_rti_psnr(_lambert(shot), shot, _lambert(held), held)[0] == ""
    assert np.isnan(written_rti_psnr(_lambert(shot), shot, _lambert(held), held)[1])


@pytest.mark.parametrize(("scene", "step"), [("coin", 1), ("tablet", 1), ("tablet", 2)])
def test_the_order_is_the_one_rti_rig_fit_writes(tmp_path: Path, scene: str, step: int) -> None:
    """Through the front door: a simulated session (16-bit TIFFs, 36 or 18 lights) fitted by
    the fit use case; its fit.json names the order the benchmark's choice must repeat (here
    orders 1, 2 and 1: a rule that always said order 1 would fail on the tablet's 36 lights).
    The coin's highlights clip: its order is chosen with the clipped observations kept (the
    model choice alone, which leaves those pixels out, says order 3; order 1 relights other
    lights of the same simulated coin best, 27.4 dB against 26.6 for order 3)."""
    from fit_sessions import dome_lights, make_session

    lights = dome_lights()[::step]
    session, _, _ = make_session(tmp_path / "s", scene=scene, lights=lights, size=(80, 96))
    run_fit(FitRequest(session, tmp_path / "f", qa=False, write_normals=False, write_ptm=False))
    written = json.loads((tmp_path / "f" / "fit.json").read_text(encoding="utf-8"))["rti"]
    entries = read_lp(session / "lights.lp")
    stack = np.stack(
        [read_image_any(session / "linear" / f"{Path(e.name).stem}.tif") for e in entries]
    )
    dirs = np.array([e.direction for e in entries])
    order = written_rti_order(stack.astype(np.float32) / 65535.0, dirs)
    assert written.startswith(f"hsh{order}:"), written
    # the coin's highlights clip: judged with them kept, order 1 on this seed by a small margin
    assert order in {("coin", 1): {1, 2}, ("tablet", 1): {2}, ("tablet", 2): {1}}[(scene, step)]
