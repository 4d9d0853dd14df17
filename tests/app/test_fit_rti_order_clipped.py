"""fit.rti's HSH order is chosen with the clipped observations kept where the model choice left
saturated pixels out (`rti_rig.app.usecases.fit.rti_order`).

Why: the model choice drops every pixel saturated in any image; on a glossy object that is much
of it, and on the matte rest the orders look alike. On the shared real acquisition the order so
chosen relit held-out lights 1.75 dB below the best order in hindsight on average, with the
clipped observations kept 0.99 dB (`benchmarks.fit_rti_order_saturation`, docs/reconstruction.md).
"""

from __future__ import annotations

import json
import re
from pathlib import Path

from fit_sessions import dome_lights, make_session

from rti_rig.app.usecases.fit import FitRequest, run_fit


def _rti_line(tmp_path: Path, scene: str, **kwargs) -> str:  # type: ignore[no-untyped-def]
    session, _, _ = make_session(tmp_path / scene, scene=scene, size=(80, 96), lights=dome_lights())
    out = tmp_path / f"{scene}_fit"
    run_fit(FitRequest(session, out, qa=False, write_normals=False, write_ptm=False, **kwargs))
    return json.loads((out / "fit.json").read_text(encoding="utf-8"))["rti"]


def test_a_glossy_session_s_order_is_chosen_with_its_clipped_values(tmp_path: Path) -> None:
    line = _rti_line(tmp_path, "coin")
    # the model choice alone (its clipped pixels left out) chose hsh3, which fit.rti had been
    # written in; judged with them kept a lower order is within 5 % (hsh1 on this seed, by a
    # small margin: either lower order passes, the old hsh3 does not)
    assert line.startswith(("hsh1:", "hsh2:")), line
    assert "with clipped observations kept" in line and "clip in some image" in line
    assert "hsh3, the model used, was judged without them" in line
    share = float(re.search(r"\(([\d.]+)% of the sampled pixels clip", line)[1])  # type: ignore[index]
    assert 1.0 < share < 50.0


def test_a_session_with_nothing_clipped_keeps_the_model_choice_s_order(tmp_path: Path) -> None:
    line = _rti_line(tmp_path, "tablet")
    assert line.startswith("hsh2:") and "clipped" not in line, line


def test_an_order_asked_for_is_written_whatever_is_clipped(tmp_path: Path) -> None:
    assert _rti_line(tmp_path, "coin", hsh_order=3).startswith("hsh3: asked for")


def test_an_hsh_model_named_is_written_as_named(tmp_path: Path) -> None:
    assert _rti_line(tmp_path, "coin", model="hsh2").startswith("hsh2: the model chosen")
