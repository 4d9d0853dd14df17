"""The session folder: images, the `.lp` from what actually ran, a journal and a manifest.

Layout (opens directly in relight-cli's folder mode, which takes the first ``*.lp`` and the
``*.jpg`` files in name order)::

    SESSION/
      image_001.jpg ...      8-bit sRGB, one per step, named in execution order
      linear/image_001.tif   16-bit linear data for fitting (same numbering)
      lights.lp              one line per image, from the light that actually fired
      journal.jsonl          one line per completed step, flushed to disk as it happens
      manifest.json          rig config, schedule, per-step timings, versions, finish reason

Nothing already captured is ever overwritten: a folder that is not empty is refused, and image
writes refuse existing files.
"""

from __future__ import annotations

import json
import os
import platform
import sys
from dataclasses import asdict, dataclass, field
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from rti_rig.errors import SessionError
from rti_rig.image_files import linear_to_srgb8, write_linear_tiff, write_srgb_jpeg
from rti_rig.lp_format import LpEntry, write_lp
from rti_rig.rig import Frame

MANIFEST = "manifest.json"
JOURNAL = "journal.jsonl"
LP_NAME = "lights.lp"
LINEAR_DIR = "linear"
FORMAT = "rti-rig-session/1"


@dataclass(frozen=True)
class StepRecord:
    """What one step actually did, with its timings on the rig clock."""

    index: int
    image: str
    linear_image: str
    planned_direction: tuple[float, float, float]
    actual_direction: tuple[float, float, float]
    led: int | None
    exposure_s: float
    rig_start_s: float
    light_s: float
    settle_s: float
    capture_s: float
    write_wall_s: float
    saturated_fraction: float
    black_fraction: float
    sha256: dict[str, str] = field(default_factory=dict)


def image_names(total: int) -> list[str]:
    """``image_001`` ... zero-padded so that name order equals execution order."""
    width = max(3, len(str(total)))
    return [f"image_{i + 1:0{width}d}" for i in range(total)]


def software_versions() -> dict[str, str]:
    import cv2
    import numpy

    from rti_rig import __version__

    return {
        "rti_rig": __version__,
        "python": sys.version.split()[0],
        "numpy": numpy.__version__,
        "opencv": cv2.__version__,
        "platform": platform.platform(),
    }


def _now_iso() -> str:
    return datetime.now(UTC).isoformat(timespec="seconds")


def _write_json_atomic(path: Path, data: dict[str, Any]) -> None:
    tmp = path.with_name(f".{path.name}.tmp")
    with open(tmp, "w", encoding="utf-8") as fh:
        json.dump(data, fh, indent=2, default=str)
        fh.write("\n")
        fh.flush()
        os.fsync(fh.fileno())
    os.replace(tmp, path)


class SessionFolder:
    """Writes one session; created empty, filled step by step, finished once."""

    def __init__(self, root: Path, total_steps: int) -> None:
        self.root = Path(root)
        self.total_steps = total_steps
        self.names = image_names(total_steps)
        self.manifest: dict[str, Any] = {}

    @classmethod
    def create(cls, root: Path, total_steps: int) -> SessionFolder:
        root = Path(root)
        if root.exists() and not root.is_dir():
            raise SessionError(f"{root} exists and is not a folder: choose another --out")
        if root.exists() and any(root.iterdir()):
            raise SessionError(
                f"{root} is not empty: refusing to write a session over existing files; "
                "choose a new --out folder"
            )
        try:
            (root / LINEAR_DIR).mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise SessionError(f"cannot create {root}: {exc.strerror or exc}") from None
        return cls(root, total_steps)

    def begin(self, header: dict[str, Any]) -> None:
        """Record what is about to run, before anything moves."""
        self.manifest = {
            "format": FORMAT,
            "software": software_versions(),
            "started_at": _now_iso(),
            **header,
            "runner": {"state": "running", "finish_reason": None},
            "steps": [],
        }
        _write_json_atomic(self.root / MANIFEST, self.manifest)

    def write_step(self, index: int, frame: Frame, record_fields: dict[str, Any]) -> StepRecord:
        """Write one captured frame (linear TIFF + sRGB JPEG) and journal it."""
        import time

        t0 = time.perf_counter()
        base = self.names[index]
        jpg, tif = f"{base}.jpg", f"{LINEAR_DIR}/{base}.tif"
        sha_tif = write_linear_tiff(self.root / tif, frame.pixels)
        sha_jpg = write_srgb_jpeg(self.root / jpg, linear_to_srgb8(frame.pixels, frame.white_level))
        record = StepRecord(
            index=index,
            image=jpg,
            linear_image=tif,
            exposure_s=frame.exposure_s,
            saturated_fraction=frame.saturated_fraction,
            black_fraction=frame.black_fraction,
            write_wall_s=time.perf_counter() - t0,
            sha256={jpg: sha_jpg, tif: sha_tif},
            **record_fields,
        )
        with open(self.root / JOURNAL, "a", encoding="utf-8") as fh:
            fh.write(json.dumps(asdict(record)) + "\n")
            fh.flush()
            os.fsync(fh.fileno())
        return record

    def finish(
        self, records: list[StepRecord], runner: dict[str, Any], timing: dict[str, Any]
    ) -> None:
        """Write the `.lp` from what actually ran, then the final manifest."""
        if records:
            write_lp(
                self.root / LP_NAME,
                [LpEntry(r.image, r.actual_direction) for r in records],
            )
        self.manifest.update(
            {
                "finished_at": _now_iso(),
                "runner": runner,
                "timing": timing,
                "lp_file": LP_NAME if records else None,
                "steps": [asdict(r) for r in records],
            }
        )
        _write_json_atomic(self.root / MANIFEST, self.manifest)


def read_manifest(root: Path) -> dict[str, Any]:
    """The manifest of a session folder, with a clear error if it is not one."""
    path = Path(root) / MANIFEST
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise SessionError(
            f"{root} has no {MANIFEST}: it is not an rti-rig session folder"
        ) from None
    except json.JSONDecodeError as exc:
        raise SessionError(f"{path} is not valid JSON ({exc}); the journal may help") from None
    if data.get("format") != FORMAT:
        raise SessionError(f"{path}: unknown session format {data.get('format')!r}")
    return data


def session_lp_entries(root: Path, linear: bool = False) -> list[LpEntry]:
    """`.lp` entries of a finished session, from the directions that actually ran."""
    manifest = read_manifest(root)
    steps = manifest.get("steps") or []
    if not steps:
        raise SessionError(f"{root}: the session recorded no images, so there is no .lp to export")
    key = "linear_image" if linear else "image"
    return [LpEntry(s[key], tuple(s["actual_direction"])) for s in steps]
