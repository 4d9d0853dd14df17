"""A simulated camera with a PC-sync (flash) contact, wired to a flash-triggered dome.

A real camera closes its X-sync contact when the shutter is fully open and opens it when the
exposure ends; a dome like cceh/rti (:mod:`rti_rig.simulator.domes.cceh_rti`) lights its next
LED on that contact. This camera does the same on the injected clock: each ``capture`` closes
the contact at the start of the exposure and opens it at its end, and the image integrates what
the emulated dome really lit over the exposure window (an LED cut off by the firmware's 4 s
timeout lights only part of a longer exposure; a bounced contact that stepped the dome twice
lights the image mostly with the next LED).

Faults at chosen exposures (1-based, in the order the camera shoots):

* ``missed_pulse``: the sync signal never reaches the dome (a loose PC-sync cable, a camera in
  a mode that does not fire its flash contact): the image is dark and the dome does not step;
* ``double_step``: the contact bounces open and closed again after the firmware's 2 ms
  debounce: the dome steps twice;
* ``power_cycle``: the dome's supply drops and comes back just before the exposure: its
  firmware starts again from LED 0 (:meth:`CcehRtiFirmware.power_cycle`), so the image is lit
  by LED 0 and the dome steps on from there.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from rti_rig.core.clock import Clock
from rti_rig.core.devices import Frame
from rti_rig.simulator.domes.cceh_rti import CcehRtiFirmware
from rti_rig.simulator.sim_camera import Renderer, SimulatedCamera

SYNC_FAULTS = ("missed_pulse", "double_step", "power_cycle")
#: A bounce long enough to pass the firmware's 2 ms debounce (3 ticks of 1.024 ms, and more).
BOUNCE_OPEN_S = 0.0035
BOUNCE_CLOSED_AGAIN_S = 0.007


@dataclass(frozen=True)
class SyncFault:
    at_image: int  # 1-based exposure number
    kind: str


class _MixState:
    """What the sensor model's noise key reads: the dominant light of the last exposure."""

    def __init__(self) -> None:
        self.direction: NDArray[np.float64] | None = None
        self.intensity = 0.0


class FlashSyncCamera:
    """Shoots like :class:`SimulatedCamera`; fires the dome's flash input at every exposure."""

    def __init__(
        self,
        render: Renderer,
        dome: CcehRtiFirmware,
        directions: NDArray[np.float64],
        clock: Clock,
        *,
        faults: tuple[SyncFault, ...] = (),
        power: Callable[[int], float] = lambda _led: 1.0,
        **sensor: object,
    ) -> None:
        self.name = "simulated camera (PC-sync to the dome)"
        self.dome = dome
        self._render = render
        self._dirs = np.asarray(directions, dtype=np.float64)
        self._clock = clock
        self._faults = {f.at_image: f.kind for f in faults}
        self._power = power
        self._state = _MixState()
        self._radiance: NDArray[np.float64] | None = None
        self._sensor = SimulatedCamera(
            self._mixed,
            self._state,
            clock,
            **sensor,  # type: ignore[arg-type]
        )
        self.exposures = 0
        #: (exposure number, start, end) of every exposure (the sync windows).
        self.windows: list[tuple[int, float, float]] = []

    def connect(self) -> None:
        self._sensor.connect()

    def close(self) -> None:
        self._sensor.close()

    def _mixed(self, _direction: object, _intensity: float) -> NDArray[np.float64]:
        assert self._radiance is not None
        return self._radiance

    def capture(self, exposure_s: float) -> Frame:
        self.exposures += 1
        n = self.exposures
        t0 = self._clock.now()
        t1 = t0 + exposure_s
        kind = self._faults.get(n)
        if kind == "power_cycle":
            self.dome.power_cycle(t0)
        if kind == "double_step":
            self.dome.flash_edge(t0, True)
            self.dome.flash_edge(t0 + BOUNCE_OPEN_S, False)
            self.dome.flash_edge(t0 + BOUNCE_CLOSED_AGAIN_S, True)
            self.dome.flash_edge(t1, False)
        elif kind != "missed_pulse":
            self.dome.pulse(t0, exposure_s)
        self.windows.append((n, t0, t1))
        seconds = self.dome.lit_during(t0, t1)
        radiance = None
        dominant, best = None, 0.0
        for led, s in sorted(seconds.items()):
            if led >= len(self._dirs):
                continue  # an LED of the firmware this dome does not have wired
            part = self._render(self._dirs[led], self._power(led)) * (s / exposure_s)
            radiance = part if radiance is None else radiance + part
            if s > best:
                dominant, best = led, s
        if radiance is None:
            radiance = self._render(None, 0.0)
        self._radiance = radiance
        self._state.direction = None if dominant is None else self._dirs[dominant]
        self._state.intensity = best / exposure_s
        return self._sensor.capture(exposure_s)
