"""The QA judges each image where the object has lit structure, not at the frame's centre.

Found reading rti_rig.reconstruct.qa: the per-image evidence (the fit the light directions and
shifts are judged against) came from a 384 px crop at the frame's centre, 0.6 % of a 24 MP
frame. An object whose centre is flat and featureless (a painting's sky, a tablet's blank
margin) with its relief elsewhere had no light direction judged: two swapped lights were
"good; light directions not checked: the fitted normals spread only 0.0°". The crop is now
chosen on the down-sampled frames where the object is lit and has structure.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.image_files import write_linear_tiff

REPO = Path(__file__).resolve().parents[2]
runner = CliRunner()
SIDE = 1024


def _lights() -> np.ndarray:
    rows = (REPO / "rig_configs" / "example_dome_48.lp").read_text().split("\n")[1:]
    return np.array([[float(v) for v in r.split()[1:4]] for r in rows if r.strip()])


def _object() -> tuple[np.ndarray, np.ndarray]:
    """Normals and albedo of a flat, plain board with a patch of bumps and pigment in its top
    left corner, wholly outside the frame's central 384 px."""
    rng = np.random.default_rng(5)
    yy, xx = np.mgrid[0:SIDE, 0:SIDE].astype(np.float64)
    height = np.zeros((SIDE, SIDE))
    albedo = np.full((SIDE, SIDE), 0.5)
    for _ in range(40):
        cy, cx = rng.uniform(40, 280, 2)
        r = rng.uniform(8, 25)
        height += rng.uniform(4, 12) * np.exp(-((yy - cy) ** 2 + (xx - cx) ** 2) / (2 * r * r))
        albedo += rng.uniform(-0.1, 0.1) * np.exp(-((yy - cy) ** 2 + (xx - cx) ** 2) / (r * r))
    gy, gx = np.gradient(height)
    normals = np.dstack([-gx, gy, np.ones_like(gx)])  # y up, as the .lp's lights
    return normals / np.linalg.norm(normals, axis=2, keepdims=True), np.clip(albedo, 0.2, 0.8)


def _write_session(folder: Path, swap: tuple[int, int]) -> Path:
    """The board under the 48 dome lights as 16-bit linear TIFFs, listed in ``lights.lp``
    with the lights of images ``swap`` (1-based) exchanged: a wrong .lp entry."""
    folder.mkdir()
    lights = _lights()
    normals, albedo = _object()
    rng = np.random.default_rng(6)
    names = []
    for i, light in enumerate(lights):
        img = 0.8 * albedo * np.maximum(normals @ light, 0.0)
        img += rng.normal(0.0, 0.002, img.shape)
        name = f"image_{i + 1:03d}.tif"
        write_linear_tiff(folder / name, np.clip(img * 65535, 0, 65535).astype(np.uint16))
        names.append(name)
    listed = lights.copy()
    a, b = swap[0] - 1, swap[1] - 1
    listed[[a, b]] = listed[[b, a]]
    lines = [str(len(names))] + [
        f"{n} {x:.6f} {y:.6f} {z:.6f}" for n, (x, y, z) in zip(names, listed, strict=True)
    ]
    lp = folder / "lights.lp"
    lp.write_text("\n".join(lines) + "\n")
    return lp


def test_two_swapped_lights_are_found_on_an_object_whose_centre_is_plain(tmp_path: Path) -> None:
    lp = _write_session(tmp_path / "board", swap=(13, 14))
    out = tmp_path / "fit"
    r = runner.invoke(app, ["fit", str(lp), "--out", str(out), "--no-ptm", "--no-hsh"])
    assert r.exit_code == 0, r.output
    qa = json.loads((out / "qa.json").read_text())
    assert set(qa["reshoot"]) == {"image_013", "image_014"}, qa["verdict"]
    assert "wrong light" in qa["verdict"], qa["verdict"]
    top, left, height, width = qa["crop"]
    assert (height, width) == (384, 384)
    assert top + height <= 400 and left + width <= 400, qa["crop"]  # on the patch, not centred
