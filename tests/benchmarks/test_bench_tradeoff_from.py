"""`rti-rig bench tradeoff --from ACQ/dirs.lp`: the trade on a real acquisition, end to end."""

from __future__ import annotations

import csv
import itertools
import os
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.shell_words import shown_path

ACQ = Path(__file__).resolve().parents[1] / "data" / "neuralrti_replay" / "dirs.lp"


def test_tradeoff_from_a_real_acquisition(tmp_path: Path) -> None:
    import re
    import shutil
    import subprocess

    from conftest import NOT_UTF8_NAME

    # in folders with spaces and brackets, as an archive's are (``Tablet [v3]/dirs.lp``)
    acq = tmp_path / "Tablet [v3]" / "dirs.lp"
    shutil.copytree(ACQ.parent, acq.parent)
    out = tmp_path / os.fsdecode(b"trade off " + NOT_UTF8_NAME)  # bytes that are not UTF-8
    r = CliRunner().invoke(app, ["bench", "tradeoff", "--from", str(acq), "--out", str(out)])
    assert r.exit_code == 0, r.output
    rows = list(csv.DictReader((out / "results.csv").open()))
    counts = sorted({int(row["n"]) for row in rows})
    # those below the 15 lights not held out (18 lights, 3 held out), and every one of them
    assert counts == [6, 9, 12, 15]
    assert [row["method"] for row in rows if int(row["n"]) == 15] == ["all"]
    assert ("adaptive", "relight") in {(row["method"], row["objective"]) for row in rows}
    methods = {(row["method"], float(row["floor_deg"])) for row in rows}
    assert {("optimal", 0.0), ("adaptive", 0.0), ("uniform", 0.0), ("uniform", 30.0)} <= methods
    for row in rows:
        assert 0.0 < float(row["normal_mean_deg"]) < 90.0
        # the median and SSIM are measured (they were NaN in every row), and sensible
        assert 0.0 < float(row["normal_median_deg"]) < 90.0
        assert 0.0 < float(row["relight_ssim"]) <= 1.0
        assert 5.0 < float(row["relight_psnr_db"]) < 80.0
        assert float(row["dome_time_s"]) > 1.0 * int(row["n"])
        assert row["arm_time_s"] == ""  # a replayed dome has no arm: an empty cell, not "nan"
        # which of the .lp's lights the layout took, numbered from 1 (the column was empty)
        took = [int(t) for t in row["lights"].split()]
        assert len(took) == len(set(took)) == int(row["n"]) and 1 <= min(took) <= max(took) <= 18
    for name in ("normal_vs_n.png", "relight_vs_dome_time.png", "summary.md"):
        assert (out / name).stat().st_size > 0
    assert not list(out.glob("*arm_time*"))
    text = (out / "summary.md").read_text()
    assert "--from" in text and "adaptive" in text
    # the summary as printed holds the acquisition's folder whole (rich's markup had taken
    # '[v3]' for a style tag and dropped it)
    assert "Tablet [v3]" in r.output, r.output
    # its command line, pasted into a shell, names the same acquisition and --out (it had
    # written the paths bare, a command that fails where a folder's name has a space, then
    # shlex-quoted, '\udce9' where the name's byte is not UTF-8, which summary.md's write
    # refused)
    found = re.search(r"Command: `([^`]*)`", text)
    assert found is not None
    words = subprocess.run(
        ["bash", "-c", "printf '%s\\0' " + found.group(1)], capture_output=True, check=True
    ).stdout.split(b"\0")[:-1]
    assert words[:3] == [b"rti-rig", b"bench", b"tradeoff"], words
    assert words[words.index(b"--from") + 1] == os.fsencode(acq)
    assert words[words.index(b"--out") + 1] == os.fsencode(out)
    assert "on the same 3 held-out lights for every plan" in text
    # what it is run for, answered first: the fewest lights per target, with a command
    assert text.index("## How many lights this object needs") < text.index("| N |")
    assert "- **Normals within 2°**" in text and "`rti-rig run RIG --out SESSION " in text, text
    # and what the user opens: the fit.rti `rti-rig fit` would write, on the same lights
    assert "**Relighting as `rti-rig fit` writes it**" in text
    for row in rows:
        assert row["file_model"].startswith("hsh"), row
        assert 5.0 < float(row["file_psnr_db"]) < 80.0


def test_every_plan_is_scored_on_the_same_held_out_lights(monkeypatch) -> None:
    """Relighting PSNR compares plans only if it is measured on the same lights for all: each
    plan is scored on one held-out set, fixed before planning, that no plan took."""
    import benchmarks.planner_real_data as real
    from benchmarks.tradeoff_from import run_tradeoff_from

    calls: list[tuple[np.ndarray, np.ndarray]] = []
    evaluate = real.evaluate_scores

    def spy(leds, images, dirs, ref, mask, model, held=None):  # type: ignore[no-untyped-def]
        calls.append((np.asarray(leds), held))
        return evaluate(leds, images, dirs, ref, mask, model, held=held)

    monkeypatch.setattr(real, "evaluate_scores", spy)
    rows, held_names = run_tradeoff_from(ACQ, progress=lambda _m: None)
    assert len(calls) == len(rows) > 10
    held = calls[0][1]
    assert held is not None and len(held) == len(held_names) == 3
    for leds, h in calls:
        np.testing.assert_array_equal(h, held)
        assert not set(leds.tolist()) & set(held.tolist())
    lp_names = [line.split()[0] for line in ACQ.read_text().splitlines()[1:]]
    assert [lp_names[i] for i in held] == held_names


def test_held_out_lights_follow_the_acquisitions_elevations() -> None:
    """One light in each band of equal count by elevation, a sixth of them, the same each run."""
    from benchmarks.tradeoff_from import held_out_lights

    rng = np.random.default_rng(3)
    el = np.radians(np.concatenate([rng.uniform(2, 20, 40), rng.uniform(20, 85, 32)]))
    az = rng.uniform(0, 2 * np.pi, 72)
    dirs = np.stack([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)], axis=1)
    held = held_out_lights(dirs)
    assert len(held) == 12 and len(set(held.tolist())) == 12
    np.testing.assert_array_equal(held, held_out_lights(dirs))
    rank = np.argsort(np.argsort(dirs[:, 2]))  # each light's place by elevation
    assert sorted((rank[held] // 6).tolist()) == list(range(12))  # one per band of 6
    assert len(held_out_lights(dirs[:10])) == 3  # never fewer than 3


@pytest.mark.parametrize("name", ["evaluate", "evaluate_scores"])
def test_a_layout_that_took_a_held_out_light_is_refused(name: str) -> None:
    import benchmarks.planner_real_data as real

    images = np.ones((8, 4, 4), np.float32)
    dirs = np.tile([0.0, 0.0, 1.0], (8, 1))
    with pytest.raises(ValueError, match="held-out"):
        getattr(real, name)(
            np.array([0, 1, 2, 3, 4, 5]), images, dirs, None, None, "ptm", np.array([5, 6])
        )


def test_scores_agree_with_evaluate_and_the_median_is_the_median() -> None:
    """evaluate_scores adds the median and SSIM to evaluate's mean and PSNR, from one fit."""
    from benchmarks.planner_real_data import evaluate, evaluate_scores, reference
    from benchmarks.tradeoff_from import load_acquisition

    images, dirs, _ = load_acquisition(ACQ)
    ref, mask = reference(images, dirs)
    leds, held = np.array([0, 2, 4, 6, 8, 10, 12, 14, 16]), np.array([1, 9, 17])
    sc = evaluate_scores(leds, images, dirs, ref, mask, "ptm", held=held)
    err, psnr, fallback = evaluate(leds, images, dirs, ref, mask, "ptm", held=held)
    assert (sc.normal_mean_deg, sc.relight_psnr_db, sc.fallback) == (err, psnr, fallback)
    assert sc.normal_median_deg < sc.normal_mean_deg  # angle errors have a long upper tail
    assert 0.0 < sc.relight_ssim < 1.0


def test_a_best_floor_of_zero_is_one_line_not_two_on_top_of_each_other() -> None:
    from benchmarks.tradeoff import Row, _series

    def row(floor: float, n: int, err: float) -> Row:
        nan = float("nan")
        return Row("s", "uniform", "normals", n, floor, err, nan, 1.0, "ptm", 20.0, nan, n, nan, 0)

    best_zero = [row(0.0, 6, 3.0), row(0.0, 9, 2.0), row(10.0, 6, 4.0), row(10.0, 9, 3.0)]
    assert list(_series(best_zero, "s")) == ["uniform (floor 0°, also the best here)"]
    best_ten = [row(0.0, 6, 5.0), row(0.0, 9, 4.0), row(10.0, 6, 4.0), row(10.0, 9, 3.0)]
    assert list(_series(best_ten, "s")) == ["uniform", "uniform, floor 10°"]


def test_tradeoff_from_too_small_an_acquisition_is_refused(tmp_path: Path) -> None:
    """Refused only once its images were read, after --out had been created: a refused
    command left an empty folder behind."""
    small = tmp_path / "acq"
    small.mkdir()
    lines = ACQ.read_text().splitlines()[1:10]  # 9 lights: 7 to plan from, 3 held out is 10
    for line in lines:
        name = line.split()[0]
        (small / name).write_bytes((ACQ.parent / name).read_bytes())
    (small / "dirs.lp").write_text("9\n" + "\n".join(lines) + "\n")
    r = CliRunner().invoke(
        app, ["bench", "tradeoff", "--from", str(small / "dirs.lp"), "--out", str(tmp_path / "o")]
    )
    assert r.exit_code == 2 and "at least 10" in r.output and "held out" in r.output
    assert not (tmp_path / "o").exists()  # refused before --out is made: nothing left behind


def test_quick_with_from_is_refused_before_anything_is_written(tmp_path: Path) -> None:
    """--quick did nothing with --from (the run took as long), yet was accepted in silence."""
    r = CliRunner().invoke(
        app, ["bench", "tradeoff", "--quick", "--from", str(ACQ), "--out", str(tmp_path / "o")]
    )
    assert r.exit_code == 2 and "--quick has no effect with --from" in " ".join(r.output.split())
    assert not (tmp_path / "o").exists()


def test_the_summary_and_the_plots_name_the_same_best_floor_even_one_short_of_a_count() -> None:
    """The summary picked its floor on every N a floor served, the plots on the N every floor
    serves: a high floor without the largest N (its lowest error) could be "best" in one and not
    the other, and a best floor without a count had no cell (a KeyError)."""
    from benchmarks.tradeoff import Row, _series
    from benchmarks.tradeoff_from import summarise_from

    nan = float("nan")

    def row(method: str, floor: float, n: int, err: float, objective: str = "normals") -> Row:
        return Row("acq/dirs.lp", method, objective, n, floor, err, err, 1.0, "ptm", 20.0, 0.5,
                   n, nan, 0.0, "hsh1", 20.0)  # fmt: skip

    rows = [row("uniform", 0.0, 6, 5.0), row("uniform", 0.0, 48, 1.0)]
    rows += [row("uniform", 30.0, 6, 4.0)]  # better at 6; no layout of 48 above 30°
    for n in (6, 48):
        rows += [row("optimal", 0.0, n, 3.0), row("adaptive", 0.0, n, 3.0)]
        rows += [row("adaptive", 0.0, n, 3.0, "relight")]
    rows.append(row("all", 0.0, 60, 1.0))
    assert "uniform, floor 30°" in _series(rows, "acq/dirs.lp")
    text = summarise_from(rows, 1.0, "test", ["a.jpg", "b.jpg", "c.jpg"])
    assert "(30°, hindsight)" in text
    assert "no layout: too few lights above 30°" in text


@pytest.mark.parametrize(
    ("listed", "hint"),
    [("image01.JPG", "image01.jpg is there"), ("gone.jpg", "copy them where their names point")],
)
def test_a_missing_image_is_named_with_its_lp_and_what_to_do(
    tmp_path: Path, listed: str, hint: str
) -> None:
    """A missing image (or one listed in another case than the file: ``image01.JPG`` for
    ``image01.jpg``) had been told "cannot read image …: there is no such file", without the
    .lp or the reason, after the other images were read: it is named with the .lp, the count
    and what to do, as run and fit say it, before anything is written."""
    import shutil

    acq = tmp_path / "acq"
    shutil.copytree(ACQ.parent, acq)
    lp = acq / "dirs.lp"
    lp.write_text(lp.read_text().replace("image01.jpg", listed, 1))
    out = tmp_path / "o"
    r = CliRunner().invoke(app, ["bench", "tradeoff", "--from", str(lp), "--out", str(out)])
    text = " ".join(r.output.split())
    assert r.exit_code == 2, r.output
    assert f"{lp}: 1 of 18 image(s) missing in {acq} ({listed})" in text
    assert hint in text
    assert not out.exists() or not any(out.iterdir())


def _acquisition(folder: Path, count: int = 12) -> Path:
    """The first ``count`` lights of the real acquisition (402x395 JPEGs: wider than
    ``MAX_PX``, so the trade-off shrinks them), copied into ``folder``; its ``dirs.lp``."""
    folder.mkdir()
    lines = ACQ.read_text().splitlines()[1 : count + 1]
    for line in lines:
        name = line.split()[0]
        (folder / name).write_bytes((ACQ.parent / name).read_bytes())
    lp = folder / "dirs.lp"
    lp.write_text(f"{count}\n" + "\n".join(lines) + "\n")
    return lp


@pytest.mark.parametrize(
    ("damage", "said"),
    [
        # shrunk to MAX_PX wide like the others, it had been measured in silence
        ("300x295", "image05.jpg is 300x295"),
        ("402x300", "image05.jpg is 402x300"),
        ("grey", "image05.jpg is greyscale"),
    ],
)
def test_an_image_of_another_size_or_kind_is_refused_by_name_before_any_work(
    tmp_path: Path, damage: str, said: str
) -> None:
    """`bench tradeoff --from` checks the images as `run ACQ/dirs.lp` does: one image of
    another size had been read with all the others and told "all input arrays must have the
    same shape" (naming none), or, larger than MAX_PX wide, scaled to fit and measured into a
    full table of results; a greyscale one among colour ones the same."""
    import cv2

    lp = _acquisition(tmp_path / "acq")
    img = cv2.imread(str(lp.parent / "image05.jpg"))
    if damage == "grey":
        img = cv2.cvtColor(img, cv2.COLOR_BGR2GRAY)
    else:
        w, h = (int(v) for v in damage.split("x"))
        img = cv2.resize(img, (w, h), interpolation=cv2.INTER_AREA)
    cv2.imwrite(str(lp.parent / "image05.jpg"), img)
    out = tmp_path / "o"
    r = CliRunner().invoke(app, ["bench", "tradeoff", "--from", str(lp), "--out", str(out)])
    text = " ".join(r.output.split())
    assert r.exit_code == 2, text
    assert text.startswith(f"error: {lp}: the images beside it "), text
    assert said in text and "list only the others" in text, text
    assert "Traceback" not in text and "planning" not in text.lower()
    assert not out.exists()  # not even an empty folder left behind
    # run ACQ/dirs.lp says the same of the same images (one check, shared)
    ran = CliRunner().invoke(app, ["run", str(lp), "--out", str(tmp_path / "s"), "--lights", "6"])
    assert ran.exit_code == 2 and said in " ".join(ran.output.split())
    # and so does fit of the .lp, before decoding any pixel: it had said numpy's words part-way
    # ("images of acq/dirs.lp differ: image05.jpg is (295, 300, 3) uint8, ...")
    fit_out = tmp_path / "f"
    fitted = CliRunner().invoke(app, ["fit", str(lp), "--out", str(fit_out), "--no-qa"])
    fit_text = " ".join(fitted.output.split())
    assert fitted.exit_code == 2, fit_text
    assert fit_text.startswith(f"error: {lp}: the images beside it "), fit_text
    assert said in fit_text and "uint8" not in fit_text, fit_text


def test_two_missing_relative_names_are_said_alike_by_run_bench_and_fit(tmp_path: Path) -> None:
    """An .lp (not a session) two of whose images, named relative to it, are gone: run and
    bench named both in one sentence, but fit stopped at the first ("image acq/image05.jpg
    listed in acq/dirs.lp is missing ..."), naming neither the other nor the way out."""
    lp = _acquisition(tmp_path / "acq", count=8)
    (lp.parent / "image05.jpg").unlink()
    (lp.parent / "image17.jpg").unlink()
    said = (
        f"2 of 8 image(s) missing in {lp.parent} (image05.jpg, image17.jpg); copy them where "
        "their names point, or remove their lines from the .lp to"
    )
    for command, verb in (
        (["run", str(lp), "--out", str(tmp_path / "s"), "--lights", "6"], "replay"),
        (["bench", "tradeoff", "--from", str(lp), "--out", str(tmp_path / "o")], "measure"),
        (["fit", str(lp), "--out", str(tmp_path / "f"), "--no-qa"], "fit"),
    ):
        r = CliRunner().invoke(app, command)
        text = " ".join(r.output.split())
        assert r.exit_code == 2, text
        assert text.startswith(f"error: {lp}: "), text
        assert f"{said} {verb} the others" in text, (command[0], text)
        assert "Traceback" not in text


def test_absolute_names_whose_files_are_there_are_said_so_by_bench_run_and_fit(
    tmp_path: Path,
) -> None:
    """An .lp naming its images by absolute paths where the files are: they are read beside
    the .lp (by design), but run, fit and bench had called them "missing" and said "copy them
    where their names point" (bench, run) or "read relative to its own folder" (fit). All
    three now say that they are at those paths, and the two ways out, in one wording."""
    src = _acquisition(tmp_path / "acq")
    lines = src.read_text().splitlines()
    elsewhere = tmp_path / "t13"
    elsewhere.mkdir()
    lp = elsewhere / "abs.lp"
    lp.write_text("\n".join([lines[0], *(f"{src.parent}/{line}" for line in lines[1:])]) + "\n")
    said = (
        "all of them exist at the path the .lp names, but an .lp's images are read beside it: "
        "an absolute name (a path on the machine that wrote the .lp) is looked for by its "
        "trailing folders and file name under the .lp's folder (sub/IMG.JPG, then IMG.JPG), "
        "then in a jpeg-exports folder beside it or beside its folder; copy "
        f"them into {elsewhere}, or write an .lp whose names are relative to its folder"
    )
    commands = {
        "bench": ["bench", "tradeoff", "--from", str(lp), "--out", str(tmp_path / "b")],
        "run": ["run", str(lp), "--out", str(tmp_path / "s"), "--lights", "6"],
        "fit": ["fit", str(lp), "--out", str(tmp_path / "f")],
    }
    for command, args in commands.items():
        r = CliRunner().invoke(app, args)
        text = " ".join(r.output.split())
        assert r.exit_code == 2, (command, text)
        assert f"12 of 12 image(s) missing in {elsewhere} ({src.parent}/image01.jpg" in text
        assert said in text, (command, text)
        assert "where their names point" not in text and "Traceback" not in text
    # a name at no such path is told where it is looked for, and to copy it there
    lp.write_text(lp.read_text().replace(str(src.parent), "/nowhere/at/all"))
    r = CliRunner().invoke(app, commands["bench"])
    text = " ".join(r.output.split())
    assert "exist at the path" not in text and f"copy them into {elsewhere}" in text


def test_absolute_names_at_no_such_path_are_told_to_copy_them_beside_the_lp(
    tmp_path: Path,
) -> None:
    """An .lp naming ``/nonexist/x/image01.jpg`` … had been told that an absolute name "is
    looked for by its file name beside the .lp", then to "copy them where their names point"
    (which leads only to "exists at the path the .lp names, but … read beside it"), and with
    every image missing to "remove their lines from the .lp to fit the others", of none.
    fit and bench tradeoff --from now say to copy them into the .lp's folder, and offer to
    remove their lines only when other images remain."""
    src = _acquisition(tmp_path / "acq")
    lines = src.read_text().splitlines()
    elsewhere = tmp_path / "t13"
    elsewhere.mkdir()
    lp = elsewhere / "abs.lp"
    lp.write_text("\n".join([lines[0], *(f"/nonexist/x/{line}" for line in lines[1:])]) + "\n")
    looked_for = (
        "an absolute name (a path on the machine that wrote the .lp) is looked for by its "
        "trailing folders and file name under the .lp's folder (sub/IMG.JPG, then IMG.JPG), "
        "then in a jpeg-exports folder beside it or beside its folder"
    )
    commands = {
        "fit": ["fit", str(lp), "--out", str(tmp_path / "f")],
        "bench": ["bench", "tradeoff", "--from", str(lp), "--out", str(tmp_path / "b")],
    }
    for command, args in commands.items():
        r = CliRunner().invoke(app, args)
        text = " ".join(r.output.split())
        assert r.exit_code == 2, (command, text)
        assert f"12 of 12 image(s) missing in {elsewhere} (/nonexist/x/image01.jpg" in text
        assert text.endswith(f"{looked_for}; copy them into {elsewhere}"), (command, text)
        assert "where their names point" not in text and "remove their lines" not in text
    # one of them missing (the others beside their .lp): its line may be removed, too
    (src.parent / "image01.jpg").unlink()
    src.write_text(src.read_text().replace("image01.jpg", "/nonexist/x/image01.jpg", 1))
    commands = {
        "fit": ["fit", str(src), "--out", str(tmp_path / "f")],
        "bench": ["bench", "tradeoff", "--from", str(src), "--out", str(tmp_path / "b")],
    }
    for command, verb in (("fit", "fit"), ("bench", "measure")):
        r = CliRunner().invoke(app, commands[command])
        text = " ".join(r.output.split())
        assert r.exit_code == 2, (command, text)
        assert f"1 of 12 image(s) missing in {src.parent} (/nonexist/x/image01.jpg)" in text
        assert text.endswith(
            f"{looked_for}; copy them into {src.parent}, or remove their lines from the .lp "
            f"to {verb} the others"
        ), (command, text)


def test_an_out_that_is_a_file_is_refused_as_a_file(tmp_path: Path) -> None:
    """`--out S_lin.lp` (a file) had been told "cannot write there (File exists: S_lin.lp);
    choose a folder you can write to", as if it were a matter of permissions."""
    lp = _acquisition(tmp_path / "acq")
    a_file = tmp_path / "S_lin.lp"
    a_file.write_text("12\n")
    r = CliRunner().invoke(app, ["bench", "tradeoff", "--from", str(lp), "--out", str(a_file)])
    text = " ".join(r.output.split())
    assert r.exit_code == 2 and f"--out {a_file} is a file: give a folder" in text, text
    assert a_file.read_text() == "12\n"
    r = CliRunner().invoke(
        app, ["bench", "tradeoff", "--from", str(lp), "--out", str(a_file / "sub")]
    )
    text = " ".join(r.output.split())
    assert r.exit_code == 2, text
    assert f"--out {a_file / 'sub'}: {a_file} is a file, not a folder: give a folder" in text


def test_a_batch_fit_whose_out_is_a_file_is_refused_as_a_file(tmp_path: Path) -> None:
    """`fit A/dirs.lp B/dirs.lp --out FILE` had been told "cannot create the batch folder
    (File exists); choose a folder you can write to" (its own mkdir), as if a matter of
    permissions, where the bench says that --out is a file."""
    sources = [str(_acquisition(tmp_path / name, 6)) for name in ("a", "b")]
    a_file = tmp_path / "S_lin.lp"
    a_file.write_text("12\n")
    for out, said in (
        (a_file, f"--out {a_file} is a file: give a folder"),
        (a_file / "sub", f"--out {a_file / 'sub'}: {a_file} is a file, not a folder: give a"),
    ):
        r = CliRunner().invoke(app, ["fit", *sources, "--out", str(out)])
        text = " ".join(r.output.split())
        assert r.exit_code == 2 and said in text, text
        assert "batch folder" not in text
    assert a_file.read_text() == "12\n"


def test_a_batch_fit_whose_out_takes_no_file_is_refused_once_by_its_name(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A read-only --out (an empty read-only mount) had failed each session on its own hidden
    partial folder ("--out OUT/.a.5928-a1d00730.partial: cannot write there"), and the batch
    ended as if the others had fitted. The tests run as root, whom modes do not stop: the new
    file in --out is refused as a read-only file system refuses it."""
    import errno
    import tempfile

    sources = [str(_acquisition(tmp_path / name, 6)) for name in ("a", "b")]
    out = tmp_path / "ro"
    out.mkdir()
    real = tempfile.mkstemp

    def read_only(*args: object, **kwargs: object) -> tuple[int, str]:
        if Path(str(kwargs.get("dir", ""))) == out:
            raise OSError(errno.EROFS, "Read-only file system")
        return real(*args, **kwargs)  # type: ignore[call-overload, no-any-return]

    monkeypatch.setattr(tempfile, "mkstemp", read_only)
    r = CliRunner().invoke(app, ["fit", *sources, "--out", str(out)], terminal_width=400)
    text = " ".join(r.output.split())
    assert r.exit_code == 2, text
    assert text.count(f"--out {out}: cannot write there") == 1, text
    assert "Read-only file system" in text and ".partial" not in text, text
    assert list(out.iterdir()) == []


def test_an_out_the_user_may_not_look_into_is_refused_by_name(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """`--out /root/x/y` for a user who may not look into /root: on Python 3.11 the check of
    whether it exists raises PermissionError (it does not say False), which had reached the
    user as a traceback from bench, a single fit (and the file check of a fit's batch folder). The
    tests run as root, whom modes do not stop: ``os.stat`` is made to refuse as for them."""
    import errno
    import os

    locked = tmp_path / "locked"
    locked.mkdir()
    real_stat = os.stat

    def stat(path: object, *args: object, **kwargs: object) -> os.stat_result:
        if str(path).startswith(f"{locked}{os.sep}"):
            raise PermissionError(errno.EACCES, os.strerror(errno.EACCES), str(path))
        return real_stat(path, *args, **kwargs)  # type: ignore[arg-type]

    lp = _acquisition(tmp_path / "acq", 6)
    other = _acquisition(tmp_path / "acq2", 6)
    enough = _acquisition(tmp_path / "acq3")  # bench refuses 6 lights before it sees --out
    out = locked / "x" / "y"
    monkeypatch.setattr(os, "stat", stat)
    for args in (
        ["bench", "tradeoff", "--from", str(enough), "--out", str(out)],
        ["fit", str(lp), str(other), "--out", str(out)],
        ["fit", str(lp), "--out", str(out)],
    ):
        r = CliRunner().invoke(app, args)
        text = " ".join(r.output.split())
        assert r.exit_code == 2, (args[0], text, r.exception)
        assert f"--out {out}: cannot write there (Permission denied: {out})" in text, text
        assert "choose a folder you can write to" in text
    monkeypatch.undo()
    assert not out.exists()


def test_the_write_probe_leaves_a_users_files_in_out_alone(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The probe that proves --out writable was a file of a fixed name, ".rti-rig-write-test":
    in a folder given with --force, a user's file of that name was replaced, then deleted (and
    two commands probing one folder at once could delete each other's probe). The trade-off
    itself is a stand-in: what is checked happens before it, as the command runs."""
    import benchmarks.tradeoff_from as tradeoff_from

    lp = _acquisition(tmp_path / "acq")
    out = tmp_path / "o"
    out.mkdir()
    mine = {".rti-rig-write-test": "mine\n", ".rti-rig-write-test-x": "also mine\n"}
    for name, text in mine.items():
        (out / name).write_text(text)
    seen: list[list[str]] = []

    def bench_from(lp: Path, out_dir: Path | None, *args: object, **kwargs: object) -> str:
        assert out_dir is not None
        seen.append(sorted(p.name for p in out_dir.iterdir()))
        return "stand-in summary"

    monkeypatch.setattr(tradeoff_from, "bench_from", bench_from)
    r = CliRunner().invoke(
        app, ["bench", "tradeoff", "--from", str(lp), "--out", str(out), "--force"]
    )
    assert r.exit_code == 0 and "stand-in summary" in r.output, r.output
    assert seen == [sorted(mine)]  # the probe was there and gone before the trade-off ran
    assert {p.name: p.read_text() for p in out.iterdir()} == mine


def test_what_the_tolerant_reader_did_to_the_lp_is_said_as_run_and_fit_say_it(
    tmp_path: Path,
) -> None:
    """A count line that disagrees with the lines listed, and a light a hair below the horizon
    (clamped to it), are kept and *said* by run, check, plan and fit, naming the file and the
    line; `bench tradeoff --from` measured such a file in silence, the clamped light's
    direction changed without a word."""
    lp = _acquisition(tmp_path / "acq")
    lines = lp.read_text().splitlines()
    name, x, y, _z = lines[3].split()
    flat = float(np.hypot(float(x), float(y)))  # its azimuth kept, at the horizon's noise
    lines[0] = "11"  # 12 lights listed
    lines[3] = f"{name} {float(x) / flat:.6f} {float(y) / flat:.6f} -0.002"
    lp.write_text("\n".join(lines) + "\n")
    r = CliRunner().invoke(app, ["bench", "tradeoff", "--from", str(lp)])
    text = " ".join(r.output.split())
    assert r.exit_code == 0, text
    assert f"note: {lp}, line 1: count line says 11 lights but the file lists 12" in text, text
    assert f"note: {lp}, line 4: light z = -0.0020 is a hair below the object plane" in text
    assert "clamped to z = 0" in text
    # the same words as fit of the same .lp (one reader, one wording)
    fitted = CliRunner().invoke(app, ["fit", str(lp), "--out", str(tmp_path / "f"), "--no-qa"])
    assert fitted.exit_code == 0, fitted.output
    assert f"{lp}, line 4: light z = -0.0020" in " ".join(fitted.output.split())


def _refused_as_out(lp: Path, out: Path) -> str:
    """``bench tradeoff --from lp --out out --force``, checked refused as an ``--out`` that
    holds the acquisition, nothing in ``out`` added or removed: its words (one line)."""
    before = sorted(p.name for p in out.iterdir())
    r = CliRunner().invoke(
        app, ["bench", "tradeoff", "--from", str(lp), "--out", str(out), "--force"]
    )
    text = " ".join(r.output.split())
    assert r.exit_code == 2, text
    assert f"error: --out {out} holds the acquisition --from reads" in text, text
    assert sorted(p.name for p in out.iterdir()) == before
    return text


@pytest.mark.parametrize("where", ["lp", "images"])
def test_the_acquisitions_own_folder_is_refused_as_out_even_with_force(
    tmp_path: Path, where: str
) -> None:
    """`--out` the folder of the `--from` acquisition (its .lp's, or its images', as in
    RTIBuilder's assembly-files/ and jpeg-exports/) with `--force` had written results.csv,
    summary.md and four PNG plots among the recorded images (which RTIBuilder imports by
    folder), as a session's folder is never written into: refused, nothing written."""
    lp = _acquisition(tmp_path / "acq")
    if where == "images":  # RTIBuilder's layout: absolute names, images in ../jpeg-exports
        images = tmp_path / "acq" / "jpeg-exports"
        images.mkdir()
        lines = lp.read_text().splitlines()
        for i, line in enumerate(lines[1:], start=1):
            name, rest = line.split(maxsplit=1)
            (lp.parent / name).rename(images / name)
            lines[i] = f"H:\\RTI\\proj\\jpeg-exports\\{name} {rest}"
        (tmp_path / "acq" / "assembly-files").mkdir()
        lp.unlink()
        lp = tmp_path / "acq" / "assembly-files" / "dirs.lp"
        lp.write_text("\n".join(lines) + "\n")
        out = images
    else:
        out = lp.parent
    text = _refused_as_out(lp, out)
    assert "even with --force" in text and "choose another folder" in text


def test_a_folder_of_links_to_the_acquisitions_images_is_refused_as_out_even_with_force(
    tmp_path: Path,
) -> None:
    """Images linked into a project's jpeg-exports/ from where the shots lie (a card's copy),
    the `.lp` in assembly-files/: the refusal compared `--out` with the folders the links
    resolve to only, so `--out` jpeg-exports/ with `--force` wrote results.csv, summary.md and
    the plots among the linked images (which RTIBuilder imports by folder). Both folders are
    refused: the one the links are listed in (jpeg-exports/), and the one they resolve to
    (the card's copy, where the images themselves lie)."""
    shots = _acquisition(tmp_path / "card").parent
    project = tmp_path / "project"
    (project / "jpeg-exports").mkdir(parents=True)
    (project / "assembly-files").mkdir()
    lines = (shots / "dirs.lp").read_text().splitlines()
    for i, line in enumerate(lines[1:], start=1):
        name, rest = line.split(maxsplit=1)
        (project / "jpeg-exports" / name).symlink_to(shots / name)
        lines[i] = f"H:\\RTI\\project\\jpeg-exports\\{name} {rest}"  # RTIBuilder's
    lp = project / "assembly-files" / "dirs.lp"
    lp.write_text("\n".join(lines) + "\n")
    links = list((project / "jpeg-exports").iterdir())
    assert links and all(p.is_symlink() for p in links)
    _refused_as_out(lp, project / "jpeg-exports")
    _refused_as_out(lp, shots)  # the links' targets: only the links, resolved, name it


@pytest.mark.parametrize("ns", [(6, 9, 12, 13), (4, 6, 9, 12, 18, 24, 36, 48)])
def test_the_plots_x_axes_read_as_plain_numbers_that_do_not_overlap(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, ns: tuple[int, ...]
) -> None:
    """An acquisition of 16 lights plots N = 6…13, less than a decade on a log axis: its ticks
    were labelled "6×10⁰ 7×10⁰ 8×10⁰ 9×10⁰", run into one another. Every figure's x labels are
    plain numbers, at least two of them, none overlapping another."""
    from matplotlib.figure import Figure

    from benchmarks.tradeoff import Row, plot

    seen: list[tuple[list[str], list[Any]]] = []  # each figure's x labels and their boxes
    savefig = Figure.savefig

    def keep(fig: Figure, *args, **kwargs):  # type: ignore[no-untyped-def]
        result = savefig(fig, *args, **kwargs)  # drawn: the labels and their extents are set
        ax = fig.axes[0]
        lo, hi = ax.get_xlim()
        labels = [
            t
            for t in ax.get_xticklabels(which="both")
            if t.get_visible() and t.get_text() and lo <= t.get_position()[0] <= hi
        ]
        renderer = fig.canvas.get_renderer()
        seen.append(
            ([t.get_text() for t in labels], [t.get_window_extent(renderer) for t in labels])
        )
        return result

    monkeypatch.setattr(Figure, "savefig", keep)
    nan = float("nan")

    def row(method: str, n: int) -> Row:  # arm times differ by method, as in a simulated run
        arm_s = 2.3 * n + (method == "optimal")
        return Row("acq", method, "normals", n, 0.0, 1 / n, nan, 1.0, "ptm", 20.0 + n, nan,
                   1.17 * n, arm_s, 0.0)  # fmt: skip

    rows = [row(method, n) for method in ("uniform", "optimal") for n in ns]
    paths = plot(rows, tmp_path)
    assert len(seen) == len(paths) == 6
    for (texts, boxes), path in zip(seen, paths, strict=True):
        assert len(texts) >= 2, (path.name, texts)
        for text in texts:
            float(text)  # "8", "10", "15": not "$\\mathdefault{8\\times10^{0}}$"
        boxes = sorted(boxes, key=lambda b: b.x0)
        for a, b in itertools.pairwise(boxes):
            assert a.x1 <= b.x0, (path.name, texts)


@pytest.mark.parametrize(
    ("layout", "said"),
    [
        ("azimuth", "lights at one azimuth"),  # every light in one upright plane
        ("horizon", "the horizon"),  # every light at z = 0.0005
    ],
)
def test_lights_that_cannot_give_reference_normals_are_refused_by_name(
    tmp_path: Path, layout: str, said: str
) -> None:
    """The trade is scored against normals fitted on every light; lights that give none had
    reached the user as the solver's "ill-conditioned ... (from Python,
    ill_conditioned='regularise' fits it regularised)", naming no file, after --out was made."""
    lp = _acquisition(tmp_path / "acq")
    names = [line.split()[0] for line in lp.read_text().splitlines()[1:]]
    if layout == "azimuth":
        el = np.radians(np.linspace(10.0, 80.0, len(names)))
        dirs = np.stack([np.cos(el), np.zeros_like(el), np.sin(el)], axis=1)
    else:
        az = np.linspace(0.0, 2.0 * np.pi, len(names), endpoint=False)
        dirs = np.stack([np.cos(az), np.sin(az), np.full_like(az, 0.0005)], axis=1)
        dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    dirs = np.clip(dirs, -0.999999, 0.999999)
    lp.write_text(
        f"{len(names)}\n"
        + "".join(
            f"{n} {x:.6f} {y:.6f} {z:.6f}\n" for n, (x, y, z) in zip(names, dirs, strict=True)
        )
    )
    out = tmp_path / "o"
    r = CliRunner().invoke(app, ["bench", "tradeoff", "--from", str(lp), "--out", str(out)])
    text = " ".join(r.output.split())
    assert r.exit_code == 2, text
    assert f"{lp}: the 12 lights cannot determine a surface normal" in text
    assert said in text and "several elevations and azimuths" in text
    assert "from Python" not in text and "Traceback" not in text
    assert not out.exists()  # refused before --out is made


def test_the_fits_trust_notes_are_sentences_said_once(tmp_path: Path) -> None:
    """Lights low on the horizon regularise the richer bases: their notes had led with the
    warning's Python class name ("RegularisedFitWarning: hsh1 fit ...") and come twice."""
    lp = _acquisition(tmp_path / "acq", 18)
    names = [line.split()[0] for line in lp.read_text().splitlines()[1:]]
    az = np.linspace(0.0, 2.0 * np.pi, len(names), endpoint=False)
    el = np.radians(np.where(np.arange(len(names)) % 2, 8.0, 22.0))
    dirs = np.stack([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)], axis=1)
    lp.write_text(
        f"{len(names)}\n"
        + "".join(
            f"{n} {x:.6f} {y:.6f} {z:.6f}\n" for n, (x, y, z) in zip(names, dirs, strict=True)
        )
    )
    r = CliRunner().invoke(app, ["bench", "tradeoff", "--from", str(lp)])
    assert r.exit_code == 0, r.output
    notes = [line for line in r.output.splitlines() if line.startswith("note:")]
    assert any("fit ridge-regularised" in n for n in notes), r.output  # the premise
    assert not [n for n in notes if "Warning" in n], notes
    assert len(notes) == len(set(notes)), notes


def test_a_stop_during_the_trade_on_an_acquisition_says_nothing_was_written(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A Ctrl-C during `bench tradeoff --from --out` says the --out holds nothing of it (it is
    written at the end), exit 130: only "stopped (Ctrl-C)" had been said, the folder left
    empty. The trade-off is a stand-in stopped midway."""
    import benchmarks.tradeoff_from as tradeoff_from

    lp = _acquisition(tmp_path / "acq")

    def bench_from(*_args: object, **_kwargs: object) -> str:
        raise KeyboardInterrupt

    monkeypatch.setattr(tradeoff_from, "bench_from", bench_from)
    out = tmp_path / "my out"
    r = CliRunner().invoke(app, ["bench", "tradeoff", "--from", str(lp), "--out", str(out)])
    assert r.exit_code == 130, r.output
    said = " ".join(r.output.split())
    assert (
        f"Stopped (Ctrl-C) during the trade on {shown_path(lp)}: nothing written to "
        f"{shown_path(out)} (its results are written once every layout is measured)" in said
    ), said
    # the folder the run made for its results is not left behind, empty: the same command run
    # again had met a folder it had made itself
    assert not out.exists()
    nested = tmp_path / "new" / "deeper"
    r = CliRunner().invoke(app, ["bench", "tradeoff", "--from", str(lp), "--out", str(nested)])
    assert r.exit_code == 130, r.output
    assert not (tmp_path / "new").exists()
    # a folder that was there before stays, and so does anything in it
    (kept := tmp_path / "kept").mkdir()
    (kept / "mine.txt").write_text("x", encoding="utf-8")
    r = CliRunner().invoke(
        app, ["bench", "tradeoff", "--from", str(lp), "--out", str(kept), "--force"]
    )
    assert r.exit_code == 130, r.output
    assert (kept / "mine.txt").read_text(encoding="utf-8") == "x"
    (kept / "mine.txt").unlink()
    r = CliRunner().invoke(app, ["bench", "tradeoff", "--from", str(lp), "--out", str(kept)])
    assert r.exit_code == 130, r.output
    assert kept.is_dir()


def test_the_trades_seconds_a_light_are_the_replayed_runs(tmp_path: Path) -> None:
    """The trade's time axis (n x PER_LIGHT_S) is what `rti-rig run ACQ/dirs.lp` itself says
    its session takes on the replayed dome: the two had been kept equal by hand."""
    import re

    from benchmarks.tradeoff_from import PER_LIGHT_S

    r = CliRunner().invoke(
        app, ["run", str(ACQ), "--out", str(tmp_path / "s"), "--lights", "6"], terminal_width=300
    )
    assert r.exit_code == 0, r.output
    said = re.search(r"Session time on the real rig: ([0-9.]+) s", r.output)
    assert said is not None, r.output
    assert abs(float(said.group(1)) - 6 * PER_LIGHT_S) <= 0.051, (said.group(0), PER_LIGHT_S)


def _stand_in_rows() -> tuple[list[Any], list[str]]:
    """Rows as run_tradeoff_from gives them (replayed-dome times), for the plumbing tests."""
    from benchmarks.tradeoff import Row
    from benchmarks.tradeoff_from import PER_LIGHT_S

    nan = float("nan")

    def row(method: str, n: int, objective: str = "normals") -> Row:
        return Row("acq/dirs.lp", method, objective, n, 0.0, 3.0, 3.0, 1.0, "ptm", 20.0, 0.5,
                   n * PER_LIGHT_S, nan, 0.0, "hsh1", 20.0)  # fmt: skip

    rows = [row(m, n) for n in (6, 9) for m in ("uniform", "optimal", "adaptive")]
    rows += [row("adaptive", n, "relight") for n in (6, 9)] + [row("all", 15)]
    return rows, ["a.jpg", "b.jpg", "c.jpg"]


def _slow_transfer_dome(rig: Path) -> tuple[Path, float]:
    """The shipped simulated dome's config with a 2.5 s transfer, written to ``rig``, and the
    time one light takes on it (its [timing] and exposure summed as a dry run sums them)."""
    import re

    from rti_rig.app.config import load_rig_config

    shipped = Path(__file__).resolve().parents[2] / "rig_configs" / "simulated_dome.toml"
    text = shipped.read_text(encoding="utf-8")
    mine = re.sub(r"(?m)^transfer_s = 0\.7 ", "transfer_s = 2.5 ", text, count=1)
    assert mine != text
    rig.write_text(mine, encoding="utf-8")
    cfg = load_rig_config(rig).config
    t = cfg.timing
    step = t.light_switch_s + t.settle_s + cfg.camera.exposure_s + t.readout_s + t.transfer_s
    assert t.transfer_s == 2.5 and step > 2.5
    return rig, step


def _trade_with_rig(rig: Path, out: Path) -> list[dict[str, str]]:
    """`rti-rig bench tradeoff --from ACQ --rig RIG --out OUT`, which must succeed; the rows of
    its results.csv."""
    r = CliRunner().invoke(
        app,
        ["bench", "tradeoff", "--from", str(ACQ), "--rig", str(rig), "--out", str(out)],
        terminal_width=400,
    )
    assert r.exit_code == 0, r.output
    return list(csv.DictReader((out / "results.csv").open()))


def test_rig_gives_the_trades_session_time_from_the_users_dome(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """`bench tradeoff --from ACQ --rig MY_DOME.toml`: the time axis is the user's dome's step
    (its [timing] and exposure), in results.csv, the summary and its command line; it had
    always been the replayed dome's defaults, 1.17 s a light, where a DSLR dome takes seconds."""
    import shlex

    import benchmarks.tradeoff_from as tradeoff_from

    monkeypatch.setattr(tradeoff_from, "run_tradeoff_from", lambda lp, progress: _stand_in_rows())
    rig, step = _slow_transfer_dome(tmp_path / "my dome.toml")
    out = tmp_path / "o"
    rows = _trade_with_rig(rig, out)
    for row in rows:
        assert float(row["dome_time_s"]) == pytest.approx(int(row["n"]) * step), row
    summary = (out / "summary.md").read_text(encoding="utf-8")
    assert f"{step:.2f} s a light (" in summary and "transfer_s 2.5" in summary, summary
    assert f"| 9 | {9 * step:.0f} |" in summary, summary
    command = summary.split("Command: `")[1].split("`")[0]
    words = shlex.split(command)
    assert words[words.index("--rig") + 1] == str(rig), command


def test_rig_config_is_read_once_the_time_is_that_of_the_config_checked(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The CLI reads --rig before minutes of computing; the trade's time axis is that reading.
    A config edited after that check (or turned invalid) had been read again once the
    acquisition was checked, and timed the trade by another config than the one checked."""
    import benchmarks.tradeoff_from as tradeoff_from

    rig, step = _slow_transfer_dome(tmp_path / "dome.toml")

    checked = tradeoff_from.check_acquisition

    def check_and_edit(lp: Path, notes: list[str]) -> list[Path]:
        found = checked(lp, notes)
        rig.write_text("this is not a rig config\n", encoding="utf-8")  # after --rig's check
        return found

    monkeypatch.setattr(tradeoff_from, "check_acquisition", check_and_edit)
    monkeypatch.setattr(tradeoff_from, "run_tradeoff_from", lambda lp, progress: _stand_in_rows())
    out = tmp_path / "o"
    rows = _trade_with_rig(rig, out)
    assert rows
    for row in rows:
        assert float(row["dome_time_s"]) == pytest.approx(int(row["n"]) * step), row


def test_rig_is_refused_for_an_arm_and_without_from_before_any_work(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """An arm's session time depends on its moves (not planned by the trade on an acquisition),
    and --rig without --from has nothing to time: each refused by name, nothing run or made."""
    import benchmarks.tradeoff_from as tradeoff_from

    def ran(*_a: object, **_k: object) -> None:
        raise AssertionError("the trade ran")

    monkeypatch.setattr(tradeoff_from, "run_tradeoff_from", ran)
    arm = Path(__file__).resolve().parents[2] / "rig_configs" / "virtual_arm.toml"
    out = tmp_path / "o"
    r = CliRunner().invoke(
        app,
        ["bench", "tradeoff", "--from", str(ACQ), "--rig", str(arm), "--out", str(out)],
        terminal_width=400,
    )
    said = " ".join(r.output.split())
    assert r.exit_code == 2 and "is an arm's config" in said and "Traceback" not in said, said
    assert not out.exists()
    r = CliRunner().invoke(app, ["bench", "tradeoff", "--rig", str(arm)], terminal_width=400)
    said = " ".join(r.output.split())
    assert r.exit_code == 2 and "it goes with --from ACQ/dirs.lp" in said, said
