"""`benchmarks.fit_rti_order_saturation` on the repository's small real acquisition."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from benchmarks import fit_rti_order_saturation as bench

ACQ = Path(__file__).resolve().parents[1] / "data" / "neuralrti_replay" / "dirs.lp"


def test_each_layout_gets_both_orders_and_their_cost() -> None:
    rows, lost = bench.rows(bench.real_layouts(ACQ, (9, 12), (0.0, 20.0)))
    assert len(rows) == len(lost) == 4
    for row in rows:
        cells = [c.strip() for c in row.strip("|").split("|")]
        assert cells[0] in {"9", "12"} and cells[1] in {"0°", "20°"}
        assert cells[3].startswith("1 (") and cells[4].startswith("1 (")  # 9–12 lights: order 1
        assert len(cells[5].split(" / ")) == 3
    # the cost is measured against the best order on the held-out lights: never negative
    assert np.all(np.array(lost) >= 0.0)


def test_the_two_columns_differ_only_by_the_rule(monkeypatch) -> None:  # type: ignore[no-untyped-def]
    """With the rule the choice sees the fit's saturation level (1.0: the top code), without it
    none, on the same pixel sample the fit uses; clipped pixels then change the evidence."""
    seen = []
    select_model = bench.select_model

    def spy(stack, lights, **kwargs):  # type: ignore[no-untyped-def]
        seen.append((stack.saturation_level, kwargs.get("max_pixels")))
        return select_model(stack, lights, **kwargs)

    monkeypatch.setattr(bench, "select_model", spy)
    rng = np.random.default_rng(0)
    dirs = rng.normal(size=(12, 3))
    dirs[:, 2] = np.abs(dirs[:, 2]) + 0.5
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    colour = rng.uniform(0.1, 0.6, size=(12, 8, 8, 3)).astype(np.float32)
    colour[0, :, :4] = 1.0  # half the image clipped under one light
    bench.chosen_order(colour, dirs, True)
    bench.chosen_order(colour, dirs, False)
    assert seen == [(1.0, bench.SAMPLE_PIXELS), (None, bench.SAMPLE_PIXELS)]
