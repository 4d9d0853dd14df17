"""`python -m benchmarks.fit_rti_order` on the repository's 18-image real replay subset: it runs,
prints a row per N and floor that its lights allow, and writes nothing unless asked."""

from __future__ import annotations

from pathlib import Path

from benchmarks import fit_rti_order

ACQ = Path(__file__).resolve().parents[1] / "data" / "neuralrti_replay"


def test_the_benchmark_tables_each_basis_and_what_fit_writes(monkeypatch, tmp_path) -> None:  # type: ignore[no-untyped-def]
    doc = tmp_path / "doc.md"
    doc.write_text("x\n")
    monkeypatch.setattr(fit_rti_order, "DOC", doc)
    md = fit_rti_order.main(["--data", str(ACQ)])
    rows = [r for r in md.splitlines() if r.startswith("| ") and r[2].isdigit()]
    # 18 lights, 3 held out: 15 left, so N = 6, 9, 12 at three floors each
    assert [r.split(" | ")[0] for r in rows] == ["| 6"] * 3 + ["| 9"] * 3 + ["| 12"] * 3
    for r in rows:
        cells = r.strip("|").split(" | ")
        assert cells[-1].strip().startswith("hsh")  # fit.rti is written from 6 lights now
        if r.startswith("| 6 ") and not cells[-3].strip().startswith("hsh"):
            assert cells[-2].strip() == "—"  # and was not, unless auto chose an HSH
    assert doc.read_text() == "x\n"  # not asked to write
