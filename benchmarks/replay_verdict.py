"""The acquisition check of a replayed session's verdict, with and without the stamps recorded
at capture: `rti-rig fit S` of a session replaying 72 16-bit TIFFs.

The verdict checks that the replayed acquisition is the one the session began with before it
names the recorded file a clipped image replays. It had hashed every image each time; now a
file whose size, mtime and ctime are the ones recorded is not read
(:func:`rti_rig.app.rig_identity.recorded_images_stamped`). "before" is the same session with
its ``recorded_files`` taken out of the manifest, as a session begun before them is checked.
The files are in the page cache (read just before): a cold disk makes "before" slower still.
The whole ``fit`` is timed too, for scale: its own work on the 12 session images dominates it,
and on a shared machine its spread is larger than the check's saving.

Run: ``python -m benchmarks.replay_verdict [--side 1024] [--images 72]`` (prints figures;
writes its acquisition and session in a temporary folder, removed after).
"""

from __future__ import annotations

import argparse
import json
import math
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np
import tifffile


def acquisition(folder: Path, images: int, side: int) -> Path:
    """``images`` 16-bit RGB TIFFs of ``side``² lit from rings, each with a clipped spot."""
    rng = np.random.default_rng(1)
    lines = [str(images)]
    for i in range(images):
        az, el = 2 * math.pi * i / images, math.radians(20 + 25 * (i % 3))
        x, y, z = math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el)
        img = rng.integers(3000, 30000, (side, side, 3), dtype=np.uint16)
        img[: side // 4, : side // 4] = 65535  # clipped: the verdict names the recorded file
        tifffile.imwrite(folder / f"image{i:02d}.tif", img, photometric="rgb")
        lines.append(f"image{i:02d}.tif {x:.6f} {y:.6f} {z:.6f}")
    (folder / "dirs.lp").write_text("\n".join(lines) + "\n")
    return folder / "dirs.lp"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--images", type=int, default=72)
    ap.add_argument("--side", type=int, default=1024)
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args()
    from typer.testing import CliRunner

    from rti_rig.app.usecases.session_integrity import _replayed_names
    from rti_rig.cli import app

    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp)
        (root / "acq").mkdir()
        lp = acquisition(root / "acq", args.images, args.side)
        size = sum(p.stat().st_size for p in (root / "acq").glob("*.tif"))
        session = root / "s"
        r = CliRunner().invoke(
            app, ["run", str(lp), "--out", str(session), "--lights", "12", "--no-verdict"]
        )
        assert r.exit_code == 0, r.output
        manifest = json.loads((session / "manifest.json").read_text())
        old = json.loads(json.dumps(manifest))
        del old["rig"]["identity"]["recorded_files"]
        print(
            f"{args.images} images of {args.side}x{args.side} 16-bit RGB, {size / 1e6:.0f} MB; "
            f"median of {args.repeats}"
        )
        for label, m in (("before (every image hashed)", old), ("now (stamps recorded)", manifest)):
            times = []
            for _ in range(args.repeats):
                t0 = time.perf_counter()
                named = _replayed_names(m)
                times.append(time.perf_counter() - t0)
            assert named, "the acquisition was not recognised"
            print(f"  acquisition check, {label}: {statistics.median(times) * 1e3:.1f} ms")
        # one fit untimed first: the first in a process pays for imports and compiling
        r = CliRunner().invoke(app, ["fit", str(session), "--out", str(root / "fit-warm-up")])
        assert r.exit_code == 0, r.output
        for label, m in (("before", old), ("now", manifest)):
            (session / "manifest.json").write_text(json.dumps(m, indent=2))
            times = []
            for i in range(args.repeats):
                t0 = time.perf_counter()
                r = CliRunner().invoke(
                    app, ["fit", str(session), "--out", str(root / f"fit-{label}-{i}")]
                )
                times.append(time.perf_counter() - t0)
                assert r.exit_code == 0, r.output
                assert "clipped in the recording, image" in " ".join(r.output.split())
            print(f"  rti-rig fit S (fit and verdict), {label}: {statistics.median(times):.2f} s")


if __name__ == "__main__":
    main()
