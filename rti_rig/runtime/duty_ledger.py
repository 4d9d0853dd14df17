"""The LED dome's duty ledger: which LEDs earlier commands lit, kept between rti-rig commands.

The thermal guard (:class:`rti_rig.runtime.dome_policy.ThermalGuard`) bounds each LED's duty
over ``duty_window_s``, but it lived in one process: ``rti-rig check`` started right after a
``run`` that ended with LED 7 lit 10 s could light LED 7 again at once, breaking the duty the
user set (``[dome.serial.thermal]``) to protect their LEDs. The ledger is a small JSON file per
physical dome holding each LED's lightings of the last ``duty_window_s``, in wall-clock
(``time.time()``) seconds, read when the dome connects and written when it closes (and, at most
every :data:`SAVE_EVERY_S` of the rig's clock, at an all-off, so a killed command leaves most of
its lightings behind).

Where it lives: ``$RTI_RIG_DUTY_LEDGER_DIR`` if set (the tests' own folder), else
``$XDG_STATE_HOME/rti-rig/dome-duty``, else ``~/.local/state/rti-rig/dome-duty``: a per-user
*state* folder (XDG: data that should persist between restarts of an application, but is not
worth backing up), not the runtime folder the emulated servos use, since LEDs stay warm across
a log-out but a stale ledger costs at most one duty window of waiting.

What is "the same dome": a hardware dome is keyed by its USB adapter's ``/dev/serial/by-id/``
name, whichever path the config gives (the by-id link, a ``by-path`` link, the ``/dev/ttyACM0``
they point to), else by its port's real path; not by the config file nor the protocol profile:
two configs for one dome (a copy with another camera, a profile tried) drive the same LEDs, and
a key that told them apart would protect nothing. Why not the real path alone: ``ttyACM0`` is
the kernel's enumeration order, not the dome; a dome that drops off USB while a command still
holds its old node comes back as ``ttyACM1``, and the next command, keyed ``ttyACM1``, had found
no ledger and lit the LEDs the last one left hot at once. A different board later plugged into
the same port (no by-id name) meets the first one's ledger: at most one duty window of waiting,
the safe side.
An emulated dome has a new pseudo-terminal each command, so it is keyed by its config's real
path (as the emulated servos' latched errors are): a rehearsal of "check right after run".

Failures are never a refusal: a ledger that cannot be read or written is one line (a
``RuntimeWarning``, said by the console as a note), and the command goes on with the LEDs it
knows. A write goes to a temporary file then ``os.replace``, so a crash mid-write leaves the
previous ledger whole. Times ahead of the clock now (a clock set back, or an emulated dome's
run on a simulated clock, whose rig time outruns the wall clock) are shifted back so that the
latest lighting ends now: the LEDs are taken as just switched off, never as long cold.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import math
import os
import re
import time
import warnings
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

from rti_rig.core.shell_words import shown_path
from rti_rig.core.state_files import replace_text

#: Overrides where the ledgers are kept (a test's own folder, say).
LEDGER_DIR_ENV = "RTI_RIG_DUTY_LEDGER_DIR"

#: At most this often (rig-clock seconds) an all-off writes the ledger mid-command.
SAVE_EVERY_S = 10.0

#: The system's stable names of USB serial adapters (udev), one link per adapter.
BY_ID_DIR = Path("/dev/serial/by-id")

#: A ledger file (or a write's stray temporary file) left untouched this long is removed when a
#: command first writes another ledger of the folder: no config's ``duty_window_s`` reaches
#: back that far (it is at most a day), so it can hold no lighting that still counts. Why: a
#: dome never driven again (a temporary copy of a config, an emulated rehearsal) left its file
#: for ever.
STALE_AFTER_S = 2 * 86400.0

#: Ledger times ahead of the wall clock by up to this are clock noise, not a clock set back.
_FUTURE_SLACK_S = 1.0

_FORMAT = 1

_UNKNOWN_EARLIER = ": which LEDs an earlier command lit is not known to this one"
_ELSEWHERE = f"; set {LEDGER_DIR_ENV} to a writable folder of your own to keep it there"

Spans = dict[int, list[tuple[float, float]]]


def ledger_dir() -> Path:
    """The per-user folder of the dome duty ledgers (see the module docstring)."""
    given = os.environ.get(LEDGER_DIR_ENV)
    if given:
        return Path(given)
    state = os.environ.get("XDG_STATE_HOME")
    if state and Path(state).is_absolute():
        return Path(state) / "rti-rig" / "dome-duty"
    return Path.home() / ".local" / "state" / "rti-rig" / "dome-duty"


@dataclass(frozen=True)
class LedgerRead:
    """What an earlier command left: each LED's lightings (wall-clock seconds), and whether
    its times were shifted back to end now (they lay ahead of the clock)."""

    spans: Spans
    shifted_s: float = 0.0


class DutyLedger:
    """The ledger file of one physical dome (see the module docstring for the key)."""

    def __init__(self, key: str, *, wall: Callable[[], float] = time.time) -> None:
        self.key = key
        self.wall = wall
        # surrogateescape: a config in a folder whose name is not UTF-8 (its path holds
        # '\udce9') had ended every command on its emulated dome with a UnicodeEncodeError
        digest = hashlib.sha256(key.encode("utf-8", "surrogateescape")).hexdigest()[:16]
        stem = re.sub(r"[^A-Za-z0-9_.-]+", "_", Path(key.split(":", 1)[-1]).name)[:40] or "dome"
        self.path = ledger_dir() / f"{stem}-{digest}.json"
        #: The folder was swept of stale ledgers by this object's first write: once a command
        #: is enough (a session writes every :data:`SAVE_EVERY_S` at an all-off, and each
        #: write had listed and stat'ed the whole folder again on that path).
        self._swept = False

    @classmethod
    def for_port(cls, port: str) -> DutyLedger:
        """A hardware dome's ledger: its adapter's by-id name (:func:`stable_port_name`); a
        port that is no file path (``COM3``, ``socket://host:port``) as given."""
        return cls("port:" + (stable_port_name(port) if os.path.isabs(port) else port))

    @classmethod
    def for_emulated(cls, config_path: Path) -> DutyLedger:
        """An emulated dome's ledger: its config's real path (its pty is new each command)."""
        return cls("emulated:" + str(Path(config_path).resolve()))

    def load(self, window_s: float) -> LedgerRead:
        """The lightings that ended within ``window_s`` of now; none if there is no ledger.

        Unreadable or damaged: none, and a warning saying so (the command goes on)."""
        now = self.wall()
        try:
            data = self.path.read_bytes()
        except (FileNotFoundError, NotADirectoryError):
            return LedgerRead({})  # none yet (a folder that cannot be made is said at the write)
        except OSError as exc:
            self._warn(f"could not be read ({exc})", _UNKNOWN_EARLIER + _ELSEWHERE)
            return LedgerRead({})
        try:
            spans = _parse(json.loads(data.decode("utf-8")))
        except (ValueError, KeyError, TypeError, AttributeError, RecursionError) as exc:
            self._warn(
                f"is damaged ({exc})",
                _UNKNOWN_EARLIER + "; it is written afresh when this command ends",
            )
            return LedgerRead({})
        latest = max((e for s in spans.values() for _, e in s), default=None)
        shifted = 0.0
        if latest is not None and latest > now + _FUTURE_SLACK_S:
            # a clock set back, or rig time on a simulated clock: the LEDs are taken as just
            # switched off (their spacing kept), never as cold for as long as the clocks differ
            shifted = latest - now
            spans = {i: [(s - shifted, e - shifted) for s, e in v] for i, v in spans.items()}
        horizon = now - window_s
        kept = {i: [(s, e) for s, e in v if e > horizon] for i, v in spans.items()}
        return LedgerRead({i: v for i, v in kept.items() if v}, shifted)

    def save(
        self, spans: Mapping[int, Sequence[tuple[float, float]]], now: float, window_s: float
    ) -> None:
        """Write the lightings that ended within ``window_s`` before ``now`` (wall-clock
        seconds, atomically); older ones are dropped, and no lighting left removes the file.
        A warning, never an error, if it cannot be written."""
        horizon = now - window_s
        kept: dict[str, list[list[float]]] = {}
        for index, lightings in sorted(spans.items()):
            # to the millisecond, outwards: a lighting is never written shorter than it was
            recent = [
                [math.floor(s * 1000) / 1000, math.ceil(e * 1000) / 1000]
                for s, e in lightings
                if e > horizon
            ]
            if recent:
                kept[str(index)] = recent
        try:
            self._write(kept)
        except OSError as exc:
            self._warn(
                f"could not be written ({exc})",
                ": the next command on this dome will not know which LEDs this one lit"
                + _ELSEWHERE,
            )

    def _write(self, kept: dict[str, list[list[float]]]) -> None:
        if not kept:
            with contextlib.suppress(FileNotFoundError):
                self.path.unlink()
            return
        body = json.dumps(
            {
                "format": _FORMAT,
                "dome": self.key,
                "written_at": round(self.wall(), 3),
                "note": "LED lightings (wall-clock start, end) of the last duty window, so that "
                "the next rti-rig command respects [dome.serial.thermal]; safe to delete",
                "lit": kept,
            },
            separators=(",", ":"),
        )
        replace_text(self.path, body)
        if not self._swept:
            self._swept = True
            # (by the file system's own clock: its times are not the ledger's, which a test
            # may move)
            _remove_stale(self.path.parent, keep=self.path, before=time.time() - STALE_AFTER_S)

    def _warn(self, what: str, advice: str) -> None:
        """One line, said by the console as a note: the command goes on."""
        warnings.warn(
            f"the dome's duty ledger {shown_path(self.path)} {what}{advice}",
            RuntimeWarning,
            stacklevel=3,
        )


def _remove_stale(folder: Path, *, keep: Path, before: float) -> None:
    """Remove the folder's ledgers and stray temporary files last written before ``before``
    (see :data:`STALE_AFTER_S`); one that cannot be removed is left, unsaid."""
    with contextlib.suppress(OSError):
        for entry in os.scandir(folder):
            if entry.path == str(keep) or not entry.name.endswith((".json", ".tmp")):
                continue
            with contextlib.suppress(OSError):
                if entry.is_file(follow_symlinks=False) and entry.stat().st_mtime < before:
                    os.unlink(entry.path)


def stable_port_name(port: str) -> str:
    """The ``/dev/serial/by-id/`` link that points where ``port`` does (the first by name if
    several do), else ``port``'s real path; a by-id link whose device is unplugged is its
    own name, as it is once the device is back (see the module docstring for why)."""
    given = Path(port)
    if given.parent == BY_ID_DIR:
        return str(given)  # the stable name itself, whether its device is there now or not
    real = os.path.realpath(port)
    try:
        links = sorted(BY_ID_DIR.iterdir())
    except OSError:  # no USB serial adapter plugged in (or not Linux)
        return real
    for link in links:
        if os.path.realpath(link) == real:
            return str(link)
    return real


def _parse(raw: object) -> Spans:
    """The ``lit`` table of a ledger, checked: LED index -> [(start, end)], finite, ordered."""
    if not isinstance(raw, dict) or raw.get("format") != _FORMAT:
        raise ValueError("not a duty ledger of this version")
    out: Spans = {}
    for key, spans in raw["lit"].items():
        index = int(key)
        if index < 0:
            raise ValueError(f"LED {index}")
        pairs = [(float(s), float(e)) for s, e in spans]
        for s, e in pairs:
            if not (s == s and e == e and abs(s) < 1e12 and abs(e) < 1e12 and s <= e):
                raise ValueError(f"LED {index}: lighting ({s}, {e})")
        out[index] = pairs
    return out
