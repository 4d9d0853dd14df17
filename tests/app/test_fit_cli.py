"""`rti-rig fit` through the front door, its files read back independently, and the QA verdict.

The `.ptm` and `.rti` readers here are written from the published format descriptions and the
viewers people open them with (HP's PTM 1.2 layout; the HSH `.rti` as RTIViewer's
`Hsh::loadData`, relight's `LRti::loadHSH` and CHI's Java HSH viewer read it), not from our
writer.
"""

from __future__ import annotations

import json
import struct
import sys
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.rti_bases import hsh_basis, ptm_basis

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from fit_sessions import _rings, dome_lights, grazing_last_lights, make_session

runner = CliRunner()


def _angles(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.degrees(np.arccos(np.clip(np.sum(a * b, axis=-1), -1.0, 1.0)))


@pytest.fixture(scope="module")
def clean(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, np.ndarray, np.ndarray]:
    return make_session(tmp_path_factory.mktemp("clean") / "s")


# normal error bounds per model on the simulated tablet (degrees, median over the image)
BOUNDS = {"robust-ps": 3.0, "ps": 8.0, "lambert": 8.0, "ptm": 10.0, "auto": 3.0}


@pytest.mark.parametrize("model", list(BOUNDS))
def test_fit_normals_against_simulator_truth(clean, tmp_path: Path, model: str) -> None:
    session, _, truth = clean
    out = tmp_path / "out"
    r = runner.invoke(app, ["fit", str(session), "--out", str(out), "--model", model, "--no-qa"])
    assert r.exit_code == 0, r.output
    normals = np.load(out / "normals.npy")
    err = float(np.median(_angles(normals, truth)))
    assert err < BOUNDS[model], f"{model}: median normal error {err:.2f}°"
    summary = json.loads((out / "fit.json").read_text())
    assert summary["why"]
    assert (out / "lights.dome").is_file() and (out / "fit.ptm").is_file()
    assert not any(w.startswith("fit.ptm is written from") for w in summary["warnings"])  # 36


def _read_ptm(path: Path) -> np.ndarray:
    """PTM 1.2 PTM_FORMAT_RGB: text header, then per colour plane, scanlines bottom-up, six
    bytes per pixel; a_i = (byte - bias_i) * scale_i. Returns (6, H, W, 3) top-down."""
    data = path.read_bytes()
    lines, pos = [], 0
    for _ in range(6):
        end = data.index(b"\n", pos)
        lines.append(data[pos:end].decode("ascii").strip())
        pos = end + 1
    assert lines[0] == "PTM_1.2" and lines[1] == "PTM_FORMAT_RGB"
    w, h = int(lines[2]), int(lines[3])
    scale = np.array([float(x) for x in lines[4].split()])
    bias = np.array([int(x) for x in lines[5].split()])
    raw = np.frombuffer(data, np.uint8, offset=pos).reshape(3, h, w, 6)
    coef = (raw.astype(np.float64) - bias) * scale  # (3, H, W, 6)
    return np.transpose(coef, (3, 1, 2, 0))[:, ::-1]


def _read_rti(path: Path) -> np.ndarray:
    """HSH .rti: '#' comment lines, type 3, 'W H 3', 'terms type size', float32 scales and
    biases, then scanlines top-down (the viewers read file row 0 as the image's top row, where
    a PTM's first scanline is its bottom one), per pixel, per colour, per term:
    byte/255*scale+bias, in units of full scale (the viewers display the relit sum × 255, or
    256, after clamping it to 0..1). Returns (terms, H, W, 3) top-down, in those units."""
    data = path.read_bytes()
    pos = 0
    fields: list[str] = []
    while len(fields) < 3:
        end = data.index(b"\n", pos)
        line = data[pos:end].decode("ascii")
        pos = end + 1
        if not line.startswith("#"):
            fields.append(line)
    assert int(fields[0]) == 3
    w, h, bands = (int(x) for x in fields[1].split())
    terms = int(fields[2].split()[0])
    scale = np.array(struct.unpack(f"<{terms}f", data[pos : pos + 4 * terms]))
    bias = np.array(struct.unpack(f"<{terms}f", data[pos + 4 * terms : pos + 8 * terms]))
    raw = np.frombuffer(data, np.uint8, offset=pos + 8 * terms).reshape(h, w, bands, terms)
    coef = raw / 255.0 * scale + bias  # (H, W, 3, terms)
    return np.transpose(coef, (3, 0, 1, 2))


def test_ptm_and_rti_read_back_relight_like_the_fit(clean, tmp_path: Path) -> None:
    import tifffile

    from rti_rig.reconstruct import fit_hsh, fit_ptm
    from rti_rig.reconstruct.stack import ImageStack

    session, lights, _ = clean
    out = tmp_path / "out"
    args = ["fit", str(session), "--out", str(out), "--no-qa", "--model", "ps", "--hsh-order", "2"]
    r = runner.invoke(app, [*args, "--export-encoding", "linear"])
    assert r.exit_code == 0, r.output
    frames = [tifffile.imread(p) for p in sorted((session / "linear").glob("*.tif"))]
    ptm = fit_ptm(ImageStack(frames), lights)
    hsh = fit_hsh(ImageStack(frames), lights, 2)
    ptm_file = _read_ptm(out / "fit.ptm")
    rti_file = _read_rti(out / "fit.rti")
    assert ptm_file.shape == ptm.coefficients.shape and rti_file.shape == hsh.coefficients.shape
    # relight at directions between the lights, in each format's display units: a PTM's relit
    # value is the byte shown (0..255), an HSH's the fraction of full scale (0..1)
    for d in ([0.3, 0.2, 0.9327], [-0.5, 0.4, 0.7681], [0.7, -0.1, 0.7071]):
        d = np.array(d) / np.linalg.norm(d)
        ref = np.tensordot(ptm_basis(d[None])[0], ptm.coefficients, axes=(0, 0)) * 255
        got = np.tensordot(ptm_basis(d[None])[0], ptm_file, axes=(0, 0))
        assert np.percentile(np.abs(got - ref), 99) < 2.5  # 8-bit quantisation of 6 terms
        ref = np.tensordot(hsh_basis(d[None], 2)[0], hsh.coefficients, axes=(0, 0))
        got = np.tensordot(hsh_basis(d[None], 2)[0], rti_file, axes=(0, 0))
        assert np.percentile(np.abs(got - ref), 99) < 4.0 / 255  # 9 terms
        # the image the right way up: the rows read back the other way round match far worse
        # (a file written bottom-up opens upside down in RTIViewer and relight)
        flipped = np.tensordot(hsh_basis(d[None], 2)[0], rti_file[:, ::-1], axes=(0, 0))
        assert np.percentile(np.abs(flipped - ref), 99) > 10 * np.percentile(np.abs(got - ref), 99)
        # and in the viewers' units: 255x too large (as written before) shows white in RTIViewer
        assert 0.0 <= float(np.median(got)) <= 1.0
    dome = json.loads((out / "lights.dome").read_text())
    # as relight's Dome::fromJson reads it: objects with x, y, z (an [x, y, z] array reads as 0)
    got = np.array([[o["x"], o["y"], o["z"]] for o in dome["directions"]])
    np.testing.assert_allclose(got, lights, atol=1e-5)
    assert dome["lightConfiguration"] == "directional" and "domeDiameter" in dome


def test_ptm_and_rti_hold_the_photographs_values_by_default(clean, tmp_path: Path) -> None:
    """Viewers show a PTM's or an HSH's relit value as it is, with no transfer curve, and
    RTIBuilder fits the JPEGs: so by default the files hold sRGB-encoded values, and relit at a
    captured light they give the photograph as its JPEG shows it. Linear values (asked for
    with --export-encoding linear) show it far darker."""
    import tifffile

    from rti_rig.core.image_files import srgb_encode

    session, lights, _ = clean
    files = {}
    for encoding in ("srgb", "linear"):
        out = tmp_path / encoding
        args = ["fit", str(session), "--out", str(out), "--no-qa", "--model", "ps"]
        if encoding == "linear":
            args += ["--export-encoding", "linear"]
        r = runner.invoke(app, args)
        assert r.exit_code == 0, r.output
        assert json.loads((out / "fit.json").read_text())["export_encoding"] == encoding
        files[encoding] = (_read_ptm(out / "fit.ptm"), _read_rti(out / "fit.rti"))
    tifs = sorted((session / "linear").glob("*.tif"))
    for k in (0, 9, 20, 30):
        photo = srgb_encode(tifffile.imread(tifs[k]) / 65535.0)  # the JPEG's values, 0..1
        if photo.ndim == 3:
            photo = photo.mean(axis=-1)
        deviation = {}
        for encoding, (ptm, rti) in files.items():
            relit_ptm = np.tensordot(ptm_basis(lights[k][None])[0], ptm, axes=(0, 0)) / 255
            relit_rti = np.tensordot(hsh_basis(lights[k][None], 2)[0], rti, axes=(0, 0))
            deviation[encoding] = [
                float(np.median(np.abs(relit.mean(axis=-1) - photo)))
                for relit in (relit_ptm, relit_rti)
            ]
        # a PTM relights a grazing light less well (its quadratic); the offset is what counts
        assert max(deviation["srgb"]) < 0.06, deviation  # within ~15 levels of 255
        assert min(deviation["linear"]) > 0.15, deviation  # linear light is far darker


def test_an_unknown_export_encoding_is_refused(clean, tmp_path: Path) -> None:
    session, _, _ = clean
    out = tmp_path / "o"
    r = runner.invoke(app, ["fit", str(session), "--out", str(out), "--export-encoding", "gamma"])
    assert r.exit_code == 2 and "--export-encoding" in r.output and "srgb" in r.output
    assert not out.exists() or not any(out.iterdir())


def test_an_hsh_order_that_does_not_exist_is_refused(clean, tmp_path: Path) -> None:
    session, _, _ = clean
    out = tmp_path / "o"
    r = runner.invoke(app, ["fit", str(session), "--out", str(out), "--hsh-order", "4"])
    assert r.exit_code == 2 and "--hsh-order 4: choose 1, 2 or 3" in " ".join(r.output.split())
    assert not out.exists() or not any(out.iterdir())
    r = runner.invoke(app, ["fit", str(session), "--out", str(out), "--hsh-order", "2", "--no-hsh"])
    assert r.exit_code == 2 and "which --no-hsh does not write" in " ".join(r.output.split())
    assert not out.exists() or not any(out.iterdir())
    # an HSH model of another order: fit.rti had been written at --hsh-order, the model
    # "chosen by --model" in no file
    argv = ["fit", str(session), "--out", str(out), "--model", "hsh2", "--hsh-order", "1"]
    r = runner.invoke(app, argv)
    assert r.exit_code == 2, r.output
    assert "--model hsh2 and --hsh-order 1 disagree" in " ".join(r.output.split()), r.output
    assert not out.exists() or not any(out.iterdir())


def test_a_refused_fit_leaves_nothing_so_the_corrected_command_runs(tmp_path: Path) -> None:
    """A fit refused once it had begun writing (model_choice.md) left --out not empty: the
    corrected command was then refused for that. An --out that existed empty stays, empty."""
    session, _, _ = make_session(tmp_path / "s", lights=dome_lights()[:12], size=(48, 64))
    out = tmp_path / "o"
    r = runner.invoke(app, ["fit", str(session), "--out", str(out), "--hsh-order", "3"])
    assert r.exit_code == 2 and "needs at least 16 lights" in " ".join(r.output.split())
    assert not out.exists()
    three, _, _ = make_session(tmp_path / "s3", lights=dome_lights()[::12][:3], size=(48, 64))
    out.mkdir()
    r = runner.invoke(app, ["fit", str(three), "--out", str(out), "--no-qa"])
    assert r.exit_code == 2, r.output
    said = " ".join(r.output.split())
    assert "fitted from 3 image(s): the simplest candidate (lambert) needs at least 4" in said
    assert "--model ps" in r.output  # what still works, said
    assert out.is_dir() and not any(out.iterdir())
    r = runner.invoke(app, ["fit", str(three), "--out", str(out), "--model", "ps", "--no-qa"])
    assert r.exit_code == 0, r.output
    r = runner.invoke(app, ["fit", str(session), "--out", str(tmp_path / "o2"), "--hsh-order", "2"])
    assert r.exit_code == 0, r.output


def test_a_fit_that_fails_after_writing_leaves_its_out_folder_empty(
    clean, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A failure once the maps and model files are written (here: the relight .dome, written
    after them) takes this run's files with it; the folder the user made stays, empty."""
    from rti_rig.app.usecases import fit as fit_module
    from rti_rig.core.errors import RtiRigError

    def fail_writing(*args, **kwargs):  # type: ignore[no-untyped-def]
        raise RtiRigError("disk full (simulated)")

    monkeypatch.setattr(fit_module.exporters, "write_relight_dome", fail_writing)
    out = tmp_path / "o"
    out.mkdir()
    seen: list[str] = []
    real_fit_all = fit_module._fit_all

    def spy(*args, **kwargs):  # type: ignore[no-untyped-def]
        result = real_fit_all(*args, **kwargs)
        seen.extend(p.name for p in out.iterdir())
        return result

    monkeypatch.setattr(fit_module, "_fit_all", spy)
    r = runner.invoke(app, ["fit", str(clean[0]), "--out", str(out), "--no-qa"])
    assert r.exit_code == 2 and "disk full (simulated)" in r.output
    assert "normals.png" in seen  # files had been written before the failure
    assert out.is_dir() and not any(out.iterdir())


def _names(indices) -> set[str]:
    return {f"image_{k + 1:03d}" for k in indices}


SIX_PAIRS = ((0, 5), (1, 6), (2, 7), (10, 14), (11, 15), (19, 23))
NINE_PAIRS = (*SIX_PAIRS, (20, 24), (27, 30), (28, 31))

CASES = {
    "clean": ({}, set(), ""),
    "misfire": ({"misfire": 5}, {"image_006"}, "misfired"),
    # a misfire that left a black frame: its gain was NaN (no pixel above the dark level), so
    # the dim check never ran and the image was called a wrong light
    "black frame": ({"black": 5}, {"image_006"}, "misfired, no light"),
    "swap": ({"swap": (3, 20)}, {"image_004", "image_021"}, "wrong light"),
    # six swapped pairs of 36 pushed the median direction error over the old gate: "good"
    "six swaps": ({"swaps": SIX_PAIRS}, _names(np.ravel(SIX_PAIRS)), "wrong light"),
    # nine pairs: half the lights wrong; a fit from all images is distorted until right and
    # wrong look alike, so the reference comes from the largest set that agrees
    "nine swaps": (
        {"swaps": NINE_PAIRS},
        _names(np.ravel(NINE_PAIRS)),
        "wrong light",
    ),
    "moved": ({"move": (33, 3, 2)}, {"image_034", "image_035", "image_036"}, "moved"),
    # 16 of 36 images moved: the fit blended two positions and only image_021 was flagged
    "moved mid-session": ({"move": (20, 3, 2)}, _names(range(20, 36)), "moved"),
    # the 10° ring taken last and moved: no image of it was drift-judged, verdict "good"
    "moved grazing ring": (
        {"move": (26, 3, 2), "lights": grazing_last_lights()},
        _names(range(26, 36)),
        "moved",
    ),
    "saturated": ({"saturate": 12}, {"image_013"}, "saturated"),
    # a 6 px move tilts the best-fit direction ~10°: it was named "wrong light (swapped?)"
    "moved 6 px": ({"move": (20, 6, 0)}, _names(range(20, 36)), "moved"),
    "moved 6 px late": ({"move": (33, 6, 4)}, {"image_034", "image_035", "image_036"}, "moved"),
}


@pytest.mark.parametrize("case", list(CASES))
def test_qa_flags_each_fault_by_name(tmp_path: Path, case: str) -> None:
    kwargs, expected, word = CASES[case]
    session, _, _ = make_session(tmp_path / "s", **kwargs)
    out = tmp_path / "out"
    r = runner.invoke(app, ["fit", str(session), "--out", str(out), "--model", "ps"])
    assert r.exit_code == 0, r.output
    qa = json.loads((out / "qa.json").read_text())
    assert set(qa["reshoot"]) == expected, qa["verdict"]
    if not expected:
        assert qa["verdict"] == "good" and "QA verdict: good" in r.output
    else:
        assert word in qa["verdict"]
        for name in expected:  # each by name, with the word
            assert any(c["name"] == name and word in "; ".join(c["problems"]) for c in qa["images"])
        if word == "moved":  # a move is not also (or instead) called a swapped light
            assert "wrong light" not in qa["verdict"], qa["verdict"]
    assert (out / "qa.html").read_text().count("<tr") == len(qa["images"]) + 1


def test_fit_refuses_a_missing_source_and_an_unknown_model(tmp_path: Path, clean) -> None:
    r = runner.invoke(app, ["fit", str(tmp_path / "nope"), "--out", str(tmp_path / "o")])
    assert r.exit_code == 2 and "session folder or an .lp" in r.output
    r = runner.invoke(app, ["fit", str(clean[0]), "--out", str(tmp_path / "o"), "--model", "x"])
    assert r.exit_code == 2 and "--model 'x' is not known" in r.output
    # the name --help gives is among the names the refusal lists (it gave only ps-robust)
    assert "robust-ps" in " ".join(r.output.split())


def test_run_prints_the_verdict_unless_told_not_to(tmp_path: Path) -> None:
    cfg = Path(__file__).resolve().parents[2] / "rig_configs" / "simulated_dome.toml"
    r = runner.invoke(app, ["run", str(cfg), "--out", str(tmp_path / "a"), "--lights", "12"])
    assert r.exit_code == 0, r.output
    assert "QA verdict:" in r.output
    r = runner.invoke(
        app, ["run", str(cfg), "--out", str(tmp_path / "b"), "--lights", "12", "--no-verdict"]
    )
    assert r.exit_code == 0 and "QA verdict" not in r.output


def test_fit_from_a_bare_lp_with_its_images_beside_it(clean, tmp_path: Path) -> None:
    import shutil

    from rti_rig.core.lp_format import LpEntry, read_lp, write_lp

    session, _, truth = clean
    folder = tmp_path / "bare"
    folder.mkdir()
    entries = []
    for e in read_lp(session / "lights.lp"):
        name = Path(e.name).stem + ".tif"
        shutil.copy(session / "linear" / name, folder / name)
        entries.append(LpEntry(name, e.direction))
    write_lp(folder / "my_dome.lp", entries)
    out = tmp_path / "out"
    r = runner.invoke(app, ["fit", str(folder / "my_dome.lp"), "--out", str(out), "--no-qa"])
    assert r.exit_code == 0, r.output
    assert float(np.median(_angles(np.load(out / "normals.npy"), truth))) < 3.0


def test_lights_dome_pairs_each_image_with_its_light_as_relight_lists_them(
    clean, tmp_path: Path
) -> None:
    """relight applies a ``.dome`` by position: relightlab's ``Project::scanDir``
    (cnr-isti-vclab/relight ``src/project.cpp``) lists the folder's images with a ``QDir``
    (default sort ``Name | IgnoreCase``) and ``DomePanel::loadDome``
    (``relightlab/domepanel.cpp``) gives image ``i`` direction ``i`` of ``Dome::fromJson``
    (``src/dome.cpp``: ``directions`` as ``{"x", "y", "z"}`` objects). An acquisition whose
    ``.lp`` lists ``img1.jpg`` … ``img10.jpg`` … in shooting order (relight lists ``img1``,
    ``img10``, ``img11``, …, ``img2``) had its lights.dome written in the ``.lp``'s order, so
    relight gave most images another image's light. QDir compares the lower-cased names by
    UTF-16 code units (``qdir.cpp``, ``qt_cmp_si``: ``QString::compare``): a name with an emoji
    (a surrogate pair from 0xD800) comes before a full-width ``ｉmg`` (0xFF49), where Python's
    code-point order had put it after, and the two images were given each other's lights.
    ``QString::toLower`` lowers each character alone: ``ΑΣ_1.jpg`` is ``ασ_1.jpg`` to it and
    comes after ``ασ.jpg``, where Python's ``str.lower`` (final sigma, ``ας_1``) put it before."""
    import shutil

    from rti_rig.core.lp_format import LpEntry, read_lp

    session = clean[0]
    folder = tmp_path / "acq"
    (folder / "linear").mkdir(parents=True)
    entries = []
    lights = read_lp(session / "lights.lp")
    # full-width 'ｉmg', an emoji, Greek capitals ending in a sigma, lower-case Greek
    unicode_names = ["\uff49mg.jpg", "\U0001f506.jpg", "\u0391\u03a3_1.jpg", "\u03b1\u03c3.jpg"]
    for k, e in enumerate(lights, start=1):
        n = len(lights) - len(unicode_names)
        name = f"Img{k}.jpg" if k <= n else unicode_names[k - n - 1]
        shutil.copy(
            session / "linear" / f"{Path(e.name).stem}.tif",
            folder / "linear" / f"{Path(name).stem}.tif",
        )
        entries.append(LpEntry(name, e.direction))
    assert len(entries) >= 12  # so that name order is not shooting order
    # written by hand: the .lp writer keeps to ASCII names, relight and rti-rig read UTF-8
    text = f"{len(entries)}\n" + "".join(
        f"{e.name} {e.direction[0]:.6f} {e.direction[1]:.6f} {e.direction[2]:.6f}\n"
        for e in entries
    )
    (folder / "dirs.lp").write_text(text, encoding="utf-8")
    out = tmp_path / "out"
    lean = ["--no-qa", "--no-ptm", "--no-hsh", "--model", "ps"]
    r = runner.invoke(app, ["fit", str(folder / "dirs.lp"), "--out", str(out), *lean])
    assert r.exit_code == 0, r.output
    dome = json.loads((out / "lights.dome").read_text(encoding="utf-8"))
    got = np.array([[d["x"], d["y"], d["z"]] for d in dome["directions"]])
    light_of = {e.name: np.array(e.direction) for e in entries}
    ascii_listed = sorted((n for n in light_of if n.isascii()), key=str.lower)  # IgnoreCase
    assert ascii_listed[:3] == ["Img1.jpg", "Img10.jpg", "Img11.jpg"]
    # Greek (0x03B1) before the emoji (0xD83D) before the full-width letter (0xFF49), by UTF-16
    # code units; 'ασ.jpg' before 'ΑΣ_1.jpg', lowered 'ασ_1.jpg' ('.' 0x2E before '_' 0x5F)
    listed = [*ascii_listed, "\u03b1\u03c3.jpg", "\u0391\u03a3_1.jpg"]
    listed += ["\U0001f506.jpg", "\uff49mg.jpg"]
    expected = np.array([light_of[name] for name in listed])
    np.testing.assert_allclose(got, expected, atol=1e-6)


def test_batch_fit_is_resumable(clean, tmp_path: Path) -> None:
    import shutil

    session = clean[0]
    second = tmp_path / "second"
    shutil.copytree(session, second)
    out = tmp_path / "batch"
    # a killed earlier run left a partial folder for the second session
    (out / ".second.partial").mkdir(parents=True)
    (out / ".second.partial" / "junk").write_text("x")
    args = ["fit", str(session), str(second), "--out", str(out), "--model", "ps", "--no-qa"]
    r = runner.invoke(app, args)
    assert r.exit_code == 0, r.output
    assert r.output.count(": done") == 2
    assert (out / session.name / "normals.npy").is_file()
    assert (out / "second" / "fit.json").is_file() and not (out / "second" / "junk").exists()
    assert not (out / ".second.partial").exists()
    first = np.load(out / "second" / "normals.npy")
    np.testing.assert_array_equal(first, np.load(out / session.name / "normals.npy"))
    r = runner.invoke(app, args)
    # words, not line breaks: Rich wraps at the terminal's width, a long tmp path included
    assert r.exit_code == 0 and " ".join(r.output.split()).count("(finished earlier)") == 2


def test_a_batch_given_the_current_folder_fits_it(
    clean, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """``fit . OTHER --out OUT`` from inside a session: ``.`` has no name of its own, and its
    output had been ``OUT/.`` (``OUT`` itself, which exists once the batch begins), so the
    session was reported "skipped (finished earlier)" and never fitted."""
    import shutil

    here = tmp_path / "coin"
    shutil.copytree(clean[0], here)
    other = tmp_path / "tablet"
    shutil.copytree(clean[0], other)
    out = tmp_path / "batch"
    monkeypatch.chdir(here)
    args = ["fit", ".", "../tablet", "--out", str(out), "--model", "ps", "--no-qa"]
    r = runner.invoke(app, args)
    assert r.exit_code == 0, r.output
    assert "finished earlier" not in r.output and r.output.count(": done") == 2
    assert (out / "coin" / "normals.npy").is_file() and (out / "tablet" / "fit.json").is_file()
    r = runner.invoke(app, args)  # and a second run finds both finished, by the same names
    # words, not line breaks: Rich wraps at the terminal's width, a long tmp path included
    assert r.exit_code == 0 and " ".join(r.output.split()).count("(finished earlier)") == 2


def test_a_batch_whose_sessions_share_a_folder_name_names_them(clean, tmp_path: Path) -> None:
    """Two days' sessions both named ``coin``: refused before anything is fitted, naming both
    sources, the output folder they would share and what to do (it had said only "two
    sources would write to the same folder: ['coin']")."""
    import shutil

    first, second = tmp_path / "day1" / "coin", tmp_path / "day2" / "coin"
    shutil.copytree(clean[0], first)
    shutil.copytree(clean[0], second)
    out = tmp_path / "batch"
    r = runner.invoke(app, ["fit", str(first), str(second), "--out", str(out), "--no-qa"])
    said = " ".join(r.output.split())
    assert r.exit_code == 2, r.output
    assert str(first) in said and str(second) in said and str(out / "coin") in said
    assert "separate batches" in said and "rename" in said
    assert not out.exists()


def test_qa_verdict_does_not_depend_on_the_order_images_are_listed(tmp_path: Path) -> None:
    """The consensus search draws images at random (seeded): drawn by their position in the
    listing, nine swapped pairs were named correctly in one order and not in others (14 of
    18 missed, 18 right lights called wrong). Drawn in an order of the lights themselves, the
    same acquisition listed in any order gets the same verdict."""
    session, _, _ = make_session(tmp_path / "s", swaps=NINE_PAIRS)
    lines = (session / "lights.lp").read_text().splitlines()
    header, rows = lines[0], lines[1:]
    expected = _names(np.ravel(NINE_PAIRS))
    rng = np.random.default_rng(1)
    for k in range(3):
        order = rng.permutation(len(rows))
        (session / "lights.lp").write_text("\n".join([header] + [rows[i] for i in order]) + "\n")
        out = tmp_path / f"out{k}"
        r = runner.invoke(app, ["fit", str(session), "--out", str(out), "--model", "ps"])
        assert r.exit_code == 0, r.output
        qa = json.loads((out / "qa.json").read_text())
        assert set(qa["reshoot"]) == expected, qa["verdict"]


def test_ptm_normals_without_a_ptm_file(clean, tmp_path: Path) -> None:
    """`--model ptm --no-ptm`: the PTM gives the normals and is not written (it had stopped
    with a KeyError traceback and left an empty folder)."""
    session, _, truth = clean
    out = tmp_path / "out"
    r = runner.invoke(
        app, ["fit", str(session), "--out", str(out), "--model", "ptm", "--no-ptm", "--no-qa"]
    )
    assert r.exit_code == 0, r.output
    assert not (out / "fit.ptm").exists() and (out / "fit.rti").is_file()
    err = float(np.median(_angles(np.load(out / "normals.npy"), truth)))
    assert err < BOUNDS["ptm"]
    # the model's line says no fit.ptm is written (it had said "Model: ptm: chosen by --model")
    said = "fit.ptm not written (--no-ptm): the model is fitted for the normal maps only"
    assert f"Model: ptm: chosen by --model; {said}" in " ".join(r.output.split()), r.output
    assert said in json.loads((out / "fit.json").read_text())["why"]


def test_a_model_not_written_is_said_on_its_line(clean, tmp_path: Path) -> None:
    """`--model hsh1 --no-hsh`: no fit.rti, and the HSH gives no normal map: the model's line
    says no file holds it (it named the HSH alone, as if written)."""
    session, _, _ = clean
    out = tmp_path / "out"
    argv = ["fit", str(session), "--out", str(out), "--model", "hsh1", "--no-hsh", "--no-qa"]
    r = runner.invoke(app, argv)
    assert r.exit_code == 0, r.output
    assert not (out / "fit.rti").exists()
    text = " ".join(r.output.split())
    assert "Model: hsh1: chosen by --model; fit.rti not written (--no-hsh): no file holds it" in (
        text
    ), r.output


def test_the_fit_says_where_its_normals_come_from(tmp_path: Path) -> None:
    """An auto fit reads its normals from the model it chose when that is Lambert (measured
    both ways: docs/reconstruction.md, "Where an auto fit's normals come from"), and says so
    in fit.json and on the CLI with how to ask for robust PS; `--model robust-ps` gives robust
    PS. At 12 lights on the simulated painting auto chooses Lambert."""
    lights = _rings(((15, 6, 0), (40, 4, 20), (70, 2, 0)))
    session, _, _ = make_session(tmp_path / "s", scene="painting", lights=lights, size=(96, 112))
    maps = {}
    for model in ("auto", "robust-ps", "lambert"):
        out = tmp_path / model
        r = runner.invoke(
            app, ["fit", str(session), "--out", str(out), "--model", model, "--no-qa"]
        )
        assert r.exit_code == 0, r.output
        summary = json.loads((out / "fit.json").read_text())
        maps[model] = (np.load(out / "normals.npy"), summary, " ".join(r.output.split()))
    normals, summary, output = maps["auto"]
    assert summary["model"] == "lambert", summary["why"]  # the case this test is for
    assert summary["normals_from"] == "lambert"
    assert "Normals: the least-squares Lambert fit" in output and "--model robust-ps" in output
    assert np.array_equal(normals, maps["lambert"][0])
    assert maps["robust-ps"][1]["normals_from"] == "ps-robust"
    assert "Normals: robust photometric stereo" in maps["robust-ps"][2]
    assert not np.array_equal(normals, maps["robust-ps"][0])


def test_a_six_light_session_gets_the_hsh_order_its_evidence_supports(tmp_path: Path) -> None:
    """At 6 lights `--model auto` chooses Lambert (not an HSH) and order 2 needs 9 lights: an
    auto fit wrote no fit.rti at all, only a PTM its 6 lights determine exactly. The HSH order
    is now chosen from the same held-out evidence (order 1 here, 4 terms), written, and relit
    as an independent HSH fit of the same images; fit.json and the CLI say why."""
    import tifffile

    from rti_rig.reconstruct import fit_hsh
    from rti_rig.reconstruct.stack import ImageStack

    lights = _rings(((30, 3, 0), (60, 3, 60)))
    session, _, _ = make_session(tmp_path / "s", scene="tablet", lights=lights, size=(64, 80))
    out = tmp_path / "out"
    args = ["fit", str(session), "--out", str(out), "--no-qa", "--export-encoding", "linear"]
    r = runner.invoke(app, args)
    assert r.exit_code == 0, r.output
    summary = json.loads((out / "fit.json").read_text())
    assert summary["model"] == "lambert", summary["why"]  # the case this test is for
    assert summary["rti"].startswith("hsh1: the lowest HSH order") and "fit.rti: hsh1" in r.output
    assert not any("fit.rti not written" in w for w in summary["warnings"])
    # the PTM beside it is written, with a word on what it is worth (nothing measures it here)
    assert any(w.startswith("fit.ptm is written from 6 lights") for w in summary["warnings"])
    assert "prefer fit.rti" in " ".join(r.output.split())
    rti_file = _read_rti(out / "fit.rti")
    assert rti_file.shape[0] == 4
    frames = [tifffile.imread(p) for p in sorted((session / "linear").glob("*.tif"))]
    hsh = fit_hsh(ImageStack(frames), lights, 1)
    for d in ([0.3, 0.2, 0.9327], [-0.5, 0.4, 0.7681]):
        d = np.array(d) / np.linalg.norm(d)
        ref = np.tensordot(hsh_basis(d[None], 1)[0], hsh.coefficients, axes=(0, 0))
        got = np.tensordot(hsh_basis(d[None], 1)[0], rti_file, axes=(0, 0))
        assert np.percentile(np.abs(got - ref), 99) < 3.0 / 255  # 8-bit quantisation, 4 terms


def test_every_model_gets_the_hsh_order_its_evidence_supports(tmp_path: Path) -> None:
    """`--model ps` (a model fit.rti cannot hold) measures the HSH orders on held-out lights too
    (it wrote order 2 from 9 lights, or nothing); below 5 lights nothing can be measured and
    fit.rti is left out with what to do; `--hsh-order` asks for an order and is refused, by
    name, where the lights cannot determine it."""
    for count in (7, 4):
        lights = _rings(((25, count - 2, 0), (60, 2, 45)))
        session, _, _ = make_session(tmp_path / f"s{count}", lights=lights, size=(48, 56))
        out = tmp_path / f"out{count}"
        r = runner.invoke(app, ["fit", str(session), "--out", str(out), "--no-qa", "--model", "ps"])
        assert r.exit_code == 0, r.output
        summary = json.loads((out / "fit.json").read_text())
        if count == 4:
            assert not (out / "fit.rti").exists() and summary["rti"] is None
            assert any("--hsh-order 1 writes order 1" in w for w in summary["warnings"])
            forced = tmp_path / "forced4"
            args = ["fit", str(session), "--out", str(forced), "--no-qa", "--hsh-order", "1"]
            r = runner.invoke(app, args)
            assert r.exit_code == 0, r.output
            assert _read_rti(forced / "fit.rti").shape[0] == 4
            assert json.loads((forced / "fit.json").read_text())["rti"] == "hsh1: asked for"
            refused = tmp_path / "refused4"
            args = ["fit", str(session), "--out", str(refused), "--no-qa", "--hsh-order", "2"]
            r = runner.invoke(app, args)
            assert r.exit_code == 2 and "--hsh-order 2" in " ".join(r.output.split())
        else:
            assert _read_rti(out / "fit.rti").shape[0] == 4
            assert summary["rti"].startswith("hsh1: the lowest HSH order within 5%")
            assert "ps, the model used, is not an HSH" in summary["rti"]


def test_fit_refuses_a_cfa_mosaic_session_by_name(tmp_path: Path) -> None:
    """A session shot with ``decode.mode = "mosaic"`` holds one colour per pixel: ``fit`` had
    fitted the checkerboard at a white level of 65535 (the sensor's range is lower) and
    written normals, .ptm and .rti without a warning. It is refused, naming the file and
    what to do; nothing is left in --out."""
    from rti_rig.core.image_files import write_linear_tiff
    from rti_rig.core.lp_format import LpEntry, write_lp
    from rti_rig.runtime.session import _tiff_description

    label = _tiff_description({"mode": "mosaic", "cfa_pattern": "RGGB"})
    session = tmp_path / "s"
    (session / "linear").mkdir(parents=True)
    rng = np.random.default_rng(0)
    entries = []
    for k, d in enumerate(dome_lights()[:8]):
        name = f"image_{k + 1:03d}"
        px = rng.integers(100, 15000, (32, 40), dtype=np.uint16)  # one plane, 14-bit range
        write_linear_tiff(session / "linear" / f"{name}.tif", px, description=label)
        entries.append(LpEntry(f"{name}.jpg", tuple(float(x) for x in d)))
    write_lp(session / "lights.lp", entries)
    out = tmp_path / "out"
    r = runner.invoke(app, ["fit", str(session), "--out", str(out)])
    said = " ".join(r.output.split())
    assert r.exit_code == 2, r.output
    assert "image_001.tif is a CFA mosaic" in said and 'decode.mode = "demosaic"' in said
    assert "Traceback" not in r.output
    assert not out.exists() or not any(out.iterdir())


def test_a_batch_says_each_session_s_notes_and_warnings(tmp_path: Path) -> None:
    """``fit S1 S2 --out ROOT`` had printed one line per session and dropped what ``fit S``
    says of it: here a 5-light session's "fit.ptm not written" (a PTM needs 6)."""
    from conftest import CONFIGS

    sessions = []
    for name, n in (("five", "5"), ("six", "6")):
        s = tmp_path / name
        cfg = str(CONFIGS / "simulated_dome.toml")
        r = runner.invoke(app, ["run", cfg, "--out", str(s), "--lights", n, "--no-verdict"])
        assert r.exit_code == 0, r.output
        sessions.append(str(s))
    r = runner.invoke(app, ["fit", *sessions, "--out", str(tmp_path / "batch"), "--no-qa"])
    assert r.exit_code == 0, r.output
    said = " ".join(r.output.split())
    five, six = said.index(f"{sessions[0]}: done"), said.index(f"{sessions[1]}: done")
    warning = said.index("warning: fit.ptm not written: a PTM needs at least 6 lights, there are 5")
    assert five < warning < six  # under its own session
    assert said.count("fit.ptm not written") == 1


#: Twelve lights in rings from 10° to 70° (the simulated dome's 12-light plan's elevations).
TWELVE = _rings(((10, 2, 0), (25, 3, 45), (40, 3, 108), (55, 3, 22), (70, 1, 60)))


@pytest.mark.parametrize("k", [2, 8, 10])
def test_an_image_clipped_throughout_is_not_called_a_wrong_light(tmp_path: Path, k: int) -> None:
    # 96-100 % clipped, its best direction was fitted on the few pixels its light barely
    # reaches: "saturated … ; wrong light: lit from 9-22° away … (swapped?)"
    session, _, _ = make_session(tmp_path / "s", lights=TWELVE, saturate=k)
    out = tmp_path / "out"
    r = runner.invoke(app, ["fit", str(session), "--out", str(out), "--model", "ps"])
    assert r.exit_code == 0, r.output
    qa = json.loads((out / "qa.json").read_text())
    name = f"image_{k + 1:03d}"
    assert set(qa["reshoot"]) == {name}, qa["verdict"]
    assert "saturated" in qa["verdict"] and "wrong light" not in qa["verdict"], qa["verdict"]
    assert (
        f"light direction not checked on {name} (more than 50% of the pixels judged clipped)"
        in (qa["verdict"])
    )


def test_an_out_folder_a_killed_fit_left_is_named_as_such(tmp_path: Path) -> None:
    """A fit killed outright (SIGKILL, an out-of-memory kill: no clean-up can run) left its
    --out holding normals.npy and fit.ptm.part; the same command was then refused as merely
    "not empty". It now says whose files they are and what to do; a folder of other files is
    still refused as not empty."""
    session, _, _ = make_session(tmp_path / "s", lights=dome_lights()[:12], size=(48, 64))
    out = tmp_path / "o"
    out.mkdir()
    (out / "normals.npy").write_bytes(b"\x93NUMPY")
    (out / "fit.ptm.part").write_bytes(b"PTM_1.2\n")
    r = runner.invoke(app, ["fit", str(session), "--out", str(out)])
    said = " ".join(r.output.split())
    assert r.exit_code == 2, r.output
    assert "holds the outputs of a fit that did not finish (fit.ptm.part, normals.npy" in said
    assert "delete that folder, or those files, and run this again" in said
    other = tmp_path / "other"
    other.mkdir()
    (other / "notes.txt").write_text("mine")
    r = runner.invoke(app, ["fit", str(session), "--out", str(other)])
    assert r.exit_code == 2 and "is not empty" in " ".join(r.output.split()), r.output


@pytest.mark.parametrize("typed", ["robust-ps", "ps-robust"])
def test_a_model_asked_by_name_is_echoed_as_typed(clean, tmp_path: Path, typed: str) -> None:
    """`--model robust-ps` (the name --help and the guide give) had been echoed as its alias,
    "Model: ps-robust: chosen by --model" (QA, 2026-12-05)."""
    session, _, _ = clean
    out = tmp_path / "out"
    r = runner.invoke(app, ["fit", str(session), "--out", str(out), "--model", typed, "--no-qa"])
    assert r.exit_code == 0, r.output
    assert f"Model: {typed}: chosen by --model" in " ".join(r.output.split()), r.output


def test_the_auto_choice_is_said_as_the_simplest_model_not_an_order(clean, tmp_path: Path) -> None:
    """A PTM or Lambert fit has no "order": "lambert: lowest order within 5%" had been said."""
    session, _, _ = clean
    out = tmp_path / "out"
    r = runner.invoke(app, ["fit", str(session), "--out", str(out), "--no-qa"])
    assert r.exit_code == 0, r.output
    text = " ".join(r.output.split())
    assert ": the simplest model within 5% of the best held-out error (" in text, text
    assert (
        "lowest order" not in text and "lowest order" not in (out / "model_choice.md").read_text()
    )
