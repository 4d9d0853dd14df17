"""`fit FOLDER` on a folder that is no session, holding lights.lp and another .lp, says which
it fitted: it had fitted lights.lp without a word, where `bench tradeoff --from` refuses the
same folder (QA, 2026-12-05)."""

from __future__ import annotations

import shutil
from pathlib import Path

from typer.testing import CliRunner

from rti_rig.cli import app

ACQ = Path(__file__).resolve().parents[1] / "data" / "neuralrti_replay" / "dirs.lp"


def _folder(folder: Path, count: int = 12) -> None:
    folder.mkdir()
    lines = ACQ.read_text().splitlines()[1 : count + 1]
    for line in lines:
        shutil.copyfile(ACQ.parent / line.split()[0], folder / line.split()[0])
    (folder / "lights.lp").write_text(f"{count}\n" + "\n".join(lines) + "\n")
    (folder / "subset.lp").write_text(f"{count - 2}\n" + "\n".join(lines[:-2]) + "\n")


def test_fit_of_a_folder_with_another_lp_names_the_one_it_did_not_fit(tmp_path: Path) -> None:
    acq = tmp_path / "acq"
    _folder(acq)
    r = CliRunner().invoke(
        app, ["fit", str(acq), "--out", str(tmp_path / "f"), "--no-qa"], terminal_width=400
    )
    assert r.exit_code == 0, r.output
    said = " ".join(r.output.split())
    assert f"{acq}: fitted from its lights.lp, not the other .lp beside it (subset.lp)" in said
    assert f"give it in the folder's place (e.g. {acq / 'subset.lp'})" in said, said
