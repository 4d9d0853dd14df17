"""Shared fixtures: repository paths and small rigs built from the shipped configs."""

from __future__ import annotations

import contextlib
import json
import os
import queue
import re
import signal
import socket
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any, AnyStr, NamedTuple

import pytest
from hypothesis import HealthCheck, settings

# Property tests check results, never speed: no per-example deadline and no "input generation
# is slow" health check, both of which fail a correct test on a loaded 2-core machine (one
# did: test_round_trip_exact_to_1e6, while another suite ran beside it). Every @settings in
# the tests inherits this profile for what it does not set itself.
settings.register_profile("rti-rig", deadline=None, suppress_health_check=[HealthCheck.too_slow])
settings.load_profile("rti-rig")


def _hangup_outlived(signum: int, frame: Any) -> None:
    """The suite's own answer to a hang-up where it was started to outlive one (``nohup``)."""


# The hang-up tests need SIGHUP as a terminal leaves it, not ignored. Under `nohup` (or a CI
# wrapper that ignores SIGHUP) the ignored disposition is inherited by every child, across exec:
# rti-rig then rightly installs nothing (a nohup'd session is meant to outlive its terminal), the
# tests' hang-ups never arrived, and two of them waited forever for a child that waited for a
# reader (a rehearsal of CI started with `nohup` hung for 45 minutes, 2026-12-05). A handler
# that does nothing keeps what nohup asked (the suite outlives its terminal) and is not
# "ignored": rti-rig answers hang-ups in-process as on a terminal, and a handler, unlike an
# ignored signal, is reset to the default in every program a test executes. The xdist workers
# (executed, so at the default) are told by the environment to do the same.
_OUTLIVE_HANGUP = "RTI_RIG_TESTS_OUTLIVE_HANGUP"
if hasattr(signal, "SIGHUP") and (
    signal.getsignal(signal.SIGHUP) == signal.SIG_IGN or os.environ.get(_OUTLIVE_HANGUP)
):
    signal.signal(signal.SIGHUP, _hangup_outlived)
    os.environ[_OUTLIVE_HANGUP] = "1"

# Likewise Ctrl-C: a shell without job control starts a background job (`cmd &` in a script)
# with SIGINT ignored, and every child inherits that across exec, so Python installs no
# KeyboardInterrupt and the Ctrl-C tests' SIGINT never arrived: a rehearsal of CI started that
# way had them fail or wait 600 s each for a child that never stopped (2026-12-05). Python's
# own handler is what a terminal leaves, and a handler, unlike an ignored signal, is reset to
# the default in every program a test executes.
if signal.getsignal(signal.SIGINT) == signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)

REPO = Path(__file__).resolve().parent.parent
CONFIGS = REPO / "rig_configs"


@contextlib.contextmanager
def shipped_dome_on_pty(monkeypatch: pytest.MonkeyPatch, config: Path) -> Iterator[Any]:
    """The dome firmware a hardware config names, emulated on a pty, the config's port
    redirected there: everything above ``serial.serial_for_url`` is the real stack, as a
    user's command builds it from the file. Yields the emulator (its history).

    The emulator is the one the config's profile names: rti-rig's own protocols (``default``,
    ``framed``, ``binary``) get :class:`DomeFirmware` with 48 LEDs; another project's firmware
    (``rtipy``, ``nab-rti-v1`` …) gets its own board from ``rti_rig.simulator.domes``, as the
    shipped ``emulated_*.toml`` dry runs do (``Board``: its own LEDs, baud rate, ``events``).
    Why: the fixture had served every profile the codec-driven ``DomeFirmware``, which spoke
    the binary protocol for a scripted profile: a test "on RTIPy" met a binary board (probe:
    "Found: binary"). A profile with no serial emulator (a dome stepped by the camera's flash,
    no ``[dome.serial]``) is refused, never served something else."""
    import serial

    from rti_rig.app.config import load_rig_config
    from rti_rig.core.clock import SystemClock
    from rti_rig.simulator.dome_firmware import RESET_BOOT_S, emulated_dome_on_pty, firmware_for
    from rti_rig.simulator.domes import SERIAL_FIRMWARES, board_for
    from rti_rig.simulator.pty_link import serve_on_pty

    dome = load_rig_config(config).config.dome
    if dome is None or dome.serial is None:
        raise ValueError(f"{config}: no [dome.serial], so no serial firmware to emulate on a pty")
    serial_settings = dome.serial
    profile = serial_settings.profile
    serving: contextlib.AbstractContextManager[Any]
    if profile in SERIAL_FIRMWARES:
        from rti_rig.drivers.led_dome.factory import protocol_for

        led_map = protocol_for(serial_settings).led_map
        firmware: Any = board_for(profile, clock=SystemClock(), led_map=led_map)
        serving = serve_on_pty(firmware, profile)
    elif profile in OWN_DOME_PROTOCOLS:
        # with its bootloader's time after each reset, as the emulator rti-rig ships serves it:
        # a board with none "printed" its banner before the host's open had flushed its input
        # (a probe under load heard "(nothing)" at 115200 baud; see RESET_BOOT_S)
        firmware = firmware_for(
            serial_settings, led_count=48, clock=SystemClock(), boot_delay_s=RESET_BOOT_S
        )
        serving = emulated_dome_on_pty(firmware)
    else:
        raise ValueError(
            f"{config}: no emulator of dome profile {profile!r} to serve (own protocols "
            f"{', '.join(OWN_DOME_PROTOCOLS)}; firmwares {', '.join(SERIAL_FIRMWARES)})"
        )
    real = serial.serial_for_url
    with serving as link:

        def redirect(url, *args, **kwargs):  # type: ignore[no-untyped-def]
            return real(link.port if url == serial_settings.port else url, *args, **kwargs)

        monkeypatch.setattr(serial, "serial_for_url", redirect)
        yield firmware


#: The dome protocols of rti-rig's own (docs/protocols/led-dome.md), which ``DomeFirmware``
#: emulates from that page (``rti_rig.simulator.own_protocols``); every other profile is a real
#: firmware's.
OWN_DOME_PROTOCOLS = ("default", "framed", "binary")


def folder_watch_config(
    tmp_path: Path,
    tether: Path,
    *,
    timeout_s: float | None = None,
    tiffs: bool = False,
    settle_s: float | None = None,
) -> Path:
    """The shipped folder-watch dome config watching ``tether``, its LED .lp named where it
    ships; ``timeout_s`` replaces its wait for a file, ``tiffs`` watches for ``*.tif`` only,
    ``settle_s`` replaces the dome's settle before each shot (1.5 s puts the shutter pulses
    whole EXIF seconds apart, for the camera-clock tests). (One rewrite for the folder-watch
    CLI tests, which had each kept, or imported from another test module, a copy.)"""
    text = (CONFIGS / "example_dome_48_folder_watch.toml").read_text(encoding="utf-8")
    changes = [
        ('lp_file = "example_dome_48.lp"', f'lp_file = "{CONFIGS / "example_dome_48.lp"}"'),
        ('folder = "~/Pictures/rti-tether"', f'folder = "{tether}"'),
    ]
    if timeout_s is not None:
        changes.append(("timeout_s = 15.0", f"timeout_s = {timeout_s}"))
    if settle_s is not None:
        changes.append(("settle_s = 0.2\n", f"settle_s = {settle_s}\n"))
    for old, new in changes:
        assert old in text, old
        text = text.replace(old, new)
    if tiffs:
        start = text.index("patterns = [")
        text = text.replace(text[start : text.index("]\n", start) + 1], 'patterns = ["*.tif"]')
    cfg = tmp_path / "example_dome_48_folder_watch.toml"
    cfg.write_text(text, encoding="utf-8")
    return cfg


class Tether(threading.Thread):
    """A camera and its tethering program on an emulated board: the board's n-th shutter
    pulse becomes ``files[n - 1]`` (a name and its bytes) in ``folder``, written whole."""

    def __init__(self, firmware: Any, folder: Path, files: list[tuple[str, bytes]]) -> None:
        super().__init__(daemon=True)
        self.firmware, self.folder, self.files = firmware, folder, files
        self.stop = threading.Event()

    def run(self) -> None:
        saved = 0
        while not self.stop.is_set() and saved < len(self.files):
            pulses = sum(e.what == "shutter" for e in list(self.firmware.history))
            if pulses > saved:
                self.save(*self.files[saved])
                saved += 1
            self.stop.wait(0.02)

    def save(self, name: str, data: bytes) -> None:
        """How the tethering program puts one shot into the folder: written in place here;
        a subclass saves it another way (a temporary renamed over the name)."""
        (self.folder / name).write_bytes(data)


class TetheredRun(NamedTuple):
    """What a tethered ``rti-rig run`` left for a test to assert on: the CLI result, its
    output unwrapped (one line), and the LEDs the board had lit once the command ended."""

    result: Any
    said: str
    lit_at_end: list[int]


def tethered_run(
    monkeypatch: pytest.MonkeyPatch,
    cfg: Path,
    tether: Path,
    files: list[tuple[str, bytes]],
    out: Path,
    camera: Callable[[Any], Any] | None = None,
    lights: int = 2,
    resume: bool = False,
) -> TetheredRun:
    """``rti-rig run cfg --out out --lights <lights> --no-verdict`` (with ``resume``: ``rti-rig
    run --resume out --no-verdict``) on the shipped dome emulated on a pty
    (:func:`shipped_dome_on_pty`), a :class:`Tether` saving ``files`` into ``tether`` (or the
    thread ``camera(firmware)`` builds: one with a ``stop`` event), stopped whatever the
    command did. One spelling of the folder-watch CLI tests' set-up, which had each written
    it out."""
    from typer.testing import CliRunner

    from rti_rig.cli import app

    with shipped_dome_on_pty(monkeypatch, cfg) as firmware:
        thread = camera(firmware) if camera is not None else Tether(firmware, tether, files)
        thread.start()
        try:
            args = (
                ["run", "--resume", str(out), "--no-verdict"]
                if resume
                else ["run", str(cfg), "--out", str(out), "--lights", str(lights), "--no-verdict"]
            )
            r = CliRunner().invoke(app, args, terminal_width=400)
        finally:
            thread.stop.set()
            thread.join(5.0)
        lit_at_end = firmware.lit_indices()
    return TetheredRun(r, " ".join(r.output.split()), lit_at_end)


class TiffRun(NamedTuple):
    """What :func:`tethered_tiffs` left: :class:`TetheredRun`'s facts, and the watched folder
    and the session folder it used."""

    result: Any
    said: str
    tether: Path
    out: Path
    lit_at_end: list[int]


def tethered_tiffs(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, files: list[bytes]) -> TiffRun:
    """:func:`tethered_run` of the shipped folder-watch dome watching ``tmp_path/tether`` for
    ``*.tif``, the n-th shutter pulse saving ``files[n - 1]`` as ``IMG_000n.tif``, into
    ``tmp_path/s``. One spelling of the watched-TIFF tests' set-up (three files had each
    written the folder, the config and the names out)."""
    tether = tmp_path / "tether"
    tether.mkdir()
    cfg = folder_watch_config(tmp_path, tether, timeout_s=20.0, tiffs=True)
    out = tmp_path / "s"
    named = [(f"IMG_{n:04d}.tif", f) for n, f in enumerate(files, 1)]
    r, said, lit_at_end = tethered_run(monkeypatch, cfg, tether, named, out)
    return TiffRun(r, said, tether, out, lit_at_end)


def refused_and_waited(monkeypatch: pytest.MonkeyPatch) -> threading.Event:
    """An event set once the folder-watch camera waits on a file it read and refused (its
    ``_changed_and_settled``): a test's writer, paused part-way, may then finish the file.
    Why an event: the writer waits on it, not on a sleep a loaded machine could outrun."""
    from rti_rig.drivers.cameras import folder_watch

    tried = threading.Event()
    real = folder_watch.FolderWatchCamera._changed_and_settled

    def waits(self: Any, *args: Any) -> Any:
        tried.set()
        return real(self, *args)

    monkeypatch.setattr(folder_watch.FolderWatchCamera, "_changed_and_settled", waits)
    return tried


#: The handlers a test must leave as it found them: a command run in the pytest process
#: (CliRunner) that left SIGINT ignored made every later subprocess a test started inherit an
#: ignored Ctrl-C (red in CI only, far from the test that leaked it).
# SIGHUP too where there is one: run, preview, check, probe, fit, plan and calibrate-lights
# answer a hang-up (hangup_as_sigterm), and a handler they leave set is a leak as SIGTERM's is
_WATCHED_SIGNALS = (signal.SIGINT, signal.SIGTERM) + (
    (signal.SIGHUP,) if hasattr(signal, "SIGHUP") else ()
)


def pytest_configure(config: pytest.Config) -> None:
    """Point the emulated servos' latched-error folder at a temporary one for the whole run,
    before any fixture: session-scoped fixtures run before the per-test
    :func:`_emulated_servos_power_cycled`, and one driving an emulated arm would otherwise
    write the user's own folder (and find a fault a developer's rehearsal left there)."""
    import os
    import shutil
    import tempfile

    from rti_rig.runtime.duty_ledger import LEDGER_DIR_ENV
    from rti_rig.simulator.servo_latch import STATE_DIR_ENV

    for env, prefix in (
        (STATE_DIR_ENV, "rti-rig-test-servo-state-"),
        # the dome duty ledgers too: a session-scoped fixture's run on a shipped dome would
        # otherwise write the user's own ledger (and wait for LEDs a rehearsal left hot)
        (LEDGER_DIR_ENV, "rti-rig-test-dome-duty-"),
    ):
        folder = tempfile.mkdtemp(prefix=prefix)
        before = os.environ.get(env)
        os.environ[env] = folder

        def restore(env: str = env, before: str | None = before, folder: str = folder) -> None:
            if before is None:
                os.environ.pop(env, None)
            else:
                os.environ[env] = before
            shutil.rmtree(folder, ignore_errors=True)

        config.add_cleanup(restore)


@pytest.fixture(autouse=True)
def _emulated_servos_power_cycled(
    tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Each test's emulated servo chains start powered up fresh: their latched hardware
    errors (kept between commands, :mod:`rti_rig.simulator.servo_latch`) go to the test's
    own folder, never the user's, nor another test's (child processes inherit it)."""
    from rti_rig.simulator.servo_latch import STATE_DIR_ENV

    monkeypatch.setenv(STATE_DIR_ENV, str(tmp_path_factory.mktemp("servo-state")))


#: The terminal width every test's CLI output is rendered at (:func:`_wide_console`).
WIDE_COLUMNS = 400


@pytest.fixture(autouse=True)
def _wide_console(monkeypatch: pytest.MonkeyPatch) -> None:
    """Every test's rich consoles (the CLI's ``out``/``err``, typer's help) render
    :data:`WIDE_COLUMNS` wide, as rich reads ``COLUMNS`` when it prints; a child process
    (``python -m rti_rig``) inherits it.

    Why: with no terminal rich wraps at 80 and folds a token longer than the line mid-word
    (``x.l p``), so a test looking for a path in the output failed wherever pytest's basetemp
    was long (``/tmp/pytest-of-root/pytest-2NN/test_name_with_long_words0/...``), and
    ``said()``'s unwrapping cannot mend a fold. ``CliRunner.invoke(terminal_width=...)`` sets
    click's width only, not rich's. A test of the wrapping at a user's width says its own
    (``CliRunner(env={"COLUMNS": "80"})``). Users' output is unchanged: this is the tests'."""
    monkeypatch.setenv("COLUMNS", str(WIDE_COLUMNS))
    cli_app = sys.modules.get("rti_rig.cli.app")
    if cli_app is not None:  # a width fixed as it was imported (COLUMNS exported then) yields
        for console in (cli_app.out, cli_app.err):
            monkeypatch.setattr(console, "_width", None)


@pytest.fixture(autouse=True)
def _dome_leds_cold(
    tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Each test's domes start with cold LEDs: a duty ledger of their own, so an earlier
    test's run on the same shipped config does not make this test's LEDs wait (a test that
    means to, runs both commands itself)."""
    from rti_rig.runtime.duty_ledger import LEDGER_DIR_ENV

    monkeypatch.setenv(LEDGER_DIR_ENV, str(tmp_path_factory.mktemp("dome-duty")))


@pytest.fixture(autouse=True)
def _signal_handlers_left_as_found() -> Iterator[None]:
    """Fail the test that changes a SIGINT/SIGTERM/SIGHUP handler and does not put it back.

    Why: a leaked handler shows up tests later, in whichever test next relies on it (a child
    process inheriting an ignored Ctrl-C); caught here, the failure names the test that leaked
    it. The handler is put back first, so one leak does not fail every test after it."""
    before = {sig: signal.getsignal(sig) for sig in _WATCHED_SIGNALS}
    yield
    leaked = []
    for sig, handler in before.items():
        now = signal.getsignal(sig)
        if now != handler:
            leaked.append(f"{signal.Signals(sig).name}: {handler!r} before, {now!r} after")
            if handler is not None:  # None: set outside Python, cannot be put back
                signal.signal(sig, handler)
    if leaked:
        pytest.fail("the test left signal handlers changed: " + "; ".join(leaked))


def built_rigs(monkeypatch: pytest.MonkeyPatch) -> list[Any]:
    """The rigs ``rti-rig check`` (its walk, ``--park-only``) builds from here on, each
    appended as built (``build_rig`` wrapped where the check and the park use it): a test
    reads the rig's lighting after the command, as the command left it."""
    import rti_rig.app.compose as compose
    import rti_rig.app.usecases.check as check_usecase
    import rti_rig.app.usecases.park as park_usecase

    rigs: list[Any] = []
    real_build = compose.build_rig

    def build(*args: Any, **kwargs: Any) -> Any:
        rigs.append(real_build(*args, **kwargs))
        return rigs[-1]

    for module in (compose, check_usecase, park_usecase):
        monkeypatch.setattr(module, "build_rig", build)
    return rigs


@pytest.fixture
def dome_config_path() -> Path:
    return CONFIGS / "simulated_dome.toml"


@pytest.fixture
def arm_config_path() -> Path:
    return CONFIGS / "virtual_arm.toml"


@pytest.fixture
def closed_port() -> Iterator[int]:
    """A local port bound but not listening: a connection to it is refused (Linux), and no
    other program can take it meanwhile."""
    sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    try:
        sock.bind(("127.0.0.1", 0))
        yield sock.getsockname()[1]
    finally:
        sock.close()


def write_config(tmp_path: Path, text: str, name: str = "rig.toml") -> Path:
    p = tmp_path / name
    p.write_text(text, encoding="utf-8")
    return p


def inprocess_arm_config(tmp_path: Path, extra: str = "") -> Path:
    """simulated_arm.toml with its servos emulated in-process (the real driver and SDK packet
    code without a pty thread: the fastest path), ``extra`` appended (``[[emulator.faults]]``)."""
    text = (CONFIGS / "simulated_arm.toml").read_text()
    assert 'transport = "pty"' in text
    cfg = tmp_path / "arm.toml"
    cfg.write_text(text.replace('transport = "pty"', 'transport = "inprocess"') + extra)
    return cfg


def shipped_variant(
    folder: Path, shipped: str, edits: tuple[tuple[str, str], ...], emulator: str = ""
) -> Path:
    """``rig_configs/<shipped>`` written to ``folder/rig.toml`` with each ``(old, new)`` edit
    made and ``emulator`` as its ``[emulator]`` block (none if empty). Each ``old`` must be in
    the shipped text: a shipped config that changed fails here, by name, not as a session that
    quietly ran on another scene or seed."""
    text = (CONFIGS / shipped).read_text(encoding="utf-8")
    for old, new in edits:
        assert old in text, f"{shipped}: {old!r}"
        text = text.replace(old, new)
    config = folder / "rig.toml"
    config.write_text(text + (f"\n[emulator]\n{emulator}" if emulator else ""), encoding="utf-8")
    return config


def qa_of(session: Path, out: Path) -> tuple[str, dict]:  # type: ignore[type-arg]
    """The QA verdict of ``rti-rig fit session --out out`` with no fit but the QA's: its words
    (one line) and its ``qa.json``."""
    from typer.testing import CliRunner

    from rti_rig.cli import app

    r = CliRunner().invoke(
        app, ["fit", str(session), "--out", str(out), "--no-ptm", "--no-hsh", "--no-normals"]
    )
    assert r.exit_code == 0, r.output
    return " ".join(r.output.split()), json.loads((out / "qa.json").read_text())


def planned_preview(preview: Path, out: Path, *extra: str) -> str:
    """What ``rti-rig plan PREVIEW --rig simulated_dome.toml --method uniform --out OUT``
    (and ``extra``) said, on one line, having checked it ended well: the preview tests read
    the plan's words on how it read the file (orientation, colour space)."""
    from typer.testing import CliRunner

    from rti_rig.cli import app

    argv = ["plan", str(preview), "--rig", str(CONFIGS / "simulated_dome.toml")]
    r = CliRunner().invoke(
        app, [*argv, "--method", "uniform", *extra, "--out", str(out)], terminal_width=400
    )
    said = " ".join(r.output.split())
    assert r.exit_code == 0 and "Traceback" not in said, said
    return said


def servo_fault(at_command: int, servo_id: int, kind: str = "overload") -> str:
    """An ``[[emulator.faults]]`` table of the emulated arm (to append to its config, e.g. as
    :func:`inprocess_arm_config`'s ``extra``): servo ``servo_id`` reports ``kind`` from the
    ``at_command``-th packet on. One spelling of the table for the arm fault tests."""
    return (
        f'\n[[emulator.faults]]\nat_command = {at_command}\nkind = "{kind}"\n'
        f"servo_id = {servo_id}\n"
    )


def run_faulted_arm(tmp_path: Path, kind: str, servo_id: int = 1) -> str:
    """Run ``rti-rig run`` (12 lights, no verdict) in a process of its own on the in-process
    emulated arm whose servo ``servo_id`` reports ``kind`` from its 150th packet, as a user
    would, and return all it printed, whitespace joined. The run must end on the fault (exit
    2), with no traceback. A process of its own: the stop's warnings are log records, printed
    on the real stderr, which a CliRunner does not show as a user sees them."""
    import os

    cfg = inprocess_arm_config(tmp_path, servo_fault(150, servo_id, kind))
    run = ["run", str(cfg), "--lights", "12", "--out", str(tmp_path / "s"), "--no-verdict"]
    r = subprocess.run(
        [sys.executable, "-m", "rti_rig", *run],
        capture_output=True,
        text=True,
        timeout=600,
        env={**os.environ, "COLUMNS": "400"},
    )
    said = " ".join((r.stdout + r.stderr).split())
    assert r.returncode == 2 and "Traceback" not in said, said
    return said


def emulators_built_by_check(monkeypatch: pytest.MonkeyPatch) -> list[Any]:
    """The emulators of the rigs ``rti-rig check`` builds from here on (``build_rig`` wrapped
    where compose and the check use case import it): what a test reads the servos' state
    from after the command."""
    import rti_rig.app.compose as compose
    import rti_rig.app.usecases.check as check_usecase

    emulators: list[Any] = []
    real_build = compose.build_rig

    def build(*args: Any, **kwargs: Any) -> Any:
        rig = real_build(*args, **kwargs)
        emulators.append(rig.emulator)
        return rig

    monkeypatch.setattr(compose, "build_rig", build)
    monkeypatch.setattr(check_usecase, "build_rig", build)  # imported by name there
    return emulators


def virtual_arm_variant(tmp_path: Path, scene: str, side: int | None = None) -> Path:
    """The shipped virtual arm (512 px, the relief) with another simulated scene and, if
    given, square frames of ``side`` px: what the QA tests run correct sessions on."""
    text = (CONFIGS / "virtual_arm.toml").read_text()
    assert "width = 512\nheight = 512" in text and 'name = "relief"' in text
    if side is not None:
        text = text.replace("width = 512\nheight = 512", f"width = {side}\nheight = {side}")
    return write_config(tmp_path, text.replace('name = "relief"', f'name = "{scene}"'), "arm.toml")


def emulated_dome_as_hardware(tmp_path: Path, shipped: str, port: str) -> Path:
    """The shipped emulated dome config ``shipped`` as a user's hardware copy of it: its board
    on ``port`` (an emulator served on a pty) and a watched-folder camera, as a real dome with
    a tethered camera is configured.

    Edited as TOML (read with tomllib, written back by :func:`toml_text`), not as text: the
    text edit put ``[camera.device]`` at the first ``[timing]`` of the file, which in
    emulated_rtipy.toml is inside a comment, and wrote a file TOML refuses."""
    import tomllib

    data = tomllib.loads((CONFIGS / shipped).read_text(encoding="utf-8"))
    assert data["backend"] == "emulated" and data["dome"]["serial"]["port"] == "emulated", shipped
    data["backend"] = "hardware"
    data["dome"]["serial"]["port"] = port
    (tmp_path / "tether").mkdir()
    data["camera"]["device"] = {"kind": "folder_watch", "folder": str(tmp_path / "tether")}
    return write_config(tmp_path, toml_text(data), "dome.toml")


def toml_text(data: dict[str, Any]) -> str:
    """``data`` (as ``tomllib`` reads a rig config: tables, arrays of tables, strings,
    numbers, booleans and arrays of those) as a TOML document that reads back as ``data``,
    checked. For tests that change a shipped config by key (the standard library reads TOML
    but writes none)."""
    from rti_rig.core.toml_strings import toml_basic_string

    def value(v: Any) -> str:
        if isinstance(v, bool):
            return "true" if v else "false"
        if isinstance(v, int | float):
            return repr(v)
        if isinstance(v, str):
            return toml_basic_string(v)
        if isinstance(v, list):
            return "[" + ", ".join(value(x) for x in v) + "]"
        if isinstance(v, dict):
            return "{" + ", ".join(f"{key(k)} = {value(x)}" for k, x in v.items()) + "}"
        raise TypeError(f"no TOML for {v!r}")

    def key(k: str) -> str:
        return k if re.fullmatch(r"[A-Za-z0-9_-]+", k) else toml_basic_string(k)

    def is_tables(v: Any) -> bool:
        return isinstance(v, list) and bool(v) and all(isinstance(x, dict) for x in v)

    lines: list[str] = []

    def table(d: dict[str, Any], path: list[str]) -> None:
        for k, v in d.items():
            if not isinstance(v, dict) and not is_tables(v):
                lines.append(f"{key(k)} = {value(v)}")
        for k, v in d.items():
            name = ".".join(key(p) for p in [*path, k])
            if isinstance(v, dict):
                lines.extend(["", f"[{name}]"])
                table(v, [*path, k])
            elif is_tables(v):
                for item in v:
                    lines.extend(["", f"[[{name}]]"])
                    table(item, [*path, k])

    table(data, [])
    text = "\n".join(lines).lstrip("\n") + "\n"
    import tomllib

    assert tomllib.loads(text) == data, "toml_text wrote a document that reads back otherwise"
    return text


def dome_variant(tmp_path: Path, scene: str, side: int) -> Path:
    """The shipped simulated dome with another simulated scene and square frames of ``side``
    px: what the QA tests run correct sessions of the dome on."""
    text = (CONFIGS / "simulated_dome.toml").read_text()
    text, n_w = re.subn(r"(?m)^width = \d+", f"width = {side}", text)
    text, n_h = re.subn(r"(?m)^height = \d+", f"height = {side}", text)
    text, n_s = re.subn(r'(?ms)(\[scene\].*?^name = )"[^"]*"', rf'\g<1>"{scene}"', text)
    assert (n_w, n_h, n_s) == (1, 1, 1), "simulated_dome.toml no longer has one width/height/scene"
    return write_config(tmp_path, text, f"{scene}_{side}.toml")


def signal_as_the_teardown_switches_off(
    monkeypatch: pytest.MonkeyPatch, signum: signal.Signals
) -> list[bool]:
    """Raise ``signum`` in this process as the first emergency teardown switches the dome's
    lights off (``DomeLighting.safe(emergency=True)``), once, with no timing: a signal landing
    mid-teardown. The list returned holds ``True`` once it was raised."""
    from rti_rig.runtime.lighting import DomeLighting

    real_safe = DomeLighting.safe
    sent: list[bool] = []

    def safe(self, emergency: bool = False) -> list[str]:  # type: ignore[no-untyped-def]
        if emergency and not sent:
            sent.append(True)
            signal.raise_signal(signum)
        return real_safe(self, emergency)

    monkeypatch.setattr(DomeLighting, "safe", safe)
    return sent


#: A folder name whose byte 0xe9 is not UTF-8 (Latin-1's é), with a space and a quote.
NOT_UTF8_NAME = b"caf\xe9 it's"
#: A ``$'...'`` word as printed: its quote and backslash escaped inside.
DOLLAR_WORD = re.compile(rb"\$'(?:[^'\\]|\\.)*'")
#: A C locale with an ASCII stdout, as a script on a legacy system runs rti-rig.
ASCII_LOCALE_ENV = {
    **os.environ,
    "PYTHONPATH": str(REPO),
    "LC_ALL": "C",
    "PYTHONIOENCODING": "ascii",
}


@pytest.fixture
def not_utf8_acquisition(tmp_path: Path) -> Path:
    """The .lp of six small grey JPEGs in a folder whose name is not UTF-8
    (:data:`NOT_UTF8_NAME`: an archive unpacked with its Windows names), lit from two
    elevations so a photometric-stereo fit finds normals. Two tests had each built it."""
    import cv2
    import numpy as np

    odd = tmp_path / os.fsdecode(NOT_UTF8_NAME)
    odd.mkdir()
    lines = ["6"]
    for i in range(6):
        az, el = 2 * np.pi * i / 6, np.radians(30 + 30 * (i % 2))
        d = (np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el))
        grey = np.full((24, 32), 40 + 30 * i, np.uint8)
        (odd / f"img{i}.jpg").write_bytes(cv2.imencode(".jpg", grey)[1].tobytes())
        lines.append(f"img{i}.jpg " + " ".join(f"{c:.6f}" for c in d))
    (odd / "dirs.lp").write_text("\n".join(lines) + "\n")
    return odd / "dirs.lp"


def rti_rig_in_ascii_locale(*args: str | Path) -> subprocess.CompletedProcess[bytes]:
    """``python -m rti_rig *args`` in :data:`ASCII_LOCALE_ENV`, its streams as bytes; no
    traceback."""
    r = subprocess.run(
        [sys.executable, "-m", "rti_rig", *map(str, args)],
        capture_output=True,
        env=ASCII_LOCALE_ENV,
        timeout=600,
    )
    assert b"Traceback" not in r.stderr, r.stderr
    return r


def pasted(word: bytes) -> bytes:
    """What bash makes of ``word`` pasted into a command line."""
    return subprocess.run(["bash", "-c", b"printf %s " + word], capture_output=True).stdout


#: Linux's fcntl to resize a pipe (``F_SETPIPE_SZ``); Python names it from 3.10 on Linux only.
F_SETPIPE_SZ = 1031


def full_pipe(writer_blocking: bool) -> tuple[int, int, bytes]:
    """A pipe of one page, filled to the last byte it takes: ``(read end, write end, filler)``.
    ``writer_blocking``: the write end left blocking (a shell's ``| less``) or non-blocking (a
    reader that set ``O_NONBLOCK``: node's ``child_process``). Linux only (``F_SETPIPE_SZ``)."""
    import fcntl

    read_end, write_end = os.pipe()
    fcntl.fcntl(write_end, F_SETPIPE_SZ, 4096)
    os.set_blocking(write_end, False)
    filler = b""
    try:
        while True:
            filler += b"x" * os.write(write_end, b"x" * 512)
    except BlockingIOError:
        pass
    os.set_blocking(write_end, writer_blocking)
    return read_end, write_end, filler


def rti_rig_on_pipe(
    args: list[str], write_end: int, stderr: Any = None, columns: int | None = 100
) -> subprocess.Popen[bytes]:
    """``python ARGS`` (``-m rti_rig ...`` or ``-c CODE``) from this checkout, its stdout the
    pipe's ``write_end`` (its stderr too unless ``stderr`` is given), ``COLUMNS`` set unless
    None; the test's own copy of ``write_end`` is closed, so its reader meets the pipe's end
    when the command's closes. The stalled-reader tests had each written this out."""
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    if columns is not None:
        env["COLUMNS"] = str(columns)
    command = subprocess.Popen(
        [sys.executable, *args],
        stdout=write_end,
        stderr=write_end if stderr is None else stderr,
        env=env,
    )
    os.close(write_end)
    return command


def unread_in_pipe(fd: int) -> int:
    """How many bytes wait in the pipe ``fd`` for its reader (``FIONREAD``)."""
    import fcntl
    import termios

    got = fcntl.ioctl(fd, termios.FIONREAD, b"\0\0\0\0")
    return int.from_bytes(got, sys.byteorder)


def moved_session_copy(session: Path, dst: Path, first: int, dx: int, dy: int) -> Path:
    """:func:`rti_rig.reconstruct.synthetic.moved_session_copy` (there so that
    benchmarks/qa_step_margin.py, which may not import tests, moves a session the same way)."""
    from rti_rig.reconstruct.synthetic import moved_session_copy as moved

    return moved(session, dst, first, dx, dy)


def dome_session(tmp_path: Path, scene: str, side: int, lights: int) -> Path:
    """A session of :func:`dome_variant` shot through the CLI, without its verdict."""
    from typer.testing import CliRunner

    from rti_rig.cli import app

    out = tmp_path / "s"
    config = dome_variant(tmp_path, scene, side)
    r = CliRunner().invoke(
        app, ["run", str(config), "--out", str(out), "--lights", str(lights), "--no-verdict"]
    )
    assert r.exit_code == 0, r.output
    return out


@pytest.fixture(scope="session")
def arm_tablet_12(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A correct session of the shipped virtual arm on the tablet with 12 lights (read only:
    the QA tests copy it to move or clip its images): an object whose shading edges move with
    the light, so two groups of its lights have median edges about a pixel apart."""
    from typer.testing import CliRunner

    from rti_rig.app.config import load_rig_config, rig_geometry
    from rti_rig.cli import app
    from rti_rig.core.lp_format import LpEntry, write_lp
    from rti_rig.planner.uniform import plan_uniform

    root = tmp_path_factory.mktemp("tablet")
    out = root / "s"
    config = virtual_arm_variant(root, "tablet")
    # its 12 uniform lights in the order the QA tests on it were written against (nearest
    # neighbour by angle, the planner's order without an arm's), not the move-time order
    # `run --lights 12` now takes: which images a part-way move or a clipped one falls on is
    # what those tests set up, by image number
    lights = plan_uniform(rig_geometry(load_rig_config(config)), 12).directions
    plan = write_lp(
        root / "plan.lp",
        [LpEntry(f"image_{k:03d}.jpg", tuple(d)) for k, d in enumerate(lights, start=1)],
    )
    args = ["run", str(config), "--out", str(out), "--plan", str(plan), "--no-verdict"]
    r = CliRunner().invoke(app, args)
    assert r.exit_code == 0, r.output
    return out


def dome_session_said(root: Path, scene: str, side: int, lights: int) -> Path:
    """A correct session of :func:`dome_variant` in ``root/s``, shot through the CLI with its
    verdict, which must end it with exit 0; what it printed, unwrapped, is in ``said.txt``
    beside it (``root/said.txt``) for tests that assert on the run's verdict."""
    from typer.testing import CliRunner

    from rti_rig.cli import app

    out = root / "s"
    config = dome_variant(root, scene, side)
    r = CliRunner().invoke(app, ["run", str(config), "--out", str(out), "--lights", str(lights)])
    assert r.exit_code == 0, r.output
    (root / "said.txt").write_text(said(r), encoding="utf-8")
    return out


@pytest.fixture(scope="session")
def dome_coin_1024_12(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The shipped simulated dome's glossy coin at 1024 px, 12 lights, with its verdict
    (:func:`dome_session_said`; read only: the QA tests copy it to dim, scale or move an
    image). Why one for the run: four QA test files each shot this same session."""
    return dome_session_said(tmp_path_factory.mktemp("coin1024"), "coin", 1024, 12)


@pytest.fixture(scope="session")
def dome_coin_512_12(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The shipped simulated dome's glossy coin at 512 px, 12 lights, with its verdict
    (:func:`dome_session_said`; read only). Why one for the run: two QA test files each shot
    this same session."""
    return dome_session_said(tmp_path_factory.mktemp("coin512"), "coin", 512, 12)


@pytest.fixture(scope="session")
def dome_painting_512_12(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The shipped simulated dome's varnished painting at 512 px, 12 lights, with its verdict
    (:func:`dome_session_said`; read only). Why one for the run: two QA test files each shot
    this same session."""
    return dome_session_said(tmp_path_factory.mktemp("painting512"), "painting", 512, 12)


@pytest.fixture(scope="session")
def dome_relief(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A correct session of the shipped simulated dome as it ships (the relief, 512 px, its
    own lights), shot through the CLI without its verdict (read only: tests copy it to move
    its images). Why one for the run: two QA test files each shot this same session."""
    from typer.testing import CliRunner

    from rti_rig.cli import app

    out = tmp_path_factory.mktemp("relief") / "s"
    config = CONFIGS / "simulated_dome.toml"
    r = CliRunner().invoke(app, ["run", str(config), "--out", str(out), "--no-verdict"])
    assert r.exit_code == 0, r.output
    return out


@pytest.fixture(scope="session")
def dome_industrial_512_24(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A correct session of the shipped simulated dome on the industrial part (brushed steel)
    at 512 px, 24 lights (:func:`dome_session`; read only: tests copy it to change it). Why
    one for the run: two QA test files each shot this same session."""
    return dome_session(tmp_path_factory.mktemp("industrial512"), "industrial", 512, 24)


def coin_dome(folder: Path, exposure_s: float = 0.05) -> Path:
    """The shipped emulated dome (48 LEDs, real driver over a pty) shooting the polished coin at
    ``exposure_s``, as emulated_dome.toml did until its scene became the matte tablet: at 0.05 s
    the coin's face clips under the high LEDs (the case the QA tests below are about)."""
    text = (CONFIGS / "emulated_dome.toml").read_text()
    assert "exposure_s = 0.05\n" in text and re.search(r'(?m)^name = "tablet"', text)
    text = re.sub(r'(?m)^name = "tablet"', 'name = "coin"', text)
    text = text.replace("exposure_s = 0.05\n", f"exposure_s = {exposure_s}\n")
    text = text.replace('"example_dome_48.lp"', f'"{(CONFIGS / "example_dome_48.lp").as_posix()}"')
    return write_config(folder, text, "coin_dome.toml")


SMALL_DOME = """
name = "small"
kind = "dome"
backend = "simulated"
[dome]
layout = "rings"
rings = [
  { elevation_deg = 20.0, count = 8 },
  { elevation_deg = 50.0, count = 4, azimuth_offset_deg = 45.0 },
]
[camera]
width = 64
height = 64
exposure_s = 0.05
[scene]
seed = 3
"""


def interrupted(  # type: ignore[no-untyped-def]
    cfg: Path,
    out: Path,
    after_step: int,
    objective: str = "normals",
    lights: int | None = 8,
    until: float | None = None,
    min_lights: int | None = None,
    band: tuple[float, float] = (0.0, 90.0),
):
    """An adaptive session (``--lights``, ``--until-error``, design ``objective``,
    ``--min-lights``, the elevation ``band``) in ``out``, cancelled once step ``after_step``
    (0-based) is committed, as Ctrl-C would (tests/app and tests/cli resume it)."""
    from rti_rig.app.config import load_rig_config
    from rti_rig.app.usecases.adaptive import open_adaptive_session
    from rti_rig.runtime.controller import CancelToken, StepCompleted, run_session

    rig, schedule, folder, source = open_adaptive_session(
        load_rig_config(cfg), out, lights, until, objective, min_lights, band
    )
    cancel = CancelToken()

    def on_event(event) -> None:  # type: ignore[no-untyped-def]
        if isinstance(event, StepCompleted) and event.index == after_step:
            cancel.cancel()

    with rig:
        return run_session(rig, schedule, folder, cancel=cancel, on_event=on_event, source=source)


def begun_before(session: Path, setting: str, constant: str) -> None:
    """Make ``session``'s manifest one an earlier build began: its adaptive settings without
    ``setting`` and its constants without ``constant`` (the stop's terms a later build added,
    whose absence a resume must handle)."""
    path = session / "manifest.json"
    data = json.loads(path.read_text())
    header = data["adaptive"]
    del header[setting]
    del header["constants"][constant]
    path.write_text(json.dumps(data, indent=2))


def cut_new_session(request: Any, after_step: int) -> Any:
    """The run of a new session opened by ``request`` (a ``NewSessionRequest``), cancelled once
    step ``after_step`` (0-based) is committed, as Ctrl-C does: a session for a resume to
    continue. (The resume tests had each kept a copy of this.)"""
    from rti_rig.app.usecases.session import open_new_session, run_opened_session
    from rti_rig.runtime.controller import CancelToken, StepCompleted

    cancel = CancelToken()

    def on_event(event) -> None:  # type: ignore[no-untyped-def]
        if isinstance(event, StepCompleted) and event.index == after_step:
            cancel.cancel()

    return run_opened_session(open_new_session(request), cancel, on_event)


def line_within(process: subprocess.Popen[AnyStr], seconds: float, what: str) -> AnyStr:
    """The next line ``process`` prints on its stdout pipe, read on a thread and waited for at
    most ``seconds``: past them the process is killed (by its own handle) and the test fails
    naming ``what`` was awaited; a process that ends without a line fails it too, with its
    exit status.

    Why: a bare ``readline()`` on a child's pipe hung the run for ever, with no word, when the
    child never printed (stuck importing or connecting on a loaded machine)."""
    assert process.stdout is not None
    stream = process.stdout
    lines: queue.Queue[AnyStr] = queue.Queue()
    threading.Thread(target=lambda: lines.put(stream.readline()), daemon=True).start()
    try:
        line = lines.get(timeout=seconds)
    except queue.Empty:
        process.kill()  # its finally need not wait on a child that is stuck
        pytest.fail(f"{what}: no line from process {process.pid} in {seconds:.0f} s (killed)")
    if not line:
        status = process.wait(timeout=seconds)
        pytest.fail(f"{what}: process {process.pid} ended (exit status {status}) without a line")
    return line


@contextlib.contextmanager
def ended_on_exit(process: subprocess.Popen[Any]) -> Iterator[subprocess.Popen[Any]]:
    """``process`` (a command this test started), killed by its own handle and reaped if it
    is still running when the block is left (a failed assertion, a timeout): no test leaves
    a child behind. Two subprocess tests had each written this ``finally`` out."""
    try:
        yield process
    finally:
        if process.poll() is None:
            process.kill()
            process.wait()


def said(result) -> str:  # type: ignore[no-untyped-def]
    """A CLI result's output with its line wrapping undone (rich wraps to the terminal)."""
    return " ".join(result.output.split())


def at_key(shown: str | Path, key: str, file: Path | None = None) -> str:
    """How a config error names where it is: ``rig.toml, line 12: key 'camera.exposure_s'``
    (``shown``: the config's path as the user gave it; ``file``: where it is, if not there).
    The line is :func:`~rti_rig.core.toml_lines.key_line_in_file`'s, tested on its own."""
    from rti_rig.core.toml_lines import key_line_in_file

    line = key_line_in_file(file or shown, key)
    if line is not None:  # checked apart from the locator: the line holds the key's own name
        text = Path(file or shown).read_text(encoding="utf-8-sig").splitlines()[line - 1]
        last = key.rsplit(".", 1)[-1].split("[")[0]
        assert last in text, f"line {line} of {shown} is not the line of {key}: {text!r}"
    return f"{shown}{'' if line is None else f', line {line}'}: key '{key}'"


def journal(session: Path) -> list[dict]:
    """A session folder's journal entries."""
    return [json.loads(line) for line in (session / "journal.jsonl").read_text().splitlines()]


def decisions(session: Path) -> list[dict]:
    """A session's recorded decisions without their wall time (what must repeat exactly)."""
    return [{k: v for k, v in s["decision"].items() if k != "decision_s"} for s in journal(session)]


def manifest(session: Path) -> dict:
    """A session folder's manifest."""
    return json.loads((session / "manifest.json").read_text())


@pytest.fixture(scope="session")
def never_reached(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    """(config, session): an `--until-error 1e-9` session on :data:`SMALL_DOME` whose target
    is never reached, so it runs to every LED — the reference the adaptive stop's tests
    compare with (read only: tests write their own sessions). Its CLI output, unwrapped, is
    in ``said.txt`` beside the session."""
    from typer.testing import CliRunner

    from rti_rig.cli import app

    base = tmp_path_factory.mktemp("until")
    cfg = write_config(base, SMALL_DOME)
    out = base / "s"
    r = CliRunner().invoke(app, ["run", str(cfg), "--out", str(out), "--until-error", "1e-9"])
    assert r.exit_code == 0, r.output
    (out.parent / "said.txt").write_text(said(r))
    return cfg, out


def dead_pid() -> int:
    """The PID of a process that has ended: an attempt folder naming it is a killed run's
    (a batch leaves the folders of running processes alone, ``fit_batch.owner_gone``)."""
    import subprocess
    import sys

    proc = subprocess.Popen([sys.executable, "-c", "pass"])
    proc.wait()
    return proc.pid


class InjectedStop(BaseException):
    """Stands for the CLI's emergency stop: a BaseException its handler raises wherever the
    signal lands."""


def descriptors_on(path: str) -> set[int]:
    """This process's open descriptors that refer to the file at ``path`` (Linux's
    ``/proc/self/fd``): what a stop must not leave behind of a port."""
    import os

    st = os.stat(path)
    found = set()
    for name in os.listdir("/proc/self/fd"):
        try:
            other = os.fstat(int(name))
        except OSError:  # the listing's own descriptor, closed since
            continue
        if (other.st_dev, other.st_ino) == (st.st_dev, st.st_ino):
            found.add(int(name))
    return found


@contextlib.contextmanager
def sigint_as_the_system_opens(path: str) -> Iterator[list[int]]:
    """A SIGINT sent to this process the first time the system's ``os.open`` of ``path``
    returns, handled by raising :class:`InjectedStop`; yields the descriptors so opened.

    The instant a stop leaked a port's descriptor: pyserial keeps the number only once
    ``os.open`` has returned, and Python runs a signal's handler as soon as the call returns.
    ``signal.raise_signal`` runs the handler before it returns, so the stop lands there, every
    time, unless the caller holds the signal (``signals_deferred``)."""
    import os

    from rti_rig.core.deferred_signals import signal_handlers

    opened: list[int] = []
    real_open = os.open

    def open_then_stopped(file: Any, flags: int, *args: Any, **kwargs: Any) -> int:
        fd = real_open(file, flags, *args, **kwargs)
        if not opened and os.fspath(file) == path:
            opened.append(fd)
            signal.raise_signal(signal.SIGINT)
        return fd

    def stop(signum: int, frame: Any) -> None:
        raise InjectedStop

    os.open = open_then_stopped
    try:
        with signal_handlers({signal.SIGINT: stop}):
            yield opened
    finally:
        os.open = real_open


class UnlimitedLighting:
    """What ``fix_exposure`` asks of a rig's lighting before it meters, for the fake rigs of
    tests that stop the metering at its start: lights with no lit-time limit (the cap from a
    limit is tested on built rigs, tests/cli/test_auto_exposure_lit_limit.py)."""

    def lit_limit_s(self) -> None:
        return None


def opened_session_kept(monkeypatch: pytest.MonkeyPatch) -> dict[str, Any]:
    """A dict whose ``"opened"`` is, once ``run`` has opened its session in this process, the
    :class:`~rti_rig.app.usecases.session.OpenedSession` it runs: for tests that look at the
    rig's devices (an emulator's LED, a simulated dome's lit LED) as the session ends."""
    import rti_rig.app.usecases.session as session_usecase

    seen: dict[str, Any] = {}
    real_run = session_usecase.run_opened_session

    def run_opened_session(opened: Any, *args: Any, **kwargs: Any) -> Any:
        seen["opened"] = opened
        return real_run(opened, *args, **kwargs)

    monkeypatch.setattr(session_usecase, "run_opened_session", run_opened_session)
    return seen


def eventually(predicate: Callable[[], object], timeout_s: float = 10.0) -> bool:
    """True once ``predicate()`` is; bytes on a pty reach the emulator's thread after a delay
    the CPU load decides, so a record is read once it has caught up (bounded: False if it has
    not within ``timeout_s``)."""
    end = time.monotonic() + timeout_s
    while not predicate():
        if time.monotonic() > end:
            return False
        time.sleep(0.005)
    return True


class SighupUnhandled(Exception):
    """A SIGHUP nothing in rti-rig answered (its default action would have ended pytest)."""


@pytest.fixture
def hangup_guarded() -> Iterator[None]:
    """For the test, a SIGHUP nothing in rti-rig answers raises :class:`SighupUnhandled`."""
    from rti_rig.core.deferred_signals import signal_handlers

    def unhandled(signum: int, frame: Any) -> None:
        raise SighupUnhandled("SIGHUP was not handled by rti-rig (the default ends the process)")

    with signal_handlers({signal.SIGHUP: unhandled}):
        yield


def sighup_at_lit_led(monkeypatch: pytest.MonkeyPatch, nth: int) -> list[Any]:
    """SIGHUP raised in the command's own process once the ``nth`` LED of the first emulated
    firmware is lit (the firmware has acknowledged it); returns the firmwares built from here
    on, to read their truth from. One helper for the hang-up tests of run, check and preview."""
    import rti_rig.simulator.dome_firmware as dome_firmware
    from rti_rig.runtime.dome_policy import DomePolicy

    firmwares: list[Any] = []
    real_firmware_for = dome_firmware.firmware_for

    def firmware_for(*args: Any, **kwargs: Any) -> Any:
        firmware = real_firmware_for(*args, **kwargs)
        firmwares.append(firmware)
        return firmware

    real_light = DomePolicy.light
    lit_steps: list[int] = []

    def light(self: Any, index: int, intensity: float = 1.0) -> None:
        real_light(self, index, intensity)
        if len(firmwares) == 1 and len(lit_steps) < nth and firmwares[0].lit is not None:
            lit_steps.append(index)
            if len(lit_steps) == nth:
                signal.raise_signal(signal.SIGHUP)

    monkeypatch.setattr(dome_firmware, "firmware_for", firmware_for)
    monkeypatch.setattr(DomePolicy, "light", light)
    return firmwares
