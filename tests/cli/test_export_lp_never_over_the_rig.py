"""`export-lp --force` never replaces the rig the session names, nor what that rig reads.

`export-lp S --out ACQ/dirs.lp --force` had replaced a replayed acquisition's 12 lights with the
session's 6 (the acquisition then refused as "4 of 6 images missing"), and `--out dome.lp
--force` a dome's LED calibration (`lp_file`) with the session's image lines (QA, 2026-12-06).
`plan` and `lights-from-sphere` refused the same.
"""

from __future__ import annotations

import hashlib
import shutil
from pathlib import Path

import pytest
from typer.testing import CliRunner

from rti_rig.cli import app

REPO = Path(__file__).resolve().parents[2]
ACQ = REPO / "tests" / "data" / "neuralrti_replay"
runner = CliRunner()


def _sha(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


@pytest.mark.parametrize("victim", ["dirs.lp", "image05.jpg"])
def test_a_replayed_acquisitions_lp_and_images_are_never_replaced(
    tmp_path: Path, victim: str
) -> None:
    acq = tmp_path / "acq"
    shutil.copytree(ACQ, acq)
    out = tmp_path / "s"
    r = runner.invoke(
        app, ["run", str(acq / "dirs.lp"), "--out", str(out), "--lights", "6", "--no-verdict"]
    )
    assert r.exit_code == 0, r.output
    target = acq / victim
    before = _sha(target)
    r = runner.invoke(app, ["export-lp", str(out), "--out", str(target), "--force"])
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    assert f"--out {target} is the " in said and "it is never replaced, even with --force" in said
    assert "Traceback" not in said
    assert _sha(target) == before


def test_a_domes_lp_file_calibration_is_never_replaced(tmp_path: Path) -> None:
    rig = tmp_path / "dome"
    rig.mkdir()
    shutil.copy(REPO / "rig_configs" / "example_dome_48.lp", rig / "dome.lp")
    text = (REPO / "rig_configs" / "simulated_dome.toml").read_text(encoding="utf-8")
    head, rest = text.split("[dome]\n", 1)
    rest = rest[rest.index("[camera]") :]  # its rings dropped: the dome is its .lp
    config = rig / "rig.toml"
    config.write_text(
        f'{head}[dome]\nlayout = "lp"\nlp_file = "dome.lp"\n\n{rest}', encoding="utf-8"
    )
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", str(config), "--out", str(out), "--lights", "6", "--no-verdict"])
    assert r.exit_code == 0, r.output
    for target, what in (
        (rig / "dome.lp", "is the session's rig's LED calibration (lp_file)"),
        (config, "is the session's rig config"),
    ):
        before = _sha(target)
        r = runner.invoke(app, ["export-lp", str(out), "--out", str(target), "--force"])
        said = " ".join(r.output.split())
        assert r.exit_code == 2, said
        assert f"--out {target} {what}; it is never replaced, even with --force" in said, said
        assert _sha(target) == before
    # a file of the user's own is still replaced with --force, as before
    mine = tmp_path / "mine.lp"
    mine.write_text("old\n", encoding="utf-8")
    r = runner.invoke(app, ["export-lp", str(out), "--out", str(mine), "--force"])
    assert r.exit_code == 0, r.output
    assert mine.read_text(encoding="utf-8").startswith("6\n")
