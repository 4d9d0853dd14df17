"""What the dome's transport and the arm's bus both need around a pyserial port's descriptor:
its identity, and a close that a stop cut short, finished.

Why a module of its own: both drivers open a pyserial port on a device path and lock it with
``flock`` (pyserial's ``exclusive=True``, the arm's bus by hand), so a stop landing inside the
close leaves the same two hazards on either (a descriptor and its lock kept; a reused
descriptor number closed again). The dome's fix had been private to its transport.
"""

from __future__ import annotations

import contextlib
import os

import serial

try:  # pyserial lets termios.error (not an OSError) escape from tcdrain/tcsetattr on POSIX
    import termios

    PORT_ERRORS: tuple[type[BaseException], ...] = (
        serial.SerialException,
        OSError,
        termios.error,
    )
    TERMIOS_ERROR: type[BaseException] | None = termios.error
except ImportError:  # pragma: no cover - Windows
    PORT_ERRORS = (serial.SerialException, OSError)
    TERMIOS_ERROR = None


def identity(ser: object) -> tuple[int, int] | None:
    """The (device, inode) of the file ``ser``'s descriptor refers to; None for a port with no
    descriptor of its own (``loop://``, a socket URL whose number is no device, an emulator's
    stand-in)."""
    fd = getattr(ser, "fd", None)
    if not isinstance(fd, int):
        return None
    try:
        st = os.fstat(fd)
    except OSError:
        return None
    return st.st_dev, st.st_ino


def finish_close(ser: serial.SerialBase, opened_as: tuple[int, int] | None) -> None:
    """Close ``ser`` again after a stop cut its close short: its descriptor (and lock) is
    released now, not when the stop's traceback lets the object go. Closed only if the
    descriptor still refers to the port opened (``opened_as``, its :func:`identity` when it
    opened): a stop landing just after pyserial's ``os.close``, before it forgot the number,
    must not close a file another thread has since been given under that number. pyserial's
    own close is otherwise used, suppressed errors and all."""
    fd = getattr(ser, "fd", None)
    if opened_as is not None and isinstance(fd, int) and identity(ser) != opened_as:
        ser.fd = None  # already closed by the close that was cut short
        ser.is_open = False
        return
    with contextlib.suppress(*PORT_ERRORS):
        ser.close()


def permission_denied_why(port: str) -> str:
    """Why a serial port that exists would not open for this user (EACCES), and what to do:
    the dome's transport and the arm's bus say it in these same words.

    Why: the system's "Permission denied" alone (the dome) or pyserial's "[Errno 13] could not
    open port P: [Errno 13] Permission denied: 'P'" (the arm) left a user to guess; on Linux a
    serial device belongs to a group (``dialout`` on Debian/Ubuntu/Fedora, ``uucp`` on Arch),
    and a user joins it once, the new group counting only from the next login. The group is
    the device's own where the system says (never "root", which no user should join)."""
    group = "dialout"
    try:
        import grp

        owner = grp.getgrgid(os.stat(port).st_gid).gr_name
        if owner != "root":
            group = owner
    except (ImportError, OSError, KeyError):  # not POSIX, the node gone, a group with no name
        pass
    return (
        "permission denied: this user may not open it; on Linux, add the user to the "
        f"'{group}' group (sudo usermod -aG {group} $USER), then log out and in again (a "
        "new group counts only from the next login)"
    )
