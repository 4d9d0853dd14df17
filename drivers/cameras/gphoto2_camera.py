"""DSLR and mirrorless cameras through python-gphoto2, one camera session kept open.

Why one session: each gphoto2 CLI run spends about a second initialising the camera
(libgphoto2 #309), and an RTI session takes 50-100 shots. Why retries: bodies report "busy"
(-110) while still writing the previous file to SDRAM or card; that is transient, anything else
is not. Why the module is injected: python-gphoto2 is an optional dependency (LGPL, bundled
libgphoto2) and tests run against a fake module; ``import gphoto2`` happens in ``connect``.

API used (python-gphoto2 2.x): ``Camera.autodetect()``, ``Camera().init()/exit()``,
``get_config()/set_config()``, widget ``get_child_by_name/get_value/set_value/count_choices/
get_choice``, ``capture(GP_CAPTURE_IMAGE)``, ``wait_for_event(ms)``, ``file_get(...).save()``,
``file_delete``; errors are ``GPhoto2Error`` with ``.code``.

Safe state: no capture in progress, ``exit()`` called on the camera (``close``).
"""

from __future__ import annotations

import contextlib
import errno
import math
import re
import shutil
import tempfile
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, TypeVar

from rti_rig.core.clock import Clock, SystemClock
from rti_rig.core.devices import Frame
from rti_rig.core.errors import CameraBusyError, CaptureError, DeviceError
from rti_rig.core.image_files import is_camera_raw
from rti_rig.core.shell_words import pip_install, pip_upgrade, shown_path
from rti_rig.drivers.cameras.gphoto2_formats import gives_raw, raw_choices
from rti_rig.drivers.cameras.raw_decode import (
    RawDecodeError,
    RawFileMissingError,
    UnsupportedRawError,
    decode_raw,
    libraw_named,
)
from rti_rig.drivers.cameras.resume_words import resume_command
from rti_rig.drivers.cameras.settings import Gphoto2CameraSettings

#: libgphoto2's name for an object of a capture kept in the camera's RAM when the body gives
#: none (``capt0000.jpg``, ``capt0001.nef``): numbered per object, so a shot's RAW and JPEG do
#: not share a stem there, as a card's files (``IMG_0003.CR2``, ``IMG_0003.JPG``) do.
_RAM_CAPTURE_NAME = re.compile(r"capt(\d+)", re.IGNORECASE)

T = TypeVar("T")

GP_ERROR_HINTS = {
    -7: "USB I/O error: check the cable and the camera's power saving",
    -52: "USB device not found: is the camera on and connected?",
    -53: "the USB device is claimed by another program (on desktops gvfs-gphoto2-volume-monitor "
    "or a file manager mounted it): stop that program or unmount the camera",
    -105: "no camera model detected: is it on, connected, and in PC/PTP mode?",
    -110: "camera busy: still writing the previous file to its card, or its autofocus could not "
    "lock (Canon bodies answer a failed focus so, every time: set the lens to MF, focused by "
    "hand)? For a slow card raise busy_retries or retry_max_delay_s in [camera.device] to wait "
    "longer (on a dome its LED is switched off while the wait outlasts max_on_s, and lit again "
    "for the shot)",
    -115: "the camera's memory card is full: free space on it, or set capture_target = "
    "'Internal RAM' so that shots are only downloaded, never stored on the card",
}
#: Codes with which libgphoto2 reports a camera that went away (switched off, cable pulled,
#: auto power-off): -7 I/O error, -10 timeout, -52 USB device not found, -105 model not found.
GONE_CODES = frozenset({-7, -10, -52, -105})

#: card folders walked before a session at most (``/``, a storage, ``DCIM``, ``100CANON`` …
#: are four): a card of more is left to be listed at the session's first shot in a folder
MAX_CARD_FOLDERS = 64
#: files listed before a session at most, and seconds (the rig's clock) spent listing: a
#: Nikon-type body fetches each file's info as libgphoto2 lists it (gphoto2 issue #204: some
#: 6 minutes for 2,700 files); the walk stops before another folder once either is passed
MAX_CARD_FILES = 2000
MAX_CARD_WALK_S = 30.0


#: Settings keys whose camera setting is named by another key (the camera's own name for it).
NAME_KEYS = {
    "iso": "iso_config",
    "aperture": "aperture_config",
    "image_format": "image_format_config",
    "shutter_config": "shutter_config",
}


#: The decoder's advice to fetch a damaged RAW again from the card, where the camera kept none.
_NO_CARD_COPY = re.compile(r"copy (?:it|the shot) again from the camera's card", re.IGNORECASE)


def _no_card_copy(match: re.Match[str]) -> str:
    """What stands in for :data:`_NO_CARD_COPY` when the card holds no copy of the shot."""
    said = (
        "there is no copy of it on the camera to copy again; the kept file is the only one, "
        "and a resumed session shoots this image again"
    )
    return said[0].upper() + said[1:] if match.group(0)[0].isupper() else said


class CameraGoneError(CaptureError):
    """The camera stopped answering mid-session (switched off, unplugged, powered down).

    The step it was taking is not recorded; every image already committed is kept, and
    ``rti-rig run --resume SESSION`` continues from the first missing image once the camera is
    back.
    """


class CardFullError(CaptureError):
    """The camera refused to shoot because its memory card is full."""


NO_CAMERA_HELP = (
    "gphoto2 found no camera: check the USB cable, that the camera is switched on and in PC/PTP "
    "mode, and that no other program (gvfs-gphoto2-volume-monitor, a gphoto2 shell, the vendor "
    "utility) holds it; `gphoto2 --auto-detect` should list it"
)


def _not_latched(name: str, value: str, got: str, key: str) -> str:
    """Why a setting read back otherwise than it was set, and what to do.

    Why: every such setting was answered "put the camera in manual (M) mode with auto-ISO
    off", advice for the exposure settings (a mode dial on Av or auto keeps its own ISO and
    shutter) that says nothing of an image format or capture target the body kept."""
    said = f"{name} set to '{value}' but the camera reports '{got}'"
    if key in ("iso", "aperture", "shutter_config"):
        return f"{said}: put the camera in manual (M) mode with auto-ISO off"
    return (
        f"{said}: the camera did not take it; set it on the camera itself (its menu), or set "
        f'{key} = "" in [camera.device] to leave it as the camera has it'
    )


def _not_offered(
    name: str, value: str, key: str, choices: list[str], *, restoring: bool = False
) -> str:
    """Why ``value`` cannot be set on the camera's setting ``name``, and which key to change.

    Why: a shutter speed had been answered "set shutter_config in [camera.device] to one of
    them", the key that holds the setting's *name*; the speed is the camera's own, chosen for
    ``[camera] exposure_s`` from the speeds it offered at connect, so only a mode dial moved
    since (the speeds offered change with it) leaves it unoffered. ``restoring``: the speed
    is the one the camera had before a test shot, being put back, which no exposure_s chose
    (it had been said "chosen for [camera] exposure_s" of it too)."""
    if key == "shutter_config" and restoring:
        return (
            f"the camera's own shutter speed '{value}' (as connect found it, put back after "
            f"the test shot) is no longer offered for {name}; the camera offers {choices}: "
            "a mode dial moved since? put the camera back in manual (M) mode and set its "
            "shutter speed on the camera"
        )
    if key == "shutter_config":
        return (
            f"shutter speed '{value}' (chosen for [camera] exposure_s from the speeds the camera "
            f"offered at connect) is no longer offered for {name}; the camera offers {choices}: "
            "put the camera back in manual (M) mode, then run the command again"
        )
    return (
        f"'{value}' is not offered for {name} (settings key '{key}'); the camera offers "
        f"{choices}: set {key} in [camera.device] to one of them, as the camera spells it"
    )


def load_gphoto2() -> Any:
    """Import python-gphoto2 lazily, with an error that says how to install it."""
    try:
        import gphoto2
    except ImportError as exc:
        raise DeviceError(
            "gphoto2",
            f"python-gphoto2 is not installed: {pip_install('gphoto2')} (binary wheels bundle "
            "libgphoto2 on Linux and macOS)",
            "import",
        ) from exc
    return gphoto2


_SECONDS = re.compile(r"^\s*(\d+(?:\.\d+)?)\s*(?:s|sec|\"|'')?\s*$", re.IGNORECASE)
_FRACTION = re.compile(r"^\s*(\d+(?:\.\d+)?)\s*/\s*(\d+(?:\.\d+)?)\s*(?:s|sec)?\s*$", re.IGNORECASE)


def parse_shutter(label: str) -> float | None:
    """Seconds for a camera shutter label ('1/125', '0.3', '2.5s', '30"'); None for bulb/auto."""
    m = _FRACTION.match(label)
    if m:
        den = float(m.group(2))
        return float(m.group(1)) / den if den else None
    m = _SECONDS.match(label)
    if m:
        v = float(m.group(1))
        return v if v > 0 else None
    return None


def nearest_shutter(
    exposure_s: float, shutters: list[tuple[float, str]]
) -> tuple[float, str, float]:
    """(seconds, label, relative error) of the offered shutter speed nearest in stops (pure)."""
    if not shutters:
        raise ValueError("the camera offers no shutter speeds")
    secs, label = min(shutters, key=lambda s: abs(math.log(s[0] / exposure_s)))
    return secs, label, abs(secs - exposure_s) / exposure_s


class Gphoto2Camera:
    """Implements the ``Camera`` protocol on a tethered stills camera."""

    def __init__(
        self,
        settings: Gphoto2CameraSettings,
        output_dir: Path | None = None,
        clock: Clock | None = None,
        gp_module: Any = None,
    ) -> None:
        self.settings = settings
        self.name = settings.name
        self.output_dir = output_dir
        #: how the user shoots a lost step again, as a clause ("… then {again}"): a session's
        #: resume, or what the use case that opened the session sets (``rti-rig preview``
        #: says to run the preview again, the command its user typed)
        self._shoot_again: str | None = None  # None: a session's resume
        #: the session folder this camera captures for (set with ``output_dir`` by the
        #: composition root's session hook): its messages name the command that resumes it
        self.session_root: Path | None = None
        self._clock = clock or SystemClock()
        self._gp = gp_module
        self._cam: Any = None
        self._shutters: list[tuple[float, str]] = []
        self._shutter_label: str | None = None
        self._count = 0
        self._staging_tmp: Path | None = None
        #: stems of the camera files of the shots taken so far (a late announcement is theirs)
        self._earlier_stems: set[str] = set()
        #: (camera path, requested and set exposure, shutter label, start) of an exposure whose
        #: files ``collect`` has not downloaded yet
        self._pending: tuple[Any, float, float, str, float] | None = None
        #: a busy spell handed back to the caller by ``expose_within`` (its light went off):
        #: the next ``expose_within`` goes on counting its tries and waits from there
        self._busy: _BusySpell | None = None
        #: whether the shot ``_fire`` took last came after busy answers (a picture may have
        #: been taken behind one and never announced: ``collect`` then lists the card folder)
        self._fired_after_busy = False
        #: the busy answers the last shot ``_fire`` took came after (said in its notices)
        self._busy_tries_of_shot = 0
        #: card folder → the names listed there after the last shot in it (what was on the
        #: card before any busy spell that follows): listed once per folder, then again only
        #: after a busy spell, so a body that is never busy costs one listing a session
        self._card_seen: dict[str, set[str]] = {}
        #: every card folder there was at connect (None: not walked, or not wholly): a folder
        #: not among them was made since, so every file in it is new
        self._card_folders: set[str] | None = None
        #: files this session downloaded and left on the card (``delete_from_camera = false``)
        self._left_on_card = 0
        #: (name, error code) of the card files whose delete after their download failed since
        #: the last ``collect`` began: said as that shot's notice
        self._undeleted: list[tuple[str, int | None]] = []
        self.retries_used = 0
        #: names of the card files of a shot whose download would not decode: left there
        self._kept_for_decode: set[str] = set()
        self.camera_model: str | None = None
        #: the USB port the camera was found on (``usb:001,005``), to name it in errors
        self.camera_port: str | None = None
        #: the image-format choices the camera offered at connect (for the first-shot refusal)
        self._format_choices: list[str] = []
        #: what connect could not establish of the image format (said by ``rti-rig check``)
        self._format_note: str | None = None
        #: a shutter speed a failed test shot could not put back (said by ``rti-rig check``
        #: beside the shot's own error: the camera's own speed, the speed last read back, and
        #: to check it on the camera; never that it "is left at" one: a write that failed
        #: part-way may have left either)
        self._restore_note: str | None = None

    # -- error handling --------------------------------------------------------------------
    def _call(
        self, command: str, fn: Callable[[], T], error: type[DeviceError] = CaptureError
    ) -> T:
        """Run one gphoto2 call, retrying the transient (busy) codes with the injected clock."""
        gp = self._gp
        s = self.settings
        delay = s.retry_delay_s
        for attempt in range(s.busy_retries + 1):
            try:
                return fn()
            except gp.GPhoto2Error as exc:
                code = getattr(exc, "code", None)
                if code in s.retry_codes and attempt < s.busy_retries:
                    self.retries_used += 1
                    self._clock.sleep(delay)
                    delay = min(delay * s.retry_backoff, s.retry_max_delay_s)
                    continue
                raise self._failure(command, exc, attempt + 1, error) from exc
        raise AssertionError("unreachable")  # pragma: no cover

    def _failure(
        self,
        command: str,
        exc: Exception,
        attempts: int,
        error: type[DeviceError] = CaptureError,
        waited_s: float | None = None,
        spent_s: float | None = None,
    ) -> DeviceError:
        """The error for a gphoto2 call that failed for good, with its code's hint.

        ``spent_s``: the time from the first try to the last, said when it is longer than the
        waits between tries (``waited_s``) by the time the tries themselves took, the light's
        relights and cool-downs: a body busy through relights and a minute's cool-down had been
        said to have been tried "over 15.5 s" after some 75 s."""
        code = getattr(exc, "code", None)
        hint = GP_ERROR_HINTS.get(code, "see `gphoto2 --debug` output")
        if command == "capture":
            hint = self._capture_advice(code, hint)
        elif code == -53:
            # opening is where a desktop's mount claims it first; past that, the command that
            # failed is named (a download or a delete had been said "could not open it")
            hint = self._claimed_advice(
                "so rti-rig could not open it"
                if command in ("autodetect", "init")
                else f"so its {command} call did not reach the camera"
            )
        over = f" over {waited_s:g} s" if waited_s else ""
        if waited_s and spent_s is not None and spent_s > waited_s + 1.0:
            over = f" over {spent_s:.0f} s ({waited_s:g} s of them the waits between tries)"
        tries = f" after {attempts} attempts{over}" if attempts > 1 else ""
        text = f"gphoto2 error {code} ({exc}){tries}: {hint}"
        if code in GONE_CODES and self._cam is not None:
            return CameraGoneError(
                self.name,
                f"the camera stopped answering during '{command}' (switched off, "
                f"unplugged or powered down?); {text}. {self._reconnect_then()}",
                command,
            )
        if code == -115:
            return CardFullError(self.name, text + self._card_filled_by_copies(), command)
        return error(self.name, text, command)

    def _device(self) -> str:
        """The camera as a user finds it: its config name, model and USB port."""
        said = [w for w in (self.camera_model, self.camera_port) if w]
        return f"{self.name} ({' on '.join(said)})" if said else self.name

    def _busy_retried_notice(self) -> str:
        """The notice of a shot taken only after the camera answered busy and was tried again.

        Why: a body busy writing its previous file to a slow card (or whose autofocus hunts)
        was retried and its shot taken, and the run said nothing of it: the waits lengthen
        every step, and a user whose body is busy at most shots is never told why the session
        runs slow, nor how close it came to ``busy_retries``. One wording for every shot, so
        the session's notice counts the shots it concerns (the journal's step notices say
        which)."""
        s = self.settings
        # the codes retried are the config's: one beside -110 is named as what it is, a code
        # the user chose to retry (the notice had called every retried reply -110)
        answered = (
            "busy (gphoto2 error -110, PTP Device Busy: still writing a previous file, or its "
            "autofocus searching)"
            if tuple(s.retry_codes) == (-110,)
            else f"a gphoto2 error of retry_codes = {list(s.retry_codes)} (-110 is PTP Device "
            "Busy: still writing a previous file, or its autofocus searching)"
        )
        return (
            f"{self._device()} answered {answered} and was tried again until it "
            f"took the shot, at most busy_retries = {s.busy_retries} tries a shot spaced "
            f"{s.retry_delay_s:g} s to {s.retry_max_delay_s:g} s apart: the waits lengthen the "
            "session; a faster card, capture_target = 'Internal RAM' or manual focus shortens "
            "them"
        )

    def _claimed_advice(self, consequence: str) -> str:
        """What GP_ERROR_IO_USB_CLAIM (-53) means and what to do, naming the camera.

        Why: libgphoto2 claims the camera's USB interface when the camera is opened
        (``gp_camera_init``), so a desktop's gvfs that mounted the camera as it was plugged
        in refuses ``rti-rig run`` there, before any shot (gphoto2 #181, libgphoto2 #617:
        ``gio mount -s gphoto2``, then replug). That refusal had said only "stop that program
        or unmount the camera", naming neither the camera nor the program nor a command; the
        capture's own refusal already said them."""
        return (
            f"the USB device of {self._device()} is claimed by another program (on desktops "
            "gvfs-gphoto2-volume-monitor or a file manager mounts a camera as it is plugged "
            f"in), {consequence}. Unmount the camera in the file manager or stop that program "
            "(`gio mount -s gphoto2`; `systemctl --user stop gvfs-gphoto2-volume-monitor` "
            "until the next login), then check that `gphoto2 --auto-detect` lists it"
        )

    def _capture_advice(self, code: int | None, hint: str) -> str:
        """What a capture that failed for good means, per libgphoto2 code: whether the camera
        took the picture (said only where the code tells), where it would be, what to do.

        Why: a capture answered GP_ERROR (-1, libgphoto2's generic failure) said only "see
        `gphoto2 --debug` output", and no capture failure said whether a picture had been
        taken, nor where to look for it: on the card (``capture_target``), or in the
        camera's RAM, lost with the next capture."""
        device = self._device()
        if self.settings.capture_target == "Internal RAM":
            look = (
                "a picture taken went into the camera's RAM (capture_target = 'Internal "
                "RAM'), which keeps it only until the next capture: it cannot be recovered"
            )
        elif self.settings.capture_target is None:
            # capture_target = "" leaves the body's own target, never read: where a picture
            # went is not known (it had been said "on the camera's card")
            look = (
                "a picture taken is where the camera's own capture target puts it "
                '(capture_target = "" leaves it as the camera has it): on its card, newest '
                "file last, or in its RAM, kept only until the next capture"
            )
        else:
            look = (
                "a picture taken is on the camera's card, newest file last: look there "
                "(rti-rig never records it)"
            )
        if code == -53:
            return self._claimed_advice(
                "so the capture never reached the camera: no picture was taken"
            )
        if code == -110:
            return (
                f"{device} answered 'busy' (PTP Device Busy, I/O in progress), refusing the "
                "shot: a body so refusing normally takes no picture, but some fire all the "
                f"same (pibooth #466), and then {look}. {hint}"
            )
        if code == -7:
            return (
                f"USB I/O error with {device}: whether the camera took the picture is not "
                f"known (the error may come before or after its shutter fires); {look}. "
                "Check the USB cable (short, no unpowered hub) and that the camera's auto "
                "power-off is disabled"
            )
        if code == -1:
            return (
                f"libgphoto2's generic error (GP_ERROR): {device} refused the capture or "
                "answered it in a way libgphoto2 could not name, so whether it took the "
                f"picture is not known; {look}. Bodies answer so for reasons of their own "
                "(libgphoto2 issues #808, #1126): switch it off and on, set its mode dial to M "
                "and close its menus, then run `env LANG=C gphoto2 --debug --debug-logfile="
                "gphoto2.log --capture-image` to see what the camera answered; a body newer "
                f"than the installed libgphoto2 may need it updated ({pip_upgrade('gphoto2')})"
            )
        return hint

    # -- lifecycle -------------------------------------------------------------------------
    def connect(self) -> None:
        """Find the camera, open one session, apply ISO/aperture/format/target, read shutters."""
        if self._cam is not None:
            return
        if self._gp is None:
            self._gp = load_gphoto2()
        gp = self._gp
        detected = [
            (str(n), str(a))
            for n, a in self._call("autodetect", lambda: list(gp.Camera.autodetect()), DeviceError)
        ]
        if not detected:
            raise DeviceError(self.name, NO_CAMERA_HELP, "connect")
        port = self.settings.port
        if port is not None:
            match = [d for d in detected if d[1] == port]
            if not match:
                raise DeviceError(self.name, _port_gone(port, detected), "connect")
            model = match[0][0]
        elif len(detected) > 1:
            raise DeviceError(self.name, _several_cameras(detected), "connect")
        else:
            model, port = detected[0]
        cam = gp.Camera()
        if self.settings.port is not None:
            ports = gp.PortInfoList()
            ports.load()
            abilities = gp.CameraAbilitiesList()
            abilities.load()
            cam.set_port_info(ports[ports.lookup_path(port)])
            cam.set_abilities(abilities[abilities.lookup_model(model)])
        # named before init: its refusals (-53, the USB device claimed) say which camera
        self.camera_model = model
        self.camera_port = port
        self._call("init", cam.init, DeviceError)
        self._cam = cam
        try:
            self._configure()
        except BaseException:
            self.close()
            raise

    def connect_notes(self) -> tuple[str, ...]:
        """What connect could not establish and the first shot will (``rti-rig check`` says
        it): an image format whose name does not tell whether it gives a RAW file."""
        return tuple(n for n in (self._format_note, self._restore_note) if n)

    def close(self) -> None:
        """End the camera session and remove the private staging folder. Safe twice and after
        a failed connect.

        The private folder holds only shots taken with no session bound (the metering series
        of ``run --auto-exposure`` or ``preview``, decoded already): it had been left in the
        system's temporary directory, a 20-30 MB RAW per test shot for ever, after every
        metered session."""
        cam, self._cam = self._cam, None
        self._shutter_label = None
        self._pending = None
        self._busy = None
        self._card_seen = {}
        self._card_folders = None
        staging, self._staging_tmp = self._staging_tmp, None
        if staging is not None:
            shutil.rmtree(staging, ignore_errors=True)
        if cam is not None:
            # the camera may already be gone; there is nothing else to release
            with contextlib.suppress(Exception):
                cam.exit()

    def __enter__(self) -> Gphoto2Camera:
        self.connect()
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # -- configuration ---------------------------------------------------------------------
    def _widget(self, config: Any, name: str, key: str) -> Any:
        """The camera's setting ``name``, asked for by the settings key ``key``.

        A missing setting names the key that holds its *name* (``image_format_config`` for
        ``image_format``): it had said "set 'image_format' to this camera's name for it",
        sending the user to put a setting's name where its value goes."""
        gp = self._gp
        try:
            return config.get_child_by_name(name)
        except gp.GPhoto2Error as exc:
            name_key = NAME_KEYS.get(key)
            leave = f'{key} = "" to leave it as the camera has it'
            if name_key is None:  # capture_target: no other name to give it
                fix = f"in [camera.device] set {leave}"
            else:
                fix = f'in [camera.device] set {name_key} = "..." to this camera\'s name for it'
                if key != name_key:
                    fix += f", or {leave}"
            raise DeviceError(
                self.name,
                f"camera has no setting '{name}' (asked for by {key}): {fix}; `gphoto2 "
                "--list-config` lists the names it has (Nikon bodies name the aperture "
                "'f-number')",
                f"get {name}",
            ) from exc

    @staticmethod
    def _choices(widget: Any) -> list[str]:
        try:
            return [str(widget.get_choice(i)) for i in range(widget.count_choices())]
        except Exception:  # text widgets have no choices
            return []

    def _set_config_values(
        self, values: dict[str, tuple[str, str]], *, restoring: bool = False
    ) -> None:
        """Set {config name: (value, settings key)}, then read back and verify each
        (``restoring``: the values are the camera's own being put back, said as such)."""
        if not values:
            return
        cam = self._cam
        config = self._call("get_config", cam.get_config, DeviceError)
        for name, (value, key) in values.items():
            widget = self._widget(config, name, key)
            choices = self._choices(widget)
            if choices and value not in choices:
                raise DeviceError(
                    self.name,
                    _not_offered(name, value, key, choices, restoring=restoring),
                    f"set {name}",
                )
            widget.set_value(value)
        self._call("set_config", lambda: cam.set_config(config), DeviceError)
        check = self._call("get_config", cam.get_config, DeviceError)
        for name, (value, key) in values.items():
            got = str(self._widget(check, name, key).get_value())
            if got != value:
                raise DeviceError(self.name, _not_latched(name, value, got, key), f"set {name}")

    def _configure(self) -> None:
        s = self.settings
        wanted: dict[str, tuple[str, str]] = {}
        if s.capture_target is not None:
            wanted["capturetarget"] = (s.capture_target, "capture_target")
        if s.image_format is not None:
            wanted[s.image_format_config] = (s.image_format, "image_format")
        if s.iso is not None:
            wanted[s.iso_config] = (s.iso, "iso")
        if s.aperture is not None:
            wanted[s.aperture_config] = (s.aperture, "aperture")
        self._set_config_values(wanted)
        config = self._call("get_config", self._cam.get_config, DeviceError)
        self._check_image_format(config)
        widget = self._widget(config, s.shutter_config, "shutter_config")
        shutters = []
        for label in self._choices(widget):
            secs = parse_shutter(label)
            if secs is not None:
                shutters.append((secs, label))
        if not shutters:
            # the key and the section, and both ways out: it had asked "is the camera in
            # manual (M) mode?" of a setting the config may have named wrongly
            raise DeviceError(
                self.name,
                f"the camera's setting '{s.shutter_config}' (shutter_config in "
                f"[camera.device]) offers no timed shutter speeds (it offers "
                f"{self._choices(widget)}): put the camera in manual (M) mode; if "
                f"'{s.shutter_config}' is not its shutter speed, set shutter_config in "
                "[camera.device] to the name `gphoto2 --list-config` gives it",
                "read shutter speeds",
            )
        self._shutters = sorted(shutters)
        self._check_shutter_latches(str(widget.get_value()), self._choices(widget))

    def _check_image_format(self, config: Any) -> None:
        """Refuse, before anything is lit, an image format libgphoto2 names as giving no RAW.

        Why: every decode mode (``[camera.device.decode] mode``: mosaic, half, demosaic) reads
        the shot's RAW, and ``collect`` refuses a shot without one; a JPEG-only
        ``image_format`` ("Large Fine JPEG") had passed ``rti-rig check`` and was refused at
        the first shot, its LED lit. The value judged is the one in effect: ``image_format``
        (set and read back above), or the camera's own when it is left (``""``). A name that
        cannot be judged (:func:`gives_raw` None) is noted for the check, and the first shot
        still refuses a shot without a RAW."""
        s = self.settings
        self._format_note, self._format_choices = None, []
        key = f"image_format_config = '{s.image_format_config}'"
        try:
            widget = config.get_child_by_name(s.image_format_config)
        except self._gp.GPhoto2Error:
            widget = None
        if widget is None:  # image_format left, and the camera has no such setting
            self._format_note = (
                f"image format not checked: the camera has no setting '{s.image_format_config}' "
                f"({key} in [camera.device]); the first shot is refused if it gives no RAW "
                "file (every decode mode reads the RAW)"
            )
            return
        value = str(widget.get_value())
        self._format_choices = self._choices(widget)
        raws = raw_choices(self._format_choices)
        judged = gives_raw(value)
        said = (
            f"image_format = '{value}' in [camera.device]"
            if s.image_format is not None
            else f"the camera's own {s.image_format_config} '{value}' (image_format is left "
            "as the camera has it in [camera.device])"
        )
        if judged is None:
            self._format_note = (
                f"{said}: libgphoto2's name does not tell whether it gives a RAW file, so it is "
                f"not checked here; the first shot is refused if it gives none (decode mode "
                f"'{s.decode.mode}' reads the RAW)"
                + (f"; the choices known to give RAW: {raws}" if raws else "")
            )
            return
        if judged:
            return
        fix = (
            f"set image_format to one the camera offers that gives a RAW: {raws}"
            if raws
            else "the camera offers no choice known to give a RAW "
            f"({self._format_choices}): set image_format to its RAW value"
        )
        raise DeviceError(
            self.name,
            f"{said} gives JPEG only, and decode mode '{s.decode.mode}' (every mode) reads the "
            f"shot's RAW: {fix}",
            f"check {s.image_format_config}",
        )

    def _check_shutter_latches(self, current: str, offered: list[str]) -> None:
        """Set another offered shutter speed, read it back, and put the camera's own back.

        Why: a body whose mode dial is not on M (Av, P) accepts a shutter speed and keeps its
        own. ISO and the others were verified at connect, but the shutter only at the first
        shot: ``rti-rig check`` passed such a camera, and ``run`` lit the first LED before
        stopping on it. Found here, it is refused before anything is lit."""
        s = self.settings
        probe = next((label for _, label in self._shutters if label != current), None)
        if probe is None:
            return  # one speed offered: nothing to tell apart
        self._set_config_values({s.shutter_config: (probe, "shutter_config")})
        self._shutter_label = probe
        if current in offered:  # "bulb" too: the camera's own, whatever it was
            self._set_config_values({s.shutter_config: (current, "shutter_config")})
            self._shutter_label = current

    def available_exposures_s(self) -> list[float]:
        """Shutter speeds the camera offers, in seconds (for ``exposure.choose_exposure``)."""
        return [secs for secs, _ in self._shutters]

    # -- capture ---------------------------------------------------------------------------
    def capture(self, exposure_s: float) -> Frame:
        """Set the shutter, fire, download the RAW (and JPEG), decode it to linear data."""
        self.expose(exposure_s)
        return self.collect()

    def expose(self, exposure_s: float) -> float | None:
        """Set the shutter and fire; return once the camera reports the image taken.

        libgphoto2's capture returns when the camera has the picture (its file is named), so
        the exposure is over: the light may go off before the download and the RAW decode,
        which take seconds for a 24-megapixel RAW over USB.
        """
        return self.expose_within(exposure_s, None)

    def expose_within(self, exposure_s: float, fire_by: float | None) -> float | None:
        """``expose``, waiting for a busy camera only while its next try is due by ``fire_by``.

        A camera that answers busy (-110: "I/O in progress", PTP Device Busy) refused the shot
        and took no picture. Its tries are spaced ``retry_delay_s``, ``retry_backoff`` times
        longer each time, at most ``retry_max_delay_s``, for ``busy_retries`` retries in all.
        When the next wait would end after ``fire_by`` (on the clock), :class:`CameraBusyError`
        is raised at once, with that wait as ``retry_in_s``: the caller's light may not stay
        lit that long, so the caller switches it off, waits, lights it again and calls this
        again, which tries at once and goes on counting from where it was (the spell is this
        camera's until a shot is taken or the tries run out). The whole wait is thus bounded
        by the retry settings, lit or not; past them the error is a plain ``CaptureError``.
        """
        if self._cam is None:
            raise CaptureError(
                self.name, "camera is not connected; call connect() first", "capture"
            )
        s = self.settings
        cam = self._cam
        problem = self.exposure_problem(exposure_s)
        if problem is not None:
            raise CaptureError(self.name, problem, "set shutter")
        secs, label, _ = nearest_shutter(exposure_s, self._shutters)
        if label != self._shutter_label:
            self._set_config_values({s.shutter_config: (label, "shutter_config")})
            self._shutter_label = label
        t_capture = self._clock.now()
        self._pending = None
        path = self._fire(cam, fire_by)
        self._pending = (path, exposure_s, secs, label, t_capture)
        return self._clock.now()

    def _fire(self, cam: Any, fire_by: float | None) -> Any:
        """Fire the shutter once the camera is not busy; see :meth:`expose_within`."""
        gp = self._gp
        s = self.settings
        now = self._clock.now()
        spell, self._busy = self._busy or _BusySpell(s.retry_delay_s, first_try_at=now), None
        while True:
            started = self._clock.now()
            try:
                path = cam.capture(gp.GP_CAPTURE_IMAGE)
                self._fired_after_busy = spell.tries > 0
                self._busy_tries_of_shot = spell.tries
                return path
            except gp.GPhoto2Error as exc:
                # a body may answer busy only after a pause (a Canon whose autofocus fails:
                # "-- long pause --", then PTP Device Busy): the next try may take as long to
                # answer, with the light lit, so it too must be over by fire_by
                took = self._clock.now() - started
                code = getattr(exc, "code", None)
                if code not in s.retry_codes or spell.tries >= s.busy_retries:
                    raise self._failure(
                        "capture",
                        exc,
                        spell.tries + 1,
                        waited_s=spell.waited_s,
                        spent_s=self._clock.now() - spell.first_try_at,
                    ) from exc
                delay = spell.delay_s
                spell.tries += 1
                spell.waited_s += delay
                spell.delay_s = min(delay * s.retry_backoff, s.retry_max_delay_s)
                self.retries_used += 1
                if fire_by is not None and self._clock.now() + delay + took > fire_by + 1e-9:
                    self._busy = spell
                    raise CameraBusyError(
                        self.name,
                        f"camera busy (gphoto2 error {code}) {spell.tries} time(s); its next "
                        f"try is due in {delay:g} s, later than the shot may be fired",
                        "capture",
                        retry_in_s=delay,
                        tries=spell.tries,
                    ) from exc
                self._clock.sleep(delay)

    def test_shot(self) -> str:
        """Take one shot at the fastest shutter speed offered, download and decode its RAW,
        and say what it showed (for ``rti-rig check``, after its lights' walk); raise the
        error a session's first shot would have met.

        Why: a body whose RAW the installed LibRaw cannot read (a body newer than it, a new
        CR3 or RAF variant) passed the check, which took no image, and the session was
        refused at its first shot, its LED lit, after the schedule had begun. The shot goes
        to the private staging folder (no session is bound) and is never kept; on a card it
        is deleted there once downloaded unless ``delete_from_camera = false``."""
        if self._cam is None:
            raise CaptureError(
                self.name, "camera is not connected; call connect() first", "test shot"
            )
        bound, self.output_dir = self.output_dir, None  # never into a session's raw/
        own = self._shutter_label  # the camera's own speed, put back as connect found it
        self._restore_note = None
        try:
            self.expose(self._shutters[0][0])
            try:
                frame = self.collect()
            except CaptureError as exc:
                if isinstance(exc.__cause__, UnsupportedRawError):
                    self._format_note = None  # a RAW came: its format is not in doubt
                    raise self._unreadable_raw(exc.__cause__) from exc
                raise
        except BaseException as exc:
            # a failed shot (an unreadable RAW, a busy body) leaves the camera's own speed too:
            # it had been put back only after a shot that decoded, the body left at its
            # fastest speed by a check that failed. The shot's error is the one said; a
            # restore that fails as well is said beside it (it had been suppressed: the
            # check said nothing of a body left at its fastest speed)
            self.output_dir = bound
            if isinstance(exc, Exception):  # not after a stop: the camera is closed next
                try:
                    self._restore_shutter(own)
                except Exception as failed:
                    # what is known: the speed last read back (the shot's); a write
                    # that failed part-way may have left either, so "is left at" is not said
                    self._restore_note = (
                        f"putting the camera's own shutter speed '{own}' back after the test "
                        f"shot failed ({getattr(failed, 'message', None) or failed}); it was "
                        f"last read back at '{self._shutter_label}' (the test shot's): check "
                        "and set it on the camera before shooting with it outside rti-rig"
                    )
            raise
        self.output_dir = bound
        self._restore_shutter(own)
        self._format_note = None  # the shot gave a RAW: nothing left to say of the format
        files = [str(f) for f in frame.metadata.get("camera_files") or []]
        raw = next((f for f in files if is_camera_raw(Path(f))), files[0] if files else "?")
        said = f"one test shot: its RAW {raw} reads with the installed {libraw_named()}"
        if self.settings.capture_target != "Internal RAM" and not self.settings.delete_from_camera:
            said += " (its file stays on the card: delete_from_camera = false)"
        # where it landed, and a card copy not deleted: said before any session, not after one
        folder = raw.rsplit("/", 1)[0] or "/"
        return "; ".join([said, *(f"note: {n}" for n in self._where_notices(folder))])

    def _restore_shutter(self, own: str | None) -> None:
        """Put back the shutter speed the camera had before a test shot (``own``)."""
        if own is not None and own != self._shutter_label:
            self._set_config_values(
                {self.settings.shutter_config: (own, "shutter_config")}, restoring=True
            )
            self._shutter_label = own

    def _unreadable_raw(self, exc: UnsupportedRawError) -> CaptureError:
        """The check's refusal of a body whose RAW the installed LibRaw cannot read: the
        camera, the LibRaw version, and what to do."""
        model = self.camera_model or "this camera"
        return CaptureError(
            self.name,
            f"{self._device()} gives RAW files the installed {libraw_named()} cannot read "
            f"(a test shot's RAW: {exc.libraw_said or 'unsupported format'}): every shot of "
            f"a session would be refused at its decode. Update rawpy ({pip_upgrade('rawpy')}) "
            f"to one whose LibRaw reads the {model} (https://www.libraw.org/supported-cameras), "
            "then run the check again. Shooting JPEG is no way round it: every decode mode "
            "reads the RAW (the camera's JPEG is only kept beside it, keep_jpeg); a body that "
            "offers DNG as an image_format may shoot that instead",
            "test shot",
        )

    def exposure_problem(self, exposure_s: float) -> str | None:
        """Why ``exposure_s`` cannot be shot on this camera (None: it can), once connected.

        For ``rti-rig check``: a session's exposure that the camera does not offer had passed
        the check and failed the session's first capture, with its light already on."""
        secs, label, err = nearest_shutter(exposure_s, self._shutters)
        if err <= self.settings.shutter_tolerance:
            return None
        return self._not_offered(exposure_s, secs, label)

    def _not_offered(self, exposure_s: float, secs: float, label: str) -> str:
        """Why an exposure cannot be shot, with the offered speeds either side and the keys
        to change. It had said "choose one of available_exposures_s()", a Python method,
        to a user whose exposure comes from the rig config's [camera] exposure_s."""
        below = [(t, lab) for t, lab in self._shutters if t < exposure_s]
        above = [(t, lab) for t, lab in self._shutters if t > exposure_s]
        near = [f"{t:g} s ('{lab}')" for t, lab in (below[-1:] + above[:1])]
        return (
            f"exposure {exposure_s:g} s is not a shutter speed this camera offers (nearest "
            f"'{label}' = {secs:g} s, {abs(secs - exposure_s) / exposure_s:.0%} off; "
            f"shutter_tolerance = {self.settings.shutter_tolerance:g}): set [camera] "
            f"exposure_s in the rig config to one it offers, {' or '.join(near)}, or raise "
            "shutter_tolerance in [camera.device] to shoot the nearest; the camera offers "
            f"'{self._shutters[0][1]}' to '{self._shutters[-1][1]}' in its own steps (its "
            "1/3 or 1/2 stop setting)"
        )

    def collect(self) -> Frame:
        """Download the last ``expose``'s RAW (and JPEG) and decode it to linear data."""
        pending, self._pending = self._pending, None
        if pending is None or self._cam is None:
            raise CaptureError(self.name, "collect() without expose() before it", "capture")
        path, exposure_s, secs, label, t_capture = pending
        s = self.settings
        gp = self._gp
        cam = self._cam
        files = [(str(path.folder), str(path.name))]
        try:
            files, late, strays = self._more_files(files)
            strays.extend(self._unannounced(str(path.folder), files + late + strays, strays))
        except CameraGoneError as exc:  # gone while it announced the shot's files
            raise self._gone_at_download(exc, str(path.folder), str(path.name)) from exc
        self._undeleted = []
        self._delete(late)  # a previous shot's file announced late: never this shot's
        self._count += 1
        raw_files = [f for f in files if is_camera_raw(Path(f[1]))]
        if not raw_files:
            kept = self._keep_unusable(files)
            self._format_note = None  # the format is known now: this error says it
            raws = raw_choices(self._format_choices)
            offered = f": it offers {raws}" if raws else ""
            raise CaptureError(
                self.name,
                f"camera delivered {[n for _, n in files]} but no RAW file: set image_format in "
                f"[camera.device] to the camera's RAW (or RAW+JPEG) value{offered}{kept}",
                "capture",
            )
        staging = self._staging_dir()
        saved: dict[str, Path] = {}
        for folder, name in files:
            if not is_camera_raw(Path(name)) and not s.keep_jpeg:
                continue
            target = _unused(staging, f"cap{self._count:04d}_{name}")
            try:
                camera_file = self._call(
                    "download",
                    lambda f=folder, n=name: cam.file_get(f, n, gp.GP_FILE_TYPE_NORMAL),
                )
            except CameraGoneError as exc:
                raise self._gone_at_download(exc, folder, name) from exc
            except CaptureError as exc:
                raise self._download_failed(exc, folder, name) from exc
            self._save(camera_file, target, folder, name)
            saved[name] = target
        # pictures the body took behind a busy answer: downloaded too (nothing captured is
        # lost), handed over as strays, never as this shot's files
        stray_saved: list[dict[str, Any]] = []
        # with no session bound (run --auto-exposure's metering, preview) the downloads go to
        # a private folder deleted at close: a stray is then left on the card, where it is the
        # only copy kept (it had been deleted there and with the folder, without a word)
        left_on_card = self.output_dir is None and s.capture_target != "Internal RAM"
        for folder, name in strays:
            target = _unused(staging, f"stray{self._count:04d}_{name}")
            camera_file = self._call(
                "download", lambda f=folder, n=name: cam.file_get(f, n, gp.GP_FILE_TYPE_NORMAL)
            )
            self._save(camera_file, target, folder, name, shot=saved)
            stray_saved.append(
                {
                    "path": str(target),
                    "name": f"{folder.rstrip('/')}/{name}",
                    "left_on_card": left_on_card,
                }
            )

        def delete_downloaded() -> None:
            if left_on_card:
                self._delete(files)
                self._note_card(str(path.folder), files + late)
                seen = self._card_seen.get(str(path.folder))
                if seen is not None:  # on the card now: never found again as a new picture
                    seen |= {n for _, n in strays}
            else:
                self._delete(files + strays)
                self._note_card(str(path.folder), files + strays + late)

        # a card's copy is deleted only once the download decodes: a RAW that would not (a
        # transfer damaged on the way, a format this LibRaw lacks) had been deleted from the
        # card first, its one good copy, and the user told to "copy it again from the
        # camera's card". A RAM capture is deleted first, as before (no copy to keep there)
        on_card = not _in_ram(str(path.folder))
        if not on_card:
            delete_downloaded()
        raw_path = saved[raw_files[0][1]]
        try:
            decoded = decode_raw(raw_path, s.decode, timestamp_s=t_capture)
        except (RawFileMissingError, CaptureError) as exc:
            if on_card and s.delete_from_camera:
                self._kept_for_decode = {n for _, n in files + strays}
            if isinstance(exc, RawFileMissingError):
                raise self._download_gone(raw_path, raw_files[0]) from exc
            raise self._undecoded(raw_path, raw_files[0], exc) from exc
        if on_card:
            delete_downloaded()
        jpeg = [str(p) for n, p in saved.items() if not is_camera_raw(Path(n))]
        iso = _number(s.iso) or decoded.gain
        metadata = dict(decoded.metadata)
        camera_path = {n: f"{f.rstrip('/')}/{n}" for f, n in files}
        notices = list(metadata.get("notices") or [])
        notices.extend(self._where_notices(str(path.folder)))
        if stray_saved:
            notices.append(
                "the camera delivered a picture besides the shot's own file(s): one it took "
                "while answering busy (its capture refused, yet its shutter fired), at a moment "
                "rti-rig did not choose, so under a light it cannot vouch for; it is kept "
                "aside in strays/ (the step's 'strays' in the journal), never as an image of "
                "the session"
            )
        if self._busy_tries_of_shot:
            notices.append(self._busy_retried_notice())
        if s.keep_jpeg and not jpeg:
            notices.append(
                f"keep_jpeg is set but the camera announced no JPEG within event_timeout_s = "
                f"{s.event_timeout_s:g} s: set image_format to its RAW+JPEG value, raise "
                "event_timeout_s, or set keep_jpeg = false"
            )
        if notices:
            metadata["notices"] = notices
        metadata.update(
            {
                "camera": self.name,
                "camera_model": self.camera_model,
                "shutter_label": label,
                "exposure_requested_s": exposure_s,
                "iso": s.iso,
                "aperture": s.aperture,
                "gain_unit": "iso",
                "camera_files": list(camera_path.values()),
                # the session keeps these under raw/ with its own names (the camera's in the
                # journal): a wrapped or repeated camera counter can never overwrite a shot
                "originals": [{"path": str(p), "name": camera_path[n]} for n, p in saved.items()],
                "jpeg_file": jpeg[0] if jpeg else None,
                "late_camera_files": [f"{f.rstrip('/')}/{n}" for f, n in late],
                # taken behind a busy answer (see _more_files): the session keeps them aside
                "stray_originals": stray_saved,
                "capture_started_s": t_capture,
                "capture_finished_s": self._clock.now(),
            }
        )
        return Frame(
            pixels=decoded.pixels,
            exposure_s=secs,
            gain=float(iso),
            white_level=decoded.white_level,
            timestamp_s=t_capture,
            metadata=metadata,
        )

    def _save(
        self,
        camera_file: Any,
        target: Path,
        folder: str,
        name: str,
        *,
        shot: dict[str, Path] | None = None,
    ) -> None:
        """Write a downloaded file to ``target``, or raise the error that says the computer's
        disk refused it, where the shot is now, and what to do.

        ``shot``: the file is a stray (a picture the body took while answering busy), and
        these are the light's own files, already downloaded (camera name -> where). Why: its
        refusal had called the stray "the shot", said it was lost or on the card as if it were
        the light's image, and said nothing of the light's own file, downloaded whole.

        Why: libgphoto2's ``gp_file_save`` answers a short write (a full disk) by unlinking
        the file and returning GP_ERROR (-1), which python-gphoto2 raises as ``GPhoto2Error``.
        Uncaught, the session stopped with "unexpected GPhoto2Error: [-1] … please report it":
        the user was not told the disk was full, nor that a shot in the camera's RAM was
        lost, nor that a resume reshoots it once there is room.

        Why the size is checked after a save that succeeded: ``gp_file_save`` ignores
        ``fclose``'s result, so a disk that fills within the last block stdio still buffers
        returns GP_OK and leaves a truncated file (libgphoto2's ``gphoto2-file.c``); it was
        kept, said to be a RAW that "would not decode", and its card copy deleted.

        Why a refused ``fopen`` is told apart: it is the same GP_ERROR (-1) with no file
        left, but a folder the user cannot write into is not a full disk, and freeing space
        does not fix it."""
        try:
            camera_file.save(str(target))
            _check_saved_whole(camera_file, target)
        except (self._gp.GPhoto2Error, OSError) as exc:
            with contextlib.suppress(OSError):
                target.unlink(missing_ok=True)  # never a partial file: ``_unused`` made it new
            free = ""
            with contextlib.suppress(OSError):
                free = f": {shutil.disk_usage(target.parent).free / 1e6:.0f} MB free there now"
            code = getattr(exc, "code", None)
            why = f"gphoto2 error {code} ({exc})" if code is not None else str(exc)
            refused = _create_refused(target) if code is not None else None
            if refused is not None:  # fopen's -1: the file could not even be made
                refusal = (
                    f"no file can be created there ({refused.strerror or refused}): not a "
                    "full disk, but the folder's permissions, a read-only mount or a folder "
                    "gone"
                )
                fix = "make that folder writable"
            else:
                refusal = f"that disk refused it (full, read-only or failing{free})"
                fix = "free space on that disk (or fix it)"
            if shot is not None:
                raise CaptureError(
                    self.name,
                    f"{folder.rstrip('/')}/{name}, a stray (a picture the camera took while "
                    "answering busy, at a moment rti-rig did not choose: never an image of the "
                    f"session), came from the camera but could not be written into "
                    f"{target.parent} ({why}); {refusal}. {self._stray_where(folder, name)}. "
                    f"{self._shot_kept(folder, shot)}. The step is not recorded: {fix}, then "
                    f"shoot this light again with: {resume_command(self.session_root)}",
                    "download",
                ) from exc
            where = self._where(folder, name)
            # a metering shot (no session bound) is no session's step: a resume had been
            # advised beside the run's "nothing was captured or written"
            then = (
                f"Its step is not recorded: {fix}, then {self.shoot_again}"
                if self.output_dir is not None
                else "It was a test shot outside any session (metering): "
                f"{fix}, then run the command again"
            )
            raise CaptureError(
                self.name,
                f"{folder.rstrip('/')}/{name} came from the camera but could not be written "
                f"into {target.parent} ({why}); {refusal}. {where[0].upper()}{where[1:]}. "
                f"{then}",
                "download",
            ) from exc

    @property
    def shoot_again(self) -> str:
        """How the user shoots a lost step again, as a clause ("… then {shoot_again}")."""
        if self._shoot_again is not None:
            return self._shoot_again
        return f"shoot it again with: {resume_command(self.session_root)}"

    @shoot_again.setter
    def shoot_again(self, clause: str) -> None:
        self._shoot_again = clause

    def _stray_where(self, folder: str, name: str) -> str:
        """Where a stray whose file did not reach the computer is now (see :meth:`_where`)."""
        on_camera = f"{folder.rstrip('/')}/{name}"
        if self.settings.capture_target == "Internal RAM":
            return (
                f"The stray was in the camera's RAM, so it is lost: {on_camera} existed only there"
            )
        return f"The stray's copy stays on the camera's card at {on_camera}"

    def _shot_kept(self, folder: str, shot: dict[str, Path]) -> str:
        """Where the light's own files are when a stray's download failed after them: on the
        computer, and (on a card) still on the card, deleted there only after every download."""
        names = ", ".join(shot)
        where = ", ".join(str(p) for p in shot.values())
        kept = (
            f"This light's own shot ({names}) was downloaded whole (into a temporary folder: "
            "no session is bound, as for a metering shot)"
            if self.output_dir is None
            else f"This light's own shot ({names}) was downloaded whole to {where}, which a "
            "resume moves to the session's recovered/ folder (never deleting it)"
        )
        if self.settings.capture_target != "Internal RAM":
            kept += f"; its copy stays on the camera's card in {folder.rstrip('/')}/"
        return kept

    def _keep_unusable(self, files: list[tuple[str, str]]) -> str:
        """Keep a session's shot that gave no RAW (a JPEG-only format, or the body's dial
        turned mid-session): downloaded beside the session's other downloads, then deleted
        from the camera as any downloaded shot is. Returns the clause that says where it is.

        Why: these files were deleted from the camera undownloaded: a picture taken under a
        session's light was lost without a word. A test shot outside any session (metering,
        ``check``) is deleted as before: it is a test, and its private folder goes at close.
        A file whose download or save fails stays where it was (card or RAM), and is named
        with why it failed (the words had said where the file stayed, not why: a full disk
        and an unplugged cable call for different fixes)."""
        if self.output_dir is None or self._cam is None:
            self._delete(files)
            return ""
        gp, cam = self._gp, self._cam
        kept: list[str] = []
        left: list[str] = []
        downloaded: list[tuple[str, str]] = []
        for folder, name in files:
            target = _unused(self._staging_dir(), f"cap{self._count:04d}_{name}")
            try:
                camera_file = self._call(
                    "download",
                    lambda f=folder, n=name: cam.file_get(f, n, gp.GP_FILE_TYPE_NORMAL),
                )
                self._save(camera_file, target, folder, name)
            except CaptureError as exc:  # CameraGoneError too: the camera left mid-download
                left.append(f"{self._where(folder, name)} (the download failed: {exc.message})")
                continue
            kept.append(shown_path(target))
            downloaded.append((folder, name))
        self._delete(downloaded)
        said = ""
        if kept:
            said += (
                f". The shot is kept at {', '.join(kept)} (a resume moves it to the session's "
                "recovered/ folder, never deleting it)"
            )
        if left:
            said += ". Not downloaded: " + "; ".join(left)
        return said

    def _where(self, folder: str, name: str) -> str:
        """Where a shot whose file did not reach the session is now: lost with the camera's
        RAM, or on its card (a card's copy is deleted only once downloaded)."""
        on_camera = f"{folder.rstrip('/')}/{name}"
        if self.settings.capture_target == "Internal RAM":
            return (
                f"the shot was taken into the camera's RAM (capture_target = 'Internal RAM'), "
                f"so it is lost: {on_camera} existed only there"
            )
        return f"the shot's copy stays on the camera's card at {on_camera}"

    def _download_failed(self, exc: CaptureError, folder: str, name: str) -> CaptureError:
        """The error for a shot's file that would not download: where the shot is now, and
        that a resume shoots it again.

        Why: a failed download (libgphoto2 -1) said only "gphoto2 error -1 …: see `gphoto2
        --debug` output". Shot into the camera's RAM (``capture_target = "Internal RAM"``) the
        picture exists nowhere else, and the body drops it at the next capture or at the
        session's end: it is lost, which the user was not told. On a card its copy stays
        there (it is deleted only once downloaded). Either way the step is not recorded, so
        ``rti-rig run --resume SESSION`` shoots it again under its own light."""
        on_camera = f"{folder.rstrip('/')}/{name}"
        where = self._where(folder, name)
        return CaptureError(
            self.name,
            f"{exc.message}; downloading {on_camera} failed, {where}. Its step is not "
            "recorded: check the USB cable and that no other program holds the camera, then "
            f"{self.shoot_again}",
            "download",
        )

    def _gone_at_download(self, exc: CameraGoneError, folder: str, name: str) -> CameraGoneError:
        """The error for a camera that went away (unplugged, switched off) after it took this
        shot, before its file was downloaded (while its files were announced or at the
        download): that, and where the shot is now.

        Why: it said only "the camera stopped answering during 'download' … Images already
        taken are kept", beside the run's "Nothing was captured": shot into the camera's RAM
        the picture is lost with the body's power, on a card its copy stays there (never
        deleted before it is downloaded), and neither was said."""
        on_camera = f"{folder.rstrip('/')}/{name}"
        # a session's step, or a metering shot (no session bound): a resume had been advised
        # of a test shot whose run said "nothing was captured or written", and of a preview
        if self.output_dir is None:
            fate = "it was a test shot outside any session (metering)"
        elif self._shoot_again is None:
            # not "the resume": a first shot's run keeps nothing, and is run again
            fate = "its step is not recorded, so it is shot again when the session goes on"
        else:
            fate = "nothing of it was recorded"  # the command again: said before
        return CameraGoneError(
            self.name,
            f"{exc.message}. This shot was taken but its file {on_camera} was not "
            f"downloaded: {self._where(folder, name)}; {fate}",
            exc.command,
        )

    def _reconnect_then(self) -> str:
        """What a camera gone (unplugged, switched off) leaves the user to do: a session's
        images are kept and ``shoot_again`` says how the rest is shot (a resume, or the
        preview again); before any session is bound (metering, a check) the command is run
        again. Why: every gone camera had been told "continue with 'rti-rig run --resume
        SESSION'", also in a preview and at a metering shot, whose run said nothing was
        captured or written.

        Why a session's words leave the command to the run: the camera does not know whether
        the session holds an image (a camera gone as it was opened, or at the first shot, had
        been told "Images already taken are kept … continue with 'rti-rig run --resume
        SESSION'" under the run's "Nothing was captured"), nor its folder as a pasteable word;
        the run's summary, printed above the error, says both."""
        if self.output_dir is None:
            return "Reconnect it, then run the command again"
        if self._shoot_again is None:
            return (
                "Reconnect it, then go on as said above: whether the session kept images, "
                "and the command that continues it"
            )
        return f"Reconnect it, then {self.shoot_again}"

    def _download_gone(self, raw_path: Path, camera_file: tuple[str, str]) -> CaptureError:
        """The error for a RAW downloaded and then gone before it was decoded: the file the
        camera reported, the folder it was downloaded into and looked for in, where the
        camera's copy is, and what to do.

        Why: it said "the camera's file IMG_0002.CR2 would not decode; it is kept at
        raw/.incoming/cap0002_IMG_0002.CR2 … RAW file not found (moved or deleted before it
        was read)": a file said kept that was gone, no word of the camera's folder or of
        what took it."""
        folder, name = camera_file
        on_camera = f"{folder.rstrip('/')}/{name}"
        if any(n == name for n, _ in self._undeleted):
            copy = f"the camera's copy stays on its card at {on_camera} (its delete failed)"
        elif name in self._kept_for_decode:
            copy = f"the camera's copy stays on its card at {on_camera}, never deleted"
        elif self.settings.delete_from_camera:
            copy = "the camera's copy was deleted after the download, so this shot is lost"
        elif self.settings.capture_target == "Internal RAM":
            copy = (
                'the camera shot it to its RAM (capture_target = "Internal RAM"), which keeps '
                "no copy once it is downloaded, so this shot is lost"
            )
        else:
            copy = f"the camera's copy is left on the camera at {on_camera}"
        where = raw_path.parent
        return CaptureError(
            self.name,
            f"the camera reported {on_camera} and it was downloaded into {shown_path(where)} as "
            f"{raw_path.name}, but it was gone from there before it could be decoded (moved or "
            "deleted by another program: a sync, backup or antivirus tool, or a clean-up of "
            f"that folder); {copy}. Keep other programs out of {shown_path(where)} (exclude it "
            "from them), then run again (a resumed session shoots this image again)",
            "decode",
        )

    def _copy_said(self, name: str) -> str:
        """The camera's copy of a downloaded shot, as an error says it.

        Why: ``delete_from_camera = false`` leaves a copy on the card only: a capture to the
        camera's RAM (the shipped DSLR example's ``capture_target``) keeps none once it is
        downloaded, and had been said "the camera's copy kept" (and, of a download gone before
        its decode, "left on the camera at /IMG_0002.CR2")."""
        if any(n == name for n, _ in self._undeleted):
            return "still on the card (its delete there failed)"
        if self.settings.delete_from_camera:
            return "deleted"
        if self.settings.capture_target == "Internal RAM":
            return 'not kept (a capture to its RAM, capture_target = "Internal RAM")'
        return "kept"

    def _undecoded(
        self, raw_path: Path, camera_file: tuple[str, str], exc: CaptureError
    ) -> CaptureError:
        """The error for a downloaded RAW that would not decode: the camera's file and where
        its only copy is kept (it is gone from the camera once downloaded).

        Why: the error named ``raw/.incoming/cap0002_IMG_0002.RAF`` only, a folder a resume
        empties into ``recovered/``, and said nothing of the camera's copy, already deleted:
        an owner who looked for the shot on the card found nothing."""
        folder, camera_name = camera_file
        where = str(raw_path)
        if self.output_dir is not None and self.output_dir.name == ".incoming":
            where += " (a resume moves it to the session's recovered/ folder, never deleting it)"
        copy = self._copy_said(camera_name)
        on_card = copy in ("kept", "still on the card (its delete there failed)")
        if camera_name in self._kept_for_decode:
            copy = f"stays on its card at {folder.rstrip('/')}/{camera_name}, not deleted"
            on_card = True
        problem = exc.problem if isinstance(exc, RawDecodeError) else exc.message
        if not on_card:
            # the decoder's "copy it again from the camera's card" had followed "the camera's
            # copy deleted" (or a capture to its RAM, which keeps none) in one sentence
            problem = _NO_CARD_COPY.sub(_no_card_copy, problem)
        return CaptureError(
            self.name,
            f"the camera's file {camera_name} would not decode; it is kept at {shown_path(where)}, "
            f"the camera's copy {copy}. "
            + problem
            + (
                ". `rti-rig check` finds a RAW this LibRaw cannot read with a test shot, "
                "before a session lights anything"
                if isinstance(exc, UnsupportedRawError)
                else ""
            ),
            "decode",
        )

    def _staging_dir(self) -> Path:
        """Where downloads land: the session's ``raw/.incoming`` once the rig told the camera
        its session (``output_dir``), else a private temporary folder (metering shots)."""
        if self.output_dir is not None:
            self.output_dir.mkdir(parents=True, exist_ok=True)
            return self.output_dir
        if self._staging_tmp is None:
            self._staging_tmp = Path(tempfile.mkdtemp(prefix=f"rti-rig-{self.name}-"))
        return self._staging_tmp

    def _more_files(
        self, files: list[tuple[str, str]]
    ) -> tuple[list[tuple[str, str]], list[tuple[str, str]], list[tuple[str, str]]]:
        """Collect FILE_ADDED events (the second file of RAW+JPEG) until the camera goes quiet
        with what this shot needs: its RAW, and its JPEG too with ``keep_jpeg`` (for at most
        ``event_timeout_s``). Returns (this shot's files, which hold the capture's own path
        unless that was a stray's; files of an earlier shot; strays).

        A stray is a picture the body took while answering busy: its capture failed (-110),
        yet the shutter fired and the file was written and announced (pibooth #466). One shot
        gives one RAW, so a RAW announced once the shot has its own is another picture's, and
        so is any file of that picture's stem. It had been kept as another of this shot's
        originals (``raw/image_003_2.cr2``, a picture taken under an earlier step's light,
        recorded under this one's); it is handed over apart, so that nothing captured is lost
        and nothing is recorded under a light it was not taken under.

        Why both rules: a body still writing its JPEG announces it after a quiet spell. Quiet
        with the RAW in hand had ended the wait, and the late announcement was collected at
        the next shot as that shot's file (``raw/image_002.jpg`` was shot 1's JPEG). A file
        with the stem of an earlier shot's file (``IMG_0001.JPG`` after ``IMG_0001.CR2``) and
        not this shot's is the earlier shot's, never this one's. Any other file of another
        stem is a stray, whichever of its files comes first. (Stems do not pair files where
        libgphoto2 numbers each object of a RAM capture, ``capt0000.jpg`` and
        ``capt0001.nef`` (:data:`_RAM_CAPTURE_NAME`); there, and for a body naming every shot
        alike, only the one-RAW rule above tells a stray, and with two RAWs numbered apart the
        last picture is the shot's: :func:`_last_picture`.)
        """
        gp = self._gp
        wait_ms = 200
        budget_s = self.settings.event_timeout_s
        stem = Path(files[0][1]).stem
        # a card's names pair a shot's files by stem (IMG_0003.CR2, IMG_0003.JPG): a file of
        # another stem is another picture's, whichever comes first (a stray's JPEG or RAW
        # announced before this shot's RAW had been kept as this shot's)
        by_stem = _RAM_CAPTURE_NAME.fullmatch(stem) is None
        more: list[tuple[str, str]] = []
        late: list[tuple[str, str]] = []
        strays: list[tuple[str, str]] = []
        # Time is counted on the clock for every event, and "quiet" is time with no file
        # announced, whatever else the body reports. Only timeouts had been counted: a body
        # that reports a property change every few milliseconds (GP_EVENT_UNKNOWN "PTP
        # Property d105 changed", python-gphoto2 #50) never let the wait end, and the
        # session hung at its first image; a wait_for_event that blocks longer than asked
        # (libgphoto2 #151: about 1.2 s before a FILE_ADDED) is counted as it took.
        spent_s = quiet_s = 0.0
        while spent_s < budget_s:
            started = self._clock.now()
            event, data = self._call("wait_for_event", lambda: self._cam.wait_for_event(wait_ms))
            took = self._clock.now() - started
            if event == gp.GP_EVENT_TIMEOUT:
                took = max(took, wait_ms / 1000)  # a clock that does not see the wait
            spent_s += took
            if event == gp.GP_EVENT_FILE_ADDED:
                quiet_s = 0.0
                item = (str(data.folder), str(data.name))
                if item in files or item in more or item in late or item in strays:
                    continue  # some bodies re-announce the first
                name = Path(item[1])
                earlier = name.stem in self._earlier_stems
                if earlier and name.stem != stem:
                    late.append(item)
                elif (
                    (by_stem and name.stem != stem)
                    or name.stem in {Path(n).stem for _, n in strays}
                    or (
                        is_camera_raw(name) and any(is_camera_raw(Path(n)) for _, n in files + more)
                    )
                ):
                    strays.append(item)
                else:
                    more.append(item)
                continue
            quiet_s += took
            if quiet_s >= wait_ms / 1000:
                names = [Path(n) for _, n in files + more]
                have_raw = any(is_camera_raw(n) for n in names)
                have_jpeg = any(not is_camera_raw(n) for n in names)
                if have_raw and (have_jpeg or not self.settings.keep_jpeg):
                    break
        self._earlier_stems.update(Path(n).stem for _, n in files + more + strays)
        own = files + more
        if not by_stem:
            split = _last_picture(own + strays, returned=files[0])
            if split is not None:
                own, strays = split
        return own, late, strays

    def _list_folder(self, folder: str) -> set[str] | None:
        """The file names in a camera folder, or None where it cannot be listed (a RAM
        capture's folder on some bodies): one listing, never retried."""
        try:
            return {str(name) for name, _ in self._cam.folder_list_files(folder)}
        except self._gp.GPhoto2Error:
            return None

    def _unannounced(
        self,
        folder: str,
        known: list[tuple[str, str]],
        strays_known: Sequence[tuple[str, str]] = (),
    ) -> list[tuple[str, str]]:
        """Pictures the body took behind a busy answer and never announced (no FILE_ADDED
        event, ever), found on its card: the files in the shot's folder that were not there
        after the last shot in it and are not files this shot's events named.

        Looked for only when the shot came after busy answers (a body that is never busy
        costs one listing of its folder a session, in :meth:`_note_card`). Such a picture
        had stayed on the card unseen, the session saying nothing of it. In the camera's
        RAM (``capture_target = "Internal RAM"``) an unannounced picture has no file to list
        and cannot be seen at all; nor can one in a folder that was on the card at connect but
        not listed then (see :meth:`list_card`) before the session's first shot in it."""
        if not self._fired_after_busy or self.settings.capture_target == "Internal RAM":
            return []
        before = self._card_seen.get(folder)
        if before is None and self._card_folders is not None:
            # not on the card at connect: the body made it since, for this session's shots
            # the walk keeps "/" for the root, which rstrip("/") makes "": the root of a
            # body saving there had been taken for a folder made since, its files for strays
            before = set() if (folder.rstrip("/") or "/") not in self._card_folders else None
        if before is None:
            return []
        now = self._list_folder(folder)
        if now is None:
            return []
        named = {n for f, n in known if f.rstrip("/") == folder.rstrip("/")}
        # a card pairs a shot's files by stem: a file of this shot's stem or an earlier
        # shot's (its JPEG still being written, announced late or never) is no stray; the
        # shot's own JPEG had been downloaded into strays/ as "taken while answering busy"
        # on every step after a busy answer (RAW+JPEG, keep_jpeg off)
        ours = self._earlier_stems | {Path(n).stem for _, n in known}
        ours -= {Path(n).stem for _, n in strays_known}  # a stray's other file is a stray
        found = [(folder, n) for n in sorted(now - before - named) if Path(n).stem not in ours]
        self._card_seen[folder] = now
        self._earlier_stems.update(Path(n).stem for _, n in found)
        return found

    def list_card(self, say: Callable[[str], None]) -> None:
        """Before a capture session's first shot (``run``, not ``check`` or ``preview``), when
        shooting to the card: walk its folders and list the files of each innermost one
        (``DCIM/100CANON``), the "before" of the session's first shot in it; ``say`` is told
        before the walk, and when it stopped short.

        Why: a card folder was first listed after the session's first shot in it, so a
        picture the body took behind a busy answer before that shot (a body still writing
        the owner's last picture as the session began) was taken for a file that had always
        been there, and stayed on the card unseen. A folder made since (the body opening
        ``101CANON``) holds only new files. The walk had been done at every connect, unsaid
        and unbounded but for its folders: minutes on a full card of a body that reads each
        file's info to list it, in ``check`` and ``preview`` too. It stops before another
        folder past :data:`MAX_CARD_FOLDERS`, :data:`MAX_CARD_FILES` or
        :data:`MAX_CARD_WALK_S` (the first shot's listing then serves, as before)."""
        if self._cam is None or self.settings.capture_target == "Internal RAM":
            return
        say(
            f"Listing the camera's card ({self.name}), to tell a picture the camera takes "
            "before the first shot from those already there (a full card may take a while)…"
        )
        folders: set[str] = set()
        todo, files, started = ["/"], 0, self._clock.now()
        while todo:
            spent = self._clock.now() - started
            if (
                len(folders) >= MAX_CARD_FOLDERS
                or files >= MAX_CARD_FILES
                or (spent >= MAX_CARD_WALK_S)
            ):
                say(
                    f"Stopped listing the camera's card after {len(folders)} folders, "
                    f"{files} files, {spent:.0f} s: the check for a picture the camera takes "
                    "behind a busy answer before the session's first shot is off (after "
                    "each shot it is made as before); a card with fewer files lists faster"
                )
                return
            folder = todo.pop()
            try:
                subs = [str(n) for n, _ in self._cam.folder_list_folders(folder)]
            except self._gp.GPhoto2Error:
                return
            folders.add(folder)
            todo.extend(f"{folder.rstrip('/')}/{n}" for n in subs)
            if not subs and folder != "/":
                listed = self._list_folder(folder)
                if listed is None:
                    return
                self._card_seen[folder] = listed
                files += len(listed)
        self._card_folders = folders

    def _note_card(self, folder: str, taken: list[tuple[str, str]]) -> None:
        """Remember what the shot's card folder holds once its files are downloaded (and
        deleted): the "before" of the next busy spell's listing. Listed the first time a
        folder is seen; after that only the shot's own files are added (when they stay on
        the card), and a busy spell's listing (:meth:`_unannounced`) replaces it."""
        if self.settings.capture_target == "Internal RAM":
            return
        seen = self._card_seen.get(folder)
        if seen is None:
            listed = self._list_folder(folder)
            if listed is None:
                return
            seen = listed
        if self.settings.delete_from_camera:
            seen = seen - {n for _, n in taken}
        else:
            seen = seen | {n for _, n in taken}
        self._card_seen[folder] = seen

    def _card_filled_by_copies(self) -> str:
        """Said with a full card when the session keeps its shots' copies there ("" else).

        Why: with ``delete_from_camera = false`` every downloaded shot stays on the card, so
        the session itself fills it; the card-full error had said only to free the card or
        capture to RAM, not that the kept copies (and the key keeping them) were the cause."""
        s = self.settings
        if s.delete_from_camera or s.capture_target == "Internal RAM":
            return ""
        left = self._left_on_card
        return (
            f"; delete_from_camera = false in [camera.device] keeps each shot's copy on the "
            f"card ({left} file{'s' if left != 1 else ''} this session downloaded are still "
            "on it), which is what fills it: set delete_from_camera = true (each shot is "
            "deleted there only once it is in the session's raw/), or free the card, then "
            f"continue with: {resume_command(self.session_root)}"
        )

    def _delete(self, files: list[tuple[str, str]]) -> None:
        """Delete downloaded files on the camera (``delete_from_camera``); a card file whose
        delete fails is remembered (:attr:`_undeleted`), to be said with the shot.

        Why: every failed delete had been suppressed, for a RAM capture's object gone once
        downloaded; on a card (locked, write-protected, or a body refusing deletes over USB)
        the copy stayed there, filling it as the session went on, and nothing said so."""
        if not self.settings.delete_from_camera:
            self._left_on_card += len(files)
            return
        gp = self._gp
        for folder, name in files:
            try:
                self._cam.file_delete(folder, name)
            except gp.GPhoto2Error as exc:
                if not _in_ram(folder):  # a RAM capture's object may vanish once downloaded
                    self._undeleted.append((name, getattr(exc, "code", None)))

    def _where_notices(self, folder: str) -> list[str]:
        """What the shot's notices say of where the camera put it, when that is not where
        ``capture_target`` asked, and of a card copy whose delete failed ([] else).

        Why: the camera's folder was never compared with the target asked: a body that wrote
        to its card with ``capture_target = "Internal RAM"`` filled a card the user thought
        unused, and one that kept the shot in its RAM with the card asked (no card in it, or a
        body ignoring the setting) left no copy on the card the user counted on as a backup.
        Each text is the same for every shot, so the session says it once, with its count."""
        s = self.settings
        said: list[str] = []
        if s.capture_target == "Internal RAM" and not _in_ram(folder):
            fate = (
                "each is deleted there once downloaded"
                if s.delete_from_camera
                else "each stays there (delete_from_camera = false)"
            )
            said.append(
                f"the camera {self._device()} wrote its shots to its card ({folder.rstrip('/')}/)"
                f", not to its RAM as capture_target = 'Internal RAM' asks: {fate}"
            )
        elif s.capture_target and s.capture_target != "Internal RAM" and _in_ram(folder):
            said.append(
                f"the camera {self._device()} kept its shots in its RAM, not on its card as "
                f"capture_target = '{s.capture_target}' asks (no card in it, or a body that "
                "ignores the setting): no copy of them stays on the card; the session's raw/ "
                "holds the only one"
            )
        if self._undeleted:
            codes = sorted({str(c) for _, c in self._undeleted})
            said.append(
                f"the camera's card copy of a shot could not be deleted there after its "
                f"download (gphoto2 error {', '.join(codes)}: a locked or write-protected "
                "card, or a body that refuses deletes over USB): it stays on the card, which "
                "fills as the session goes on; the downloaded copy is kept whole. Free the "
                "card, or set delete_from_camera = false in [camera.device] to stop trying"
            )
        return said


def _in_ram(folder: str) -> bool:
    """Whether a capture's folder is the camera's RAM: libgphoto2's PTP driver names a capture
    kept there in ``/`` (``/capt0000.nef``), a card's in its storage (``/store_00020001/…``)."""
    return folder.rstrip("/") == ""


def _ram_number(name: str) -> int | None:
    """The object number of a libgphoto2 RAM capture name (``capt0003.cr2`` → 3), else None."""
    m = _RAM_CAPTURE_NAME.fullmatch(Path(name).stem)
    return int(m.group(1)) if m else None


def _last_picture(
    files: list[tuple[str, str]], returned: tuple[str, str]
) -> tuple[list[tuple[str, str]], list[tuple[str, str]]] | None:
    """(the shot's files, the strays) among a RAM capture's numbered files holding two RAWs
    or more, or None where numbers cannot order them (a body naming every shot alike).

    libgphoto2 numbers each object of a RAM capture as it sees it (``capt%04d``, a counter
    per object: camlibs/ptp2 ``capcnt++``), and a body announces its objects as it creates
    them, so a picture taken behind a busy answer, taken before the shot that succeeded, has
    the lower numbers: the shot's RAW is the highest-numbered one, and its JPEG the object
    next to it on the side the body puts its JPEG (before the RAW when the capture returned a
    JPEG, after it when it returned the RAW). The first RAW had been taken as the shot's: on
    a body returning the JPEG of RAW+JPEG, the stray's RAW, announced before the shot's own,
    was kept as the image (and the stray's JPEG as a second JPEG of the step), the shot's own
    RAW set aside as the stray."""
    numbers = [_ram_number(n) for _, n in files]
    raws = [f for f in files if is_camera_raw(Path(f[1]))]
    if len(raws) < 2 or None in numbers or len(set(numbers)) != len(numbers):
        return None
    raw = max(raws, key=lambda f: _ram_number(f[1]) or 0)
    n = _ram_number(raw[1]) or 0
    jpeg_number = n - 1 if not is_camera_raw(Path(returned[1])) else n + 1
    own = [raw] + [
        f for f in files if not is_camera_raw(Path(f[1])) and _ram_number(f[1]) == jpeg_number
    ]
    return own, [f for f in files if f not in own]


@dataclass
class _BusySpell:
    """One wait for a busy camera: its tries so far, the time waited, the next wait."""

    delay_s: float
    tries: int = 0
    waited_s: float = 0.0
    #: when its first try was made (on the camera's clock)
    first_try_at: float = 0.0


class _SavedShort(OSError):
    """A save gphoto2 reported done whose file on disk is shorter than the camera's."""

    def __str__(self) -> str:
        return str(self.strerror)


def _check_saved_whole(camera_file: Any, target: Path) -> None:
    """Raise :class:`_SavedShort` if ``target`` holds fewer bytes than ``camera_file``.

    ``gp_file_save`` returns GP_OK even when its final ``fclose`` could not flush the last
    buffered block to a full disk (it ignores ``fclose``'s result): only the size tells.
    The camera file's size is its data in memory (python-gphoto2's
    ``get_data_and_size``); a file whose data cannot be had is not checked, nor one another
    program took away as it landed (the decode that follows says that, naming the folder)."""
    try:
        expected = memoryview(camera_file.get_data_and_size()).nbytes
    except Exception:  # an older binding, or a file not in memory: not checked
        return
    try:
        got = target.stat().st_size
    except FileNotFoundError:
        return
    if got < expected:
        raise _SavedShort(
            errno.ENOSPC,
            f"only {got} of its {expected} bytes reached the disk, though gphoto2 reported "
            "the save done",
        )


def _create_refused(target: Path) -> OSError | None:
    """The error creating ``target`` gives now, or None if a file can be created there.

    Why: ``gp_file_save`` answers both a refused ``fopen`` and a short write with GP_ERROR
    (-1) and no file; trying the ``fopen`` again tells a folder that cannot be written into
    (permissions, a read-only mount, a folder gone) from a full disk."""
    try:
        with open(target, "xb"):
            pass
    except FileExistsError:
        return None
    except OSError as exc:  # a disk out of inodes or quota refuses the file too: that is full
        return None if exc.errno in (errno.ENOSPC, errno.EDQUOT) else exc
    with contextlib.suppress(OSError):
        target.unlink()
    return None


def _unused(folder: Path, name: str) -> Path:
    """``folder/name``, or with a ``-2``, ``-3``… suffix if taken: never overwrite a download."""
    target = folder / name
    n = 2
    while target.exists():
        target = folder / f"{Path(name).stem}-{n}{Path(name).suffix}"
        n += 1
    return target


def _number(text: str | None) -> float:
    try:
        return float(text) if text is not None else 0.0
    except ValueError:
        return 0.0


def _several_cameras(detected: list[tuple[str, str]]) -> str:
    """The refusal of a config with no ``port`` when several cameras are on the bus: each in
    words and the line that takes it. Why: it had read "several cameras found [('Canon EOS
    600D', 'usb:001,005'), ('Nikon D750', 'usb:001,006')]: set 'port' to choose one", a Python
    list and no line to paste. Two bodies of one model are told apart by unplugging one: the
    port is where a camera is plugged, not which camera it is."""
    found = _cameras_said(detected)
    lines = " or ".join(f'port = "{where}"' for _, where in detected)
    same = (
        " Two of them are the same model: unplug one to see which port is left."
        if len({model for model, _ in detected}) < len(detected)
        else ""
    )
    return (
        f"{len(detected)} cameras found: {found}. Set the one to use in [camera.device]: "
        f"{lines} ({USB_PORT_SAID}).{same}"
    )


#: Why a ``usb:BUS,DEVICE`` port is no camera's lasting name (said with a port to set).
USB_PORT_SAID = (
    "a usb: port is the USB device number, which changes each time the camera is plugged in "
    "again or wakes from its power saving"
)


def _cameras_said(detected: list[tuple[str, str]]) -> str:
    """The cameras gphoto2 found, in words: ``Canon EOS 600D on usb:001,005; …``."""
    return "; ".join(f"{model} on {where}" for model, where in detected)


def _port_gone(port: str, detected: list[tuple[str, str]]) -> str:
    """The refusal of a configured ``port`` no camera is on, naming the cameras found.

    Why worded so: libgphoto2's ``usb:BUS,DEVICE`` is the USB device number, which the
    system gives anew at every plugging. A camera that dropped off a hub mid-session and came
    back is on another one (usb:001,004 → usb:001,005), and the refusal had been "no camera on
    port usb:001,004; found [('Canon EOS 600D', 'usb:001,005')]": a Python list, and nothing
    of why nor what to do. rti-rig does not take the other camera by itself (with ``port`` set
    there may be two bodies, and a resume must not shoot the rest on the wrong one): it names
    what is there and the line to change; the port is not part of the session's rig identity,
    so the resume then goes on."""
    found = _cameras_said(detected)
    usb = f" ({USB_PORT_SAID})" if port.startswith("usb:") else ""
    fix = (
        f'set port = "{detected[0][1]}" in [camera.device], or remove the port line to '
        "use the only camera found"
        if len(detected) == 1
        else "set port in [camera.device] to the one to use"
    )
    return f"no camera on port {port}{usb}; cameras found now: {found}. If it is yours, {fix}"
