"""Error hierarchy.

Every error a user can meet says *where* (file and line, config key, device, LED or step) and
*what to do*. Callers catch :class:`RtiRigError` at the CLI edge and print it without a traceback.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from rti_rig.core.shell_words import shown_path
from rti_rig.core.toml_lines import key_line_in_file


class RtiRigError(Exception):
    """Base class of every error rti-rig raises on purpose."""

    #: What metering's teardown established of the lights, where this error ended metering
    #: (set by the session use case, said by the CLI before the error), None otherwise.
    #: Declared: it had been set with a ``# type: ignore`` and read with ``getattr``.
    lights_state: str | None = None


class ConfigError(RtiRigError):
    """A rig config is unreadable or invalid; names the file and the key."""

    def __init__(
        self, path: Path | str, key: str | None, message: str, line: int | None = None
    ) -> None:
        self.path = str(path)
        self.key = key
        self.message = message
        #: The line the key is written on (found in the file when not given; None: not in it).
        self.line = line if line is not None or not key else key_line_in_file(path, key)
        where = shown_path(self.path)
        if self.line is not None:
            where += f", line {self.line}"
        if key:
            where += f": key '{key}'"
        super().__init__(f"{where}: {message}")


class LpFormatError(RtiRigError):
    """An `.lp` light-position file breaks the format; names the file and line."""

    def __init__(self, path: Path | str, line: int | None, message: str) -> None:
        self.path = str(path)
        self.line = line
        self.message = message
        where = (
            f"{shown_path(self.path)}, line {line}" if line is not None else shown_path(self.path)
        )
        super().__init__(f"{where}: {message}")


class ImageFileError(RtiRigError, OSError):
    """An image file that cannot be read as its header says (truncated, a short read): named,
    with what to do. Also an ``OSError``, so code that handles unreadable files still does."""


class ScheduleError(RtiRigError):
    """A light schedule cannot run on this rig (found before anything moves)."""


class DeviceError(RtiRigError):
    """A device failed or answered wrongly; names the device and the command."""

    def __init__(self, device: str, message: str, command: str | None = None) -> None:
        self.device = device
        self.command = command
        self.message = message
        cmd = f" during '{command}'" if command else ""
        super().__init__(f"{device}{cmd}: {message}")


class MoveCancelled(DeviceError):
    """A move (the teardown's park) was cancelled by its caller part-way, and the arm stopped
    by a hold where it stood (torque on): raised only once that hold was written to every
    joint, so whoever catches it may say the arm is held there (a stop that did not hold
    every joint raises its own error instead)."""


@dataclass(frozen=True)
class UnheldJoint:
    """A joint a stop could not hold, and what was read of its servo when it tried.

    ``fault``: the servo answered with a hardware fault (an overload, overheating…), for which
    a servo may shut itself down, torque off; ``torque_on``: its Torque Enable as read after
    that fault (None: not read, or no fault was read: a servo that did not answer);
    ``no_reply``: the servo sent no status at all (its reply window ran out), so nothing is
    known of it: it may be unpowered (the chain's supply gone: torque off, the joint limp) as
    well as powered and holding its last goal."""

    joint: str
    servo_id: int
    fault: bool
    torque_on: bool | None = None
    no_reply: bool = False


class StopIncomplete(DeviceError):
    """A stop that did not hold every joint; :attr:`unheld` says what was read of each joint
    it did not hold. Why: the lights line said of every such stop that the servo "keeps its
    last goal under torque", also of a servo that had shut itself off after an overload,
    torque read off: a limp joint, the arm free to sag."""

    #: the joints not held, as read (set by the driver that raises it)
    unheld: tuple[UnheldJoint, ...] = ()


class CaptureError(DeviceError):
    """The camera did not deliver a usable frame."""


class CameraBusyError(CaptureError):
    """The camera answered busy and took **no** picture, and its next try is due later than
    the caller allowed it to wait (the time the step's light may stay lit).

    Raised by a :class:`rti_rig.core.devices.BusyAwareCamera` only when asked to fire by a
    time: the caller switches its light off, waits ``retry_in_s`` in the dark, lights it
    again and asks once more; the camera keeps counting its tries across these calls, so the
    whole wait stays bounded by its own retry settings (then it raises a plain
    :class:`CaptureError`).
    """

    def __init__(
        self,
        device: str,
        message: str,
        command: str | None,
        retry_in_s: float,
        tries: int,
    ) -> None:
        super().__init__(device, message, command)
        #: how long to wait before the next try (the camera's own back-off)
        self.retry_in_s = retry_in_s
        #: how many times it has answered busy so far in this wait
        self.tries = tries


class SessionError(RtiRigError):
    """The session folder cannot be written or read as asked (never overwrites captures)."""
