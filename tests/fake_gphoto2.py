"""A stand-in for python-gphoto2's camera API, with a camera body behind it.

Modelled on the documented python-gphoto2 2.x API and libgphoto2's behaviour (not on our
driver): ``gp.Camera.autodetect()`` → [(model, port)], ``Camera().init()/exit()``,
``get_config()``/``set_config()`` with widgets (``get_child_by_name``, ``get_value``,
``set_value``, ``count_choices``, ``get_choice``), ``capture(GP_CAPTURE_IMAGE)`` → a path with
``.folder``/``.name``, ``wait_for_event(ms)`` → (event type, data), ``file_get(folder, name,
GP_FILE_TYPE_NORMAL)`` → a CameraFile with ``save(path)``, ``file_delete``; errors are
``GPhoto2Error`` with ``.code`` (libgphoto2's result codes: -7 I/O, -52 USB device not found,
-105 unknown model, -110 busy, -115 no space left).

Quirks of real bodies it reproduces (from gphoto/libgphoto2 issue threads, see
/work/shared/reference/hardware-notes.md §5): "busy" right after a shot (for a number of tries,
or for a time as a body writing to a slow card is: it takes no picture meanwhile; or, pibooth
#466, busy yet the picture taken, its file announced by event at once, at the next shot or
never: ``folder_list_files`` then shows it on the card), a body switched off or unplugged
(every call then fails with -7 and autodetect finds nothing), a card that fills up, the
computer's disk filling at a download (:func:`save_as_libgphoto2`: libgphoto2's own source), a file
counter that wraps (IMG_9999 → IMG_0001) or a RAM target that names every shot the same
(Nikon's ``capt0000.nef``), RAW+JPEG delivered as two files, the second through a FILE_ADDED
event (some bodies also announce the first one, and end with CAPTURE_COMPLETE), several bodies
on the bus, and a setting that does not latch (the mode dial not on M).
"""

from __future__ import annotations

import os
import types
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

GP_CAPTURE_IMAGE = 0
GP_FILE_TYPE_NORMAL = 1
GP_EVENT_UNKNOWN, GP_EVENT_TIMEOUT, GP_EVENT_FILE_ADDED = 0, 1, 2
GP_EVENT_CAPTURE_COMPLETE = 4
SHUTTERS = ["bulb", "30", "2", "1", "0.5", "1/4", "1/8", "1/15", "1/30", "1/60", "1/125", "1/250"]


class GPhoto2Error(Exception):
    def __init__(self, code: int) -> None:
        super().__init__(f"[{code}] libgphoto2 error")
        self.code = code


@dataclass
class Body:
    """The physical camera: ``render(body)`` gives the RAW file's bytes for the current shot."""

    #: the RAW file's bytes for the current shot; it may read ``body.config`` (shutter, ISO)
    render: Callable[[Body], bytes]
    model: str = "Canon EOS 600D"
    port: str = "usb:001,005"
    raw_suffix: str = ".CR2"
    #: "counter" (IMG_0001.CR2 and .JPG), "repeat" (every shot capt0000.*), or "object" (one
    #: number per object, capt0000.jpg then capt0001.cr2, as libgphoto2's ptp2 names the
    #: objects of a capture kept in the camera's RAM: its Nikon capture counts ``capcnt++``)
    naming: str = "counter"
    counter_start: int = 1
    counter_wrap: int = 9999
    config: dict[str, str] = field(
        default_factory=lambda: {
            "capturetarget": "Memory card",
            "imageformat": "Large Fine JPEG",
            "iso": "Auto",
            "aperture": "5.6",
            "shutterspeed": "1/60",
        }
    )
    choices: dict[str, list[str]] = field(
        default_factory=lambda: {
            "capturetarget": ["Internal RAM", "Memory card"],
            "imageformat": ["Large Fine JPEG", "RAW", "RAW + Large Fine JPEG"],
            "iso": ["Auto", "100", "200", "400"],
            "aperture": ["5.6", "8", "11"],
            "shutterspeed": SHUTTERS,
        }
    )
    #: what a format gives, as (RAW, JPEG), for a name that does not say it ("Unknown value
    #: 0007", libgphoto2's name for a code its table lacks); others by the name (RAW, JPEG)
    format_gives: dict[str, tuple[bool, bool]] = field(default_factory=dict)
    #: what autodetect finds, when not just this body: [] for none, or several bodies
    detected: list[tuple[str, str]] | None = None
    #: settings the body accepts but does not change (e.g. the mode dial is not on M)
    read_only: set[str] = field(default_factory=set)
    announce_first: bool = False  # also send FILE_ADDED for the file capture() returned
    capture_complete_event: bool = False  # end a shot's events with CAPTURE_COMPLETE
    #: op name → error codes raised by its next calls, in order
    failures: dict[str, list[int]] = field(default_factory=dict)
    busy_after_shot: int = 0  # the next N captures after a shot answer -110 first
    #: of those busy answers, the next N took the picture all the same (the shutter fired, the
    #: file is written and announced by a FILE_ADDED event, yet capture answered -110), as
    #: bodies do whose release times out while the shot goes on (pibooth #466)
    busy_yet_shot: int = 0
    #: such a picture is announced only once the next shot is taken (a body still writing it)
    stray_announced_late: bool = False
    #: such a picture is never announced at all (no FILE_ADDED event, ever): on a card it is
    #: only seen by listing the folder; in the camera's RAM it is lost
    stray_never_announced: bool = False
    #: the camera file names of the pictures taken behind a busy answer
    stray_files: list[str] = field(default_factory=list)
    #: a slow card: every capture answers -110 (and takes no picture) until ``busy_for_s`` of
    #: ``busy_clock`` time have passed since the last shot (PTP Device Busy, gphoto2 #308)
    busy_for_s: float = 0.0
    busy_clock: Any = None
    #: a capture answers busy only after this much ``busy_clock`` time (a Canon body whose
    #: autofocus fails: "-- long pause --", then PTP Device Busy; libgphoto2 #30, pibooth #246)
    busy_takes_s: float = 0.0
    #: the body's own time: a capture that fires takes its shutter time on it, as libgphoto2's
    #: capture returns only once the picture is taken (None: at once, for tests of other things)
    clock: Any = None
    #: each download takes this much ``download_clock`` time (a 24 MP RAW over USB 2: 2-3 s)
    download_s: float = 0.0
    download_clock: Any = None
    card_free_shots: int = 1000
    #: listing a folder takes this much ``list_clock`` time per file: a Nikon-type body, whose
    #: libgphoto2 driver fetches each file's info to list it (gphoto2 issue #204: some 6
    #: minutes for 2,700 files, 0.13 s a file)
    list_s_per_file: float = 0.0
    list_clock: Any = None
    #: the card folder the body saves in, ``DCIM/<n>CANON``: a DCF body opens the next one
    #: when its file number passes 9999 (DCF, JEITA CP-3461: file numbers 0001-9999 in
    #: folders 100-999; Canon's manuals: "when the file number reaches 9999 a new folder is
    #: created"), with ``folder_rollover``; the files of the folders before it stay there
    card_folder: int = 100
    folder_rollover: bool = False
    #: the last file number the body used before the session (its counter, kept across cards)
    last_file_number: int | None = None
    older_folders: dict[str, dict[str, bytes]] = field(default_factory=dict)
    jpeg_first: bool = False  # RAW+JPEG: capture() returns the JPEG, the RAW comes by event
    #: RAW+JPEG: the second file is announced only after this many quiet event waits (a body
    #: still writing its JPEG); a shot taken before then finds the announcement pending
    second_file_quiet_waits: int = 0
    #: a body that reports a property change (GP_EVENT_UNKNOWN "PTP Property d105 changed")
    #: every ``chatter_s`` of ``chatter_clock`` time whenever it has nothing else to say, as
    #: Canon bodies do (python-gphoto2 #50); at most ``chatter_limit`` times, so that a driver
    #: that never stops listening fails a test instead of hanging it
    chatter_s: float = 0.0
    chatter_clock: Any = None
    chatter_limit: int = 10_000
    #: the computer's disk takes this many more downloads whole, then only ``disk_free_bytes``
    #: more bytes (None: never full). Where those run out decides what ``CameraFile.save``
    #: does (see :func:`save_as_libgphoto2`): within what ``fwrite`` hands to the kernel, the
    #: save raises -1 and the file is removed; within the last block stdio still buffers at
    #: ``fclose``, it returns as if all went well and leaves a truncated file
    disk_free_saves: int | None = None
    disk_free_bytes: int = 0
    #: where the body writes its pictures whatever ``capturetarget`` reads back: "card" or
    #: "ram" (None: as the setting says). Assumed, not from a cited source: a body with no
    #: card in it keeps its captures in RAM, one that ignores the setting writes to its card
    stores_in: str | None = None
    powered: bool = True
    off_at_shot: int | None = None  # switched off when asked for this shot (1-based)
    #: unplugged as the n-th (1-based) call of an op begins, as (op, n): ("file_get", 3) at
    #: the third download, ("wait_for_event", 1) as the first shot's files are announced
    off_at_call: tuple[str, int] | None = None
    op_counts: dict[str, int] = field(default_factory=dict)
    shots: int = 0
    card: dict[str, bytes] = field(default_factory=dict)
    ram: dict[str, bytes] = field(default_factory=dict)
    deleted: list[str] = field(default_factory=list)
    calls: list[str] = field(default_factory=list)
    _events: list[tuple[int, object]] = field(default_factory=list)
    _late: list[list] = field(default_factory=list)  # type: ignore[type-arg]
    _busy: int = 0
    _busy_until: float = float("-inf")
    _counter: int = 0
    _objects: int = 0

    def still_writing(self, tries: int) -> None:
        """The body is still writing a picture taken before the session (the owner's last
        test shot): its next ``tries`` captures answer busy, as after a shot."""
        self._busy = tries

    def switch_off(self) -> None:
        """Switched off or unplugged: every call fails, nothing is detected."""
        self.powered = False

    def switch_on(self) -> None:
        self.powered = True

    def check(self, op: str) -> None:
        self.calls.append(op)
        self.op_counts[op] = self.op_counts.get(op, 0) + 1
        if self.off_at_call == (op, self.op_counts[op]):
            self.off_at_call = None
            self.switch_off()
        if not self.powered:
            raise GPhoto2Error(-7 if op != "autodetect" else -52)
        queue = self.failures.get(op)
        if queue:
            raise GPhoto2Error(queue.pop(0))

    def next_stem(self) -> str:
        if self.naming == "repeat":
            return "capt0000"
        n = (self.counter_start - 1 + self._counter) % self.counter_wrap + 1
        self._counter += 1
        if self.folder_rollover and self.last_file_number is not None:
            if n <= self.last_file_number:  # past 9999: the next folder, its files from 0001
                self.older_folders[self.card_dir()] = self.card
                self.card, self.card_folder = {}, self.card_folder + 1
            self.last_file_number = n
        return f"IMG_{n:04d}"

    def card_dir(self) -> str:
        """The card folder the body saves in, as libgphoto2's PTP driver names it."""
        return f"/store_00020001/DCIM/{self.card_folder}CANON"

    def bus(self) -> list[tuple[str, str]]:
        return [(self.model, self.port)] if self.detected is None else list(self.detected)

    def store(self) -> dict[str, bytes]:
        if self.stores_in is not None:
            return self.ram if self.stores_in == "ram" else self.card
        # a body without the setting (not every make has it in libgphoto2) shoots to its card
        return self.ram if self.config.get("capturetarget") == "Internal RAM" else self.card


#: glibc's stdio buffer for a regular file: its ``st_blksize`` (4096 on ext4, xfs, btrfs)
STDIO_BUFSIZ = 4096


def save_as_libgphoto2(data: bytes, target: str, room: int | None) -> None:
    """``gp_file_save`` of a memory CameraFile (what ``camera.file_get`` returns), on a disk
    that takes ``room`` more bytes (None: all of them).

    Source: libgphoto2's ``libgphoto2/gphoto2-file.c`` (gphoto/libgphoto2), ``gp_file_save``,
    GP_FILE_ACCESSTYPE_MEMORY: ``fopen(filename, "wb")``, its failure GP_ERROR (-1) with no
    file made; ``fwrite`` of the whole buffer, and if it writes short: "Not enough space on
    device in order to save '%s'.", ``fclose``, ``unlink(filename)``, GP_ERROR (-1);
    otherwise ``fclose(fp)`` *whose return value is not checked*, the mtime set with
    ``utime`` if the CameraFile has one (not modelled), GP_OK.

    What stdio does underneath (glibc, assumed, not read for this fake): ``fwrite`` of more
    than its buffer writes the whole blocks through to the kernel and keeps the last partial
    block (1 to ``STDIO_BUFSIZ`` bytes) buffered; ``fclose`` flushes that. So a disk that
    fills within the bytes ``fwrite`` wrote through makes it write short (file removed, -1),
    and one that fills within the last buffered block fails only the final flush, which
    ``gp_file_save`` ignores: GP_OK, and a file of ``room`` bytes left behind. A file of no
    more than one block (a small JPEG, a tiny RAW) is all buffered: a full disk can only give
    the truncated file. python-gphoto2 raises a result below 0 as ``GPhoto2Error``."""
    try:
        fh = open(target, "wb")  # noqa: SIM115 - closed below on every path, as libgphoto2 does
    except OSError as exc:  # fopen failed (permissions, no such folder): GP_ERROR, no file
        raise GPhoto2Error(-1) from exc
    size = len(data)
    buffered = (size - 1) % STDIO_BUFSIZ + 1 if size else 0  # the last block, flushed at fclose
    if room is None or room >= size:
        fh.write(data)
        fh.close()
        return
    if room < size - buffered:  # fwrite writes short
        fh.write(data[:room])
        fh.close()
        os.unlink(target)
        raise GPhoto2Error(-1)
    fh.write(data[:room])  # fwrite "wrote" it all; fclose's flush fails, its result ignored
    fh.close()


def shutter_s(label: str) -> float:
    """Seconds of a shutter label of ``SHUTTERS`` ('1/125', '0.5', '30'; 'bulb': 0)."""
    if label == "bulb":
        return 0.0
    num, _, den = label.partition("/")
    return float(num) / float(den or 1)


class _Widget:
    def __init__(self, values: dict[str, str], choices: list[str]) -> None:
        self._values, self._choices = values, choices
        self.name = ""

    def get_value(self) -> str:
        return self._values[self.name]

    def set_value(self, v: str) -> None:
        self._values[self.name] = v

    def count_choices(self) -> int:
        return len(self._choices)

    def get_choice(self, i: int) -> str:
        return self._choices[i]


def make_module(body: Body) -> types.ModuleType:
    """A module object that can stand in for ``gphoto2`` (``sys.modules["gphoto2"]``)."""
    mod = types.ModuleType("gphoto2")

    class Config:
        def __init__(self) -> None:
            self.values = dict(body.config)

        def get_child_by_name(self, name: str) -> _Widget:
            if name not in self.values:
                raise GPhoto2Error(-2)
            w = _Widget(self.values, body.choices.get(name, []))
            w.name = name
            return w

    class CameraFilePath:
        def __init__(self, folder: str, name: str) -> None:
            self.folder, self.name = folder, name

    class CameraFile:
        def __init__(self, data: bytes) -> None:
            self._data = data

        def save(self, target: str) -> None:
            room: int | None = None  # bytes the disk still takes (None: the whole file)
            if body.disk_free_saves is not None:
                if body.disk_free_saves <= 0:
                    room = body.disk_free_bytes
                body.disk_free_saves -= 1
            save_as_libgphoto2(self._data, target, room)

        def get_data_and_size(self) -> bytes:
            """python-gphoto2's ``gp_file_get_data_and_size``: the file's bytes in memory."""
            return self._data

    def take_picture(announce_all: bool = False) -> CameraFilePath:
        """The shutter fires: the files are written and announced (``announce_all``: all
        of them by event, for a picture whose capture answered busy)."""
        stem = body.next_stem()  # first: it may open the card's next folder
        store = body.store()
        fmt = body.config["imageformat"]
        files = []
        raw, jpeg = body.format_gives.get(fmt, ("RAW" in fmt, "JPEG" in fmt))
        if raw:
            files.append(stem + body.raw_suffix)
        if jpeg:
            files.append(stem + ".JPG")
        if body.clock is not None:  # the shutter is open for its time, then the file named
            body.clock.sleep(shutter_s(body.config["shutterspeed"]))
        raw_data = body.render(body)
        if body.jpeg_first:
            files.sort(key=lambda n: not n.endswith(".JPG"))
        if body.naming == "object":  # libgphoto2's RAM names: one number per object, in order
            files = [
                f"capt{body._objects + i:04d}{n[n.rindex('.') :]}" for i, n in enumerate(files)
            ]
            body._objects += len(files)
        for name in files:
            store[name] = raw_data if not name.endswith(".JPG") else b"\xff\xd8\xff\xd9"
        if store is body.card:
            body.card_free_shots -= 1
        body.shots += 1
        body._busy = body.busy_after_shot
        if body.busy_for_s:
            body._busy_until = body.busy_clock.now() + body.busy_for_s
        folder = body.card_dir() if store is body.card else "/"
        for name in files if body.announce_first or announce_all else files[1:]:
            event = (GP_EVENT_FILE_ADDED, CameraFilePath(folder, name))
            if name != files[0] and body.second_file_quiet_waits:
                body._late.append([body.second_file_quiet_waits, event])
            else:
                body._events.append(event)
        if body.capture_complete_event:
            body._events.append((GP_EVENT_CAPTURE_COMPLETE, None))
        return CameraFilePath(folder, files[0])

    class Camera:
        @staticmethod
        def autodetect() -> list[tuple[str, str]]:
            body.check("autodetect")
            return body.bus()

        def init(self) -> None:
            body.check("init")
            if not body.bus():
                raise GPhoto2Error(-105)

        def exit(self) -> None:
            body.calls.append("exit")

        def get_config(self) -> Config:
            body.check("get_config")
            return Config()

        def set_config(self, config: Config) -> None:
            body.check("set_config")
            for k, v in config.values.items():
                if body.choices.get(k) and v not in body.choices[k]:
                    raise GPhoto2Error(-2)
                if k not in body.read_only:
                    body.config[k] = v

        def capture(self, kind: int) -> CameraFilePath:
            if body.off_at_shot is not None and body.shots + 1 == body.off_at_shot:
                body.off_at_shot = None
                body.switch_off()
            try:
                body.check("capture")
                if body._busy:
                    body._busy -= 1
                    if body.busy_yet_shot:
                        body.busy_yet_shot -= 1
                        still_busy = body._busy
                        stray = take_picture(announce_all=True)
                        body._busy = still_busy  # it goes on answering busy as it was
                        body.stray_files.append(stray.name)
                        if body.stray_never_announced:
                            body._events[:] = [e for e in body._events if e[1] is None]
                        elif body.stray_announced_late:  # held back until the next shot
                            held = [e for e in body._events if e[1] is not None]
                            body._events[:] = [e for e in body._events if e not in held]
                            body._late.extend([10**9, e] for e in held)
                    raise GPhoto2Error(-110)
                if body.busy_for_s and body.busy_clock.now() < body._busy_until:
                    raise GPhoto2Error(-110)
            except GPhoto2Error as exc:
                if exc.code == -110 and body.busy_takes_s:
                    body.busy_clock.sleep(body.busy_takes_s)
                raise
            # the files a previous shot was still writing are announced by now
            body._events.extend(event for _, event in body._late)
            body._late.clear()
            store = body.store()
            if store is body.card and body.card_free_shots <= 0:
                raise GPhoto2Error(-115)
            return take_picture()

        def wait_for_event(self, timeout_ms: int) -> tuple[int, object]:
            body.check("wait_for_event")
            if body._events:
                return body._events.pop(0)
            if body._late:
                body._late[0][0] -= 1
                if body._late[0][0] < 0:
                    return body._late.pop(0)[1]
            if body.chatter_s:
                body.chatter_limit -= 1
                if body.chatter_limit < 0:
                    raise AssertionError("the driver never stopped waiting for events")
                body.chatter_clock.sleep(body.chatter_s)
                return GP_EVENT_UNKNOWN, "PTP Property d105 changed"
            return GP_EVENT_TIMEOUT, None

        def file_get(self, folder: str, name: str, kind: int) -> CameraFile:
            body.check("file_get")
            if body.download_s:
                body.download_clock.sleep(body.download_s)
            store = body.store()
            if name not in store:
                raise GPhoto2Error(-108)
            return CameraFile(store[name])

        def folder_list_files(self, folder: str) -> list[tuple[str, None]]:
            """python-gphoto2's CameraList of (name, value) pairs: the files in ``folder``."""
            body.check("folder_list_files")
            folder = folder.rstrip("/") or "/"
            store = body.older_folders.get(folder, {})
            store = body.card if folder == body.card_dir() else store
            store = body.ram if folder == "/" else store
            if body.list_s_per_file:
                body.list_clock.sleep(len(store) * body.list_s_per_file)
            return [(name, None) for name in sorted(store)]

        def folder_list_folders(self, folder: str) -> list[tuple[str, None]]:
            """python-gphoto2's CameraList of (name, value) pairs: the folders in ``folder``;
            as libgphoto2's PTP driver shows a card, its storage at the top, then DCIM."""
            body.check("folder_list_folders")
            dcim = [f.rsplit("/", 1)[1] for f in [*body.older_folders, body.card_dir()]]
            tree = {"": ["store_00020001"], "/store_00020001": ["DCIM"]}
            tree["/store_00020001/DCIM"] = dcim
            return [(sub, None) for sub in tree.get(folder.rstrip("/"), [])]

        def file_delete(self, folder: str, name: str) -> None:
            body.check("file_delete")
            store = body.store()
            if store is body.ram:
                store.pop(name, None)  # RAM files vanish once downloaded
                raise GPhoto2Error(-108)
            if name not in store:
                raise GPhoto2Error(-108)
            del store[name]
            body.deleted.append(name)
            body.card_free_shots += 1

        def set_port_info(self, info: object) -> None:
            body.calls.append(f"set_port_info {info}")

        def set_abilities(self, abilities: object) -> None:
            body.calls.append(f"set_abilities {abilities}")

    class PortInfoList(list):  # type: ignore[type-arg]
        def load(self) -> None:
            self.extend(port for _, port in body.bus())

        def lookup_path(self, path: str) -> int:
            return self.index(path)

    class CameraAbilitiesList(list):  # type: ignore[type-arg]
        def load(self) -> None:
            self.extend(model for model, _ in body.bus())

        def lookup_model(self, model: str) -> int:
            return self.index(model)

    for name, value in {
        "GPhoto2Error": GPhoto2Error,
        "Camera": Camera,
        "CameraFile": CameraFile,
        "CameraFilePath": CameraFilePath,
        "PortInfoList": PortInfoList,
        "CameraAbilitiesList": CameraAbilitiesList,
        "GP_CAPTURE_IMAGE": GP_CAPTURE_IMAGE,
        "GP_FILE_TYPE_NORMAL": GP_FILE_TYPE_NORMAL,
        "GP_EVENT_UNKNOWN": GP_EVENT_UNKNOWN,
        "GP_EVENT_TIMEOUT": GP_EVENT_TIMEOUT,
        "GP_EVENT_FILE_ADDED": GP_EVENT_FILE_ADDED,
        "GP_EVENT_CAPTURE_COMPLETE": GP_EVENT_CAPTURE_COMPLETE,
    }.items():
        setattr(mod, name, value)
    return mod
