"""What a session stopped at a dead LED is told to do next (``rti-rig run``).

Why: a board that senses LED current refuses a dead LED (firmware error "LED fault"), and the
run ended "Continue with: rti-rig run --resume S" right after the driver said that a resume
stops there again: the resume lights that LED first. The advice here is one that works: repair
it and resume, or shoot the other lights with a plan that leaves it out (as
``calibrate-lights`` advises of a card session stopped the same way): the rig's LED ``.lp``
without its line, or for a session of some LEDs a plan written beside it
(:func:`write_plan_without`), since the user has no file of the lights ``--lights N`` chose.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from rti_rig.core.dome_link import DomeLedError, DomeLinkError, LinkFault
from rti_rig.core.errors import RtiRigError
from rti_rig.core.out_folders import free_folder_beside, free_name
from rti_rig.core.rig_geometry import led_said
from rti_rig.core.shell_words import shell_word
from rti_rig.drivers.led_dome.messages import ERR_LED_FAULT


def is_dead_led(fault: str | None, code: int | None) -> bool:
    """Whether a link error beneath an LED's error is the board refusing that LED as faulty (no
    current drawn: dead, or its wiring cut). Decided by the firmware's error code, not by the
    message's words: a thermal cut-out is refused too, but a resume after the LED cooled goes
    on; a board that rebooted under the LED goes on after a resume as well."""
    return fault == LinkFault.REJECTED and code == ERR_LED_FAULT


def dead_led_of(exc: BaseException) -> int | None:
    """The LED a board refused as faulty (:func:`is_dead_led`), None for any other error."""
    if not isinstance(exc, DomeLedError):
        return None
    cause = exc.__cause__
    if isinstance(cause, DomeLinkError) and is_dead_led(cause.fault, cause.code):
        return exc.led
    return None


def dead_led_recorded(runner: dict[str, Any]) -> int | None:
    """The dead LED a finished run's manifest ``runner`` records (``led_error``, written by the
    controller from the error's types), None for any other finish; None too for a manifest
    written before ``led_error`` was recorded."""
    record = runner.get("led_error")
    if not isinstance(record, dict):
        return None
    led = record.get("led")
    if not isinstance(led, int) or isinstance(led, bool):
        return None
    return led if is_dead_led(record.get("fault"), record.get("code")) else None


def dead_led_advice(
    loaded: Any, schedule: Any, out_dir: Path, led: int, adaptive: bool = False
) -> str:
    """How to go on from a session stopped at dead LED ``led``: repair it, then resume; or
    shoot the others meanwhile with a plan without it (the rig's LED ``.lp`` without its line
    when the session planned every LED, else a plan without its direction).

    An ``adaptive`` session's ``schedule`` is only its first design, the rest chosen as it
    goes: no plan of its other lights exists. Its first design, minus nothing (the dead LED
    is one it chose later), had been written as "the session's N other lights" (N one short),
    a plan of a few lights offered in the session's place."""
    dome = loaded.config.dome
    cfg = shell_word(str(loaded.path))
    directions, names = _dome_leds(loaded)
    # by its number and direction ("LED 36 (az 112.5°, el 55.0°)"): a ring dome's LED had
    # been said "LED 36 (led_036)", the id its plans and manifests keep
    which = led_said(led, directions[led], names[led]) if 0 <= led < len(names) else f"LED {led}"
    leds = {s.led for s in schedule.steps}
    repaired = (
        f"that LED or its wiring is repaired, continue with: rti-rig run --resume "
        f"{shell_word(str(out_dir))}"
    )
    resume, resume_sentence = f"once {repaired}", f"Once {repaired}"
    # real names beside the session, not there yet: PLAN.lp and NEW_DIR pasted had made a
    # folder named NEW_DIR (and a plan by hand in whatever folder the shell was in)
    base = Path(out_dir)
    plan_lp = shell_word(str(free_name(base.with_name(f"{base.name}-without-led-{led}.lp"))))
    new_dir = shell_word(str(free_folder_beside(base, f"without-led-{led}")))
    rig_lp = (
        f"copy {shell_word(str(loaded.folder / dome.lp_file))} (the rig's LED .lp) without the "
        f"line of {which}, the count on its first line one less, as {plan_lp}"
        if dome is not None and dome.lp_file
        else None
    )
    if adaptive:
        meanwhile = (
            ""
            if rig_lp is None
            else f" To shoot every other LED now instead (not adaptively), {rig_lp} and run "
            f"rti-rig run {cfg} --plan {plan_lp} --out {new_dir}."
        )
        return (
            f"A resume lights {which} first and stops there again. An adaptive session "
            f"chooses its lights as it goes, so no plan of its other lights exists."
            f"{meanwhile} {resume_sentence}"
        )
    if rig_lp is not None and leds == set(range(len(names))):
        plan = rig_lp
    else:
        plan_file = write_plan_without(schedule, out_dir, led)
        if plan_file is not None:
            # the session's own lights (a --plan's, or those --lights N chose), which the
            # user had no file of: coordinates to find and delete by hand were no command
            written, reused = plan_file
            how = "are already" if reused else "were written"
            return (
                f"A resume lights {which} first and stops there again. The session's "
                f"{len(leds - {led})} other lights, in its order, {how} beside it "
                f"as {written.name}; to shoot them now: rti-rig run {cfg} --plan "
                f"{shell_word(str(written))} --out {new_dir}. {resume_sentence}"
            )
        step = next((s for s in schedule.steps if s.led == led), None)
        where = "" if step is None else " ({:.6f} {:.6f} {:.6f})".format(*step.direction)
        plan = f"write the lights to shoot without the direction of {which}{where} as {plan_lp}"
    return (
        f"A resume lights {which} first and stops there again. To shoot the other lights now, "
        f"{plan} and run rti-rig run {cfg} --plan {plan_lp} --out {new_dir}; {resume}"
    )


def write_plan_without(schedule: Any, out_dir: Path, led: int) -> tuple[Path, bool] | None:
    """Write the session's lights without LED ``led``, in its order, as a new ``.lp`` beside
    ``out_dir`` (``<name>-without-led-<led>.lp``, never over an existing file); its path and
    whether it was there already with this very content (reused, not written again), or None
    when it cannot be written (no other light, a folder one cannot write to).

    Beside the session, not in it: a second ``.lp`` in the session folder would be offered to
    relight and RTIBuilder beside its ``lights.lp``, naming images it does not hold. An
    identical file is reused: each resume stopped at the same LED had written another copy
    (``-2.lp``, ``-3.lp``); a file that differs (another plan, edited by the user) is kept and
    the next free name taken."""
    from rti_rig.core.lp_format import LpEntry, format_lp

    kept = [s for s in schedule.steps if s.led != led]
    if not kept:
        return None
    text = format_lp(
        [LpEntry(f"image_{i:03d}.jpg", s.direction) for i, s in enumerate(kept, start=1)]
    )
    base = Path(out_dir).absolute()
    for n in range(1, 100):
        suffix = "" if n == 1 else f"-{n}"
        path = base.parent / f"{base.name}-without-led-{led}{suffix}.lp"
        try:
            with open(path, "x", encoding="ascii", newline="\n") as fh:  # never over a file
                fh.write(text)
        except FileExistsError:
            if _holds(path, text):
                return path, True
            continue
        except OSError:
            return None
        return path, False
    return None


def _holds(path: Path, text: str) -> bool:
    """Whether the file at ``path`` holds exactly ``text`` (False if it cannot be read)."""
    try:
        return path.read_bytes() == text.encode("ascii")
    except (OSError, UnicodeEncodeError):
        return False


def _dome_leds(loaded: Any) -> tuple[Any, list[str]]:
    """The dome's LED directions and names, none where they cannot be read (advice only: an
    LED is then said by its number alone)."""
    from rti_rig.app.config import dome_led_directions

    try:
        return dome_led_directions(loaded)
    except RtiRigError:
        return (), []
