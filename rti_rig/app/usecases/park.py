"""Use case: park an arm and do nothing else (``rti-rig check RIG --park-only``).

Why: a check or run stopped with the arm mid-pose advised "park it with rti-rig check RIG",
which walks every self-test pose again before it parks: eight moves near the object when the
user asked for one. This connects the arm (as every command does: limits checked, goal set to
where it stands, torque on), switches the lamp off, stops, moves to the config's park pose
and closes with the config's ``torque_policy`` (the teardown of a session, with no session):
nothing else moves. A stop (Ctrl-C, SIGTERM) during the park holds the arm where it stands,
torque on, as a session's park does, and is said as such; with ``torque_policy =
"release_on_close"`` an arm the stop left at its park pose (within the driver's
``PARKED_TICKS``) is released by the close all the same, and said to be.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import NoReturn

from rti_rig.app.compose import build_rig
from rti_rig.app.config import load_rig_config
from rti_rig.app.usecases.check import CheckStopped
from rti_rig.app.usecases.safe_state import lights_state
from rti_rig.core.deferred_signals import signals_deferred
from rti_rig.core.errors import RtiRigError
from rti_rig.core.shell_words import shell_word, shown_path
from rti_rig.runtime.controller import EmergencyStop
from rti_rig.runtime.lighting import ArmLighting, attempt_all, park_check

#: what a park stopped while its rig was being built may say of the arm: no byte was sent
ARM_NOT_REACHED = "nothing was sent to the arm: the park stopped before connecting it"


class ParkStopped(CheckStopped):
    """The park was stopped (SIGTERM, Ctrl-C); the arm was made safe first (lamp off, stop,
    held where the stop found it). A check's stop with no walk: ``lights`` what is known of
    the arm after the teardown (read back; never "parked" unless so), ``todo`` the command
    that parks it, None when it parked or was never reached."""

    def __init__(
        self,
        stop: EmergencyStop,
        lights: str,
        teardown_failures: tuple[str, ...] = (),
        todo: str | None = None,
    ) -> None:
        super().__init__(stop, lights, teardown_failures, todo=todo)
        self.args = (f"park stopped ({stop}): {lights}",)


@dataclass(frozen=True)
class ParkReport:
    """What ``check --park-only`` established (``.lines()``, ``.ok``)."""

    #: where the arm was left, as read back, and what its lamp-off and stop established
    lights: str
    parked: bool
    teardown_failures: tuple[str, ...] = ()
    #: the connect's error, when the arm could not be connected (nothing was moved then)
    aborted: str | None = None

    @property
    def ok(self) -> bool:
        return self.parked and not self.teardown_failures and self.aborted is None

    def lines(self) -> list[str]:
        out = [f"teardown problem: {f}" for f in self.teardown_failures]
        if self.aborted is not None:
            out.append(f"arm: not parked: its connect failed: {self.aborted}")
        out.append(f"arm: {self.lights}")
        out.append("RESULT: " + ("PASS" if self.ok else "FAIL"))
        return out


def refuse_unparkable(
    loaded: object,
    rig_config: Path,
    others: Sequence[Sequence[str]] = (),
) -> None:
    """Refuse ``--park-only`` for a rig that has no arm to park (a dome, a replay): a dome has
    no park pose, and its all-off is what ``rti-rig check`` ends with.

    ``others``: the check's other options given with ``--park-only``, each as its command-line
    words (``["--intensity", "0.5"]``). Why: ``check DOME --park-only --intensity 0.5`` was
    refused for the option, and then, the option dropped, for the dome: one problem at a time.
    Both are said at once, and a dome's check command keeps the walk's options given
    (``--intensity``, ``--auto-exposure``), which its check takes."""
    config = loaded.config  # type: ignore[attr-defined]
    if config.arm is not None and config.backend != "replay":
        return
    replay = config.backend == "replay"
    # a replay's own words: it had been called a rig config, and told that its check ends
    # "with every LED switched off", of an .lp and its images that have no LED
    what, ends = (
        ("is a replayed acquisition (a .lp and its images), with nothing to move", "")
        if replay
        else (
            "rig config describes a dome, which has no park pose",
            " (its check ends with every LED switched off)",
        )
    )
    # a dome's check lights at --intensity and meters for --auto-exposure; a replay's check
    # refuses both, and --reboot-faulted is an arm's
    kept = [] if replay else [o for o in others if o[0] in _DOME_CHECK_OPTIONS]
    dropped = [o[0] for o in others if o not in kept]
    left_out = (
        f"{' and '.join(dropped)} left out, which {'a replay' if replay else 'a dome'}'s check "
        "does not take"
        if dropped
        else ""
    )
    if left_out:
        ends = f" ({ends[2:-1]}; {left_out})" if ends else f" ({left_out})"
    words = " ".join(shell_word(w) for o in kept for w in o)
    command = f"rti-rig check {shell_word(str(rig_config))}" + (f" {words}" if words else "")
    raise RtiRigError(
        f"{shown_path(rig_config)}: --park-only parks an arm; this {what}. "
        f"To check it{ends}: {command}"
    )


#: the options of ``rti-rig check`` that a dome's check takes, kept in the command a dome's
#: ``--park-only`` refusal gives
_DOME_CHECK_OPTIONS = ("--intensity", "--auto-exposure")


def refuse_park_only_with(rig_config: Path, others: Sequence[Sequence[str]]) -> NoReturn:
    """Refuse ``--park-only`` given with the check's other options (``others``, as in
    :func:`refuse_unparkable`), saying in the one message every reason it is refused: the
    options, and a rig with nothing to park or a config that does not load.

    Why: each had been said alone, the next only once the first was put right."""
    names = " and ".join(o[0] for o in others)
    drop = f"--park-only parks the arm and does nothing else: drop {names}"
    try:
        loaded = load_rig_config(rig_config)
    except RtiRigError as exc:
        raise RtiRigError(f"{exc}\nAlso: {drop}.") from None
    refuse_unparkable(loaded, rig_config, others)
    raise RtiRigError(drop)


def park_arm(rig_config: Path, on_start: Callable[[], None] | None = None) -> ParkReport:
    """Connect the arm of ``rig_config``, lamp off, stop, park, close (torque as the config's
    ``torque_policy`` says), and say where it was left, as read back.

    ``on_start`` is called once the config is known to have an arm, before anything opens.
    Raises :class:`ParkStopped` after a Ctrl-C or SIGTERM, the arm made safe first."""
    loaded = load_rig_config(rig_config)
    refuse_unparkable(loaded, rig_config)
    if on_start is not None:
        on_start()
    try:
        built = build_rig(loaded)
    except EmergencyStop as exc:
        raise ParkStopped(exc, ARM_NOT_REACHED) from None
    with built as rig:
        lighting = rig.lighting
        if not isinstance(lighting, ArmLighting):  # the config's arm built something else
            raise RtiRigError(f"{shown_path(rig_config)}: --park-only found no arm to park")
        # the park is what was asked for, whatever park_after_session says of a session's end
        lighting.park_after_session = True
        stop: EmergencyStop | None = None
        aborted: str | None = None
        try:
            lighting.connect()
        except EmergencyStop as exc:  # Ctrl-C while connecting: made safe, not parked
            stop = exc
        except Exception as exc:  # a servo fault, a silent servo: said, nothing moved
            aborted = str(exc)
        failures: list[str] = []
        try:
            # the whole teardown before a stop is acted on (the park's own hold lets a stop
            # end the park, the arm held where it stands)
            with signals_deferred():
                if aborted is None:
                    failures += lighting.safe(emergency=stop is not None)
                failures += attempt_all([("close", lighting.close)])
        except EmergencyStop as exc:  # held during the teardown, delivered now
            stop = stop or exc
        lights = lights_state(rig, bool(failures))
        end = lighting.end
        parked = end is not None and end.outcome == "parked"
        if stop is not None:
            raise ParkStopped(stop, lights, tuple(failures), _todo(lighting, parked, rig_config))
        return ParkReport(lights, parked, tuple(failures), aborted)


def _todo(lighting: ArmLighting, parked: bool, rig_config: Path) -> str | None:
    """How to park an arm a stopped park left where it was: this command again (after making
    it safe, if the stop did not hold every joint); None if it parked or was never reached."""
    if parked or lighting.end is None:
        return None
    command = park_check(str(rig_config))
    if lighting.unheld or "stop" in lighting.not_sent:
        return f"Once the arm is safe (the lines above say how), park it with {command}"
    return f"To park it: {command}"
