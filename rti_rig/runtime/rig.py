"""A rig: lighting + camera + clock + timing, assembled from a config by the composition root.

The runtime must not depend on how a rig is configured (TOML, pydantic, drivers' settings), so
what it reads of the loaded config is written here as protocols; the composition root's
``rti_rig.app.config.LoadedRig`` satisfies them.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from contextlib import AbstractContextManager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Protocol, TypeVar

from rti_rig.core.clock import Clock
from rti_rig.core.devices import Camera
from rti_rig.core.rig_geometry import ArmGeometry, DomeGeometry, LampGeometry
from rti_rig.runtime.lighting import Lighting

log = logging.getLogger("rti_rig.rig")

T = TypeVar("T")


class RigResources:
    """What a rig holds open besides its devices (an emulator, its pseudo-terminal), closed
    last opened first, each whatever the others did, every failure kept.

    Why not a ``contextlib.ExitStack``: its close raises the last failure alone (the others
    only chained to it), and raised from a close in a ``finally`` or an ``except`` it replaced
    the error that led there: an emulator that did not close cleanly after a run stopped on a
    servo's overload made the run end on "unexpected OSError", the overload unsaid."""

    def __init__(self) -> None:
        self._open: list[tuple[str, Callable[[], object]]] = []

    def enter_context(self, cm: AbstractContextManager[T], what: str) -> T:
        """Enter ``cm``; its exit is the close of ``what`` (as a failure names it)."""
        value = cm.__enter__()
        self._open.append((what, lambda: cm.__exit__(None, None, None)))
        return value

    def callback(self, close: Callable[[], object], what: str) -> None:
        """Call ``close`` at the close, named ``what`` in its failure."""
        self._open.append((what, close))

    def close(self) -> list[str]:
        """Close everything, last opened first; each failure as ``"<what> close: <error>"``
        (never raised: a close must not hide the error that led to it). Safe twice."""
        failures: list[str] = []
        while self._open:
            what, close = self._open.pop()
            try:
                close()
            except Exception as exc:  # every resource is closed whatever one does
                failures.append(f"{what} close: {exc}")
        return failures

    def close_said(self, owner: str) -> None:
        """:meth:`close`, each failure said as a warning record naming ``owner`` (the command
        line says it as a note): for a close on the way out of an error, whose caller has
        nobody else to hand them to."""
        for failure in self.close():
            log.warning("%s: %s", owner, failure)


class CameraConfig(Protocol):
    """What the runtime reads of a rig's camera settings."""

    width: int
    height: int
    exposure_s: float
    min_exposure_s: float
    max_exposure_s: float


class TimingConfig(Protocol):
    """The rig's timing, as the controller waits on it."""

    settle_s: float
    #: from the end of the exposure until the camera reports the image taken
    readout_s: float
    #: the image's transfer to the host, with its LED lit where the camera cannot say when
    #: its exposure is over
    transfer_s: float
    #: a light's switching time, counted in the time an LED stays lit
    light_switch_s: float


class RigConfig(Protocol):
    name: str
    kind: str
    backend: str

    @property
    def camera(self) -> CameraConfig: ...

    @property
    def timing(self) -> TimingConfig: ...


class LoadedRig(Protocol):
    """A rig config as loaded: the parsed config, where it came from and its exact text."""

    @property
    def config(self) -> RigConfig: ...

    path: str
    sha256: str
    raw: dict[str, Any]


@dataclass
class Rig:
    """Everything the controller needs to run a schedule."""

    loaded: LoadedRig
    geometry: DomeGeometry | ArmGeometry
    lighting: Lighting
    camera: Camera
    clock: Clock
    #: Things the rig holds open besides its devices (an emulator's pseudo-terminal…).
    resources: RigResources = field(default_factory=RigResources)
    #: Called with the session folder before the devices connect: a DSLR's downloads go there
    #: (the composition root registers what its devices need to know of the session).
    session_hooks: list[Callable[[Path], None]] = field(default_factory=list)
    #: Judges each image before its label is committed (a camera-triggered dome's
    #: :class:`rti_rig.runtime.flash_sync.CaptureCheck`); None: labels are what was commanded.
    capture_check: Callable[..., None] | None = None
    #: Called once after the last step of a completed run with a function that shoots one more
    #: frame and the session folder; returns notes for the user, or raises to disown the run
    #: (a camera-triggered dome's end-of-run proof, :class:`rti_rig.runtime.flash_sync.EndCheck`).
    end_check: Callable[..., list[str]] | None = None
    #: The bound on one image's files on disk, as the composition root reads it from the
    #: camera config (a RAW camera's decode mode and kept files); None: the controller's own
    #: full-size RGB bound. The start-up check before the rig opens counts the same.
    bytes_per_image: int | None = None
    #: Given the first delivered frame's width and height: the ``[camera]`` width and height
    #: it implies and the bound on one image's files at that size (the composition root's
    #: :func:`rti_rig.app.disk_estimate.size_from_frame`); None: the config's size stands.
    size_from_frame: Callable[[int, int], tuple[int, int, int]] | None = None
    #: The lamps' distance and the frame's field on the object, as the composition root reads
    #: them from the config (``[lamps]``, or a simulated scene's own); None: not given.
    lamps: LampGeometry | None = None

    def bind_session(self, root: Path) -> None:
        """Tell the devices which session folder this run writes (before ``connect``)."""
        for hook in self.session_hooks:
            hook(Path(root))

    def close(self) -> list[str]:
        """Release what ``build_rig`` opened (the controller has already made the devices
        safe); return each failure (``"<what> close: <error>"``) for the caller to say, never
        raising it: the error that led to the close, if any, is the one that goes on."""
        return self.resources.close()

    def close_said(self) -> None:
        """:meth:`close`, each failure said as a warning record (the command line says it as a
        note): for a close on the way out of an error, or with nobody to hand them to."""
        self.resources.close_said(self.name)

    def __enter__(self) -> Rig:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close_said()

    @property
    def name(self) -> str:
        return self.loaded.config.name

    @property
    def camera_config(self) -> CameraConfig:
        return self.loaded.config.camera

    @property
    def timing(self) -> TimingConfig:
        return self.loaded.config.timing
