"""A recorded acquisition of PNGs with an alpha channel (a grey camera's grey + alpha, PNG
colour type 4; or RGBA, type 6), through `rti-rig check`, `run` and `fit` of its `.lp`.

OpenCV reads grey + alpha as four samples, the grey copied to three colours: the replay rig
recorded a grey acquisition as colour (its check had said, from the header, "of one kind"
grey) and the fit fitted it as colour; any PNG's alpha was dropped unsaid. The folder watch
reads such PNGs as grey and says the alpha once: so do these, from the same header reading.
A plain 16-bit grey PNG is read as it is, with nothing said."""

from __future__ import annotations

import math
import struct
import subprocess
import sys
import zlib
from pathlib import Path

import numpy as np
import pytest
import tifffile

RTI_RIG = [sys.executable, "-c", "from rti_rig.cli import main; main()"]
KINDS = {"grey+alpha-16": (4, 16), "grey+alpha-8": (4, 8), "rgba-16": (6, 16), "grey-16": (0, 16)}


def _png(pixels: np.ndarray, colour_type: int, depth: int, trns: bytes | None = None) -> bytes:
    """A PNG of ``pixels`` (H, W, samples), written to the PNG spec by hand: OpenCV writes no
    grey + alpha PNG; ``trns`` is a transparency key chunk's data."""
    h, w = pixels.shape[:2]
    rows = b"".join(
        b"\x00" + pixels[y].astype(">u2" if depth == 16 else "u1").tobytes() for y in range(h)
    )

    def chunk(kind: bytes, data: bytes) -> bytes:
        return (
            struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))
        )

    head = struct.pack(">IIBBBBB", w, h, depth, colour_type, 0, 0, 0)
    return (
        b"\x89PNG\r\n\x1a\n"
        + chunk(b"IHDR", head)
        + (b"" if trns is None else chunk(b"tRNS", trns))
        + chunk(b"IDAT", zlib.compress(rows))
        + chunk(b"IEND", b"")
    )


def _acquisition(
    folder: Path, colour_type: int, depth: int, trns: bool = False
) -> tuple[Path, list[np.ndarray]]:
    """12 PNGs lit from a ring at 40°: the .lp and each image's pixels (alpha included);
    ``trns``: each with a transparency key (a grey or RGB value)."""
    samples = {0: 1, 2: 3, 4: 2, 6: 4}[colour_type]
    top = 65535 if depth == 16 else 255
    rng = np.random.default_rng(5)
    lines, shots = ["12"], []
    for i in range(12):
        az, el = 2 * math.pi * i / 12, math.radians(40)
        x, y, z = math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el)
        pixels = rng.integers(top // 10, top // 2, (24, 32, samples)).astype(np.uint32)
        if samples in (2, 4):
            pixels[..., -1] = rng.integers(0, top, (24, 32))  # an alpha that varies
        key = struct.pack(">" + "H" * samples, *([7] * samples)) if trns else None
        (folder / f"im{i:02d}.png").write_bytes(_png(pixels, colour_type, depth, key))
        lines.append(f"im{i:02d}.png {x:.6f} {y:.6f} {z:.6f}")
        shots.append(pixels)
    (folder / "dirs.lp").write_text("\n".join(lines) + "\n")
    return folder / "dirs.lp", shots


def _cli(*args: str) -> tuple[int, str]:
    r = subprocess.run([*RTI_RIG, *args], capture_output=True, text=True, timeout=600)
    return r.returncode, r.stdout + r.stderr


@pytest.mark.parametrize("kind", list(KINDS))
def test_a_replayed_png_acquisition_keeps_its_grey_or_colour_and_says_the_alpha_once(
    tmp_path: Path, kind: str
) -> None:
    colour_type, depth = KINDS[kind]
    acq = tmp_path / "acq"
    acq.mkdir()
    lp, shots = _acquisition(acq, colour_type, depth)
    alpha = colour_type in (4, 6)
    note = "12 of 12 image(s) are PNGs with an alpha channel (im00.png, im01.png, im02.png ...)"

    code, said = _cli("check", str(lp))
    assert code == 0 and "RESULT: PASS" in said, said
    assert said.count("alpha channel") == (1 if alpha else 0), said
    assert (note in " ".join(said.split())) == alpha, said

    out = tmp_path / "s"
    code, said = _cli("run", str(lp), "--out", str(out), "--lights", "12", "--no-verdict")
    assert code == 0 and "Traceback" not in said, said
    assert said.count("alpha channel") == (1 if alpha else 0), said  # once, not per image
    for n, shot in enumerate(shots, 1):
        image = tifffile.imread(out / "linear" / f"image_{n:03d}.tif")
        expected = shot[..., :3] if colour_type == 6 else shot[..., 0]
        assert image.shape == expected.shape, (kind, image.shape)  # grey + alpha is grey
        if depth == 16:  # the recorded pixels themselves, the alpha left out
            assert np.array_equal(image, expected)

    code, said = _cli("fit", str(lp), "--out", str(tmp_path / "f"))
    assert code == 0 and "Traceback" not in said, said
    assert said.count("alpha channel") == (1 if alpha else 0), said
    albedo = np.load(tmp_path / "f" / "albedo.npy")
    assert albedo.shape == ((24, 32, 3) if colour_type == 6 else (24, 32)), albedo.shape


@pytest.mark.parametrize(
    ("colour_type", "trns", "said"),
    [
        (4, False, "12 of 12 image(s) are PNGs with an alpha channel (im00.png, im01.png"),
        (0, True, "12 of 12 image(s) are PNGs with a transparency key (tRNS: im00.png, im01"),
        (2, True, "12 of 12 image(s) are PNGs with a transparency key (tRNS: im00.png, im01"),
    ],
)
def test_bench_tradeoff_from_says_an_alpha_or_a_transparency_key_as_run_and_fit_do(
    tmp_path: Path, colour_type: int, trns: bool, said: str
) -> None:
    """`bench tradeoff --from` had said nothing of the alpha run and fit say; a PNG's
    transparency key (tRNS) was dropped unsaid by all three (OpenCV drops it from a grey PNG,
    and makes it an alpha sample of an RGB one that the readers drop). One note, alike."""
    acq = tmp_path / "acq"
    acq.mkdir()
    lp, _ = _acquisition(acq, colour_type, 16, trns=trns)
    kinds = ("alpha channel", "transparency key")
    for args in (
        ("run", str(lp), "--out", str(tmp_path / "s"), "--lights", "12", "--no-verdict"),
        ("fit", str(lp), "--out", str(tmp_path / "f"), "--no-qa"),
        ("bench", "tradeoff", "--from", str(lp)),
    ):
        code, text = _cli(*args)
        assert code == 0 and "Traceback" not in text, (args[0], text)
        assert sum(text.count(k) for k in kinds) == 1, (args[0], text)
        assert said in " ".join(text.split()), (args[0], text)


def test_a_grey_alpha_png_preview_is_planned_from_as_grey_its_alpha_said(tmp_path: Path) -> None:
    """`plan --preview` read a grey + alpha PNG as colour (OpenCV's B = G = R = grey), its
    alpha dropped unsaid; it is read as the replay rig and the fit read it, and said once."""
    from conftest import CONFIGS

    from rti_rig.app.compose import read_preview_image

    acq = tmp_path / "acq"
    acq.mkdir()
    _, shots = _acquisition(acq, 4, 16)
    preview = acq / "im00.png"
    assert np.array_equal(read_preview_image(preview), shots[0][..., 0])  # grey, as stored
    code, text = _cli(
        "plan",
        str(preview),
        "--rig",
        str(CONFIGS / "simulated_dome.toml"),
        "--preview-light",
        "30,45",
        "--out",
        str(tmp_path / "plan.lp"),
    )
    assert code == 0 and "Traceback" not in text, text
    assert text.count("alpha channel") == 1, text
    assert "1 of 1 image(s) are PNGs with an alpha channel (im00.png)" in " ".join(text.split())


@pytest.mark.parametrize(("colour_type", "trns"), [(0, True), (2, False), (6, False)])
def test_fit_reads_each_png_once_to_learn_its_transparency(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, colour_type: int, trns: bool
) -> None:
    """`rti-rig fit` of a PNG acquisition learns each image's transparency (its colour type,
    then its chunks up to the pixels) from one opening of the file: it had opened every PNG
    once for the colour type and again for the chunks. The note is said as before."""
    import inspect

    from typer.testing import CliRunner

    from rti_rig.cli import app

    acq = tmp_path / "acq"
    acq.mkdir()
    lp, _ = _acquisition(acq, colour_type, 16, trns=trns)
    opened: dict[str, int] = {}
    real_open = Path.open

    def counting_open(self: Path, *args, **kwargs):  # type: ignore[no-untyped-def]
        if self.suffix == ".png" and any(
            f.function == "png_transparency" for f in inspect.stack(context=0)[1:4]
        ):
            opened[self.name] = opened.get(self.name, 0) + 1
        return real_open(self, *args, **kwargs)

    monkeypatch.setattr(Path, "open", counting_open)
    r = CliRunner().invoke(app, ["fit", str(lp), "--out", str(tmp_path / "f"), "--no-qa"])
    assert r.exit_code == 0, r.output
    assert opened == {f"im{i:02d}.png": 1 for i in range(12)}, opened
    kind = {0: "transparency key", 2: None, 6: "alpha channel"}[colour_type]
    assert (kind is None) == ("12 of 12 image(s) are PNGs with" not in r.output), r.output
    if kind is not None:
        assert r.output.count(kind) == 1, r.output
