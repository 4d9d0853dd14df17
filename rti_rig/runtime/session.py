"""The session folder: images, the `.lp` from what actually ran, a journal and a manifest.

Layout (opens directly in relight-cli's folder mode, which takes the first ``*.lp`` and the
``*.jpg`` files in name order)::

    SESSION/
      image_001.jpg ...      8-bit sRGB, one per step, named in execution order
      linear/image_001.tif   16-bit linear data for fitting (same numbering)
      raw/image_001.nef      the camera's original file(s) for the step, named by the session
                             (the camera's own name is kept in the journal); RAW+JPEG pairs
                             keep both files
      lights.lp              one line per image, from the light that actually fired
      journal.jsonl          one line per completed step, flushed to disk as it happens
      manifest.json          rig config, schedule, per-step timings, versions, finish reason

Nothing already captured is ever overwritten: a folder that is not empty is refused, and image
writes refuse existing files.
"""

from __future__ import annotations

import hashlib
import json
import os
import platform
import shutil
import sys
import time
from dataclasses import asdict, dataclass, field
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from rti_rig.core.devices import Frame
from rti_rig.core.errors import SessionError
from rti_rig.core.image_files import linear_to_srgb8, write_linear_tiff, write_srgb_jpeg
from rti_rig.core.lp_format import LpEntry, write_lp

MANIFEST = "manifest.json"
JOURNAL = "journal.jsonl"
LP_NAME = "lights.lp"
LINEAR_DIR = "linear"
RAW_DIR = "raw"
#: Where a DSLR downloads before the step is committed (files left here by a crash are moved to
#: recovered/ on resume, never used as a step's image and never deleted).
RAW_INCOMING = f"{RAW_DIR}/.incoming"
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
    #: session file → the camera's (or watched folder's) own name for it
    originals: dict[str, str] = field(default_factory=dict)
    #: how the linear image was made from the RAW file (mode, CFA pattern, black/white levels
    #: per channel, white balance, colour, orientation, source file); empty for non-RAW cameras
    decode: dict[str, Any] = field(default_factory=dict)
    notices: list[str] = field(default_factory=list)
    #: an adaptive session's decision for this step and its evidence (None: a fixed schedule)
    decision: dict[str, Any] | None = None


def planned_steps(manifest: dict[str, Any]) -> int:
    """How many steps a session may take: its schedule's, or an adaptive session's maximum."""
    adaptive = manifest.get("adaptive") or {}
    return int(adaptive.get("max_lights") or len(manifest.get("schedule", {}).get("steps", [])))


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


def estimated_bytes_per_image(width: int, height: int, channels: int = 3) -> int:
    """A generous upper bound for one step's files: uncompressed 16-bit TIFF plus a JPEG."""
    pixels = width * height * channels
    return 2 * pixels + pixels // 2 + 16_384


def check_free_space(root: Path, steps: int, bytes_per_image: int) -> None:
    """Refuse to start when the disk cannot hold the images still to be captured."""
    probe = Path(root)
    while not probe.exists():
        probe = probe.parent
    free = shutil.disk_usage(probe).free
    need = steps * bytes_per_image + 8 * 1024 * 1024
    if free < need:
        raise SessionError(
            f"not enough free disk space for {steps} image(s) under {probe}: need about "
            f"{need / 1e6:.0f} MB, {free / 1e6:.0f} MB free; free space or choose another --out"
        )


class SessionFolder:
    """Writes one session: created empty (or reopened to resume), filled step by step."""

    def __init__(self, root: Path, total_steps: int) -> None:
        self.root = Path(root)
        self.total_steps = total_steps
        self.names = image_names(total_steps)
        self.manifest: dict[str, Any] = {}
        self.resume: ResumeState | None = None

    @staticmethod
    def check_new(root: Path) -> None:
        """Refuse a folder a new session may not be written into (checked before the rig is
        even opened, so nothing moves or lights for a session that cannot be kept)."""
        root = Path(root)
        if root.exists() and not root.is_dir():
            raise SessionError(f"{root} exists and is not a folder: choose another --out")
        if root.exists() and any(root.iterdir()):
            raise SessionError(
                f"{root} is not empty: refusing to write a session over existing files; "
                "choose a new --out folder, or continue an interrupted session with "
                f"'rti-rig run --resume {root}'"
            )

    @classmethod
    def create(cls, root: Path, total_steps: int) -> SessionFolder:
        root = Path(root)
        cls.check_new(root)
        try:
            (root / LINEAR_DIR).mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise SessionError(f"cannot create {root}: {exc.strerror or exc}") from None
        return cls(root, total_steps)

    @classmethod
    def reopen(cls, root: Path) -> SessionFolder:
        """Open an interrupted session to capture the steps it has not done yet.

        What is on disk is verified against the journal's checksums first; see
        :func:`prepare_resume`.
        """
        state = prepare_resume(Path(root))
        folder = cls(Path(root), planned_steps(state.manifest))
        folder.manifest = state.manifest
        folder.resume = state
        return folder

    @property
    def done(self) -> dict[int, StepRecord]:
        return dict(self.resume.done) if self.resume else {}

    def begin(self, header: dict[str, Any]) -> None:
        """Record what is about to run, before anything moves."""
        run = {
            "started_at": _now_iso(),
            "software": software_versions(),
            # which config (and light calibration) this run's images were shot with
            "config_sha256": (header.get("rig") or {}).get("config_sha256"),
        }
        if self.resume is not None:
            if header["schedule"] != self.manifest["schedule"]:
                raise SessionError(
                    f"{self.root}: the schedule to resume differs from the one the session began "
                    "with; a resumed session must run the same steps"
                )
            runs = self.manifest.setdefault("runs", [])
            for old in runs:
                old.setdefault("finish_reason", "crashed")
            run["resumed_with_steps_done"] = len(self.resume.done)
            run["recovered_files"] = self.resume.recovered
            runs.append(run)
            self.manifest["runner"] = {"state": "running", "finish_reason": None}
        else:
            self.manifest = {
                "format": FORMAT,
                "software": run["software"],
                "started_at": run["started_at"],
                **header,
                "runner": {"state": "running", "finish_reason": None},
                "runs": [run],
                "steps": [],
            }
        _write_json_atomic(self.root / MANIFEST, self.manifest)

    def write_step(self, index: int, frame: Frame, record_fields: dict[str, Any]) -> StepRecord:
        """Write one captured frame (linear TIFF, then sRGB JPEG), then journal it.

        The journal line is the commit point: a step is done only once its line is on disk, and
        its checksums prove the files are the ones written.
        """
        t0 = time.perf_counter()
        base = self.names[index]
        jpg, tif = f"{base}.jpg", f"{LINEAR_DIR}/{base}.tif"
        decode = dict(frame.metadata.get("decode") or {})
        listed = frame.metadata.get("originals") or []
        originals = self._keep_originals(base, listed)
        for item, rel in zip(listed, originals, strict=True):
            if decode.get("source_file") == str(item["path"]):
                # where the decoded RAW is kept now, and the camera's own name for it
                decode["raw_file"] = rel
                decode["camera_file"] = originals[rel][1]
        sha = {name: digest for name, (digest, _) in originals.items()}
        sha[tif] = write_linear_tiff(
            self.root / tif, frame.pixels, description=_tiff_description(decode)
        )
        sha[jpg] = write_srgb_jpeg(
            self.root / jpg, linear_to_srgb8(frame.pixels, frame.white_level)
        )
        record = StepRecord(
            index=index,
            image=jpg,
            linear_image=tif,
            exposure_s=frame.exposure_s,
            saturated_fraction=frame.saturated_fraction,
            black_fraction=frame.black_fraction,
            write_wall_s=time.perf_counter() - t0,
            sha256=sha,
            originals={name: source for name, (_, source) in originals.items()},
            decode=decode,
            notices=[str(n) for n in frame.metadata.get("notices") or []],
            **record_fields,
        )
        with open(self.root / JOURNAL, "a", encoding="utf-8") as fh:
            fh.write(json.dumps(asdict(record)) + "\n")
            fh.flush()
            os.fsync(fh.fileno())
        return record

    def _keep_originals(
        self, base: str, originals: list[dict[str, Any]]
    ) -> dict[str, tuple[str, str]]:
        """Put the camera's own files under ``raw/`` with the session's name for the step.

        A file already inside the session (a DSLR download staged in ``raw/.incoming``) is
        moved; a file elsewhere (a watched folder another program owns) is copied. The session
        names the files itself, so a camera whose counter wraps or repeats names can never make
        one step's original overwrite another's. Returns {session name: (sha256, camera name)}.
        """
        kept: dict[str, tuple[str, str]] = {}
        root = self.root.resolve()
        for item in originals:
            src = Path(item["path"])
            suffix = src.suffix.lower()
            rel = f"{RAW_DIR}/{base}{suffix}"
            n = 2
            while rel in kept:  # two files of one step with one suffix
                rel = f"{RAW_DIR}/{base}_{n}{suffix}"
                n += 1
            dest = self.root / rel
            if dest.exists():
                raise SessionError(f"{dest} already exists: refusing to overwrite a captured file")
            dest.parent.mkdir(parents=True, exist_ok=True)
            inside = src.resolve().is_relative_to(root)
            tmp = dest.with_name(f".{dest.name}.partial")
            if inside:
                os.replace(src, tmp)
            else:
                shutil.copyfile(src, tmp)
            digest = _fsync_sha256(tmp)
            os.replace(tmp, dest)
            kept[rel] = (digest, str(item.get("name") or src.name))
        return kept

    def finish(
        self, records: list[StepRecord], runner: dict[str, Any], timing: dict[str, Any]
    ) -> None:
        """Write the `.lp` from what actually ran (all runs, in step order), then the manifest."""
        every = {r.index: r for r in self.done.values()}
        every.update({r.index: r for r in records})
        ordered = [every[i] for i in sorted(every)]
        if ordered:
            write_lp(
                self.root / LP_NAME,
                [LpEntry(r.image, r.actual_direction) for r in ordered],
            )
        run = self.manifest["runs"][-1]
        run.update({"finished_at": _now_iso(), "finish_reason": runner["finish_reason"], **timing})
        runs = self.manifest["runs"]
        self.manifest.update(
            {
                "finished_at": run["finished_at"],
                "runner": {**runner, "steps_done": len(ordered)},
                "timing": {
                    "rig_time_s": sum(r.get("rig_time_s", 0.0) for r in runs),
                    "wall_time_s": sum(r.get("wall_time_s", 0.0) for r in runs),
                    "runs": len(runs),
                },
                "lp_file": LP_NAME if ordered else None,
                "steps": [asdict(r) for r in ordered],
                "notices": session_notices(ordered),
            }
        )
        _write_json_atomic(self.root / MANIFEST, self.manifest)


def session_notices(records: list[StepRecord]) -> list[str]:
    """What the user should know about the images as a whole (each distinct notice once, with
    how many images it concerns), e.g. that a rotated camera gave sensor-oriented images, or
    that the images are CFA mosaics rather than pictures."""
    counts: dict[str, int] = {}
    for r in records:
        for n in r.notices:
            counts[n] = counts.get(n, 0) + 1
        if r.decode.get("mode") == "mosaic":
            n = (
                "the images are CFA mosaics (decode.mode = 'mosaic'): one colour per pixel, "
                "not demosaiced; the JPEGs are grey checkerboards, not pictures"
            )
            counts[n] = counts.get(n, 0) + 1
    total = len(records)
    return [f"{n} [{c} of {total} images]" for n, c in counts.items()]


@dataclass
class ResumeState:
    """What an interrupted session folder holds, verified."""

    manifest: dict[str, Any]
    done: dict[int, StepRecord]
    recovered: list[str]


def read_journal(root: Path) -> list[dict[str, Any]]:
    """Journal lines; a torn last line (the process died while appending) is ignored."""
    path = Path(root) / JOURNAL
    if not path.exists():
        return []
    lines = path.read_text(encoding="utf-8").split("\n")
    out = []
    for i, line in enumerate(lines):
        if not line.strip():
            continue
        try:
            out.append(json.loads(line))
        except json.JSONDecodeError:
            if i == len(lines) - 1:  # no newline after it: torn by a crash, never committed
                break
            raise SessionError(
                f"{path}, line {i + 1}: not valid JSON, so it cannot be known which images are "
                "complete; restore the journal from a backup or start a new session (nothing "
                "in this folder has been changed)"
            ) from None
    return out


def _fsync_sha256(path: Path) -> str:
    """SHA-256 of a file just written, after making sure it is on disk."""
    h = hashlib.sha256()
    with open(path, "rb+") as fh:
        for chunk in iter(lambda: fh.read(1 << 20), b""):
            h.update(chunk)
        os.fsync(fh.fileno())
    return h.hexdigest()


def _tiff_description(decode: dict[str, Any]) -> str | None:
    """A label inside the linear TIFF saying what its pixels are, for RAW-derived images."""
    if not decode:
        return None
    if decode.get("mode") == "mosaic":
        return (
            f"rti-rig: CFA mosaic ({decode.get('cfa_pattern')}), black level removed per "
            "photosite, NOT demosaiced, no white balance: one colour per pixel"
        )
    return (
        f"rti-rig: linear {decode.get('color_space')} RGB from RAW ({decode.get('mode')}), "
        f"white balance {decode.get('white_balance')}, sensor orientation"
    )


def _sha256(path: Path) -> str | None:
    try:
        return hashlib.sha256(path.read_bytes()).hexdigest()
    except FileNotFoundError:
        return None


def prepare_resume(root: Path) -> ResumeState:
    """Verify an interrupted session and set aside anything that is not a committed step.

    A step counts as done when its journal line exists and every file it names is on disk with
    the journaled checksum. Image files that no committed step accounts for (a write cut short
    between the TIFF and the JPEG, a checksum mismatch) are *moved* to ``recovered/``, never
    deleted; half-written temporary files are removed (they never were an image).
    """
    manifest = read_manifest(root)
    total = planned_steps(manifest)
    if total == 0:
        raise SessionError(f"{root}: the manifest holds no schedule, so there is nothing to resume")
    runner = manifest.get("runner", {})
    if runner.get("finish_reason") == "completed":
        done = runner.get("steps_done", total)
        if manifest.get("adaptive") and done < total:  # an adaptive session that chose to stop
            stop = (manifest["adaptive"].get("result") or {}).get("stop") or {}
            raise SessionError(
                f"{root}: this adaptive session already completed: it stopped after {done} of "
                f"at most {total} lights ({stop.get('reason', 'its stopping rule')})"
            )
        raise SessionError(f"{root}: this session already completed all {total} steps")
    names = image_names(total)
    fields = set(StepRecord.__dataclass_fields__)
    done: dict[int, StepRecord] = {}
    for entry in read_journal(root):
        idx = entry.get("index")
        if (
            not isinstance(idx, int)
            or not 0 <= idx < total
            or entry.get("image") != f"{names[idx]}.jpg"
        ):
            raise SessionError(
                f"{root}: journal entry {entry.get('image')!r} does not fit the schedule"
            )
        ok = all(_sha256(root / name) == digest for name, digest in entry["sha256"].items())
        if ok:
            rec = {k: v for k, v in entry.items() if k in fields}
            for key in ("planned_direction", "actual_direction"):
                rec[key] = tuple(rec[key])
            done[idx] = StepRecord(**rec)
        else:
            done.pop(idx, None)
    keep = {name for rec in done.values() for name in rec.sha256}
    recovered: list[str] = []
    stamp = datetime.now(UTC).strftime("%Y%m%dT%H%M%S")
    leftovers = [
        *root.glob("image_*"),
        *(root / LINEAR_DIR).glob("image_*"),
        *(root / RAW_DIR).glob("image_*"),
        *(p for p in (root / RAW_INCOMING).glob("*") if p.is_file()),
    ]
    for path in sorted(leftovers):
        rel = path.relative_to(root).as_posix()
        if rel in keep:
            continue
        dest = root / "recovered" / stamp / rel
        dest.parent.mkdir(parents=True, exist_ok=True)
        os.replace(path, dest)
        recovered.append(dest.relative_to(root).as_posix())
    partials = [
        *root.glob(".*.partial"),
        *(root / LINEAR_DIR).glob(".*.partial"),
        *(root / RAW_DIR).glob(".*.partial"),
    ]
    for partial in partials:
        partial.unlink()
    (root / LINEAR_DIR).mkdir(exist_ok=True)
    return ResumeState(manifest=manifest, done=done, recovered=recovered)


def read_manifest(root: Path) -> dict[str, Any]:
    """The manifest of a session folder, with a clear error if it is not one."""
    path = Path(root) / MANIFEST
    if not Path(root).exists():
        raise SessionError(f"{root} does not exist: give a session folder written by 'rti-rig run'")
    if not Path(root).is_dir():
        raise SessionError(
            f"{root} is a file: give the session folder that holds it (the one with {MANIFEST})"
        )
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
