"""A replay (`rti-rig run ACQ/dirs.lp --out S`) of files that say another colour space records
them in it: the session's images of an Adobe RGB acquisition are not declared sRGB.

Why: a replay's images were all declared sRGB, whatever their files said (the manifest's
"linear sRGB", a linear-sRGB ICC profile in every linear TIFF). Files built in
:mod:`colour_files` (sources cited there).
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import tifffile
from colour_files import icc_profile, jpeg
from typer.testing import CliRunner

from rti_rig.cli import app


def test_a_replay_of_adobe_rgb_jpegs_is_said_adobe_rgb(tmp_path: Path) -> None:
    acq = tmp_path / "acq"
    acq.mkdir()
    lines = []
    profile = icc_profile("Adobe RGB (1998)")
    for k in range(8):  # eight lights on a ring at 45 degrees' elevation
        name = f"image{k + 1:02d}.jpg"
        (acq / name).write_bytes(jpeg(60 + 10 * k, icc=profile))
        a = 2 * math.pi * k / 8
        r = math.sqrt(0.5)
        lines.append(f"{name} {r * math.cos(a):.6f} {r * math.sin(a):.6f} {r:.6f}")
    (acq / "dirs.lp").write_text(f"{len(lines)}\n" + "\n".join(lines) + "\n")
    out = tmp_path / "s"
    r = CliRunner().invoke(
        app, ["run", str(acq / "dirs.lp"), "--out", str(out), "--no-verdict"], terminal_width=400
    )
    said = " ".join(r.output.split())
    assert r.exit_code == 0 and "Traceback" not in said, said
    manifest = json.loads((out / "manifest.json").read_text())
    colour = manifest["image_colour"]
    assert colour["linear"].startswith("Adobe RGB (1998) primaries, NOT sRGB"), colour
    assert colour["jpeg"].startswith("Adobe RGB (1998) primaries through the sRGB curve"), colour
    with tifffile.TiffFile(out / manifest["steps"][0]["linear_image"]) as tif:
        assert tif.pages[0].tags.get(34675) is None  # no sRGB profile on Adobe RGB pixels
        assert "its ICC profile 'Adobe RGB (1998)'" in tif.pages[0].description
    assert "the replayed files are Adobe RGB (1998)" in said, said
