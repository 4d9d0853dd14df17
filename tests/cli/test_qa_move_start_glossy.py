"""A move part-way through a session of a glossy object, which the fit cannot confirm, is
named from its first moved image, or said to have begun somewhere between two images where
the edges place it no closer, the images between named as ones that may have moved; no image
the edges' splits leave open is named as certainly moved.

Found by a truth-table campaign: the shipped simulated dome's coin at 1024 px, 12 lights,
moved (2, 0) px from image 7 on, was "moved from image_005 on" (512 and 256 px: from
image_004). The fit explains the coin too poorly to weigh the edges' candidate splits
(qa.STEP_FIT_NO_EVIDENCE), and the first candidate was taken: at 512 px a split at image 4
with 11 of its 12 images where it says, against the split at image 7 with all 12; at 256 px
both splits with all 12. Review: a split some of whose images sit where it does not say was
still said as certain (256 px, (0, -2) from image 6: "from image_007 on", image_006 left
out of the reshoot), and the images between tied splits were left out of the reshoot.

Not mended: at 256 px a move (2, 0) from image 5 is "moved from image_004 on" as certain;
the edges read image_004 as moved, exactly as for a move from image 4 (one split at
image 4, all 12 images where it says), so nothing here tells the two apart.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest
from conftest import dome_session, moved_session_copy
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()
LIGHTS = 12
MAYBE = "may have moved"
MOVED = "object or camera moved from"


def _qa(session: Path, out: Path) -> dict:  # type: ignore[type-arg]
    r = runner.invoke(app, ["fit", str(session), "--out", str(out), "--no-ptm", "--no-hsh"])
    assert r.exit_code == 0, r.output
    assert "QA verdict:" in " ".join(r.output.split()), r.output
    return json.loads((out / "qa.json").read_text())


def _named(qa: dict, word: str) -> list[str]:  # type: ignore[type-arg]
    return [c["name"] for c in qa["images"] if any(p.startswith(word) for p in c["problems"])]


def _image(i: int) -> str:
    return f"image_{i:03d}"


@pytest.fixture(scope="module")
def sessions(tmp_path_factory: pytest.TempPathFactory, dome_coin_512_12: Path) -> dict[int, Path]:
    assert LIGHTS == 12  # the lights of the shared 512 px session
    return {
        256: dome_session(tmp_path_factory.mktemp("coin256"), "coin", 256, LIGHTS),
        512: dome_coin_512_12,
    }


# (first moved image 1-based, shift): the range each was stated with at 256 px, measured:
# (7, 2, 0) splits at images 4 and 7 alike -> between image_004 and image_007;
# (6, 0, -2) one split at image 7 with 11 of 12 -> between image_002 and image_007;
# (7, 0, 2) one split at image 6 with 11 of 12 -> between image_006 and image_008;
# (8, 2, 0) one split at image 8 with 11 of 12 -> between image_005 and image_008.
@pytest.mark.parametrize(
    ("first", "dx", "dy", "lo"), [(7, 2, 0, 4), (6, 0, -2, 2), (7, 0, 2, 6), (8, 2, 0, 5)]
)
def test_a_move_the_edges_cannot_place_is_said_as_a_range(  # type: ignore[no-untyped-def]
    sessions, tmp_path: Path, first: int, dx: int, dy: int, lo: int
) -> None:
    moved = moved_session_copy(sessions[256], tmp_path / "moved", first, dx, dy)
    qa = _qa(moved, tmp_path / "f")
    verdict = qa["verdict"]
    truly = {_image(i) for i in range(first, LIGHTS + 1)}
    certain, maybe = set(_named(qa, MOVED)), set(_named(qa, MAYBE))
    assert certain <= truly, verdict  # nothing said moved as certain that held still
    assert truly <= certain | maybe, verdict  # every moved image is named
    assert (certain | maybe) <= set(qa["reshoot"]), verdict
    m = re.search(r"moved between (image_\d+) and (image_\d+)", verdict)
    assert m is not None, verdict
    a, b = int(m[1][6:]), int(m[2][6:])
    assert (a, a <= first <= b) == (lo, True), verdict
    assert maybe == {_image(i) for i in range(a, b)}, verdict  # the open range, named
    assert certain == {_image(i) for i in range(b, LIGHTS + 1)}, verdict


def test_a_move_the_edges_place_is_said_as_certain(sessions, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    first = 7
    qa = _qa(moved_session_copy(sessions[512], tmp_path / "moved", first, 2, 0), tmp_path / "f")
    verdict = qa["verdict"]
    assert _named(qa, MOVED) == [_image(i) for i in range(first, LIGHTS + 1)], verdict
    assert f"moved from image_{first:03d} on" in verdict, verdict
    assert not _named(qa, MAYBE) and "moved between" not in verdict, verdict


@pytest.mark.parametrize("side", [512, 256])
def test_the_coin_held_still_is_not_called_moved(sessions, tmp_path: Path, side: int) -> None:  # type: ignore[no-untyped-def]
    qa = _qa(sessions[side], tmp_path / "f")
    assert "moved" not in qa["verdict"], qa["verdict"]
