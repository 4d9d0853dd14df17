"""Which process, on which host, holds a batch attempt's folders: the record an attempt leaves
beside them, and the judgement of whether that process is gone.

Why: a killed batch's partial folder is removed by the next run once the process that made it
no longer runs. That process had been told by the PID in the folder's name alone, asked of
*this* host; on a shared ``--out`` (a lab NAS, where a Dask cluster's workers on several hosts
fit into one folder) another host's running fit has a PID that means nothing here, and its
folder was removed under it. An attempt now records, before its folders exist, the host it runs
on (its name, its machine id, its boot id), its PID namespace, its PID and the process's start
time, in ``.OUTPUT.ATTEMPT.owner`` beside them (a file: the partial folder must begin empty,
and a refit's set-aside ``.earlier`` folder is the same attempt's). A folder is removed only
when that host is established to be this one (the same machine id, or the same boot id: a host
name alone may be two hosts') and the process is gone (or its PID now names another process).
"""

from __future__ import annotations

import json
import os
import socket
from contextlib import suppress
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from rti_rig.app.usecases.fit_attempts import AttemptFolder
from rti_rig.core.shell_words import shown_path

#: The suffix of an attempt's owner record, after ``.OUTPUT.ATTEMPT``.
OWNER_SUFFIX = "owner"


def owner_record_path(attempt: AttemptFolder, root: Path) -> Path:
    """The owner record of ``attempt`` in batch folder ``root`` (one per attempt, whatever
    folders it has)."""
    return root / f".{attempt.output}.{attempt.attempt}.{OWNER_SUFFIX}"


def _read(path: str) -> str | None:
    try:
        return Path(path).read_text(encoding="ascii").strip() or None
    except (OSError, UnicodeDecodeError):  # not Linux, or hidden from this process
        return None


def _start_time(pid: int) -> str | None:
    """When process ``pid`` started, in clock ticks since boot (``/proc/PID/stat`` field 22),
    or None where it cannot be read: a PID reused by a later process has another."""
    stat = _read(f"/proc/{pid}/stat")
    if stat is None:
        return None
    fields = stat.rpartition(")")[2].split()  # the name in parentheses may hold spaces
    return fields[19] if len(fields) > 19 else None


def _pid_namespace() -> str | None:
    try:
        return os.readlink("/proc/self/ns/pid")
    except OSError:
        return None


def this_process() -> dict[str, Any]:
    """The owner record of this process."""
    return {
        "host": socket.gethostname(),
        "machine_id": _read("/etc/machine-id"),
        "boot_id": _read("/proc/sys/kernel/random/boot_id"),
        "pid_namespace": _pid_namespace(),
        "pid": os.getpid(),
        "started": _start_time(os.getpid()),
    }


def write_owner_record(attempt: AttemptFolder, root: Path) -> Path:
    """Record this process as ``attempt``'s owner, before any of its folders is made (whoever
    finds one of them finds the record too). Written whole and renamed into place."""
    path = owner_record_path(attempt, root)
    tmp = path.with_name(f"{path.name}.tmp")
    try:
        tmp.write_text(json.dumps(this_process()), encoding="utf-8")
        tmp.replace(path)
    except OSError:  # a full disk: nothing half-written is left beside the batch's folders
        with suppress(OSError):
            tmp.unlink()
        raise
    return path


def remove_owner_record(attempt: AttemptFolder, root: Path) -> None:
    """Remove ``attempt``'s record (its folders gone); one already gone is no error."""
    with suppress(OSError):
        owner_record_path(attempt, root).unlink()


@dataclass(frozen=True)
class Owner:
    """What is known of the process that made an attempt's folders."""

    #: it no longer runs (or never recorded one): its folders may be removed
    gone: bool
    #: the host it runs on when that is another host (or this one's other PID namespace, or a
    #: record that cannot be read): the words a batch says of the folder it leaves, else ""
    elsewhere: str = ""
    #: its folder names a PID but no host: an older rti-rig's, taken as this host's
    unrecorded: bool = False
    pid: int | None = None


def owner_of(folder: Path, *, mine_too: bool = False) -> Owner:
    """Whether the process that made attempt folder ``folder`` is gone (``mine_too``: this
    process's own attempts count as gone, for a batch that begins and fits nothing yet).

    A folder naming no PID (``.OUTPUT.partial``, the oldest runs') counts as gone. A folder
    naming a PID without an owner record was made by an rti-rig from before the record: it is
    taken as this host's, as that rti-rig did (a careful user upgrades the hosts sharing one
    ``--out`` together; keeping such folders for ever would leave every killed run's behind),
    and the batch says so when it removes one."""
    attempt = AttemptFolder.parse(folder.name)
    pid = None if attempt is None else attempt.pid
    if attempt is None or pid is None:
        return Owner(gone=True)
    path = owner_record_path(attempt, folder.parent)
    try:
        record = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        return Owner(gone=_gone_here(pid, None, mine_too), unrecorded=True, pid=pid)
    except (OSError, ValueError):
        return Owner(
            gone=False, elsewhere=f"an unknown host (its record {shown_path(path)} is unreadable)"
        )
    if not isinstance(record, dict):
        return Owner(
            gone=False, elsewhere=f"an unknown host (its record {shown_path(path)} is unreadable)"
        )
    here = this_process()
    host = str(record.get("host"))
    pid = record.get("pid") if isinstance(record.get("pid"), int) else pid

    def known(key: str) -> bool:  # recorded there and read here
        return None not in (record.get(key), here[key])

    def differs(key: str) -> bool:  # known on both sides, and not the same
        return known(key) and record.get(key) != here[key]

    def same(key: str) -> bool:  # known on both sides, and the same
        return known(key) and record.get(key) == here[key]

    if host != here["host"] or differs("machine_id"):
        return Owner(gone=False, elsewhere=f"host {host}", pid=pid)
    # This very machine only when established: the same machine id, or the same boot id (one
    # running kernel). A host name alone is not: two hosts lacking /etc/machine-id may share
    # one, and the other's boot id, unlike this one's, had been read as this host restarted
    # since, and its running fit's folder removed. In doubt the folder is left, and said.
    if not (same("machine_id") or same("boot_id")):
        return Owner(gone=False, elsewhere=_UNTOLD.format(host=host), pid=pid)
    if differs("boot_id"):  # this host, restarted since: every process of then is gone
        return Owner(gone=True, pid=pid)
    if differs("pid_namespace"):  # a container sharing this host's name: its PIDs are its own
        return Owner(gone=False, elsewhere=f"host {host} (another PID namespace)", pid=pid)
    started = record.get("started")
    return Owner(gone=_gone_here(pid, started, mine_too), pid=pid)


#: Where a fit runs whose record names this host's name but cannot be told to be this machine.
_UNTOLD = (
    "host {host}, or on this host before a restart (its record and this host share neither "
    "a machine id nor a boot id: which of the two cannot be told)"
)


def _gone_here(pid: int, started: Any, mine_too: bool) -> bool:
    """Whether process ``pid`` of this host no longer runs, or its PID now names another
    process (``started``, its start time when recorded, is not the running one's)."""
    if pid == os.getpid():
        return mine_too
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return True
    except OSError:  # PermissionError: it runs, as another user
        pass
    if started is not None:
        now = _start_time(pid)
        if now is not None and now != str(started):
            return True  # the PID was reused by a later process
    return False
