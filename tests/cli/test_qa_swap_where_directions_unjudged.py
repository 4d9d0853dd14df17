"""Two swapped images are named as a swap even on an object whose light directions cannot be
judged by their angle, and not as the object moving.

Found by a truth-table campaign: the simulated dome's industrial part (brushed steel), 24
lights, images 2 and 3 swapped (two 10° lights 144° apart): at 1024 px the verdict said the
object moved from image_005 on by (-1.1, -8.3) px (a block of four images whose shifts against
the fit wander, split off by qa._moved_block), at 512 px it named neither image. Its images
point too far from their lights to judge any by its angle; each swapped image is rendered
4-8× closer under the other's recorded light than under its own (qa_directions.swapped_pairs).

Margins seen (review, 2026-11-30), for a geometric test "each best direction within the
object's typical direction error of the other's light": the pair's best directions lie 4.5°
and 5.5-7.5° from each other's lights at 512 px, but 58.6° and 21.9° at 1024 px, where the
object's typical error (1.55 × the lower quartile of all images' errors) is 19-21° and the
check's own object_typical is not computed (NaN). Such a test would lose the 1024 px swap, so
the pairs are still required only to cross (each best direction nearer the other's light).
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()


def _qa(session: Path, out: Path) -> dict:  # type: ignore[type-arg]
    r = runner.invoke(app, ["fit", str(session), "--out", str(out), "--no-ptm", "--no-hsh"])
    assert r.exit_code == 0, r.output
    assert "QA verdict:" in " ".join(r.output.split()), r.output
    return json.loads((out / "qa.json").read_text())


@pytest.fixture(scope="module")
def industrial(dome_industrial_512_24: Path) -> Path:
    return dome_industrial_512_24


def _wrong(qa: dict) -> dict[str, str]:  # type: ignore[type-arg]
    return {
        c["name"]: p for c in qa["images"] for p in c["problems"] if p.startswith("wrong light")
    }


def test_a_swapped_pair_is_said_as_a_swap(industrial: Path, tmp_path: Path) -> None:
    session = tmp_path / "swapped"
    shutil.copytree(industrial, session)
    a, b = session / "linear" / "image_002.tif", session / "linear" / "image_003.tif"
    a.rename(session / "x.tif")
    b.rename(a)
    (session / "x.tif").rename(b)
    qa = _qa(session, tmp_path / "f")
    verdict = qa["verdict"]
    wrong = _wrong(qa)
    assert sorted(wrong) == ["image_002", "image_003"], verdict
    assert "recorded for image_003" in wrong["image_002"], verdict
    assert "recorded for image_002" in wrong["image_003"], verdict
    assert all("(swapped?)" in p for p in wrong.values()), verdict
    assert "moved" not in verdict, verdict
    # qa.json agrees with itself: no direction was judged by its angle, none is claimed
    assert qa["median_direction_error_deg"] is None, qa
    assert qa["directions_checked"] is False, qa


def test_the_correct_session_has_no_swap(industrial: Path, tmp_path: Path) -> None:
    qa = _qa(industrial, tmp_path / "f")
    assert not _wrong(qa), qa["verdict"]
    assert "swapped" not in qa["verdict"], qa["verdict"]


def test_a_shuffled_lp_names_no_swapped_pair_nor_says_one_is(
    industrial: Path, tmp_path: Path
) -> None:
    """Its lights.lp shuffled (seed 2), the verdict leads with lights likely wrong and names no
    image for its light; it had still said "a swapped pair is still named where each image is
    rendered clearly closer …" of a pair it did not name."""
    import numpy as np

    from rti_rig.core.lp_format import LpEntry, read_lp, write_lp

    session = tmp_path / "shuffled"
    shutil.copytree(industrial, session)
    entries = read_lp(session / "lights.lp")
    order = np.random.default_rng(2).permutation(len(entries))
    write_lp(
        session / "lights.lp",
        [LpEntry(e.name, entries[k].direction) for e, k in zip(entries, order, strict=True)],
    )
    r = runner.invoke(
        app,
        ["fit", str(session), "--out", str(tmp_path / "f"), "--no-ptm", "--no-hsh", "--no-normals"],
    )
    assert r.exit_code == 0, r.output
    qa = json.loads((tmp_path / "f" / "qa.json").read_text())
    assert qa["lights_likely_wrong"] is True, qa["verdict"]
    assert not _wrong({"images": [c for c in qa["images"] if c["name"] in qa["reshoot"]]})
    assert "swapped pair" not in " ".join(r.output.split()), r.output
    assert not any("swapped pair" in c for c in qa["caveats"]), qa["caveats"]
