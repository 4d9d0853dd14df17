"""`benchmarks.adaptive` scores every layout's relighting on the same held-out lights.

Scoring each layout on the lights *it* did not take compares layouts on different lights (one
that took the grazing lights is judged on the easier high ones), so the tables' relighting
verdicts compared unlike things. Now, per draw and N, the held-out set is the candidates none of
the compared layouts took.
"""

from __future__ import annotations

import numpy as np
import pytest

import benchmarks.adaptive as bench


def test_the_held_out_set_is_what_no_layout_took() -> None:
    held = bench.common_held_out(10, {"a": np.array([0, 1, 2]), "b": np.array([2, 3, 9])})
    np.testing.assert_array_equal(held, [4, 5, 6, 7, 8])
    with pytest.raises(ValueError, match="every candidate"):
        bench.common_held_out(4, {"a": np.array([0, 1]), "b": np.array([2, 3])})


def test_every_layout_of_a_draw_is_scored_on_the_same_lights(monkeypatch) -> None:
    fitted: list[np.ndarray] = []
    scored: list[np.ndarray] = []
    written: list[np.ndarray] = []
    relight_model, relight_psnr = bench.relight_model, bench.relight_psnr
    written_rti_psnr = bench.written_rti_psnr

    def model_spy(images, lights, model):  # type: ignore[no-untyped-def]
        fitted.append(np.asarray(lights))
        return relight_model(images, lights, model)

    def psnr_spy(model, images, lights, *args):  # type: ignore[no-untyped-def]
        scored.append(np.asarray(lights))
        return relight_psnr(model, images, lights, *args)

    def written_spy(images, lights, held_images, held_lights, *args, **kwargs):  # type: ignore[no-untyped-def]
        written.append(np.asarray(held_lights))
        # the order is chosen on the colour images of the same layout, as the fit chooses it
        assert kwargs["chosen_on"].shape[:1] == images.shape[:1]
        assert kwargs["chosen_on"].shape[-1] == 3
        return written_rti_psnr(images, lights, held_images, held_lights, *args, **kwargs)

    monkeypatch.setattr(bench, "_CACHE", {})  # plan afresh, and leave no entry behind
    monkeypatch.setattr(bench, "NS", (6,))
    monkeypatch.setattr(bench, "relight_model", model_spy)
    monkeypatch.setattr(bench, "relight_psnr", psnr_spy)
    monkeypatch.setattr(bench, "written_rti_psnr", written_spy)
    out, _ = bench.sim(1, scenes=("painting",))
    layouts = len(bench.FLOORS) + 3  # the floors, optimal, adaptive (normals and relight)
    assert len(scored) == len(fitted) == layouts
    for lights in scored[1:]:
        np.testing.assert_array_equal(lights, scored[0])
    held = {tuple(np.round(v, 9)) for v in scored[0]}
    for lights in fitted:  # no layout was scored on a light it was fitted on
        assert not held & {tuple(np.round(v, 9)) for v in lights}
    assert out["painting"]["held_out"] == [len(scored[0])]
    # the written file's table is scored on the same lights, one score per layout
    assert len(written) == layouts
    for lights in written:
        np.testing.assert_array_equal(lights, scored[0])
    assert {k: len(v) for k, v in out["painting"]["file_psnr"].items()} == {
        k: 1 for k in out["painting"]["psnr"]
    }
    assert set(out["painting"]["file_basis"][(6, "optimal")]) == {"hsh1"}
