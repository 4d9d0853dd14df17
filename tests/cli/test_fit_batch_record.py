"""A batch tells a session that changed from one that was only copied or rewritten.

Its record of what a fit read had been each image's size and modification time and a digest of
the lights rounded to 6 decimals: a session copied without its timestamps (plain ``cp``, rsync
without ``-t``) was refitted in full, and one whose ``lights.lp`` was written again with 5
decimals was refitted as "its lights changed", without saying which. Images are now told by
the checksums the session's journal took at capture, and lights by the tolerance a resume uses.
"""

from __future__ import annotations

import json
import math
import os
import shutil
from pathlib import Path

import pytest
from conftest import SMALL_DOME, said, write_config
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()


def batch(*sources: Path, out: Path):  # type: ignore[no-untyped-def]
    """``rti-rig fit S... --out OUT`` as a user runs it (PS: any light count from 3 fits)."""
    args = ["fit", *map(str, sources), "--out", str(out), "--model", "ps", "--no-qa"]
    return runner.invoke(app, args)


def rewrite_lp(lp: Path, decimals: int, raise_deg: dict[int, float] | None = None) -> list[str]:
    """Write ``lp`` again with ``decimals`` decimals, the lights at the given line indices
    raised in elevation by the given degrees (an angle of exactly that much); its image names."""
    head, *rows = lp.read_text(encoding="utf-8").splitlines()
    out, names = [head], []
    for i, row in enumerate(rows):
        name, *xyz = row.split()
        x, y, z = map(float, xyz)
        if raise_deg and i in raise_deg:
            el = math.asin(z) + math.radians(raise_deg[i])
            az = math.atan2(y, x)
            x, y, z = math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el)
        out.append(" ".join([name, *(f"{v:.{decimals}f}" for v in (x, y, z))]))
        names.append(Path(name).stem)
    lp.write_text("\n".join(out) + "\n", encoding="utf-8")
    return names


def fitted(tmp_path: Path) -> tuple[Path, Path, Path]:
    """Sessions S and T (6 lights each), fitted by a batch into FB: (S, T, FB)."""
    cfg = write_config(tmp_path, SMALL_DOME)
    s, t, fb = tmp_path / "S", tmp_path / "T", tmp_path / "FB"
    for session in (s, t):
        r = runner.invoke(app, ["run", str(cfg), "--out", str(session), "--lights", "6"])
        assert r.exit_code == 0, r.output
    r = batch(s, t, out=fb)
    assert r.exit_code == 0 and said(r).count(": done") == 2, r.output
    return s, t, fb


@pytest.mark.e2e
@pytest.mark.slow
def test_a_session_copied_without_timestamps_stands(tmp_path: Path) -> None:
    s, t, fb = fitted(tmp_path)
    copy = tmp_path / "copy" / "S"  # cp, rsync without -t: every file has a new mtime
    shutil.copytree(s, copy, copy_function=shutil.copyfile)
    tif = Path("linear") / "image_001.tif"
    assert (copy / tif).stat().st_mtime_ns != (s / tif).stat().st_mtime_ns
    r = batch(copy, t, out=fb)
    assert r.exit_code == 0, r.output
    assert f"{copy}: skipped (finished earlier)" in said(r), r.output


@pytest.mark.e2e
@pytest.mark.slow
def test_an_lp_written_again_with_5_decimals_stands(tmp_path: Path) -> None:
    s, t, fb = fitted(tmp_path)
    rewrite_lp(s / "lights.lp", 5)
    r = batch(s, t, out=fb)
    assert r.exit_code == 0, r.output
    assert said(r).count("skipped (finished earlier)") == 2, r.output


@pytest.mark.e2e
@pytest.mark.slow
def test_a_light_moved_by_a_fifth_of_a_degree_is_refitted_by_name(tmp_path: Path) -> None:
    s, t, fb = fitted(tmp_path)
    names = rewrite_lp(s / "lights.lp", 6, raise_deg={2: 0.2})
    r = batch(s, t, out=fb)
    assert r.exit_code == 0, r.output
    expected = "refitted (its session changed since the earlier fit: 1 of 6 lights moved: "
    assert f"{s}: {expected}{names[2]}'s by 0.20°)" in said(r), r.output
    assert f"{t}: skipped (finished earlier)" in said(r), r.output
    r = batch(s, t, out=fb)  # refitted with the moved light: it stands
    assert said(r).count("skipped (finished earlier)") == 2, r.output


@pytest.mark.e2e
@pytest.mark.slow
def test_a_fit_recording_nothing_comparable_is_skipped_with_a_word(tmp_path: Path) -> None:
    """A fit.json from before the record, or with the record's first form (image sizes and
    times, a digest of the lights), stands with a word on how to refit it: refitting every
    such session unasked would redo a whole backlog."""
    s, t, fb = fitted(tmp_path)
    for fit, inputs in ((fb / "S", None), (fb / "T", {"images": [], "lights_sha256": "0" * 64})):
        summary = json.loads((fit / "fit.json").read_text(encoding="utf-8"))
        summary.pop("inputs")
        if inputs is not None:
            summary["inputs"] = inputs
        (fit / "fit.json").write_text(json.dumps(summary), encoding="utf-8")
    r = batch(s, t, out=fb)
    assert r.exit_code == 0, r.output
    for source, fit in ((s, fb / "S"), (t, fb / "T")):
        assert (
            f"{source}: skipped (finished earlier); its fit.json does not record what it was "
            f"fitted from, so whether its session changed since cannot be told: delete {fit} to "
            "fit it again"
        ) in said(r), r.output


@pytest.mark.e2e
@pytest.mark.slow
def test_a_plain_lp_without_a_journal_is_still_told_by_its_files_times(tmp_path: Path) -> None:
    """An .lp with its images beside it has no journal to vouch for them: an image touched
    since the fit (a re-export over it) is taken for changed, as before."""
    s, t, fb = fitted(tmp_path)
    plain = tmp_path / "P"
    plain.mkdir()
    shutil.copy(s / "lights.lp", plain / "lights.lp")
    for jpg in s.glob("image_*.jpg"):
        shutil.copy(jpg, plain / jpg.name)
    r = batch(plain, t, out=fb)
    assert r.exit_code == 0 and f"{plain}: done" in said(r), r.output
    jpg = sorted(plain.glob("image_*.jpg"))[1]
    st = jpg.stat()
    os.utime(jpg, ns=(st.st_atime_ns, st.st_mtime_ns + 10**9))
    r = batch(plain, t, out=fb)
    assert r.exit_code == 0, r.output
    expected = "refitted (its session changed since the earlier fit: 1 of 6 images changed: "
    assert f"{plain}: {expected}{jpg.stem})" in said(r), r.output
