"""What to tell a user whose configured serial port is not there: the serial ports that are.

In the field a dome or an arm drops off a USB hub (a laptop on battery suspends the hub, a
cable is knocked) and comes back as another device: ``/dev/ttyACM0`` becomes ``/dev/ttyACM1``
when the old node was still held as the kernel enumerated the device again. The rig config
still names ``/dev/ttyACM0``, and "No such file or directory" alone sent the user hunting.

What a demanding user expects, and why it is done this way:

* rti-rig never moves to another port by itself. The port that appeared may be another
  device (the arm's U2D2, a second dome, a GPS puck): sending a dome's all-off or a servo's
  goal position to it is the kind of guess a rig must not make. The user chooses.
* The error names the serial ports present now, with what the system says of each (its
  description, its USB serial number) and its stable ``/dev/serial/by-id/`` name, so the
  choice is one look, not a search.
* A config naming a kernel name that can change (``/dev/ttyACM0``, ``/dev/ttyUSB0``) is told
  that the by-id name stays the same across a replug (the shipped example configs use one).
* The session resumes with the corrected config: a serial port's name is not part of the rig's
  identity (:mod:`rti_rig.app.rig_identity`), so ``rti-rig run FIXED.toml --resume DIR`` goes
  on, while the board's own identity (its handshake, the arm's servo models) is checked at
  connect as at any start. Saying so is left to the caller, which knows the session.
"""

from __future__ import annotations

import os
from pathlib import Path

from rti_rig.core.shell_words import shell_word

#: Where udev keeps names that survive a replug (one symlink per USB serial device).
BY_ID = Path("/dev/serial/by-id")


def _stable_names() -> dict[str, str]:
    """Device node → its ``/dev/serial/by-id/`` name (empty where udev keeps none)."""
    names: dict[str, str] = {}
    try:
        links = sorted(BY_ID.iterdir())
    except OSError:  # no USB serial device now, or not Linux
        return names
    for link in links:
        try:
            names.setdefault(os.path.realpath(link), str(link))
        except OSError:
            continue
    return names


def ports_present_note(port: str, command: str | None = None) -> str:
    """A sentence for an error about ``port`` that does not exist: the serial ports present
    now and how to point the config at one ("" outside /dev: a URL such as ``loop://``, an
    emulator's pseudo-terminal). Never raises: a listing that fails says so, rather than
    replacing the error it was to explain.

    ``command``: the command that was given the port itself (``rti-rig probe``), said again
    with each port present (its stable name where udev keeps one), as one shell word; None:
    the port came from a rig config, which is where to set it. Why: ``rti-rig probe`` of a
    missing port had been told to "set that port in the rig config", which it was not given."""
    if not port.startswith("/dev/"):
        # a URL (``loop://``), or an emulator's pseudo-terminal that its own config serves: no
        # device a user would point a config at
        return ""
    try:
        from serial.tools import list_ports

        found = sorted(list_ports.comports(), key=lambda p: p.device)
    except Exception as exc:  # a hint must not replace the error it explains
        # the system's reason, not Python's text of it ("[Errno 13] ...: '/sys/class/tty'")
        why = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc)
        return f"the serial ports present could not be listed ({why or type(exc).__name__})"
    stable = _stable_names()
    kernel_name = not port.startswith(("/dev/serial/by-id/", "/dev/serial/by-path/"))
    advice = (
        f" ({shell_word(port)} is a name the system gives at each plugging; the "
        "/dev/serial/by-id/ name stays the same, use it)"
        if kernel_name
        else ""
    )
    if not found:
        return f"no serial port is present now{advice}"
    described = []
    for p in found:
        facts = [
            str(f)
            for f in (p.description, f"serial number {p.serial_number}" if p.serial_number else "")
            if f and f != "n/a"
        ]
        name = stable.get(os.path.realpath(p.device)) or stable.get(p.device)
        if name:
            facts.append(shell_word(name))  # a path said pastes as the bytes on disk
        device = shell_word(p.device)
        described.append(f"{device} ({', '.join(facts)})" if facts else device)
    if command is None:
        fix = "set that port in the rig config"
    else:
        names = [
            stable.get(os.path.realpath(p.device)) or stable.get(p.device) or p.device
            for p in found
        ]
        fix = "give it to the command again: " + " or ".join(
            f"{command} {shell_word(name)}" for name in names
        )
    return (
        f"serial ports present now: {'; '.join(described)}. If the device came back under "
        f"another name, {fix}{advice}"
    )
