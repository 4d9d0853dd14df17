"""Moves part-way through a session that the QA had missed are named from their first moved
image; the same sessions held still stay unaccused.

Found by an injection sweep over correct simulated sessions (every case below was called
"good", or had scattered images named "moved", most of them before the move):

* the painting on the shipped simulated dome, 12 lights, moved (1, 2) px from image 7: with
  half the images at each position every whole-pixel peak against the median of all sits at
  0, so no split was proposed (now also from the median of each half of the session);
* the virtual arm's 256 px tablet, 24 lights, moved (2, 2) px from image 12: its shading
  edges move with the light, so no edges' step holds (now the shifts against the fit, split
  in capture order and confirmed by a refit from one side: qa._moved_block);
* the glossy coin and the industrial part, moved (2, 0) px: the edges' step was found, from
  the right image, and refused by the fit, which explains neither object well enough to
  confirm anything (qa.STEP_FIT_NO_EVIDENCE);
* the virtual arm's 256 px industrial part, 48 lights, moved (1, 2) px from image 25: found
  and confirmed, but named from image 24, which never moved (now placed by the fit); in the
  arm's own move-time order (``run --lights``, no plan) not found at all: its lights sweep
  the hemisphere by azimuth, so the two sides' median edges differed by their shading as well
  (a weak peak whose centroid lay over a pixel off: no step; now the two sides' images lit
  alike are compared, qa_drift.lit_alike), and the fit, undone, read 0.81 of the residual as
  captured against qa.DRIFT_CONFIRM 0.8 over every lit pixel, most of them the part's flat
  faces (now also over its edges, where a move shows: 0.63, qa._where_a_move_shows); and
  (scene seed 1) each image labelled against the before side's median of every image, lit
  from the other half, read 9 of the 24 moved images as still (now against the images lit
  alike).

The arm sessions are shot in the arm's default order, as a user's `run --lights` is.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from conftest import moved_session_copy, virtual_arm_variant, write_config
from typer.testing import CliRunner

from rti_rig.cli import app

REPO = Path(__file__).resolve().parents[2]
runner = CliRunner()


def _dome_variant(folder: Path, scene: str) -> Path:
    text = (REPO / "rig_configs" / "simulated_dome.toml").read_text()
    assert 'name = "relief"' in text
    return write_config(folder, text.replace('name = "relief"', f'name = "{scene}"'), "dome.toml")


#: (rig, scene, side, lights, first moved image (1-based), dx, dy): x right, y down, px.
CASES = {
    "painting": ("dome", "painting", None, 12, 7, 1, 2),
    "tablet": ("arm", "tablet", 256, 24, 12, 2, 2),
    "coin": ("arm", "coin", None, 24, 13, 2, 0),
    "industrial": ("dome", "industrial", None, 12, 5, 2, 0),
    # in the arm's own order (the session held still is the module's arm_industrial_48)
    "industrial_arm_48": ("arm", "industrial", 256, 48, 25, 1, 2),
}


@pytest.fixture(scope="module", params=sorted(CASES))
def case(request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory):  # type: ignore[no-untyped-def]
    rig, scene, side, lights, first, dx, dy = CASES[request.param]
    if request.param == "painting":  # the same session another QA test file shoots: shared
        return request.getfixturevalue("dome_painting_512_12"), lights, first, dx, dy
    if request.param == "industrial_arm_48":  # the session held still tested below: shared
        return request.getfixturevalue("arm_industrial_48"), lights, first, dx, dy
    root = tmp_path_factory.mktemp(request.param)
    config = virtual_arm_variant(root, scene, side) if rig == "arm" else _dome_variant(root, scene)
    out = root / "s"
    args = ["run", str(config), "--out", str(out), "--lights", str(lights), "--no-verdict"]
    r = runner.invoke(app, args)
    assert r.exit_code == 0, r.output
    return out, lights, first, dx, dy


def _qa(session: Path, out: Path) -> dict:  # type: ignore[type-arg]
    r = runner.invoke(app, ["fit", str(session), "--out", str(out), "--no-ptm", "--no-hsh"])
    assert r.exit_code == 0, r.output
    assert "QA verdict:" in " ".join(r.output.split()), r.output
    return json.loads((out / "qa.json").read_text())


_moved_copy = moved_session_copy


def test_the_move_is_named_from_its_first_image(case, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    session, lights, first, dx, dy = case
    qa = _qa(_moved_copy(session, tmp_path / "moved", first, dx, dy), tmp_path / "f")
    name = f"image_{first:03d}"
    # from its first image, or as a range beginning there where the edges place it no closer
    # (the industrial part, 12 lights: its 30 % clipped image_012 reads as not moved, so the
    # split at image_005 is not borne out by every image)
    v = qa["verdict"]
    assert f"moved from {name} on" in v or f"moved between {name} and" in v, v
    moved = [c["name"] for c in qa["images"] if any("moved" in p for p in c["problems"])]
    assert moved == [f"image_{i:03d}" for i in range(first, lights + 1)], qa["verdict"]
    shift = next(c for c in qa["images"] if c["name"] == name)["drift_px"]
    np.testing.assert_allclose(shift, [dx, -dy], atol=0.75)  # x right, y up
    # where the fit explains the object poorly its note says how the move was claimed (it
    # said a shift is claimed only where the fit and the edges agree, beside a move the fit
    # had not confirmed)
    if "show it alike" in qa["drift_note"]:
        assert "a move part-way through is claimed from the edges" in qa["drift_note"]


def test_the_session_held_still_is_not_called_moved(case, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    session = case[0]
    qa = _qa(session, tmp_path / "f")
    assert "moved" not in qa["verdict"], qa["verdict"]


@pytest.fixture(scope="module")
def arm_industrial_48(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The virtual arm's 256 px industrial part, 48 lights in the arm's own (move-time)
    order, as `run --lights` shoots it (read only). Scene seed 1: its move was missed for
    each of the three reasons in the module's docstring (seed 0's for the first two only)."""
    root = tmp_path_factory.mktemp("arm_industrial_48")
    config = virtual_arm_variant(root, "industrial", 256)
    text = config.read_text()
    assert "\nseed = 0\n" in text
    config.write_text(text.replace("\nseed = 0\n", "\nseed = 1\n"))
    out = root / "s"
    r = runner.invoke(
        app, ["run", str(config), "--out", str(out), "--lights", "48", "--no-verdict"]
    )
    assert r.exit_code == 0, r.output
    return out


def _steps_seen(session: Path, out: Path, monkeypatch: pytest.MonkeyPatch) -> tuple[list, dict]:  # type: ignore[type-arg]
    """The edges' steps the QA's search yields while `fit` runs on ``session``, and qa.json."""
    import rti_rig.reconstruct.qa as qa_module

    seen = []
    search = qa_module.step_candidates

    def recorded(*args, **kwargs):  # type: ignore[no-untyped-def]
        for step in search(*args, **kwargs):
            seen.append(step)
            yield step

    monkeypatch.setattr(qa_module, "step_candidates", recorded)
    return seen, _qa(session, out)


def test_the_arm_order_session_held_still_has_no_step(
    arm_industrial_48: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The session held still, in the arm's own order: no step, nothing called moved (its
    sides' median edges read up to 0.97 px apart on seed 0, against qa_drift.STEP_PX 1.0;
    their images lit alike, up to 0.35 px: a margin any change to the sides' estimate must
    keep)."""
    seen, qa = _steps_seen(arm_industrial_48, tmp_path / "f", monkeypatch)
    assert seen == []
    assert "moved" not in qa["verdict"], qa["verdict"]
    assert not [c["name"] for c in qa["images"] if any("moved" in p for p in c["problems"])]
