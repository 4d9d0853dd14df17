"""A recorded acquisition as a rig (`rti-rig run ACQ/dirs.lp`), and real `.lp` flaws tolerated.

The replay rig must give back the source's images: for 16-bit sources the same linear TIFF
bytes; for JPEG sources the same decoded pixels (the session's linear TIFF, encoded as the
session encodes it, equals the decoded source JPEG).
"""

from __future__ import annotations

import json
import math
import re
import shlex
import shutil
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.image_files import (
    linear_to_srgb8,
    read_jpeg_rgb,
    read_linear_tiff,
)
from rti_rig.core.lp_format import read_lp
from rti_rig.simulator.replay import SRGB8_TO_LINEAR16
from tests.conftest import SMALL_DOME, cut_new_session, write_config

REPO = Path(__file__).resolve().parents[2]
ACQ = REPO / "tests" / "data" / "neuralrti_replay"
runner = CliRunner()


def _journal(session: Path) -> list[dict]:
    return [json.loads(line) for line in (session / "journal.jsonl").read_text().splitlines()]


def test_srgb_table_round_trips_every_code() -> None:
    codes = np.arange(256, dtype=np.uint8)
    assert np.array_equal(linear_to_srgb8(SRGB8_TO_LINEAR16[codes], 65535), codes)
    assert np.all(np.diff(SRGB8_TO_LINEAR16.astype(int)) > 0)  # monotone: it is a linearisation


def test_replay_of_a_real_jpeg_acquisition_gives_its_decoded_pixels(tmp_path: Path) -> None:
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", str(ACQ / "dirs.lp"), "--out", str(out), "--lights", "6"])
    assert r.exit_code == 0, r.output
    assert "Session time on the real rig" in r.output
    source = read_lp(ACQ / "dirs.lp")
    steps = _journal(out)
    assert len(steps) == 6 and len({s["led"] for s in steps}) == 6
    fired = read_lp(out / "lights.lp")
    for step, entry in zip(steps, fired, strict=True):
        src = source[step["led"]]
        decoded = read_jpeg_rgb(ACQ / src.name)
        mine = linear_to_srgb8(read_linear_tiff(out / step["linear_image"]), 65535)
        assert mine.shape == decoded.shape == (395, 402, 3)
        assert np.array_equal(mine, decoded), src.name
        np.testing.assert_allclose(entry.direction, src.direction, atol=2e-6)
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["rig"]["backend"] == "replay"


def test_replay_of_a_16bit_acquisition_gives_byte_identical_linear_tiffs(tmp_path: Path) -> None:
    cfg = write_config(tmp_path, SMALL_DOME)
    first = tmp_path / "first"
    r = runner.invoke(app, ["run", str(cfg), "--out", str(first)])
    assert r.exit_code == 0, r.output
    acq = first / "linear.lp"
    r = runner.invoke(app, ["export-lp", str(first), "--out", str(acq), "--linear"])
    assert r.exit_code == 0, r.output
    again = tmp_path / "again"
    r = runner.invoke(app, ["run", str(acq), "--out", str(again)])  # every light
    assert r.exit_code == 0, r.output
    names = [e.name for e in read_lp(acq)]
    steps = _journal(again)
    assert len(steps) == len(names) == 12
    for step in steps:
        src = (first / names[step["led"]]).read_bytes()
        assert (again / step["linear_image"]).read_bytes() == src, names[step["led"]]


def _flawed_acquisition(tmp_path: Path, count_line: str, z_of_line_4: str) -> Path:
    acq = tmp_path / "acq"
    shutil.copytree(ACQ, acq)
    lines = (acq / "dirs.lp").read_text().splitlines()
    lines[0] = count_line
    fields = lines[3].split()
    # a unit vector a hair below the plane, as calibration noise leaves one (with x and y as
    # they were, the line would be a mistyped vector of length 0.51, refused)
    flat = math.hypot(float(fields[1]), float(fields[2]))
    z = float(z_of_line_4)
    scale = math.sqrt(1.0 - z * z) / flat
    fields[1:] = [f"{float(fields[1]) * scale:.6f}", f"{float(fields[2]) * scale:.6f}", z_of_line_4]
    lines[3] = " ".join(fields)
    (acq / "dirs.lp").write_text("\n".join(lines) + "\n")
    return acq / "dirs.lp"


def test_real_flaws_are_tolerated_and_reported_by_plan_and_run(tmp_path: Path) -> None:
    lp = _flawed_acquisition(tmp_path, "17", "-0.0012")
    plan = tmp_path / "p.lp"
    r = runner.invoke(
        app, ["plan", "--rig", str(lp), "--lights", "6", "--method", "optimal", "--out", str(plan)]
    )
    assert r.exit_code == 0, r.output
    text = " ".join(r.output.split())
    assert f"{lp}, line 4: light z = -0.0" in text and "clamped to z = 0" in text
    assert f"{lp}, line 1: count line says 17 lights but the file lists 18" in text
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", str(lp), "--out", str(out), "--plan", str(plan)])
    assert r.exit_code == 0, r.output
    assert "clamped to z = 0" in " ".join(r.output.split())
    assert len(read_lp(out / "lights.lp")) == 6


def _manifest(session: Path) -> dict:
    return json.loads((session / "manifest.json").read_text())


def test_the_readers_notes_are_recorded_in_the_manifest(tmp_path: Path) -> None:
    """What the tolerant reader assumed is part of the session's record, not only the terminal:
    the rig's own `.lp` (fixed and adaptive sessions) and a `--plan` file's."""
    lp = _flawed_acquisition(tmp_path, "17", "-0.0012")
    out = tmp_path / "fixed"
    r = runner.invoke(app, ["run", str(lp), "--out", str(out), "--lights", "5"])
    assert r.exit_code == 0, r.output
    m = _manifest(out)
    notes = m["input_notes"]
    assert notes == m["runs"][0]["input_notes"] and len(notes) == 2
    assert any(n.startswith(f"{lp}, line 4: light z = -0.0") and "clamped" in n for n in notes)
    assert any(f"{lp}, line 1: count line says 17" in n for n in notes)

    # a --plan file with its own flaw: its note is recorded beside the rig's
    plan = tmp_path / "plan.lp"
    entries = read_lp(lp, upper_hemisphere=True, notes=[])[:5]
    plan.write_text(
        "4\n"
        + "".join(f"{e.name} {e.direction[0]} {e.direction[1]} {e.direction[2]}\n" for e in entries)
    )
    out = tmp_path / "planned"
    r = runner.invoke(app, ["run", str(lp), "--out", str(out), "--plan", str(plan)])
    assert r.exit_code == 0, r.output
    notes = _manifest(out)["input_notes"]
    assert len(notes) == 3 and any(f"{plan}, line 1: count line says 4" in n for n in notes)

    out = tmp_path / "adaptive"
    r = runner.invoke(app, ["run", str(lp), "--out", str(out), "--adaptive", "--lights", "5"])
    assert r.exit_code == 0, r.output
    m = _manifest(out)
    assert len(m["input_notes"]) == 2 and "clamped" in " ".join(m["input_notes"])


def test_a_resumed_run_records_the_notes_of_the_rig_it_read_again(tmp_path: Path) -> None:
    from rti_rig.app.usecases.session import NewSessionRequest

    lp = _flawed_acquisition(tmp_path, "17", "-0.0012")
    out = tmp_path / "cut"
    cut_new_session(NewSessionRequest(lp, out, lights=5), after_step=1)
    assert len(_journal(out)) == 2
    r = runner.invoke(app, ["run", "--resume", str(out)])
    assert r.exit_code == 0, r.output
    assert "clamped to z = 0" in " ".join(r.output.split())  # printed on resume too
    m = _manifest(out)
    assert len(m["runs"]) == 2 and len(_journal(out)) == 5
    for run in m["runs"]:
        assert len(run["input_notes"]) == 2 and "clamped" in " ".join(run["input_notes"])
    assert m["input_notes"] == m["runs"][0]["input_notes"]


def test_a_clean_acquisition_records_no_reader_notes(tmp_path: Path) -> None:
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", str(ACQ / "dirs.lp"), "--out", str(out), "--lights", "5"])
    assert r.exit_code == 0, r.output
    m = _manifest(out)
    assert "input_notes" not in m and "input_notes" not in m["runs"][0]


def test_a_light_well_below_the_plane_is_refused_with_file_and_line(tmp_path: Path) -> None:
    lp = _flawed_acquisition(tmp_path, "18", "-0.2")
    for args in (
        ["plan", "--rig", str(lp), "--lights", "6", "--out", str(tmp_path / "p.lp")],
        ["run", str(lp), "--out", str(tmp_path / "s"), "--lights", "6"],
    ):
        r = runner.invoke(app, args)
        assert r.exit_code == 2, r.output
        text = " ".join(r.output.split())
        assert f"{lp}, line 4" in text and "below the object plane" in text
        assert "Traceback" not in r.output
    assert not (tmp_path / "s").exists()


def test_an_acquisition_with_missing_images_is_refused_before_anything_runs(
    tmp_path: Path,
) -> None:
    acq = tmp_path / "acq"
    shutil.copytree(ACQ, acq)
    (acq / "image05.jpg").unlink()
    r = runner.invoke(app, ["run", str(acq / "dirs.lp"), "--out", str(tmp_path / "s")])
    assert r.exit_code == 2
    text = " ".join(r.output.split())
    assert "1 of 18 image(s) missing" in text and "image05.jpg" in text
    # and what to do, as for a damaged or unreadable image
    assert "copy them where their names point, or remove their lines from the .lp" in text
    assert not (tmp_path / "s").exists()


@pytest.mark.parametrize(
    ("damage", "fragment"),
    [
        # an empty file has no header to read its size from: it had passed the check, and the
        # session stopped at its light part-way (and its resume stopped there again)
        ("empty", "1 of 18 image(s) beside it cannot be read (cannot read image"),
        # one greyscale image among colour ones: the session ran, then QA and fit failed on
        # "images differ in shape"
        ("greyscale", "image01.jpg is colour but image45.jpg is greyscale"),
    ],
)
def test_an_acquisition_with_an_unreadable_or_other_kind_of_image_is_refused_up_front(
    tmp_path: Path, damage: str, fragment: str
) -> None:
    import cv2

    acq = tmp_path / "acq"
    shutil.copytree(ACQ, acq)
    target = acq / "image45.jpg"
    if damage == "empty":
        target.write_bytes(b"")
    else:
        grey = cv2.cvtColor(cv2.imread(str(target)), cv2.COLOR_BGR2GRAY)
        assert cv2.imwrite(str(target), grey)
    r = runner.invoke(app, ["run", str(acq / "dirs.lp"), "--out", str(tmp_path / "s")])
    assert r.exit_code == 2, r.output
    assert fragment in " ".join(r.output.split())
    assert not (tmp_path / "s").exists()


def test_an_all_greyscale_acquisition_replays_and_fits(tmp_path: Path) -> None:
    """A monochrome camera's acquisition is one kind of image: replayed and fitted."""
    import cv2

    acq = tmp_path / "acq"
    shutil.copytree(ACQ, acq)
    for jpg in acq.glob("*.jpg"):
        assert cv2.imwrite(str(jpg), cv2.cvtColor(cv2.imread(str(jpg)), cv2.COLOR_BGR2GRAY))
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", str(acq / "dirs.lp"), "--out", str(out), "--lights", "6"])
    assert r.exit_code == 0, r.output
    r = runner.invoke(app, ["fit", str(out), "--out", str(tmp_path / "f"), "--no-qa"])
    assert r.exit_code == 0, r.output
    assert (tmp_path / "f" / "fit.json").is_file()


def test_an_rtibuilder_project_replays_and_fits_with_its_absolute_windows_names(
    tmp_path: Path,
) -> None:
    """RTIBuilder keeps the .lp in assembly-files/ and names each image by its path on the
    machine that built the project (here with a space in a folder's name): such a real .lp had
    been refused ("an absolute path").
    Replayed, every image is the recorded one for its light; fitted, every light is used."""
    project = tmp_path / "icon_RTI"
    (project / "assembly-files").mkdir(parents=True)
    shutil.copytree(ACQ, project / "jpeg-exports", ignore=shutil.ignore_patterns("*.lp"))
    lines = (ACQ / "dirs.lp").read_text().splitlines()
    windows = [lines[0]] + [
        f"H:\\RTI Data\\icon_RTI\\jpeg-exports\\{line}" for line in lines[1:] if line.strip()
    ]
    lp = project / "assembly-files" / "icon_RTI.lp"
    lp.write_bytes(("\r\n".join(windows) + "\r\n").encode())
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", str(lp), "--out", str(out), "--lights", "6", "--no-verdict"])
    assert r.exit_code == 0, r.output
    source = read_lp(ACQ / "dirs.lp")
    for step in _journal(out):
        decoded = read_jpeg_rgb(ACQ / source[step["led"]].name)
        mine = linear_to_srgb8(read_linear_tiff(out / step["linear_image"]), 65535)
        assert np.array_equal(mine, decoded)
    r = runner.invoke(app, ["fit", str(lp), "--out", str(tmp_path / "f"), "--no-qa"])
    assert r.exit_code == 0, r.output
    assert json.loads((tmp_path / "f" / "fit.json").read_text())["read"].startswith("18 images")
    # a plan on it (the names have a space: its writer had stopped with a traceback), then run
    plan = tmp_path / "plan.lp"
    r = runner.invoke(app, ["plan", "--rig", str(lp), "--lights", "6", "--out", str(plan)])
    assert r.exit_code == 0, r.output
    assert read_lp(plan)[0].name == "image01.jpg"
    r = runner.invoke(
        app, ["run", str(lp), "--out", str(tmp_path / "p"), "--plan", str(plan), "--no-verdict"]
    )
    assert r.exit_code == 0, r.output


@pytest.mark.parametrize("layout", ["planar", "rgba"])
def test_replay_of_planar_or_alpha_tiffs_gives_their_rgb_pixels(
    tmp_path: Path, layout: str
) -> None:
    """A planar TIFF (Photoshop's "Per Channel" order) had been read as (3, H, 3): the session
    stopped at its first capture saying the first image was not the first image's size. An
    alpha sample carries no light: the frame is the RGB pixels."""
    import tifffile

    rng = np.random.default_rng(3)
    acq = tmp_path / "acq"
    acq.mkdir()
    sources = []
    lines = ["4"]
    for i, (x, y, z) in enumerate([(0.5, 0, 0.866), (0, 0.5, 0.866), (-0.5, 0, 0.866), (0, 0, 1)]):
        px = rng.integers(0, 65535, (24, 32, 3), dtype=np.uint16)
        if layout == "planar":
            stored, extra = np.moveaxis(px, -1, 0), {"planarconfig": "separate"}
        else:
            alpha = np.full((24, 32, 1), 65535, np.uint16)
            stored, extra = np.concatenate([px, alpha], axis=2), {"extrasamples": ["unassalpha"]}
        tifffile.imwrite(acq / f"img{i}.tif", stored, photometric="rgb", **extra)
        sources.append(px)
        lines.append(f"img{i}.tif {x} {y} {z}")
    (acq / "dirs.lp").write_text("\n".join(lines) + "\n")
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", str(acq / "dirs.lp"), "--out", str(out), "--no-verdict"])
    assert r.exit_code == 0, r.output
    steps = _journal(out)
    assert len(steps) == 4
    for step in steps:
        assert np.array_equal(read_linear_tiff(out / step["linear_image"]), sources[step["led"]])


def test_a_resume_whose_acquisition_moved_asks_for_its_lp_not_a_toml(tmp_path: Path) -> None:
    """The replayed acquisition moved after the session: the resume had asked for
    "rti-rig run RIG.toml --resume S", a rig config the user never had, then for
    "rti-rig run ACQ/dirs.lp --resume S", a template; it names the path the manifest holds,
    as shell words (a folder with a space and a quote), and that command resumes once the
    acquisition is back. (A session that completed needs no rig to be said complete: its
    resume says so however its acquisition moved, tests/cli/test_resume_complete_config_moved;
    so this one is cut short, as Ctrl-C leaves it.)"""
    from tests.conftest import interrupted

    acq = tmp_path / "Coin 'A' acq"
    shutil.copytree(ACQ, acq)
    out = tmp_path / "s"
    interrupted(acq / "dirs.lp", out, after_step=1, lights=6)
    acq.rename(tmp_path / "moved")
    r = runner.invoke(app, ["run", "--resume", str(out)])
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    assert "the recorded acquisition it replayed" in said and "is not there any more" in said
    assert "ACQ/" not in said and "RIG.toml" not in said, said
    command = said.split("put it back there (its images beside it): ", 1)[1].split(", or ")[0]
    words = shlex.split(command)
    assert words == ["rti-rig", "run", str(acq / "dirs.lp"), "--resume", str(out)], said
    (tmp_path / "moved").rename(acq)
    r = runner.invoke(app, [*words[1:], "--no-verdict"])
    assert r.exit_code == 0, r.output
    assert (out / "lights.lp").is_file()
    acq.rename(tmp_path / "moved-again")  # complete now: said so without its rig
    r = runner.invoke(app, ["run", "--resume", str(out)])
    assert r.exit_code == 0 and "session is complete" in " ".join(r.output.split()), r.output


#: The four lights of the small acquisitions the refusals below are built on.
FOUR_LIGHTS = [(0.5, 0, 0.866), (0, 0.5, 0.866), (-0.5, 0, 0.866), (0, 0, 1)]


def _four_images(acq: Path, seed: int, write) -> None:  # type: ignore[no-untyped-def]
    """A 4-light acquisition in ``acq``: ``write(i, pixels)`` saves image ``i`` (16-bit RGB
    noise) and returns its file name; dirs.lp lists them."""
    rng = np.random.default_rng(seed)
    acq.mkdir()
    lines = ["4"]
    for i, (x, y, z) in enumerate(FOUR_LIGHTS):
        name = write(i, rng.integers(0, 65535, (24, 32, 3), dtype=np.uint16))
        lines.append(f"{name} {x} {y} {z}")
    (acq / "dirs.lp").write_text("\n".join(lines) + "\n")


def _refused_by_check_and_run(tmp_path: Path, acq: Path, *fragments: str) -> None:
    """`check` of ``acq/dirs.lp`` fails it (RESULT: FAIL, exit 1: its images are what it
    checks) and `run` refuses it (exit 2), every fragment said, no PASS, no traceback, and no
    session folder is made."""
    for args, code in (
        (["check", str(acq / "dirs.lp")], 1),
        (["run", str(acq / "dirs.lp"), "--out", str(tmp_path / "s")], 2),
    ):
        r = runner.invoke(app, args)
        said = " ".join(r.output.split())
        assert r.exit_code == code, said
        assert said.endswith("RESULT: FAIL") == (code == 1), said
        for fragment in fragments:
            assert fragment in said, said
        assert "PASS" not in said and "Traceback" not in r.output
    assert not (tmp_path / "s").exists()


@pytest.mark.parametrize("kind", ["float", "stack"])
def test_a_tiff_a_replay_cannot_give_is_refused_before_anything_runs(
    tmp_path: Path, kind: str
) -> None:
    """A float TIFF (an HDR export) or a stack of pages has a header like any other: `check`
    had passed it ("undamaged and readable") and `run` stopped at it part-way, telling the user
    to resume into the same stop."""
    import tifffile

    acq = tmp_path / "acq"

    def write(i: int, px: np.ndarray) -> str:
        if i == 2:  # the third image only: the session would have captured two
            odd = px.astype(np.float32) / 65535 if kind == "float" else np.stack([px, px])
            tifffile.imwrite(acq / f"img{i}.tif", odd, photometric="rgb")
        else:
            tifffile.imwrite(acq / f"img{i}.tif", px, photometric="rgb")
        return f"img{i}.tif"

    _four_images(acq, 5, write)
    _refused_by_check_and_run(
        tmp_path,
        acq,
        "1 of 4 image(s) beside it hold pixels a replay cannot give",
        "img2.tif",
        "is not 8/16-bit grey or RGB; save it again as",
    )


@pytest.mark.parametrize("suffix", [".png", ".tif"])
def test_a_png_or_tiff_cut_short_is_refused_before_anything_runs(
    tmp_path: Path, suffix: str
) -> None:
    """A PNG or TIFF cut short (a full card, an interrupted copy) keeps a whole header: `check`
    had said PASS ("undamaged and readable") and `run` stopped at it part-way, as it stops on a
    cut-short JPEG no more."""
    import cv2
    import tifffile

    acq = tmp_path / "acq"

    def write(i: int, px: np.ndarray) -> str:
        path = acq / f"img{i}{suffix}"
        if suffix == ".png":
            cv2.imwrite(str(path), px)
        else:
            tifffile.imwrite(path, px, photometric="rgb")
        return path.name

    _four_images(acq, 7, write)
    victim = acq / f"img2{suffix}"
    victim.write_bytes(victim.read_bytes()[:2000])
    _refused_by_check_and_run(
        tmp_path,
        acq,
        "1 of 4 image(s) beside it are damaged images",
        f"img2{suffix}: ",
        "(cut short)",
        "copy them again",
    )


def test_an_acquisition_repeating_a_light_is_refused_in_a_replays_words(tmp_path: Path) -> None:
    """Two images shot under one light (a repeated reference shot): the refusal had named
    "key 'dome.lp_file'", a key of a rig config the user never wrote."""
    acq = tmp_path / "acq"
    shutil.copytree(ACQ, acq)
    lines = (acq / "dirs.lp").read_text().splitlines()
    shutil.copy(acq / "image01.jpg", acq / "image01b.jpg")
    again = "image01b.jpg " + " ".join(lines[1].split()[1:])
    (acq / "dirs.lp").write_text("\n".join([str(len(lines)), *lines[1:], again]) + "\n")
    r = runner.invoke(app, ["run", str(acq / "dirs.lp"), "--out", str(tmp_path / "s")])
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    # the lines to edit named (light 1 is on line 2, past the count line)
    assert (
        "lights 1 (line 2: image01.jpg) and 19 (line 20: image01b.jpg) share one direction" in said
    ), said
    assert "remove one of the two lines" in said and "dome.lp_file" not in said
    assert not (tmp_path / "s").exists()
    # the trade-off, which holds lights out by direction, refuses it too (it had measured it,
    # a held-out light's twin among the lights planned from)
    r = runner.invoke(
        app, ["bench", "tradeoff", "--from", str(acq / "dirs.lp"), "--out", str(tmp_path / "b")]
    )
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    assert "lights 1 (line 2: image01.jpg) and 19 (line 20: image01b.jpg) share one" in said
    assert "a trade-off holds lights out" in said and not (tmp_path / "b").exists()


def test_a_resume_on_an_acquisition_whose_images_changed_is_refused(tmp_path: Path) -> None:
    """An image of the replayed acquisition replaced between the interruption and the resume
    had been mixed in without a word: the resume's images came from another acquisition than
    the first part's. Refused, nothing changed; the new session it offers runs as printed, with
    the session's --lights; with the original put back it continues."""
    from rti_rig.app.usecases.session import NewSessionRequest
    from rti_rig.runtime.controller import FinishReason

    acq = tmp_path / "acq"
    shutil.copytree(ACQ, acq)
    out = tmp_path / "s"
    run = cut_new_session(NewSessionRequest(acq / "dirs.lp", out, lights=8), after_step=2)
    assert run.finish_reason is FinishReason.CANCELLED
    before = sorted(p.relative_to(out).as_posix() for p in out.rglob("*"))
    last = read_lp(acq / "dirs.lp")[-1].name
    shutil.copy(acq / read_lp(acq / "dirs.lp")[0].name, acq / last)  # an image replaced
    r = runner.invoke(app, ["run", "--resume", str(out)])
    assert r.exit_code == 2, r.output
    said = " ".join(r.output.split())
    assert "are not the ones this session began with" in said and "Put the original" in said
    # which one, by name: the manifest holds each file's checksum
    assert f"({last} differs from the one recorded)" in said, said
    assert sorted(p.relative_to(out).as_posix() for p in out.rglob("*")) == before
    # the new session it offers runs as printed, with this one's 8 lights (it had no command)
    command = re.search(r"as it is now \(rti-rig run ([^()]+)\)$", said)
    assert command, said
    args = shlex.split(command.group(1))
    assert args[:2] == [str(acq / "dirs.lp"), "--out"] and "--lights" in args, args
    new = Path(args[2])
    assert new.parent == out.parent and not new.exists(), args
    r = runner.invoke(app, ["run", *args, "--no-verdict"])
    assert r.exit_code == 0, r.output
    assert len(read_lp(new / "lights.lp")) == 8
    shutil.copy(ACQ / last, acq / last)  # put back
    r = runner.invoke(app, ["run", "--resume", str(out), "--no-verdict"])
    assert r.exit_code == 0, r.output
    assert len(read_lp(out / "lights.lp")) == 8


def test_an_acquisition_of_camera_raw_files_is_refused_by_check_run_and_fit_before_any_work(
    tmp_path: Path,
) -> None:
    """An `.lp` listing the camera's RAW files (DNG here, written by the spec-based test
    writer from the real acquisition's pixels) had passed `check` ("undamaged and readable": a
    DNG is a TIFF to the header reader), then stopped `run` at its first capture (and `fit` at
    its first read) behind an OpenCV warning line, "not an image OpenCV decodes". All three
    now say up front that they are RAW files and what to give instead."""
    from tests.dng_spec_writer import dng, mosaic_from_rgb

    acq = tmp_path / "acq"
    acq.mkdir()
    lines = (ACQ / "dirs.lp").read_text().splitlines()
    out_lines = [lines[0]]
    for line in lines[1:]:
        name, rest = line.split(maxsplit=1)
        rgb = read_jpeg_rgb(ACQ / name).astype(np.float64) / 255.0
        even = rgb[: rgb.shape[0] // 2 * 2, : rgb.shape[1] // 2 * 2]
        stem = Path(name).stem
        (acq / f"{stem}.dng").write_bytes(dng(mosaic_from_rgb(even, "RGGB", (0, 0, 0, 0), 65535)))
        out_lines.append(f"{stem}.dng {rest}")
    lp = acq / "dirs.lp"
    lp.write_text("\n".join(out_lines) + "\n")
    said = "18 of 18 image(s) beside it are camera RAW files (image01.dng, image05.dng"
    checked = runner.invoke(app, ["check", str(lp)])
    text = " ".join(checked.output.split())
    assert checked.exit_code == 1 and "RESULT: FAIL" in text, text
    assert said in text and "16-bit linear TIFF" in text, text
    ran = runner.invoke(app, ["run", str(lp), "--out", str(tmp_path / "s"), "--lights", "6"])
    ran_text = " ".join(ran.output.split())
    assert ran.exit_code == 2 and said in ran_text, ran_text
    assert "OpenCV" not in ran_text and not (tmp_path / "s").exists()
    fitted = runner.invoke(app, ["fit", str(lp), "--out", str(tmp_path / "f"), "--no-qa"])
    fit_text = " ".join(fitted.output.split())
    assert fitted.exit_code == 2 and said in fit_text and "OpenCV" not in fit_text, fit_text


def test_a_plan_of_an_acquisition_with_spaced_accented_names_replays_on_it(
    tmp_path: Path,
) -> None:
    """`plan --rig ACQ/dirs.lp` writes "my image é00.jpg" as "my_image_e00.jpg" (the .lp it
    writes is read by tools that split names at spaces); `run ACQ/dirs.lp --plan` matches the
    plan to the rig's lights by direction, not by name, so each planned light replays the
    recorded image of its own light."""
    acq = tmp_path / "acq"
    acq.mkdir()
    lines = (ACQ / "dirs.lp").read_text(encoding="utf-8").splitlines()
    renamed = [lines[0]]
    for n, line in enumerate(lines[1:]):
        name, *xyz = line.split()
        shutil.copyfile(ACQ / name, acq / f"my image é{n:02d}.jpg")
        renamed.append(" ".join([f"my image é{n:02d}.jpg", *xyz]))
    (acq / "dirs.lp").write_text("\n".join(renamed) + "\n", encoding="utf-8")
    plan = tmp_path / "plan.lp"
    r = runner.invoke(
        app, ["plan", "--rig", str(acq / "dirs.lp"), "--lights", "6", "--out", str(plan)]
    )
    assert r.exit_code == 0, r.output
    assert all(" " not in e.name for e in read_lp(plan))  # the names as the plan writes them
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", str(acq / "dirs.lp"), "--plan", str(plan), "--out", str(out)])
    assert r.exit_code == 0, r.output
    source = read_lp(acq / "dirs.lp")
    steps = _journal(out)
    assert len(steps) == 6
    for step, planned in zip(steps, read_lp(plan), strict=True):
        src = source[step["led"]]
        np.testing.assert_allclose(planned.direction, src.direction, atol=2e-6)
        decoded = read_jpeg_rgb(acq / src.name)
        mine = linear_to_srgb8(read_linear_tiff(out / step["linear_image"]), 65535)
        assert np.array_equal(mine, decoded), src.name


def test_a_config_of_backend_replay_is_refused_with_the_lp_to_give(tmp_path: Path) -> None:
    """The manifest's form of a replay rig, written by hand: its images had been looked for
    beside the TOML, none checked before the run, and the first capture blamed an unplugged
    drive; `check` called it "not an .lp". Refused by `run` and `check`, naming the .lp."""
    acq = tmp_path / "acq"
    shutil.copytree(ACQ, acq)
    cfg = tmp_path / "replay.toml"
    cfg.write_text(
        'name = "my replay"\nkind = "dome"\nbackend = "replay"\n[dome]\nlayout = "lp"\n'
        'lp_file = "acq/dirs.lp"\n[camera]\nwidth = 402\nheight = 395\n'
    )
    for args in (["run", str(cfg), "--out", str(tmp_path / "s")], ["check", str(cfg)]):
        r = runner.invoke(app, args)
        said = " ".join(r.output.split())
        assert r.exit_code == 2, said
        assert "key 'backend': 'replay' is the rig rti-rig makes of a recorded acquisition" in said
        assert f"rti-rig run {acq / 'dirs.lp'} --out" in said and "Traceback" not in said
        assert f"rti-rig run {acq / 'dirs.lp'} --resume SESSION" in said, said
    assert not (tmp_path / "s").exists()


def test_an_image_rewritten_while_it_is_replayed_stops_the_run_naming_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """An image of the acquisition rewritten during the run (an export writing over it while
    the session ran) had been copied into the session as it was then, with exit 0, the
    manifest recording the file the run began with (QA, 2026-12-06). The run stops at its step
    naming the file; the images before it are kept, and with the original put back the resume
    continues. A file whose stamp alone moved (a chmod, a backup's utime, a sync client's
    tag: the same bytes) is judged by its bytes and the run goes on."""
    import os

    from rti_rig.simulator import replay

    acq = tmp_path / "acq"
    shutil.copytree(ACQ, acq)
    names = [e.name for e in read_lp(acq / "dirs.lp")]
    real_capture = replay.ReplayCamera.capture
    shots: list[int] = []

    def touched(self, exposure_s):  # type: ignore[no-untyped-def]
        if self._dome.lit is not None:
            shots.append(self._dome.lit)
            if len(shots) == 2:  # every image of it: mode set again, times set back
                for name in names:
                    st = (acq / name).stat()
                    os.chmod(acq / name, st.st_mode & 0o7777)
                    os.utime(acq / name, ns=(st.st_atime_ns, st.st_mtime_ns))
        return real_capture(self, exposure_s)

    monkeypatch.setattr(replay.ReplayCamera, "capture", touched)
    same = tmp_path / "same"
    r = runner.invoke(app, ["run", str(acq / "dirs.lp"), "--out", str(same), "--lights", "6"])
    assert r.exit_code == 0, r.output
    assert len(read_lp(same / "lights.lp")) == 6

    originals = {name: (acq / name).read_bytes() for name in names}
    shots.clear()

    def rewritten(self, exposure_s):  # type: ignore[no-untyped-def]
        if self._dome.lit is not None:
            shots.append(self._dome.lit)
            if len(shots) == 2:  # during the run, every image of it re-exported: other bytes
                for name in names:
                    (acq / name).write_bytes(originals[name] + b"\0")
        return real_capture(self, exposure_s)

    monkeypatch.setattr(replay.ReplayCamera, "capture", rewritten)
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", str(acq / "dirs.lp"), "--out", str(out), "--lights", "6"])
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    assert "Traceback" not in said
    assert "was changed since this run began (its bytes differ from those the run began" in said
    assert "Put the file back as it was, from a copy, and resume" in said, said
    assert [e["image"] for e in _journal(out)] == ["image_001.jpg"]  # the step before it kept
    # the originals put back, the resume (which hashes them) goes on
    for name in names:
        (acq / name).write_bytes(originals[name])
    monkeypatch.setattr(replay.ReplayCamera, "capture", real_capture)
    r = runner.invoke(app, ["run", "--resume", str(out), "--no-verdict"])
    assert r.exit_code == 0, r.output
    assert len(read_lp(out / "lights.lp")) == 6


def test_a_resume_on_another_acquisition_says_so_and_advises_a_count_it_has(
    tmp_path: Path,
) -> None:
    """Resumed on another recorded acquisition (fewer lights, at other directions), a session
    had been told "one was edited, replaced or re-exported since", and advised a new session
    with its own --lights 12, which that acquisition of 11 refused (QA, 2026-12-06)."""
    from rti_rig.app.usecases.session import NewSessionRequest
    from rti_rig.runtime.controller import FinishReason

    acq = tmp_path / "acq"
    shutil.copytree(ACQ, acq)
    out = tmp_path / "s"
    run = cut_new_session(NewSessionRequest(acq / "dirs.lp", out, lights=12), after_step=2)
    assert run.finish_reason is FinishReason.CANCELLED
    other = tmp_path / "other"
    shutil.copytree(ACQ, other)
    lines = (other / "dirs.lp").read_text(encoding="utf-8").splitlines()
    (other / "dirs.lp").write_text("\n".join(["11", *lines[1:12]]) + "\n", encoding="utf-8")
    r = runner.invoke(app, ["run", str(other / "dirs.lp"), "--resume", str(out)])
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    assert f"{other / 'dirs.lp'} is another acquisition than the one this session began with" in (
        said
    ), said
    assert "(11 lights, the session's 18 lights)" in said, said
    assert "edited" not in said, said
    assert f"Continue it on its own acquisition, {acq / 'dirs.lp'}: rti-rig run --resume {out}" in (
        said
    ), said
    command = re.search(r"new session from this one \(rti-rig run ([^()]+)\)$", said)
    assert command, said
    args = shlex.split(command.group(1))
    assert args[args.index("--lights") + 1] == "11", args
    r = runner.invoke(app, ["run", *args, "--no-verdict"])
    assert r.exit_code == 0, r.output
    assert len(read_lp(Path(args[2]) / "lights.lp")) == 11
    # the session's own .lp edited in place (lines cut) is no other acquisition: said as an
    # edit, to be put back (naming it "another" had advised a resume refused the same way)
    lines = (acq / "dirs.lp").read_text(encoding="utf-8").splitlines()
    (acq / "dirs.lp").write_text("\n".join(["11", *lines[1:12]]) + "\n", encoding="utf-8")
    r = runner.invoke(app, ["run", str(acq / "dirs.lp"), "--resume", str(out)])
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    assert "another acquisition" not in said and "Put the original files back" in said, said
    command = re.search(r"as it is now \(rti-rig run ([^()]+)\)$", said)
    assert command, said
    args = shlex.split(command.group(1))
    assert args[args.index("--lights") + 1] == "11", args  # a count it has
