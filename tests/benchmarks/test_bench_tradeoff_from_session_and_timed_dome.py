"""`bench tradeoff --from`: a session folder with another .lp beside its lights.lp, and the
session time on a dome whose firmware times its LEDs itself (RTIPy)."""

from __future__ import annotations

import csv
import shutil
from pathlib import Path
from typing import Any

import pytest
from typer.testing import CliRunner

from rti_rig.cli import app

ROOT = Path(__file__).resolve().parents[2]
ACQ = ROOT / "tests" / "data" / "neuralrti_replay" / "dirs.lp"


def _stand_in(seen: list[Path]) -> Any:
    """A run_tradeoff_from that records the .lp it was given and returns stand-in rows."""
    from tests.benchmarks.test_bench_tradeoff_from import _stand_in_rows

    def run(lp: Path, progress: Any) -> Any:
        seen.append(Path(lp))
        return _stand_in_rows()

    return run


def _folder(folder: Path, lp_name: str, count: int = 12) -> Path:
    """The first ``count`` lights of the shipped acquisition copied into ``folder`` as
    ``lp_name``."""
    folder.mkdir()
    lines = ACQ.read_text().splitlines()[1 : count + 1]
    for line in lines:
        name = line.split()[0]
        shutil.copyfile(ACQ.parent / name, folder / name)
    lp = folder / lp_name
    lp.write_text(f"{count}\n" + "\n".join(lines) + "\n")
    return lp


def test_a_session_folder_is_read_from_its_lights_lp_beside_an_exported_lp(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A session (its manifest beside lights.lp) that also holds the demo_linear.lp that
    `export-lp --linear` offers to write into it had been refused as "a folder with 2 .lp
    files"; it is read from its lights.lp, as `fit` reads it, and the other .lp is named."""
    import benchmarks.tradeoff_from as tradeoff_from

    seen: list[Path] = []
    monkeypatch.setattr(tradeoff_from, "run_tradeoff_from", _stand_in(seen))
    session = tmp_path / "session"
    lights = _folder(session, "lights.lp")
    (session / "manifest.json").write_text("{}\n", encoding="utf-8")
    shutil.copyfile(lights, session / "demo_linear.lp")
    out = tmp_path / "o"
    r = CliRunner().invoke(
        app, ["bench", "tradeoff", "--from", str(session), "--out", str(out)], terminal_width=400
    )
    assert r.exit_code == 0, r.output
    assert seen == [lights], seen
    said = " ".join(r.output.split())
    assert "its lights.lp is read, not the other .lp beside it (demo_linear.lp" in said, said
    assert "Traceback" not in r.output


def test_a_folder_that_is_not_a_session_with_two_lp_stays_refused(tmp_path: Path) -> None:
    """Without rti-rig's manifest, which of two .lp lists the acquisition cannot be told."""
    acq = tmp_path / "acq"
    lp = _folder(acq, "dirs.lp")
    shutil.copyfile(lp, acq / "subset.lp")
    (acq / "lights.lp").unlink(missing_ok=True)
    r = CliRunner().invoke(
        app,
        ["bench", "tradeoff", "--from", str(acq), "--out", str(tmp_path / "o")],
        terminal_width=400,
    )
    assert r.exit_code != 0, r.output
    said = " ".join(r.output.split())
    assert "a folder with 2 .lp files" in said and "give the .lp of the acquisition" in said, said
    assert not (tmp_path / "o").exists()


def test_a_timed_firmwares_hold_window_is_in_the_session_time(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """`--rig emulated_rtipy.toml`: RTIPy reads a command only after 1 s of silence and holds
    each LED lit for its 2 s window, which the dry run's driver waits out (about 3.07 s a
    light, measured); the bench had said 1.17 s a light, its [timing] and exposure alone."""
    import benchmarks.tradeoff_from as tradeoff_from

    monkeypatch.setattr(tradeoff_from, "run_tradeoff_from", _stand_in([]))
    rig = ROOT / "rig_configs" / "emulated_rtipy.toml"
    out = tmp_path / "o"
    r = CliRunner().invoke(
        app,
        ["bench", "tradeoff", "--from", str(ACQ), "--rig", str(rig), "--out", str(out)],
        terminal_width=400,
    )
    assert r.exit_code == 0, r.output
    rows = list(csv.DictReader((out / "results.csv").open()))
    for row in rows:
        per_light = float(row["dome_time_s"]) / int(row["n"])
        assert 3.0 <= per_light <= 3.2, row  # 0.007 wire + 1 silence + 2 window + 0.05 margin
    summary = " ".join((out / "summary.md").read_text(encoding="utf-8").split())
    assert "3.06 s a light" in summary, summary
    assert "framing silence 1 s" in summary and "the 2 s it holds the LED lit" in summary, summary


def test_an_untimed_dome_keeps_its_timing_sum(tmp_path: Path) -> None:
    """The simulated dome (no timed firmware): its [timing] and exposure, 1.17 s a light, the
    dry run's own figure (9.4 s for 8 lights)."""
    from benchmarks.tradeoff_from import rig_facts

    (seconds, said), _ = rig_facts(ROOT / "rig_configs" / "simulated_dome.toml")
    assert seconds == pytest.approx(1.17) and "transfer_s 0.7" in said
