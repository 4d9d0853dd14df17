"""An RTIBuilder project folder (or its jpeg-exports) given where an acquisition goes (`fit`,
`run`, `check`, `bench tradeoff --from`).

RTIBuilder keeps a project's .lp in ``assembly-files/`` and its images in ``jpeg-exports/``;
the project folder is what a user sees as the acquisition. `fit PROJECT` had said it "holds
no .lp file", `run PROJECT` and `check PROJECT` named no .lp to give, and `bench tradeoff
--from PROJECT` said "a folder with no .lp file"; and so of its jpeg-exports folder, where a
user sees the images.
"""

from __future__ import annotations

import json
import shlex
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()
LIGHTS = 8
#: the folders of a project a user may give for the acquisition: the project, its images
GIVEN = pytest.mark.parametrize("given", [".", "jpeg-exports"])


def _project(root: Path, lights: int = LIGHTS) -> Path:
    """A tiny RTIBuilder project (``lights`` lights, 64x48 JPEGs; the .lp with absolute Windows
    names, a BOM and CRLF, as RTIBuilder writes it), in a folder whose name has a space; its
    .lp."""
    import cv2

    project = root / "icon RTI"
    (project / "assembly-files").mkdir(parents=True)
    (project / "jpeg-exports").mkdir()
    yy, xx = np.mgrid[0:48, 0:64]
    nx, ny = (xx - 32) / 100, (yy - 24) / 100
    nz = np.sqrt(1 - nx**2 - ny**2)
    lines = []
    for i in range(lights):
        az, el = 2 * np.pi * i / lights, np.radians(20 + 50 * (i % 2))
        d = (np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el))
        shade = np.clip(nx * d[0] + ny * d[1] + nz * d[2], 0, 1) * 220
        name = f"icon_{i + 1:02d}.JPG"
        assert cv2.imwrite(str(project / "jpeg-exports" / name), np.dstack([shade] * 3))
        xyz = " ".join(f"{c:.6f}" for c in d)
        lines.append(f"C:\\RTI\\icon RTI\\jpeg-exports\\{name} {xyz}")
    lp = project / "assembly-files" / "icon.lp"
    lp.write_bytes(("\ufeff" + "\r\n".join([str(lights), *lines]) + "\r\n").encode())
    return lp


@GIVEN
def test_fit_of_an_rtibuilder_project_folder_fits_its_assembly_files_lp(
    tmp_path: Path, given: str
) -> None:
    lp = _project(tmp_path)
    out = tmp_path / "fit"
    folder = str(lp.parents[1] / given)
    r = runner.invoke(app, ["fit", folder, "--out", str(out), "--no-qa", "--model", "ps"])
    said = " ".join(r.output.split())
    assert r.exit_code == 0, said
    assert f"fitted from {lp} (RTIBuilder's layout)" in said
    assert json.loads((out / "fit.json").read_text())["read"] == f"{LIGHTS} images from {lp}"


def test_run_of_an_rtibuilder_project_folder_replays_its_one_lp_and_resumes(
    tmp_path: Path,
) -> None:
    """`run PROJECT` had been refused, naming the .lp to give; it replays that .lp, says so,
    keeps the .lp in the manifest (a bare `--resume` finds it), and `run PROJECT --resume`
    continues a session it began."""
    from rti_rig.app.usecases.session import NewSessionRequest
    from rti_rig.runtime.controller import FinishReason
    from tests.conftest import cut_new_session

    lp = _project(tmp_path, lights=4)
    project = lp.parents[1]
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", str(project), "--out", str(out)])
    said = " ".join(r.output.split())
    assert r.exit_code == 0, said
    assert f"replaying its light list assembly-files/icon.lp ({shlex.quote(str(lp))})" in said
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["rig"]["config_path"] == str(lp.resolve()), manifest["rig"]
    assert len(list(out.glob("image_*.jpg"))) == 4

    cut = tmp_path / "cut"
    run = cut_new_session(NewSessionRequest(project, cut, lights=4), after_step=1)
    assert run.finish_reason is FinishReason.CANCELLED
    r = runner.invoke(app, ["run", str(project), "--resume", str(cut)])
    said = " ".join(r.output.split())
    assert r.exit_code == 0, said
    assert "4 image(s) in the session" in said, said
    assert json.loads((cut / "manifest.json").read_text())["rig"]["config_path"] == str(
        lp.resolve()
    )


def test_fit_json_records_the_lp_read_by_its_absolute_path(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """fit.json's "read" had kept the path as given ('8 images from ../assembly-files/icon.lp'),
    which names nothing to a user reading it from elsewhere later: it is the absolute path, as
    the manifest records its paths; "source" stays the argument as given. lights.dome's label
    is the same absolute path."""
    lp = _project(tmp_path)
    monkeypatch.chdir(lp.parents[1] / "jpeg-exports")
    given = "../assembly-files/icon.lp"
    r = runner.invoke(app, ["fit", given, "--out", "fit", "--no-qa", "--model", "ps"])
    assert r.exit_code == 0, r.output
    summary = json.loads((lp.parents[1] / "jpeg-exports" / "fit" / "fit.json").read_text())
    assert summary["read"] == f"{LIGHTS} images from {lp}", summary["read"]
    assert summary["source"] == given
    # lights.dome's label likewise (it had kept the relative path)
    dome = json.loads((lp.parents[1] / "jpeg-exports" / "fit" / "lights.dome").read_text())
    assert dome["label"] == str(lp), dome["label"]


@GIVEN
def test_check_and_plan_of_an_rtibuilder_project_folder_take_its_one_lp(
    tmp_path: Path, given: str
) -> None:
    lp = _project(tmp_path, lights=4)
    folder = str(lp.parents[1] / given)
    r = runner.invoke(app, ["check", folder])
    said = " ".join(r.output.split())
    assert r.exit_code == 0 and "RESULT: PASS" in said, said
    # check replays nothing: it had said "replaying its light list"
    assert f"checking its light list {'../' if given != '.' else ''}assembly-files/icon" in said
    assert "replaying" not in said, said
    plan = tmp_path / "plan.lp"
    r = runner.invoke(app, ["plan", "--rig", folder, "--lights", "4", "--out", str(plan)])
    said = " ".join(r.output.split())
    assert r.exit_code == 0, said
    assert "planning on its light list" in said and "on a dome of 4 LEDs" in said, said
    assert "replaying" not in said, said


def test_a_project_folder_with_several_lps_is_refused_naming_each_to_paste(
    tmp_path: Path,
) -> None:
    lp = _project(tmp_path, lights=4)
    other = lp.with_name("icon (old).lp")
    other.write_bytes(lp.read_bytes())
    project = str(lp.parents[1])
    for command in (
        ["run", project, "--out", str(tmp_path / "s")],
        ["check", project],
        ["plan", "--rig", project, "--out", str(tmp_path / "p.lp")],
    ):
        r = runner.invoke(app, command)
        said = " ".join(r.output.split())
        assert r.exit_code == 2, said
        assert "assembly-files holds 2 light lists" in said, said
        words = shlex.split(said.rsplit("give the one that lists its images: ", 1)[1])
        assert [w for w in words if w != "or"][:2] == [str(other), str(lp)], said
        assert not (tmp_path / "s").exists() and not (tmp_path / "p.lp").exists()


@GIVEN
def test_tradeoff_from_an_rtibuilder_project_folder_takes_its_assembly_files_lp(
    tmp_path: Path, given: str
) -> None:
    """Checked on the function `--from` goes through: the trade-off itself takes minutes."""
    from rti_rig.cli.bench import _acquisition_lp

    lp = _project(tmp_path)
    assert _acquisition_lp(lp.parents[1] / given).resolve() == lp.resolve()


@pytest.mark.parametrize("given", [".", "assembly-files/icon.lp", "jpeg-exports"])
def test_tradeoff_never_writes_into_the_project_given_as_from(tmp_path: Path, given: str) -> None:
    """`--out PROJ --force` with the project (or its .lp, or its jpeg-exports) as --from is
    refused, as --out PROJ/jpeg-exports is: it had put results.csv, summary.md and four plots
    beside assembly-files/ and jpeg-exports/ (QA, 2026-12-06)."""
    lp = _project(tmp_path, lights=12)  # a trade-off takes 10 or more
    project = lp.parents[1]
    before = sorted(p.name for p in project.iterdir())
    argv = ["bench", "tradeoff", "--from", str(project / given), "--out", str(project)]
    r = CliRunner().invoke(app, [*argv, "--force"], terminal_width=400)
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    assert "holds the acquisition --from reads" in said and "even with --force" in said, said
    assert sorted(p.name for p in project.iterdir()) == before


def test_an_image_missing_from_an_rtibuilder_project_is_to_be_copied_beside_its_siblings(
    tmp_path: Path,
) -> None:
    """It had been said "missing in" the .lp's assembly-files/ and to be copied there, away
    from the others in jpeg-exports/; copied where it is now said to go, it is found."""
    lp = _project(tmp_path)
    exports = lp.parents[1] / "jpeg-exports"
    lost = exports / "icon_05.JPG"
    kept = lost.read_bytes()
    lost.unlink()
    for command in (
        ["fit", str(lp), "--out", str(tmp_path / "f"), "--no-qa"],
        ["check", str(lp)],
        ["run", str(lp), "--out", str(tmp_path / "s")],
    ):
        said = " ".join(runner.invoke(app, command).output.split())
        assert f"1 of {LIGHTS} image(s) missing in {exports} (" in said, said
        assert f"copy them into {exports}, or remove their lines" in said, said
        assert "assembly-files," not in said and "assembly-files (" not in said, said
        # nor "an .lp is a recorded acquisition whose images lie beside it" (run, check)
        assert "beside it:" not in said, said
    assert not (tmp_path / "s").exists()
    lost.write_bytes(kept)
    r = runner.invoke(app, ["check", str(lp)])
    assert r.exit_code == 0 and "RESULT: PASS" in r.output, r.output


def test_fit_of_images_without_an_lp_says_what_to_give(tmp_path: Path) -> None:
    """A folder of images alone (jpeg-exports copied without its project) had been told only
    that it "holds no .lp file: not a session folder"."""
    lp = _project(tmp_path)
    images = (lp.parents[1] / "jpeg-exports").rename(tmp_path / "images")
    r = runner.invoke(app, ["fit", str(images), "--out", str(tmp_path / "f")])
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    assert f"{images} holds no .lp file: not a session folder; give a session folder" in said
    assert "the .lp that lists the images with their lights" in said, said
    assert not (tmp_path / "f").exists()
