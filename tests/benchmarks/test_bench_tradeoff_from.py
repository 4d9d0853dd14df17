"""`rti-rig bench tradeoff --from ACQ/dirs.lp`: the trade on a real acquisition, end to end."""

from __future__ import annotations

import csv
from pathlib import Path

from typer.testing import CliRunner

from rti_rig.cli import app

ACQ = Path(__file__).resolve().parents[1] / "data" / "neuralrti_replay" / "dirs.lp"


def test_tradeoff_from_a_real_acquisition(tmp_path: Path) -> None:
    out = tmp_path / "trade"
    r = CliRunner().invoke(app, ["bench", "tradeoff", "--from", str(ACQ), "--out", str(out)])
    assert r.exit_code == 0, r.output
    rows = list(csv.DictReader((out / "results.csv").open()))
    counts = sorted({int(row["n"]) for row in rows})
    assert counts == [6, 9, 12]  # those below the acquisition's 18 lights
    methods = {(row["method"], float(row["floor_deg"])) for row in rows}
    assert {("optimal", 0.0), ("adaptive", 0.0), ("uniform", 0.0), ("uniform", 30.0)} <= methods
    for row in rows:
        assert 0.0 < float(row["normal_mean_deg"]) < 90.0
        assert 5.0 < float(row["relight_psnr_db"]) < 80.0
        assert float(row["dome_time_s"]) > 1.0 * int(row["n"])
    for name in ("normal_vs_n.png", "relight_vs_dome_time.png", "summary.md"):
        assert (out / name).stat().st_size > 0
    assert not list(out.glob("*arm_time*"))
    text = (out / "summary.md").read_text()
    assert "--from" in text and "adaptive" in text


def test_tradeoff_from_too_small_an_acquisition_is_refused(tmp_path: Path) -> None:
    small = tmp_path / "acq"
    small.mkdir()
    lines = ACQ.read_text().splitlines()[1:7]
    for line in lines:
        name = line.split()[0]
        (small / name).write_bytes((ACQ.parent / name).read_bytes())
    (small / "dirs.lp").write_text("6\n" + "\n".join(lines) + "\n")
    r = CliRunner().invoke(
        app, ["bench", "tradeoff", "--from", str(small / "dirs.lp"), "--out", str(tmp_path / "o")]
    )
    assert r.exit_code == 2 and "at least 7" in r.output
