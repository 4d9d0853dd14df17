"""`run --resume` on a dome whose calibration `.lp` was written again with fewer digits.

The same positions saved with five decimals, or four and CRLF line ends, are the same rig: the
resume continues (it had been refused, "16 of 48 LEDs moved, by up to 0.00°"). An LED that
really moved by 0.2° is still refused, and a refusal names its angle in digits that are not
zero.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest
from conftest import cut_new_session, journal, said, write_config
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()

SHIPPED_LP = Path(__file__).resolve().parents[2] / "rig_configs" / "example_dome_48.lp"

DOME_LP = """
name = "lp-dome"
kind = "dome"
backend = "simulated"
[dome]
layout = "lp"
lp_file = "dome.lp"
[camera]
width = 48
height = 48
exposure_s = 0.05
[scene]
seed = 3
"""


def _read_lp(path: Path) -> tuple[list[str], np.ndarray]:
    rows = [line.split() for line in path.read_text().splitlines()[1:] if line.strip()]
    return [r[0] for r in rows], np.asarray([[float(x) for x in r[1:4]] for r in rows])


def _write_lp(path: Path, names: list[str], dirs: np.ndarray, decimals: int, eol: str) -> None:
    lines = [str(len(names))]
    lines += [
        f"{n} " + " ".join(f"{x:.{decimals}f}" for x in d) for n, d in zip(names, dirs, strict=True)
    ]
    path.write_bytes((eol.join(lines) + eol).encode())


def _cut(tmp_path: Path) -> tuple[Path, Path]:
    """A session on the shipped 48-LED `.lp`, cancelled after three images as Ctrl-C does."""
    from rti_rig.app.usecases.session import NewSessionRequest

    shutil.copy(SHIPPED_LP, tmp_path / "dome.lp")
    cfg = write_config(tmp_path, DOME_LP)
    out = tmp_path / "out"
    cut_new_session(NewSessionRequest(cfg, out), after_step=2)
    assert len(journal(out)) == 3
    return cfg, out


@pytest.mark.parametrize(("decimals", "eol"), [(5, "\n"), (4, "\r\n")])
def test_an_lp_written_again_with_fewer_digits_resumes(
    tmp_path: Path, decimals: int, eol: str
) -> None:
    _, out = _cut(tmp_path)
    names, dirs = _read_lp(tmp_path / "dome.lp")
    _write_lp(tmp_path / "dome.lp", names, dirs, decimals, eol)
    r = runner.invoke(app, ["run", "--resume", str(out), "--no-verdict"])
    assert r.exit_code == 0, r.output
    assert "light positions" not in said(r)
    assert len(journal(out)) == 48


def test_an_led_moved_by_a_fifth_of_a_degree_is_refused_with_its_angle(tmp_path: Path) -> None:
    _, out = _cut(tmp_path)
    names, dirs = _read_lp(tmp_path / "dome.lp")
    v = dirs[20] / np.linalg.norm(dirs[20])
    across = np.cross(v, [0.0, 0.0, 1.0])
    across /= np.linalg.norm(across)
    t = np.radians(0.2)
    dirs[20] = np.cos(t) * v + np.sin(t) * across  # 0.2° off, on the unit sphere
    _write_lp(tmp_path / "dome.lp", names, dirs, 6, "\n")
    r = runner.invoke(app, ["run", "--resume", str(out), "--no-verdict"])
    assert r.exit_code == 2, r.output
    assert "light positions: 1 of 48 LEDs moved, by up to 0.20° (LED index 20)" in said(r)
    assert "add --accept-rig-change" in said(r)
    assert len(journal(out)) == 3  # nothing captured


def test_an_lp_written_with_three_decimals_is_refused_saying_rounding_could_explain_it(
    tmp_path: Path,
) -> None:
    _, out = _cut(tmp_path)
    names, dirs = _read_lp(tmp_path / "dome.lp")
    _write_lp(tmp_path / "dome.lp", names, dirs, 3, "\n")
    r = runner.invoke(app, ["run", "--resume", str(out), "--no-verdict"])
    assert r.exit_code == 2, r.output
    text = said(r)
    assert "0.00°" not in text
    assert "no more than rounding the .lp to 3 decimals moves a light" in text
    assert len(journal(out)) == 3
