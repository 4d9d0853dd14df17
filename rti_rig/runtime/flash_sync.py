"""A dome the camera steps (cceh/rti): the host only shoots; the lights come from its order.

The dome has no link to the host. Each flash (PC-sync) pulse of the camera lights the next LED
of the firmware's fixed order, and the firmware switches off by itself at the end of the pulse,
or at the latest ``timeout_s`` after it. So this lighting commands nothing: ``set`` says which
LED the firmware's order puts on image *i*, ``off`` and ``safe`` do nothing, and
:meth:`CameraTriggeredLighting.lights_state` says exactly what is known — never "lights are
off". Whether the dome really lit that LED is judged from the image before its label is
committed (:class:`CaptureCheck`); a slip stops the session with :class:`LightSlipError`.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Protocol

from rti_rig.core.devices import Frame
from rti_rig.core.errors import RtiRigError
from rti_rig.core.rig_geometry import DomeGeometry
from rti_rig.core.schedule import LightStep
from rti_rig.runtime.lighting import NO_LIT_LIMIT, ActualLight


class LightSlipError(RtiRigError):
    """An image was not lit by the LED the dome's order puts on it (a missed or double step).

    The image is kept, set aside unlabelled; the session's `.lp` lists only the images before.
    """


class CaptureCheck(Protocol):
    """Judges image ``index`` before its label is committed; raises :class:`LightSlipError`
    (after keeping the image) when it was not lit by ``actual``."""

    def __call__(self, index: int, frame: Frame, actual: ActualLight, root: Path) -> None: ...


class EndCheck(Protocol):
    """Runs once after the last image of a completed run: may ``shoot`` extra frames (each
    steps the dome), returns notes for the user, raises :class:`LightSlipError` to disown it."""

    def __call__(self, shoot: Callable[[], Frame], root: Path) -> list[str]: ...


class CameraTriggeredLighting:
    """The lights of a flash-stepped dome: image ``i`` is LED ``i`` of the firmware's order."""

    def __init__(self, geometry: DomeGeometry, firmware: str, timeout_s: float) -> None:
        self.geometry = geometry
        self.firmware = firmware
        self.timeout_s = timeout_s
        self.name = f"camera-triggered dome ({firmware})"

    def connect(self) -> None:
        pass  # no link: the dome listens only to the camera's flash contact

    def close(self) -> None:
        pass

    def problem(self, step: LightStep) -> str | None:
        if step.led is None or not 0 <= step.led < self.geometry.count:
            return (
                f"this dome lights its LEDs in its own order (0..{self.geometry.count - 1}); "
                "a step must name one of them"
            )
        if step.exposure_s is not None and step.exposure_s > self.timeout_s:
            return (
                f"exposure {step.exposure_s:g} s: the {self.firmware} firmware switches its LED "
                f"off {self.timeout_s:g} s after the flash pulse"
            )
        return None

    def set(self, step: LightStep) -> ActualLight:
        """Nothing to command: the camera's pulse will light LED ``step.led``, if nothing slips."""
        assert step.led is not None
        d = self.geometry.directions[step.led]
        return ActualLight((float(d[0]), float(d[1]), float(d[2])), step.led)

    def off(self) -> None:
        pass  # the firmware switches off at the end of the flash pulse

    def safe(self, emergency: bool = False) -> list[str]:
        return []  # nothing can be sent: lights_state says what the firmware does by itself

    def lit_limit_s(self) -> None:
        """None: the host lights nothing, so it keeps no lit-time limit (the firmware's own
        ``timeout_s`` bounds each flash, checked against the exposure in :meth:`problem`).

        Why not ``timeout_s``: this limit is what the host must keep a light it lit within.
        Given one, the controller would switch "off" and "relight" the LED around a busy
        camera (:func:`rti_rig.runtime.controller.fire_lit`), and say an all-off was sent to
        a dome that has no link; here the LED lights only with the flash pulse, so a busy
        camera keeps nothing lit. The firmware's window bounds the exposure instead, refused
        before anything is lit: ``camera.exposure_s`` at the config's load
        (:func:`rti_rig.app.flash_sync.check_exposure`), a planned step's exposure here, and
        the metering (``--auto-exposure``) and ``--plan`` are refused on this dome."""
        return None

    def lit_limit_said(self) -> str:
        """No limit to name (:meth:`lit_limit_s` is None)."""
        return NO_LIT_LIMIT

    # no link, nothing commanded: each other ability of the Lighting protocol has nothing to
    # say, and says so here (the controller had guessed at them with getattr)

    def hold(self) -> None:
        """No link to keep open."""

    def off_said(self) -> None:
        """None: no all-off is sent, so none is recorded (:meth:`lights_state` says why)."""
        return None

    def cool_down_s(self, step: LightStep, at: float) -> float:
        """0: the host keeps no thermal guard over LEDs it does not light."""
        return 0.0

    def listen(self, say: Callable[[str], None] | None) -> None:
        """Nothing to say: no link to lose."""

    def check_held(self) -> None:
        """Nothing to check: an LED does not move (a slip is the capture check's)."""

    def resends(self) -> tuple[dict[str, list[str]], str | None]:
        """Nothing: no command is sent, so none is resent."""
        return {}, None

    def reconnections(self) -> list[dict[str, object]]:
        """[]: no link to reopen."""
        return []

    def port_close_failure(self) -> None:
        """None: no port to close."""
        return None

    @property
    def link_open(self) -> bool:
        """Always False: this dome has no link to the host (the camera's flash signal steps
        it), so there is no all-off to send."""
        return False

    @staticmethod
    def resume_hint(config: str, out: str) -> str:
        """What the CLI says instead of "continue with --resume": the dome's count went on, so
        the whole sequence is shot again, by the run of ``config`` into ``out`` (both as shell
        words; ``out`` a folder free when said). Why the command: "start a new session" had
        left the user to find the config and a folder."""
        return (
            "A camera-triggered dome cannot resume a session (its own count went on): long-press "
            f"its start button to rewind it, then start a new session: rti-rig run {config} "
            f"--out {out}"
        )

    def lights_state(self) -> str:
        return (
            f"no all-off could be sent: this dome ({self.firmware}) has no link to the host, "
            "the camera's flash signal steps it; its firmware lights an LED only while "
            f"the flash signal is on and switches it off by itself {self.timeout_s:g} s after "
            "the last flash at the latest. That lights are off is not confirmed: look at the "
            "dome"
        )
