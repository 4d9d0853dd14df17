"""A real, correct acquisition lit brighter from one side is not called "too bright for its light".

The gilded icon of tests/data/neuralrti_replay is about 3× brighter per unit of light height lit
from azimuth -50..35° than from the other side. Its 59° image09 (azimuth -26°, 21 % clipped)
had as its only mates, lit from within 5° of its elevation, image41 (104°) and image61 (-149°),
both on the dark side and agreeing, and `rti-rig fit` told the user to reshoot it as "about
3.6× too bright for its light … (auto-exposure left on?)". An elevation now predicts a level
only where the session shows that the azimuth does not matter, and a clipped image is not
judged by the exposure check at all (it is named saturated instead).
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

from typer.testing import CliRunner

from rti_rig.cli import app

REPO = Path(__file__).resolve().parents[2]
ACQ = REPO / "tests" / "data" / "neuralrti_replay"
runner = CliRunner()


def _fit(lp: Path, out: Path) -> tuple[dict, str]:
    r = runner.invoke(app, ["fit", str(lp), "--out", str(out), "--no-ptm", "--no-hsh"])
    assert r.exit_code == 0, r.output
    return json.loads((out / "qa.json").read_text()), " ".join(r.output.split())


def _exposure_named(qa: dict) -> dict[str, str]:
    return {
        c["name"]: p
        for c in qa["images"]
        for p in c["problems"]
        if "too dark for its light" in p or "too bright for its light" in p
    }


def _image09(qa: dict) -> dict:
    (c,) = [c for c in qa["images"] if c["name"].startswith("image09")]
    return c


def test_the_real_acquisition_names_no_image_for_its_exposure(tmp_path: Path) -> None:
    qa, said = _fit(ACQ / "dirs.lp", tmp_path / "f")
    assert _exposure_named(qa) == {}, qa["verdict"]
    assert "for its light" not in said, said
    # its 20° images disagree 1.9× by azimuth: no elevation predicts a level here
    assert _image09(qa)["exposure_ratio"] is None
    # what is wrong with image09 is still said: it is clipped
    assert any(p.startswith("saturated") for p in _image09(qa)["problems"])


def test_a_clipped_image_is_not_judged_where_the_other_rings_happen_to_agree(
    tmp_path: Path,
) -> None:
    """The same acquisition without image05, image33, image53 and image65 (a correct session of
    14 lights): the disagreeing pairs of elevation-mates are gone, and the remaining 21° pair
    (image13, azimuth -6°, and image49, 132°) agrees within 1.35×, lit from image09's side and
    its mates'. The azimuth rule would judge image09 at 3.6×; it is clipped (21 %), and not
    judged."""
    sub = tmp_path / "acq"
    sub.mkdir()
    dropped = {"image05.jpg", "image33.jpg", "image53.jpg", "image65.jpg"}
    lines = (ACQ / "dirs.lp").read_text().splitlines()[1:]
    kept = [ln for ln in lines if ln.split()[0] not in dropped]
    assert len(kept) == 14
    for ln in kept:
        shutil.copy(ACQ / ln.split()[0], sub)
    (sub / "dirs.lp").write_text("\n".join([str(len(kept)), *kept]) + "\n")
    qa, said = _fit(sub / "dirs.lp", tmp_path / "f")
    assert _exposure_named(qa) == {}, qa["verdict"]
    assert "for its light" not in said, said
    assert _image09(qa)["exposure_ratio"] is None
    assert any(p.startswith("saturated") for p in _image09(qa)["problems"])
