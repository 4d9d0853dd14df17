"""`rti-rig bench` as the installed command runs it (README: `rti-rig bench tradeoff ...`).

The console script's ``sys.path`` has neither the current folder nor the checkout, so the
benchmarks (not installed) were not found even from the repository's folder; only
``python -m rti_rig bench`` worked.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from conftest import said

REPO = Path(__file__).resolve().parents[2]


def test_installed_rti_rig_bench_finds_the_checkout_benchmarks(tmp_path: Path) -> None:
    script = Path(sys.executable).parent / "rti-rig"
    assert script.is_file(), "rti-rig is installed in this environment (pip install -e .)"
    missing = tmp_path / "nowhere" / "dirs.lp"
    for cwd in (REPO, tmp_path):
        r = subprocess.run(
            [str(script), "bench", "tradeoff", "--from", str(missing)],
            cwd=cwd,
            capture_output=True,
            text=True,
            timeout=300,
        )
        text = " ".join((r.stdout + r.stderr).split())
        assert r.returncode == 2, text
        assert "checkout" not in text, text  # the benchmarks were found
        assert "Traceback" not in text and "dirs.lp" in text, text


ACQ = REPO / "tests" / "data" / "neuralrti_replay" / "dirs.lp"


def test_tradeoff_from_without_out_prints_and_writes_nothing(tmp_path: Path) -> None:
    from typer.testing import CliRunner

    from rti_rig.cli import app

    r = CliRunner().invoke(app, ["bench", "tradeoff", "--from", str(ACQ)])
    assert r.exit_code == 0, r.output
    assert r.exception is None or isinstance(r.exception, SystemExit), repr(r.exception)
    assert "adaptive" in r.output and "nothing written" in r.output


def test_tradeoff_out_that_cannot_be_written_is_refused_before_computing(tmp_path: Path) -> None:
    from typer.testing import CliRunner

    from rti_rig.cli import app

    a_file = tmp_path / "a_file"
    a_file.write_text("x")
    out = a_file / "trade"
    r = CliRunner().invoke(app, ["bench", "tradeoff", "--from", str(ACQ), "--out", str(out)])
    assert r.exit_code == 2, r.output
    assert r.exception is None or isinstance(r.exception, SystemExit), repr(r.exception)
    text = said(r)
    assert str(out) in text and "N = 6 done" not in text  # refused before any work


def test_tradeoff_refuses_to_replace_a_folder_s_files_without_force(tmp_path: Path) -> None:
    """A user's own summary.md had been replaced without a word; a session folder is never
    written into, --force or not. Refused before any work."""
    from typer.testing import CliRunner

    from rti_rig.cli import app

    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "summary.md").write_text("my notes")
    session = tmp_path / "session"
    session.mkdir()
    (session / "manifest.json").write_text("{}")
    for out, force, expect in (
        (mine, [], "is not empty"),
        (session, ["--force"], "never written into"),
        (session / "sub", ["--force"], "never written into"),
    ):
        r = CliRunner().invoke(
            app, ["bench", "tradeoff", "--from", str(ACQ), "--out", str(out), *force]
        )
        text = said(r)
        assert r.exit_code == 2 and expect in text and "N = 6 done" not in text, text
    assert (mine / "summary.md").read_text() == "my notes"
    assert not (session / "sub").exists()


def test_tradeoff_from_shows_fit_warnings_as_notes_not_python_warnings(tmp_path: Path) -> None:
    """A fit warning (here HSH2 on lights bunched towards the zenith: the acquisition's lights
    pulled in to within ~50° of it) is a note in the report, not a Python warning with a source
    line. (The acquisition as recorded no longer warns: its lights held out for relighting
    changed the layouts compared.)"""
    import shutil

    import numpy as np

    from rti_rig.core.lp_format import LpEntry, read_lp, write_lp

    bunched = []
    for e in read_lp(ACQ):
        v = np.array([e.direction[0] * 0.45, e.direction[1] * 0.45, e.direction[2]])
        shutil.copy(ACQ.parent / e.name, tmp_path / e.name)
        bunched.append(LpEntry(e.name, tuple(float(x) for x in v / np.linalg.norm(v))))
    lp = write_lp(tmp_path / "dirs.lp", bunched)
    script = Path(sys.executable).parent / "rti-rig"
    r = subprocess.run(
        [str(script), "bench", "tradeoff", "--from", str(lp)],
        capture_output=True,
        text=True,
        timeout=600,
    )
    text = r.stdout + r.stderr
    assert r.returncode == 0, text
    assert ".py:" not in text, text  # no "rti_rig/reconstruct/ptm.py:134: ...Warning"
    flat = " ".join(text.split())
    # said as its sentence, without the Python class name (it had led "IllConditionedFitWarning: ")
    assert "note: hsh2 fit ill-conditioned over the hemisphere: relighting amplifies" in flat
    assert "Warning" not in flat, text


def test_the_checkout_benchmarks_go_first_even_behind_another_benchmarks(
    tmp_path: Path, monkeypatch
) -> None:
    """Another importable ``benchmarks`` earlier on the path (PYTHONPATH, the folder the command
    runs in) is not taken for the checkout's own."""
    from rti_rig.cli.bench import _find_benchmarks

    fake = tmp_path / "fake"
    (fake / "benchmarks").mkdir(parents=True)
    (fake / "benchmarks" / "__init__.py").write_text("")
    (fake / "benchmarks" / "tradeoff.py").write_text("raise RuntimeError('not ours')\n")
    monkeypatch.setattr(sys, "path", [str(fake), str(REPO), *sys.path])
    _find_benchmarks()
    assert sys.path[0] == str(REPO)
    assert sys.path.count(str(REPO)) == 1


def test_tradeoff_from_a_folder_takes_its_only_lp(tmp_path: Path) -> None:
    """`--from SESSION_DIR` had answered "Is a directory"; `rti-rig fit` takes a folder."""
    import pytest

    from rti_rig.cli.bench import _acquisition_lp
    from rti_rig.core.errors import RtiRigError

    assert _acquisition_lp(ACQ.parent) == ACQ
    assert _acquisition_lp(ACQ) == ACQ
    with pytest.raises(RtiRigError, match=r"a folder with no \.lp file"):
        _acquisition_lp(tmp_path)
    for name in ("a.lp", "b.lp"):
        (tmp_path / name).write_text("1\nx.jpg 0 0 1\n")
    with pytest.raises(RtiRigError, match=r"2 \.lp files \(a\.lp, b\.lp\)"):
        _acquisition_lp(tmp_path)


def test_tradeoff_from_a_file_that_is_not_an_lp_names_what_to_give(tmp_path: Path) -> None:
    """Found by a front-door audit: `--from` an acquisition's image was told its "line 1 holds
    NUL bytes … save it again as UTF-8", and `--from` a rig config "line 4: expected 'name x y
    z'"; `fit` and `run` name an .lp as what they want."""
    from typer.testing import CliRunner

    from rti_rig.cli import app

    image = ACQ.parent / "image01.jpg"
    for given in (image, REPO / "rig_configs" / "simulated_dome.toml"):
        r = CliRunner().invoke(app, ["bench", "tradeoff", "--from", str(given)])
        text = said(r)
        assert r.exit_code == 2, text
        assert r.exception is None or isinstance(r.exception, SystemExit), repr(r.exception)
        assert f"--from {given}: not an .lp file" in text, text
        assert "give the .lp that lists the acquisition's images" in text
        assert "NUL" not in text and "expected 'name x y z'" not in text
