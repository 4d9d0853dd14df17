"""Run a dry-run session in a child process and make it die at a chosen moment.

Used by the resume tests: ``python tests/session_child.py STAGE K CONFIG OUT LIGHTS`` runs
``rti-rig run CONFIG --out OUT --lights LIGHTS`` and SIGKILLs itself at STAGE of step K (0-based),
or, with STAGE ``slow``, runs each capture slowly so that the parent can send it a signal.
"""

from __future__ import annotations

import os
import signal
import sys
import time

STAGE, K = sys.argv[1], int(sys.argv[2])
CONFIG, OUT, LIGHTS = sys.argv[3], sys.argv[4], sys.argv[5]

import rti_rig.image_files as image_files  # noqa: E402
import rti_rig.session as session  # noqa: E402
import simulator.sim_camera as sim_camera  # noqa: E402
import simulator.sim_lights as sim_lights  # noqa: E402
from rti_rig.cli import app  # noqa: E402

counts = {"light": 0, "capture": 0, "write": 0, "journal": 0}


def die() -> None:
    os.kill(os.getpid(), signal.SIGKILL)


real_light = sim_lights.SimulatedDome.light


def light(self, index, intensity=1.0):  # type: ignore[no-untyped-def]
    if STAGE == "before_light" and counts["light"] == K:
        die()
    real_light(self, index, intensity)
    if STAGE == "after_light" and counts["light"] == K:
        die()
    counts["light"] += 1


real_capture = sim_camera.SimulatedCamera.capture


def capture(self, exposure_s):  # type: ignore[no-untyped-def]
    if STAGE == "slow":
        time.sleep(0.05)
    frame = real_capture(self, exposure_s)
    if STAGE == "during_capture" and counts["capture"] == K:
        die()
    counts["capture"] += 1
    return frame


real_write = image_files._atomic_write


def atomic_write(path, data):  # type: ignore[no-untyped-def]
    n = counts["write"]
    counts["write"] += 1
    if STAGE == "during_write" and n == 2 * K:  # half of the TIFF is on disk
        with open(path.with_name(f".{path.name}.partial"), "wb") as fh:
            fh.write(data[: len(data) // 2])
        die()
    if STAGE == "between_files" and n == 2 * K + 1:  # TIFF renamed, JPEG not yet written
        die()
    return real_write(path, data)


real_asdict = session.asdict


def asdict(obj):  # type: ignore[no-untyped-def]
    if STAGE == "before_journal" and isinstance(obj, session.StepRecord):
        if counts["journal"] == K:
            die()
        counts["journal"] += 1
    return real_asdict(obj)


sim_lights.SimulatedDome.light = light
sim_camera.SimulatedCamera.capture = capture
image_files._atomic_write = atomic_write
session.asdict = asdict
app(["run", CONFIG, "--out", OUT, "--lights", LIGHTS], standalone_mode=True)
