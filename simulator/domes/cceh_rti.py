"""The cceh/rti dome firmware (``firmware/rti.cpp``, ATmega328p) as its source behaves.

The dome looks to the camera like a flash gun: the camera's PC-sync (flash) contact steps it.
There is **no serial link at all**: nothing to command, nothing that answers. The facts modelled,
from the version at commit f647d3f of cceh/rti ``firmware/rti.cpp`` (and its user manual,
``doc_src/user_manual.rst``):

* **60 LEDs** (``LED_595_MASK``, "the prototype has 60 LEDs"), driven through two 595 shift
  registers. The main loop *programs* the next LED into the shift register; the flash interrupt
  only *latches* what is programmed and enables the outputs. At boot the loop programs LED 0
  (``write595(LED_595_MASK[0])``; an older version, commit 0a4eeba, does not, so there the first
  flash after power-up lights nothing useful until the start button is long-pressed).
* **The flash input** (INT1, any edge, active low). An edge is acted on only if more than
  ``flash_input_debounce_delay`` = 2 ms (of ``millis()``, a 1.024 ms tick) passed since the
  previous edge — *any* previous edge, acted on or not. On an acted-on active edge:
  latch + outputs on (the programmed LED lights), start the 4 s timer, ``++led_index``; the main
  loop then programs the LED of the new index, if it is below 60. On an acted-on release edge:
  outputs off. So an LED is lit while the camera holds its sync contact closed.
* **The 4 s timeout** (``max_exposure = 4``; timer 1 at 15625 Hz × 4): 4 s after the last
  acted-on flash edge the outputs go off (and the camera-trigger line is released) even if the
  sync contact is still closed. A later flash restarts the timer.
* **End of the sequence**: at ``led_index >= 60`` the dome releases its camera-trigger line
  ("stop the camera one shot early") and stops programming: the shift register still holds the
  last LED's pattern, so every further flash re-lights **LED 59**.
* **Start button**: a long press (> 1 s) switches off, rewinds ``led_index`` to 0, programs
  LED 0 and pulls the camera-trigger line (a camera wired to it shoots continuously); a short
  press toggles the pilot (focus) light, all LEDs (``PILOT_595_MASK = 0xFFFF``), and leaves
  that pattern in the shift register: the next flash lights every LED until the start button is
  long-pressed again.

In rti-rig's host-only mode the host fires the camera, the camera's flash contact steps the
dome, and the dome's own camera-trigger cable stays unplugged. The emulator records which LEDs
are lit from every moment on (:attr:`timeline`) and every edge it saw (:attr:`events`), so a
test asserts what the dome did.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

LED_COUNT = 60
#: ms of ``millis()`` that must pass since the previous flash edge (strictly more).
DEBOUNCE_MS = 2
#: One ``millis()`` tick (timer 0 overflow at 16 MHz / 64 / 256).
TICK_S = 0.001024
#: The firmware's safety timeout after a flash (``max_exposure``), seconds.
TIMEOUT_S = 4.0
#: A long press of the start button (``start_button_long_press_interval``), seconds.
LONG_PRESS_S = 1.0
ALL_LEDS = frozenset(range(LED_COUNT))


@dataclass(frozen=True)
class Edge:
    """A change of the flash (PC-sync) input: ``active`` = contact closed."""

    t: float
    active: bool


class CcehRtiFirmware:
    """The dome's state machine, driven by timed edges on its flash input and start button."""

    name = "cceh-rti"
    led_count = LED_COUNT

    def __init__(self, start: float = 0.0) -> None:
        self.t = start
        self.led_index = 0
        #: what the shift register holds: the LEDs a latch will light
        self.programmed: frozenset[int] = frozenset({0})  # f647d3f programs LED 0 at boot
        self._lit: frozenset[int] = frozenset()
        self._last_edge_tick: int | None = None
        self._timeout_at: float | None = None
        self.camera_trigger = False
        self.pilot_on = False
        #: (time, LEDs lit from then on), in order.
        self.timeline: list[tuple[float, frozenset[int]]] = [(start, frozenset())]
        #: (time, what): every edge, acted on or ignored, timeouts, button presses.
        self.events: list[tuple[float, str]] = [(start, "boot")]

    # ------------------------------------------------------------------ inputs

    def flash_edge(self, t: float, active: bool) -> None:
        """An edge on the flash input at time ``t`` (edges must come in time order)."""
        self.advance(t)
        tick = math.floor(t / TICK_S + 1e-9)
        acted = self._last_edge_tick is None or tick - self._last_edge_tick > DEBOUNCE_MS
        self._last_edge_tick = tick
        what = "flash" if active else "release"
        if not acted:
            self.events.append((t, f"{what} ignored (debounce)"))
            return
        if active:
            self._set_lit(t, self.programmed)
            self._timeout_at = t + TIMEOUT_S
            self.led_index += 1
            self.events.append(
                (t, f"flash: LEDs {sorted(self.programmed)} on, index -> {self.led_index}")
            )
            if self.led_index >= LED_COUNT:
                self.camera_trigger = False
            if self.led_index < LED_COUNT:  # the main loop programs the next LED
                self.programmed = frozenset({self.led_index})
        else:
            self._set_lit(t, frozenset())
            self.events.append((t, "release: off"))

    def pulse(self, t: float, duration_s: float) -> None:
        """The sync contact closed at ``t`` for ``duration_s``."""
        self.flash_edge(t, True)
        self.flash_edge(t + duration_s, False)

    def long_press(self, t: float) -> None:
        """Hold the start button for more than 1 s from ``t``: rewind to LED 0, trigger on."""
        t_act = t + LONG_PRESS_S
        self.advance(t_act)
        self._set_lit(t_act, frozenset())
        self.led_index = 0
        self.programmed = frozenset({0})
        self.camera_trigger = True
        self.pilot_on = False
        self.events.append((t_act, "start (long press): index -> 0"))

    def power_cycle(self, t: float) -> None:
        """The dome's supply lost and back at ``t`` (a loose barrel jack, a brown-out).

        Why: ``led_index`` is a static the C runtime zeroes at every start, and ``main()``
        switches the outputs off, releases the camera line and programs ``LED_595_MASK[0]``
        (cceh/rti ``firmware/rti.cpp`` at f647d3f): the board forgets how far the run got,
        and its next flash lights LED 0 again, whatever image the host is at."""
        self.advance(t)
        self._set_lit(t, frozenset())
        self.led_index = 0
        self.programmed = frozenset({0})
        self._last_edge_tick = None
        self._timeout_at = None
        self.camera_trigger = False
        self.pilot_on = False
        self.events.append((t, "power cycle: boot, index -> 0"))

    def short_press(self, t: float) -> None:
        """Toggle the pilot light (every LED), leaving its pattern in the shift register."""
        self.advance(t)
        self.camera_trigger = False
        if self.pilot_on:
            self._set_lit(t, frozenset())
        else:
            self.programmed = ALL_LEDS
            self._set_lit(t, ALL_LEDS)
        self.pilot_on = not self.pilot_on
        self.events.append((t, f"pilot light {'on' if self.pilot_on else 'off'}"))

    def advance(self, t: float) -> None:
        """Let time pass to ``t``: the 4 s timer fires if due."""
        if self._timeout_at is not None and self._timeout_at <= t:
            at, self._timeout_at = self._timeout_at, None
            self._set_lit(at, frozenset())
            self.camera_trigger = False
            self.events.append((at, "timeout: off"))
        self.t = max(self.t, t)

    # ------------------------------------------------------------------ truth

    def lit_at(self, t: float) -> frozenset[int]:
        state: frozenset[int] = frozenset()
        for when, lit in self.timeline:
            if when > t:
                break
            state = lit
        return state

    def lit_during(self, t0: float, t1: float) -> dict[int, float]:
        """Seconds each LED was lit within [t0, t1] (what an exposure of that window saw)."""
        self.advance(t1)
        seconds: dict[int, float] = {}
        for k, (when, lit) in enumerate(self.timeline):
            end = self.timeline[k + 1][0] if k + 1 < len(self.timeline) else math.inf
            lo, hi = max(when, t0), min(end, t1)
            if hi > lo:
                for led in lit:
                    seconds[led] = seconds.get(led, 0.0) + (hi - lo)
        return seconds

    def _set_lit(self, t: float, leds: frozenset[int]) -> None:
        if leds != self._lit:
            self._lit = leds
            self.timeline.append((t, leds))
