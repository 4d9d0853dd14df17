"""A session shot and fitted through the CLI, its files read and relit the way the viewers do.

Independent of rti-rig's writers *and* of its bases: nothing from ``rti_rig.reconstruct`` or
``rti_rig.core.rti_bases`` is used here. Each file is read, and relit, as the third-party
program does, re-derived from its published source:

* ``fit.ptm`` as RTIViewer's ``RGBPtm::loadData`` reads ``PTM_FORMAT_RGB`` (HP's PTM 1.2
  layout): per colour plane, scanlines from the bottom of the image up, six bytes per pixel,
  ``a_i = int((byte - bias_i) * scale_i)`` (the viewer keeps integer coefficients), relit as
  ``a0 lu² + a1 lv² + a2 lu lv + a3 lu + a4 lv + a5`` with ``(lu, lv)`` the light's x and y,
  the result shown as the byte itself;
* ``fit.rti`` as RTIViewer's ``UniversalRti::load`` / ``Hsh::loadData`` read an HSH ``.rti``
  (scanlines top-down, per pixel R, G, B blocks of terms, ``byte / 255 × scale + bias``) and
  as its ``getHSH`` (``util.h``, RTIViewer 1.1; the same weights in CHI's Java viewer) weights
  the terms: ``phi = atan2(ly, lx)`` in [0, 2π), ``theta = min(acos(lz), π/2 − 0.04)``, the
  relit sum × 255 shown;
* ``lights.lp`` as relight's ``parseLP`` (src/lp.cpp) reads it: a count line of at most 1000,
  then exactly four whitespace-separated fields a line, the image named relative to the file;
* ``normals.png`` decoded by imagecodecs (not OpenCV, which wrote it): R, G, B = x, y, z as
  ``(n + 1) / 2``, y towards the top of the image, as relight writes and reads its normal maps.

What the files are compared with is the photographs (the JPEGs the session wrote, which the
default ``--export-encoding srgb`` fits) and the scene's geometry: the simulated ``relief``
scene has a hemispherical boss at the image centre, so its flank facing a light is the bright
one and its normals point away from the centre. An image upside down, mirrored, or relit with
the light's y (or x) negated matches the photograph far worse, which is what catches a row
order, a coefficient order or a sign that a viewer would read differently.
"""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import imagecodecs
import numpy as np
import pytest
from typer.testing import CliRunner

from rti_rig.cli import app

REPO = Path(__file__).resolve().parents[2]
runner = CliRunner()

# not square, so that a transposed read cannot pass
WIDTH, HEIGHT = 128, 96


@pytest.fixture(scope="module")
def shot(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    """``rti-rig run`` on the shipped simulated dome (smaller frames), then ``rti-rig fit``."""
    base = tmp_path_factory.mktemp("viewers")
    text = (REPO / "rig_configs" / "simulated_dome.toml").read_text(encoding="utf-8")
    text, n_w = re.subn(r"(?m)^width = \d+", f"width = {WIDTH}", text)
    text, n_h = re.subn(r"(?m)^height = \d+", f"height = {HEIGHT}", text)
    assert n_w == n_h == 1
    cfg = base / "dome.toml"
    cfg.write_text(text, encoding="utf-8")
    session = base / "S"
    r = runner.invoke(app, ["run", str(cfg), "--out", str(session)])
    assert r.exit_code == 0, r.output
    fitted = base / "F"
    r = runner.invoke(app, ["fit", str(session), "--out", str(fitted), "--no-qa"])
    assert r.exit_code == 0, r.output
    return session, fitted


# --- readers, as the viewers read -------------------------------------------------------------


def read_lp_as_relight(path: Path) -> list[tuple[str, np.ndarray]]:
    lines = path.read_bytes().decode("ascii").split("\n")
    n = int(lines[0])
    assert 0 < n <= 1000
    entries = []
    for line in lines[1 : n + 1]:
        tokens = line.split()
        assert len(tokens) == 4, line
        assert line == " ".join(tokens), f"stray whitespace or CR in {line!r}"
        entries.append((tokens[0], np.array([float(t) for t in tokens[1:]])))
    assert all(not rest for rest in lines[n + 1 :])  # nothing after the n lines
    return entries


def _header_lines(data: bytes, count: int, skip_comments: bool) -> tuple[list[str], int]:
    lines: list[str] = []
    pos = 0
    while len(lines) < count:
        end = data.index(b"\n", pos)
        line = data[pos:end].decode("ascii")
        pos = end + 1
        if not (skip_comments and line.startswith("#")):
            lines.append(line)
    return lines, pos


def read_ptm_as_rtiviewer(path: Path) -> np.ndarray:
    """(H, W, 3, 6) integer coefficients, row 0 = the top row shown."""
    data = path.read_bytes()
    lines, pos = _header_lines(data, 6, skip_comments=False)
    assert lines[0] == "PTM_1.2" and lines[1] == "PTM_FORMAT_RGB"
    w, h = int(lines[2]), int(lines[3])
    scale = [float(v) for v in lines[4].split(" ") if v]
    bias = [int(v) for v in lines[5].split(" ") if v]  # the viewer reads them as integers
    assert len(scale) == len(bias) == 6
    body = np.frombuffer(data, np.uint8, offset=pos)
    assert body.size == 3 * h * w * 6
    planes = body.reshape(3, h, w, 6).astype(np.float64)
    coef = np.trunc((planes - np.array(bias)) * np.array(scale))  # static_cast<int>
    # the first scanline of a plane is the image's bottom row (the loop runs y = h-1 .. 0)
    return np.transpose(coef[:, ::-1], (1, 2, 0, 3))


def relight_ptm_as_rtiviewer(coef: np.ndarray, light: np.ndarray) -> np.ndarray:
    lu, lv = float(light[0]), float(light[1])
    value = coef @ np.array([lu * lu, lv * lv, lu * lv, lu, lv, 1.0])
    return np.floor(np.clip(value, 0.0, 255.0))  # tobyte


def read_rti_as_rtiviewer(path: Path) -> np.ndarray:
    """(H, W, 3, terms) float coefficients, row 0 = the top row shown."""
    data = path.read_bytes()
    assert data.startswith(b"#HSH1.2\r\n")  # relight's LRti::load compares its first 7 bytes
    lines, pos = _header_lines(data, 3, skip_comments=True)
    assert int(lines[0]) == 3  # HSH
    w, h, colours = (int(v) for v in lines[1].split())
    terms, _basis_type, element_size = (int(v) for v in lines[2].split())
    assert colours == 3 and element_size == 1 and terms in (4, 9, 16)
    scale = np.frombuffer(data, "<f4", terms, pos).astype(np.float64)
    bias = np.frombuffer(data, "<f4", terms, pos + 4 * terms).astype(np.float64)
    body = np.frombuffer(data, np.uint8, offset=pos + 8 * terms)
    assert body.size == h * w * 3 * terms
    return body.reshape(h, w, 3, terms) / 255.0 * scale + bias


def read_rti_as_jedmills_rtiviewer(path: Path) -> np.ndarray:
    """(H, W, 3, terms) as JedMills' RTIViewer reads an HSH ``.rti`` (JedMills/RTIViewer
    ``src/ptmCreation/RTIParser.java``): ``getHeaderData`` reads lines with a
    ``BufferedReader`` (a line ends at LF, CR or CRLF) and takes the data to start at the sum
    of ``line.length() + 2`` over the lines up to the first that is no comment, then two more;
    ``getTexelDataHSH`` skips that many bytes and reads the little-endian scales and biases,
    then the bytes. Only files whose header lines end in CRLF (as the HSH fitter RTIBuilder
    runs writes them) are read where they are."""
    text = path.read_bytes().decode("latin-1")
    lines = iter(re.split(r"\r\n|\r|\n", text))
    line = next(lines)
    start = len(line) + 2
    while line.startswith("#"):
        line = next(lines)
        start += len(line) + 2
    first, second = next(lines), next(lines)
    start += len(first) + 2 + len(second) + 2
    w, h, _ = (int(v) for v in first.split())
    terms = int(second.split()[0])
    data = path.read_bytes()
    scale = np.frombuffer(data, "<f4", terms, start).astype(np.float64)
    bias = np.frombuffer(data, "<f4", terms, start + 4 * terms).astype(np.float64)
    body = np.frombuffer(data, np.uint8, h * w * 3 * terms, start + 8 * terms)
    return body.reshape(h, w, 3, terms) / 255.0 * scale + bias


def test_fit_rti_reads_alike_in_jedmills_rtiviewer_and_in_rtiviewer(shot) -> None:
    """JedMills' RTIViewer finds an HSH file's data by counting 2 bytes per header line end;
    fit.rti's header lines had ended in LF alone, so it read every scale, bias and
    coefficient from 5 bytes too far (garbage), where RTIViewer, relight and CHI's viewer,
    reading to the LF, read it right. With CRLF, as RTIBuilder's HSH fitter writes them, all
    read the same coefficients."""
    _, fitted = shot
    data = (fitted / "fit.rti").read_bytes()
    header = data[: data.index(b" 2 1\r\n") + len(b" 2 1\r\n")]
    assert header.count(b"\n") == header.count(b"\r\n") == 5  # every header line ends in CRLF
    np.testing.assert_array_equal(
        read_rti_as_jedmills_rtiviewer(fitted / "fit.rti"),
        read_rti_as_rtiviewer(fitted / "fit.rti"),
    )


def rtiviewer_hsh_weights(light: np.ndarray, terms: int) -> np.ndarray:
    x, y, z = np.asarray(light, dtype=np.float64) / np.linalg.norm(light)
    phi = math.atan2(y, x)
    if phi < 0:
        phi += 2 * math.pi
    theta = min(math.acos(z), math.pi / 2 - 0.04)
    c = math.cos(theta)
    c2 = c * c
    s = math.sqrt(c - c2)
    pi = math.pi
    w = [
        1 / math.sqrt(2 * pi),
        math.sqrt(6 / pi) * math.cos(phi) * s,
        math.sqrt(3 / (2 * pi)) * (2 * c - 1),
        math.sqrt(6 / pi) * s * math.sin(phi),
        math.sqrt(30 / pi) * math.cos(2 * phi) * (c2 - c),
        math.sqrt(30 / pi) * math.cos(phi) * (2 * c - 1) * s,
        math.sqrt(5 / (2 * pi)) * (6 * c2 - 6 * c + 1),
        math.sqrt(30 / pi) * (2 * c - 1) * s * math.sin(phi),
        math.sqrt(30 / pi) * (c2 - c) * math.sin(2 * phi),
        2 * math.sqrt(35 / pi) * math.cos(3 * phi) * (c - c2) ** 1.5,
        math.sqrt(210 / pi) * math.cos(2 * phi) * (2 * c - 1) * (c2 - c),
        2 * math.sqrt(21 / pi) * math.cos(phi) * s * (5 * c2 - 5 * c + 1),
        math.sqrt(7 / (2 * pi)) * (20 * c2 * c - 30 * c2 + 12 * c - 1),
        2 * math.sqrt(21 / pi) * s * (5 * c2 - 5 * c + 1) * math.sin(phi),
        math.sqrt(210 / pi) * (2 * c - 1) * (c2 - c) * math.sin(2 * phi),
        2 * math.sqrt(35 / pi) * (c - c2) ** 1.5 * math.sin(3 * phi),
    ]
    return np.array(w[:terms])


def relight_rti_as_rtiviewer(coef: np.ndarray, light: np.ndarray) -> np.ndarray:
    value = coef @ rtiviewer_hsh_weights(light, coef.shape[-1]) * 255.0
    return np.floor(np.clip(value, 0.0, 255.0))  # tobyte(val * 255)


def photograph(session: Path, name: str) -> np.ndarray:
    img = imagecodecs.imread(session / name)  # RGB, rows top-down
    assert img.shape == (HEIGHT, WIDTH, 3)
    return img.astype(np.float64)


# --- the boss at the centre of the relief scene ----------------------------------------------

CY, CX = (HEIGHT - 1) / 2, (WIDTH - 1) / 2
FLANK = 0.7 * 0.22 * min(HEIGHT, WIDTH)  # 70 % of the boss's radius from its centre


def flank(img: np.ndarray, side: str) -> float:
    """Mean of a 5×5 window on the boss's right/left/top/bottom flank (top = smaller rows)."""
    dy, dx = {"right": (0, 1), "left": (0, -1), "top": (-1, 0), "bottom": (1, 0)}[side]
    r, c = round(CY + dy * FLANK), round(CX + dx * FLANK)
    return float(np.mean(img[r - 2 : r + 3, c - 2 : c + 3]))


# --- the tests --------------------------------------------------------------------------------


def test_lights_lp_reads_as_relight_parses_it_in_the_lp_frame(shot) -> None:
    session, _ = shot
    entries = read_lp_as_relight(session / "lights.lp")
    names = [name for name, _ in entries]
    assert len(entries) == 48
    # relight-cli pairs the folder's images, sorted by name, with the lines by order
    assert names == sorted(p.name for p in session.glob("*.jpg"))
    for name, d in entries:
        assert "/" not in name and "\\" not in name and (session / name).is_file()
        assert abs(np.linalg.norm(d) - 1.0) < 1e-5 and d[2] > 0
    # the frame: x to the image's right, y to its top (rows run down), z to the camera
    light = dict(entries)
    right = max(names, key=lambda n: light[n][0])
    top = max(names, key=lambda n: light[n][1])
    img = photograph(session, right).mean(axis=-1)
    assert flank(img, "right") > flank(img, "left") + 30
    img = photograph(session, top).mean(axis=-1)
    assert flank(img, "top") > flank(img, "bottom") + 30


def _lights_to_check(entries: list[tuple[str, np.ndarray]]) -> list[tuple[str, np.ndarray]]:
    """Lights above 30° whose x and y are both far from 0 (so that negating either moves the
    light well away)."""
    return [(n, d) for n, d in entries if d[2] > 0.5 and abs(d[0]) > 0.2 and abs(d[1]) > 0.2]


def ptm_terms(d: np.ndarray) -> np.ndarray:
    return np.array([d[0] * d[0], d[1] * d[1], d[0] * d[1], d[0], d[1], 1.0])


@pytest.mark.parametrize("kind", ["ptm", "rti"])
def test_files_relit_by_the_viewer_formula_give_the_photographs(shot, kind: str) -> None:
    """Relit as RTIViewer relights it, each file gives (a) the photograph taken under that
    light, to within what its model can fit, and (b) the same model fitted here, by least
    squares in the viewer's own basis, to the 48 photographs, to within its 8-bit storage;
    read upside down, mirrored, or relit with the light's x or y negated it gives neither."""
    session, fitted = shot
    entries = read_lp_as_relight(session / "lights.lp")
    if kind == "ptm":
        coef = read_ptm_as_rtiviewer(fitted / "fit.ptm")
        relight = relight_ptm_as_rtiviewer
        basis = ptm_terms
        bound = 14.0  # a PTM's quadratic misses the boss's shadows: measured 3.4-12.3 levels
    else:
        coef = read_rti_as_rtiviewer(fitted / "fit.rti")
        relight = relight_rti_as_rtiviewer
        terms = coef.shape[-1]
        basis = lambda d: rtiviewer_hsh_weights(d, terms)  # noqa: E731
        bound = 4.0  # measured 1.9-2.4 levels of 255
    assert coef.shape[:3] == (HEIGHT, WIDTH, 3)
    photos = np.stack([photograph(session, n) for n, _ in entries]).reshape(len(entries), -1)
    design = np.array([basis(d) for _, d in entries])
    mine = np.linalg.lstsq(design, photos, rcond=None)[0]  # the model, fitted independently
    checked = _lights_to_check(entries)
    assert len(checked) >= 8
    for name, d in checked:
        photo = photograph(session, name)
        ref = np.clip(basis(d) @ mine, 0.0, 255.0).reshape(photo.shape)
        relit = relight(coef, d)
        err = float(np.mean(np.abs(relit - photo)))
        assert err < bound, f"{kind} at {name}: {err:.1f} levels from the photograph"
        err = float(np.mean(np.abs(relit - ref)))
        assert err < 2.5, f"{kind} at {name}: {err:.1f} levels from the model fitted here"
        wrong = {
            "upside down": relit[::-1],
            "mirrored": relit[:, ::-1],
            "light y negated": relight(coef, d * [1, -1, 1]),
            "light x negated": relight(coef, d * [-1, 1, 1]),
        }
        for what, other in wrong.items():
            e = float(np.mean(np.abs(other - ref)))
            assert e > max(4.0, 3 * err), f"{kind} at {name}: {what} {e:.1f} vs {err:.1f}"


def test_normal_map_png_is_rgb_xyz_with_y_up(shot) -> None:
    _, fitted = shot
    png = imagecodecs.png_decode((fitted / "normals.png").read_bytes())
    assert png.dtype == np.uint16 and png.shape == (HEIGHT, WIDTH, 3)
    n = png.astype(np.float64) / 65535.0 * 2.0 - 1.0  # channels in file order: R, G, B
    assert np.median(np.abs(np.linalg.norm(n, axis=-1) - 1.0)) < 1e-3
    x, y, z = n[..., 0], n[..., 1], n[..., 2]
    # the boss's normals point away from its centre: right flank +x, top flank +y (up)
    assert flank(x, "right") > 0.4 and flank(x, "left") < -0.4
    assert flank(y, "top") > 0.4 and flank(y, "bottom") < -0.4
    assert abs(flank(x, "top")) < 0.2 and abs(flank(y, "right")) < 0.2
    assert float(np.min(z)) >= 0.0 and float(np.median(z)) > 0.9


def test_a_16_term_rti_says_that_relight_reads_hsh_only_to_9_terms(shot, tmp_path) -> None:
    """relight converts a legacy .rti with ``convertRTI`` (src/cli/convert_rti.cpp): its
    ``LRti`` knows a plane order of 9 HSH terms and ``Rti::lightWeightsHsh`` (src/rti.cpp)
    computes 9 weights; its converter back refuses anything but 12 or 27 planes. So a
    16-term fit.rti (order 3, which `fit` writes when the held-out evidence asks for it)
    opens in RTIViewer but not correctly in relight: the fit says so on fit.rti's own line (a
    note, not a fit warning: the file is as good as asked), and how to get a file relight
    reads."""
    session, fitted = shot
    summary = json.loads((fitted / "fit.json").read_text())
    terms = read_rti_as_rtiviewer(fitted / "fit.rti").shape[-1]
    said = "relight" in summary["rti"] and "--hsh-order 2" in summary["rti"]
    assert said == (terms == 16), summary["rti"]
    assert not [w for w in summary["warnings"] if "relight" in w]
    lean = ["--no-qa", "--no-normals", "--no-ptm"]
    out = tmp_path / "o2"
    r = runner.invoke(app, ["fit", str(session), "--out", str(out), *lean, "--hsh-order", "2"])
    assert r.exit_code == 0, r.output
    assert read_rti_as_rtiviewer(out / "fit.rti").shape[-1] == 9
    summary = json.loads((out / "fit.json").read_text())
    assert "relight" not in summary["rti"]
    out = tmp_path / "o3"
    r = runner.invoke(app, ["fit", str(session), "--out", str(out), *lean, "--hsh-order", "3"])
    assert r.exit_code == 0, r.output
    assert read_rti_as_rtiviewer(out / "fit.rti").shape[-1] == 16
    said = " ".join(r.output.split())
    assert "fit.rti: hsh3" in said and "--hsh-order 2" in said.split("fit.rti: hsh3", 1)[1]
    assert "relight" in json.loads((out / "fit.json").read_text())["rti"]
    # webGLRtiMaker (jcupitt/webRTIViewer webGLRTIMaker-src/rti.h: 9-entry scale, bias and
    # plane arrays) and JedMills' RTIViewer (src/ptmCreation/RTIParser.java: terms 0-8) read
    # 9 terms at most either: a 16-term file for the web viewer had been sent without a word
    rti = json.loads((out / "fit.json").read_text())["rti"]
    assert "webGLRtiMaker" in rti and "JedMills" in rti, rti
