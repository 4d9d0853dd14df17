"""A library's log records do not reach the user's terminal raw.

The command line configures no logging, so tifffile's warnings about a TIFF with damaged tags
went to Python's last-resort handler: ``rti-rig fit`` printed dozens of
``<TiffTag.fromfile> raised TiffFileError(...)`` lines around its own sentences, for a file
whose pixels decoded whole."""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import tifffile

RTI_RIG = [sys.executable, "-c", "from rti_rig.cli import main; main()"]


def _acquisition(folder: Path) -> Path:
    """12 TIFFs lit from a ring at 40°, one with garbage over tags its pixels do not need."""
    lines = ["12"]
    for i in range(12):
        tifffile.imwrite(
            folder / f"im{i}.tif",
            np.full((32, 32), 3000 * (i + 1), dtype=np.uint16),
            compression="zlib",
        )
        az, el = 2 * math.pi * i / 12, math.radians(40)
        x, y, z = math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el)
        lines.append(f"im{i}.tif {x:.6f} {y:.6f} {z:.6f}")
    (folder / "dirs.lp").write_text("\n".join(lines) + "\n")
    damaged = folder / "im3.tif"
    data = damaged.read_bytes()
    damaged.write_bytes(data[:100] + b"\xff" * 100 + data[200:])
    return folder / "dirs.lp"


def test_tifffile_warnings_are_not_printed_raw(tmp_path: Path) -> None:
    lp = _acquisition(tmp_path)
    with tifffile.TiffFile(tmp_path / "im3.tif") as tif:  # the damage is of the kind meant
        assert np.all(tif.pages[0].asarray() == 12000)
    r = subprocess.run(
        [*RTI_RIG, "fit", str(lp), "--out", str(tmp_path / "o")],
        capture_output=True,
        text=True,
        timeout=600,
    )
    said = r.stdout + r.stderr
    assert "Wrote" in said, said  # the fit ran: the files were read
    assert "TiffFileError" not in said and "<TiffTag" not in said and "<tifffile" not in said, said
