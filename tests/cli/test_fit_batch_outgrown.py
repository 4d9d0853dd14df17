"""A batch refits a session that changed since its earlier fit, and says why.

Only the output folder's existence had been checked: a session fitted while interrupted, then
continued with ``run --resume`` (or mended with ``--reshoot-lost``), kept its out-of-date fit
("5 images from S/lights.lp") while the batch said "skipped (finished earlier)".
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
from conftest import SMALL_DOME, interrupted, said, write_config
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()


def batch(*sources: Path, out: Path):  # type: ignore[no-untyped-def]
    """``rti-rig fit S... --out OUT`` as a user runs it (PS: any light count from 3 fits)."""
    args = ["fit", *map(str, sources), "--out", str(out), "--model", "ps", "--no-qa"]
    return runner.invoke(app, args)


def read(fit: Path) -> str:
    """What a fit folder's fit.json says it was made from."""
    return str(json.loads((fit / "fit.json").read_text(encoding="utf-8"))["read"])


@pytest.mark.e2e
@pytest.mark.slow
def test_a_resumed_session_is_refitted_by_its_batch(tmp_path: Path) -> None:
    cfg = write_config(tmp_path, SMALL_DOME)
    s, other, fb = tmp_path / "S", tmp_path / "T", tmp_path / "FB"
    interrupted(cfg, s, after_step=4, lights=8)  # 5 of 8 images
    r = runner.invoke(app, ["run", str(cfg), "--out", str(other), "--lights", "6"])
    assert r.exit_code == 0, r.output
    r = batch(s, other, out=fb)
    assert r.exit_code == 0 and said(r).count(": done") == 2, r.output
    assert read(fb / "S").startswith("5 images")
    r = batch(s, other, out=fb)  # nothing changed: both stand
    assert said(r).count("skipped (finished earlier)") == 2, r.output

    r = runner.invoke(app, ["run", "--resume", str(s)])
    assert r.exit_code == 0, r.output
    r = batch(s, other, out=fb)
    text = said(r)
    assert r.exit_code == 0, r.output
    assert f"{s}: refitted (its session changed since the earlier fit: 5 → 8 images)" in text
    assert f"{other}: skipped (finished earlier)" in text
    assert read(fb / "S").startswith("8 images")
    assert sorted(p.name for p in fb.iterdir()) == ["S", "T"]  # no partial or earlier left
    r = batch(s, other, out=fb)
    assert said(r).count("skipped (finished earlier)") == 2, r.output


@pytest.mark.e2e
@pytest.mark.slow
def test_a_reshot_session_is_refitted_and_a_failed_refit_keeps_the_earlier_fit(
    tmp_path: Path,
) -> None:
    cfg = write_config(tmp_path, SMALL_DOME)
    s, fb = tmp_path / "S", tmp_path / "FB"
    for session in (s, tmp_path / "T"):
        r = runner.invoke(app, ["run", str(cfg), "--out", str(session), "--lights", "6"])
        assert r.exit_code == 0, r.output
    tif = s / "linear" / "image_003.tif"
    data = bytearray(tif.read_bytes())
    data[-100] ^= 0xFF  # changed since capture: its checksum no longer matches
    tif.write_bytes(bytes(data))
    # fitted from the damaged image: the record says so (the journal's checksum is the
    # captured image's, which the reshoot brings back; the simulator shoots the same bytes)
    r = batch(s, tmp_path / "T", out=fb)
    assert r.exit_code == 0, r.output
    r = runner.invoke(app, ["run", "--resume", str(s), "--reshoot-lost"])
    assert r.exit_code == 0, r.output
    r = batch(s, tmp_path / "T", out=fb)
    assert r.exit_code == 0, r.output
    expected = "refitted (its session changed since the earlier fit: 1 of 6 images changed: "
    assert f"{s}: {expected}image_003)" in said(r), r.output
    r = batch(s, tmp_path / "T", out=fb)  # the reshot session, as fitted: it stands
    assert f"{s}: skipped (finished earlier)" in said(r), r.output

    # the session now cannot be fitted: the refit fails and the earlier fit stays as it was
    before = (fb / "S" / "fit.json").read_bytes()
    (s / "linear" / "image_002.tif").unlink()
    (s / "image_002.jpg").unlink()
    r = batch(s, tmp_path / "T", out=fb)
    assert r.exit_code == 2, r.output
    assert f"(the earlier fit in {fb / 'S'} is kept)" in said(r), r.output
    assert (fb / "S" / "fit.json").read_bytes() == before
    assert sorted(p.name for p in fb.iterdir()) == ["S", "T"]
    shutil.rmtree(fb)
