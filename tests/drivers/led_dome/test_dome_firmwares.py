"""Real dome firmwares (their emulators, written from their sources) through the front door.

Each built-in firmware profile is probed, checked and run with 8 lights by the CLI over a
pseudo-terminal through real pyserial; the emulator's record of which LEDs were lit is checked
at every capture and at the end. Timeouts on the pty are generous (seconds), and the dry run's
own clock is virtual, so CPU load cannot exhaust them; the link's real time is added to it
(what the real rig would spend), so a dry run's reported rig time moves with load by the
pty's latency (milliseconds), which no test here bounds from above. RTIPy's dry run runs in
real time (its LEDs go dark on the board's clock, which the camera's time must pass on): at the
shipped exposure each capture leaves 0.85 s of its 2 s window spare.
"""

from __future__ import annotations

import json
import logging
import re
import signal
import sys
import time
from pathlib import Path

import pytest
from conftest import CONFIGS, eventually, line_within
from typer.testing import CliRunner

from rti_rig.app.compose import build_rig
from rti_rig.app.config import load_rig_config
from rti_rig.cli import app
from rti_rig.core.errors import RtiRigError
from rti_rig.core.lp_format import read_lp
from rti_rig.drivers.led_dome.dome_profiles import builtin_spec
from rti_rig.drivers.led_dome.settings import DomeSerialSettings
from rti_rig.planner.uniform import plan_uniform
from rti_rig.runtime.controller import run_session
from rti_rig.runtime.session import SessionFolder
from rti_rig.simulator.domes import board_for
from rti_rig.simulator.pty_link import serve_on_pty

pytestmark = [
    pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux"),
    pytest.mark.pty,
]
runner = CliRunner()

CONFIG = {
    "nab-rti-v1": "emulated_nab_rti_v1.toml",
    "rtipy": "emulated_rtipy.toml",
    "minirti": "emulated_minirti.toml",
    "elexol-24r1": "emulated_elexol.toml",
    "rti-dome-m": "emulated_rti_dome.toml",
    "nichlock": "emulated_nichlock.toml",
}
PROBED = ["nab-rti-v1", "rtipy", "minirti", "elexol-24r1", "nichlock"]


def said(result) -> str:  # type: ignore[no-untyped-def]
    return " ".join(result.output.split())


@pytest.mark.slow  # real firmware timing over a pty: seconds per firmware
@pytest.mark.parametrize("profile", PROBED)
def test_probe_names_the_firmware_and_leaves_it_dark(profile: str) -> None:
    board = board_for(profile)
    with serve_on_pty(board, profile) as link:
        r = runner.invoke(app, ["probe", link.port], terminal_width=400)
        assert r.exit_code == 0, r.output
        assert f'profile = "{profile}"' in r.output
        # the rate it answered at, which a config copied from the example (baudrate = 115200)
        # must be given: the printed lines had left it out
        assert f"baudrate = {builtin_spec(profile)['baudrate']}" in r.output, r.output
        assert eventually(lambda: board.lit == frozenset())
    if profile == "rtipy":
        # each probe's line holds what came while it was the last one sent: RTIPy answers a
        # command once 1 s of silence ends it, so its answer to the mask and '<9>' (one
        # command to it) came before 'T,0,0,0' was sent, and had been shown as T's
        heard = dict(line.split(": ", 1) for line in r.stdout.splitlines()[:9])
        assert heard["'T,0,0,0' at 9600 baud"] == "'I received: T,0,0,0 the instructionByte was: T'"
        unknown = heard["'<9>' (an unknown code) at 9600 baud"]
        assert unknown.startswith("'I received: ") and "<9> the instructionByte was: " in unknown


@pytest.mark.slow  # real firmware timing over a pty
def test_probe_asks_again_when_a_reply_is_lost_and_finds_the_elexol_board() -> None:
    """docs/domes.md's own rehearsal: the Elexol board's answer to the first ``?`` is lost.
    The probe had gone on to the other firmwares and said "No known dome firmware answered";
    a probe met by silence is sent once more on the same open port, as the driver resends."""
    from rti_rig.simulator.dome_firmware import Fault, FaultKind, FaultPlan

    board = board_for("elexol-24r1", faults=FaultPlan((Fault(1, FaultKind.DROP_REPLY),)))
    with serve_on_pty(board, "elexol-24r1") as link:
        r = runner.invoke(app, ["probe", link.port], terminal_width=400)
    text = said(r)
    assert r.exit_code == 0, text
    assert 'profile = "elexol-24r1"' in text and "No known dome firmware" not in text, text


@pytest.mark.slow  # real firmware timing over a pty
def test_probe_sends_the_nab_all_off_again_when_its_reply_is_lost() -> None:
    """The Nab sketch boots fully lit; the probe's ``<0>`` is its only way dark. One lost reply
    had ended the probe "all-off sent but NOT acknowledged: check the dome" (and a ``<0>`` the
    board missed left it lit): it is sent again on the same open port (reopening would reset
    the board, lit again)."""
    from rti_rig.simulator.dome_firmware import Fault, FaultKind, FaultPlan

    board = board_for("nab-rti-v1", faults=FaultPlan((Fault(1, FaultKind.DROP_REPLY),)))
    with serve_on_pty(board, "nab-rti-v1") as link:
        r = runner.invoke(app, ["probe", link.port], terminal_width=400)
        assert eventually(lambda: board.lit == frozenset())
    assert r.exit_code == 0, r.output
    text = said(r)
    assert "all-off sent and acknowledged" in text and "NOT acknowledged" not in text, text
    assert board.commands == 2
    # on the port its banner was heard on: it had been opened again for the all-off, a second
    # reset that lit every LED again and waited out the boot once more (~2 s)
    assert sum(what == "boot" for _, what in board.events) == 1, board.events


@pytest.mark.slow  # real firmware timing over a pty: seconds per firmware
def test_a_firmware_served_in_another_process_can_be_probed() -> None:
    """``python -m rti_rig.simulator.dome_firmware --profile nab-rti-v1`` serves the sketch's
    emulator, so ``rti-rig probe`` can be rehearsed as docs/domes.md shows; the server had
    offered only the project's own protocols (default, framed, binary)."""
    import subprocess

    proc = subprocess.Popen(
        [sys.executable, "-m", "rti_rig.simulator.dome_firmware", "--profile", "nab-rti-v1"],
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        line = line_within(proc, 120, "the served firmware's port")
        assert line.startswith("emulated nab-rti-v1 firmware (64 LEDs, 9600 baud) on "), line
        r = runner.invoke(app, ["probe", line.split()[-1]])
        assert r.exit_code == 0, r.output
        assert 'profile = "nab-rti-v1"' in r.output and "baudrate = 9600" in r.output
        assert "all-off sent and acknowledged" in said(r)
    finally:
        proc.terminate()  # the process this test started, by its own handle
        proc.wait(timeout=10)


@pytest.mark.slow  # real firmware timing over a pty: seconds per firmware
def test_a_baudrate_left_from_the_example_is_named_when_the_sketch_does_not_answer(
    tmp_path: Path,
) -> None:
    """``baudrate = 115200`` (the example config's) on the 9600-baud Nab sketch: the check had
    said only "check the port, the baud rate and the protocol profile", naming neither the key
    nor the rate the firmware talks at (docs/domes.md warns of this very mistake)."""
    text = (CONFIGS / CONFIG["nab-rti-v1"]).read_text()
    text = text.replace('profile = "nab-rti-v1"', 'profile = "nab-rti-v1"\nbaudrate = 115200')
    rig = tmp_path / "rig.toml"
    rig.write_text(text)
    r = runner.invoke(app, ["check", str(rig)])
    assert r.exit_code == 1, r.output
    text = said(r)
    assert "dome.serial.baudrate = 115200" in text and "talks at 9600 baud" in text, text
    assert "remove that key or set it to 9600" in text


def test_the_baudrate_hint_is_said_only_where_the_rate_matters() -> None:
    from rti_rig.app.dome_factory import baudrate_hint

    def hint(**kw: object) -> str:
        return baudrate_hint(DomeSerialSettings(port="x", **kw))  # type: ignore[arg-type]

    assert hint(profile="nab-rti-v1") == ""  # the profile's own rate
    assert hint(profile="rti-dome-m", baudrate=115200) == ""  # native USB: any rate works
    assert hint(profile="framed", baudrate=9600) == ""  # the project's own: no published rate
    said_ = hint(profile="rtipy", protocol={"baudrate": 19200})
    assert "dome.serial.protocol.baudrate = 19200" in said_ and "at 9600 baud" in said_


@pytest.mark.slow  # real firmware timing over a pty: seconds per firmware
def test_probe_finds_a_nichlock_board_at_9600_without_lighting_it() -> None:
    """nichlock/rti keeps its baud rate in EEPROM (its settings menu offers 9600). Such a board
    was not recognised (only 115200 was), so the probe went on to RTIPy's ``T,0,0,0``: its
    three ``0`` stepped the dome to LED 2, left lit, and the probe said "nothing that lights an
    LED was sent"."""
    from rti_rig.simulator.domes.nichlock import NichlockBoard

    board = NichlockBoard(baudrate=9600)
    with serve_on_pty(board, "nichlock") as link:
        r = runner.invoke(app, ["probe", link.port])
        assert r.exit_code == 0, r.output
        assert 'profile = "nichlock"' in r.output and "baudrate = 9600" in r.output
        time.sleep(0.5)  # anything still on its way has reached the board
        assert all(lit == frozenset() for _, lit in board.timeline), board.timeline


@pytest.mark.slow  # real firmware timing over a pty: seconds per firmware
def test_probe_finds_a_nichlock_board_set_to_19200_in_its_menu() -> None:
    """nichlock's settings menu (``a``, ``2``) offers 19200 and 2400 too; a board set so was
    "No known dome firmware answered" (only 9600 and 115200 were listened at), and every later
    probe's bytes reached it as keys of its menus."""
    from rti_rig.simulator.domes.nichlock import NichlockBoard

    board = NichlockBoard(baudrate=19200)
    with serve_on_pty(board, "nichlock") as link:
        r = runner.invoke(app, ["probe", link.port])
        assert r.exit_code == 0, r.output
        assert 'profile = "nichlock"' in r.output and "baudrate = 19200" in r.output
        assert b"?" not in board.heard and b"m" not in board.heard  # found by listening
        assert all(lit == frozenset() for _, lit in board.timeline), board.timeline


@pytest.mark.slow  # real firmware timing over a pty: seconds per firmware
def test_probe_says_a_nichlock_board_waits_in_its_touch_calibration() -> None:
    """Its boot printed "Starting Calibration.." and never its prompt; the probe said only
    "Found: nichlock", and the check that followed met the calibration."""
    from rti_rig.simulator.domes.nichlock import NichlockBoard

    board = NichlockBoard(touch_calibrated=False)
    with serve_on_pty(board, "nichlock") as link:
        r = runner.invoke(app, ["probe", link.port])
    assert r.exit_code == 0, r.output
    assert 'profile = "nichlock"' in r.output
    text = said(r)
    assert "Note: its boot waits in its touch-screen calibration" in text
    assert "tap the two red circles on its display" in text


@pytest.mark.slow  # real firmware timing over a pty: seconds per firmware
def test_probe_says_plainly_when_nothing_known_answers() -> None:
    board = board_for("rti-dome-m")  # never answers anything
    with serve_on_pty(board, "silent") as link:
        r = runner.invoke(app, ["probe", link.port])
    assert r.exit_code == 1
    assert "No known dome firmware answered" in said(r)
    assert "(nothing)" in r.output
    assert board.lit == frozenset()


def test_probe_of_a_port_that_cannot_be_opened_concludes_nothing_about_firmware(
    tmp_path: Path,
) -> None:
    """A mistyped port had been told 'No known dome firmware answered' and to set a profile."""
    r = runner.invoke(app, ["probe", str(tmp_path / "ttyACM9")])
    assert r.exit_code == 1
    text = said(r)
    assert "cannot open serial port" in text and "no firmware was asked" in text
    assert "No known dome firmware answered" not in text and "profile =" not in text
    assert "nothing was sent" in text


@pytest.mark.slow  # real firmware timing over a pty: seconds per firmware
@pytest.mark.parametrize("profile", list(CONFIG))
def test_check_passes_on_each_firmware(profile: str) -> None:
    r = runner.invoke(app, ["check", str(CONFIGS / CONFIG[profile])])
    assert r.exit_code == 0, r.output
    if profile in UNANSWERED_LIGHTS:  # sent, and only a person watching can say more
        assert "RESULT: SENT, NOT VERIFIED" in said(r) and "sent without error" in said(r)
        assert "passed:" not in said(r)
    else:
        assert "RESULT: PASS" in r.output
    assert "lights:" in r.output


#: The firmwares that answer no light command (their check cannot see an LED light).
UNANSWERED_LIGHTS = ("elexol-24r1", "rti-dome-m")


def _hardware(tmp_path: Path, shipped: str, port: str, camera_connects: bool = True) -> Path:
    """A shipped emulated config as the real dome's: backend hardware, on ``port``; its camera
    a tethering folder that exists (``camera_connects``) or a video device that does not."""
    text = (CONFIGS / shipped).read_text()
    text = text.replace('backend = "emulated"', 'backend = "hardware"')
    text = text.replace('port = "emulated"', f'port = "{port}"')
    if camera_connects:
        (tmp_path / "tether").mkdir(exist_ok=True)
        device = f'kind = "folder_watch"\nfolder = "{tmp_path / "tether"}"\n'
    else:
        device = f'kind = "opencv"\ndevice = "{tmp_path / "v9"}"\nresponse = "srgb"\n'
    text = text[: text.index("[scene]")].replace(
        "exposure_s = 0.05\n", f"exposure_s = 0.05\n[camera.device]\n{device}", 1
    )
    cfg = tmp_path / "dome.toml"
    cfg.write_text(text)
    return cfg


@pytest.mark.slow  # real firmware timing over a pty
def test_a_profile_that_answers_nothing_does_not_pass_another_board(tmp_path: Path) -> None:
    """The rti-dome-m profile on a miniRTI board: every command "passed" (none is answered),
    and check said PASS of a board that lit nothing it was asked to."""
    board = board_for("minirti")
    with serve_on_pty(board, "minirti") as link:
        cfg = _hardware(tmp_path, "emulated_rti_dome.toml", link.port)
        r = runner.invoke(app, ["check", str(cfg)], terminal_width=400)
    assert r.exit_code == 0, r.output
    assert "RESULT: PASS" not in r.output
    assert "RESULT: SENT, NOT VERIFIED" in said(r) and "watch the dome" in said(r)


@pytest.mark.slow  # real firmware timing over a pty
def test_a_profile_without_a_handshake_whose_board_never_answers_names_port_baud_profile(
    tmp_path: Path,
) -> None:
    """The nichlock profile on a miniRTI board: its first command is not answered. The guide
    promises port, baud and profile advice when a board is silent or speaks another protocol;
    that came only with a handshake, and this said "no reply … gave up after 3 attempts"."""
    board = board_for("minirti")
    with serve_on_pty(board, "minirti") as link:
        cfg = _hardware(tmp_path, "emulated_nichlock.toml", link.port)
        cfg.write_text(cfg.read_text().replace("reply_timeout_s = 3.0", "reply_timeout_s = 0.5"))
        r = runner.invoke(app, ["check", str(cfg)], terminal_width=400)
    assert r.exit_code == 1, r.output
    text = said(r)
    assert "nothing on this port has answered yet" in text
    assert "the baud rate and the protocol profile" in text


@pytest.mark.slow  # real firmware timing over a pty
def test_a_board_that_talks_another_protocol_is_not_said_to_be_silent(tmp_path: Path) -> None:
    """The miniRTI profile on a Nab sketch board: the board sends its banner and replies, which
    the profile cannot read. It had been told "nothing on this port has answered yet", sending
    the user to the cable and the power supply of a board that was talking. Its banner, later
    than the profile's 1.5 s boot wait, now names the firmware that talks."""
    board = board_for("nab-rti-v1")
    with serve_on_pty(board, "nab-rti-v1") as link:
        cfg = _hardware(tmp_path, "emulated_minirti.toml", link.port)
        r = runner.invoke(app, ["check", str(cfg)], terminal_width=400)
    assert r.exit_code == 1, r.output
    text = said(r)
    assert "nothing on this port has answered" not in text
    assert "printed the boot banner of the nab-rti-v1 firmware, not the minirti one" in text
    assert "rti-rig probe PORT" in text


@pytest.mark.slow  # real firmware timing over a pty
def test_a_board_whose_banner_came_at_another_baud_rate_is_not_said_to_be_silent(
    tmp_path: Path,
) -> None:
    """The nichlock profile (115200 baud) on the 9600-baud Nab sketch: its banner arrives as
    unreadable bytes, then the all-off's reply times out. That had been said "nothing on this
    port has answered yet: check … that the board is powered", of a board that was talking."""
    board = board_for("nab-rti-v1")
    with serve_on_pty(board, "nab-rti-v1") as link:
        cfg = _hardware(tmp_path, "emulated_nichlock.toml", link.port)
        cfg.write_text(cfg.read_text().replace("reply_timeout_s = 3.0", "reply_timeout_s = 0.5"))
        r = runner.invoke(app, ["check", str(cfg)], terminal_width=400)
    text = said(r)
    assert r.exit_code == 1, text
    assert "nothing on this port has answered" not in text, text
    assert "a board on this port sends bytes, but none this rig config's protocol" in text
    assert "lights may still be on" in text  # the sketch boots lit; nothing it reads was sent


@pytest.mark.slow  # real firmware timing over a pty: seconds per firmware
@pytest.mark.parametrize("profile", list(CONFIG))
def test_session_of_8_lights_has_the_scheduled_led_lit_at_every_capture(
    profile: str, tmp_path: Path
) -> None:
    loaded = load_rig_config(CONFIGS / CONFIG[profile])
    with build_rig(loaded) as rig:
        board = rig.emulator  # type: ignore[attr-defined]
        schedule = plan_uniform(rig.geometry, 8)
        seen: list[frozenset[int]] = []
        real_capture = rig.camera.capture
        current: list[int] = []

        def set_light(step):  # type: ignore[no-untyped-def]
            current[:] = [step.led]
            return real_set(step)

        real_set = rig.lighting.set
        rig.lighting.set = set_light  # type: ignore[method-assign]

        def capture(exposure_s: float):  # type: ignore[no-untyped-def]
            want = frozenset(current)
            eventually(lambda: board.lit == want)
            seen.append(board.lit)
            return real_capture(exposure_s)

        rig.camera.capture = capture  # type: ignore[method-assign]
        result = run_session(rig, schedule, SessionFolder.create(tmp_path / "s", 8))
        assert [frozenset({r.led}) for r in result.records] == seen
        assert len(seen) == 8
        assert eventually(lambda: board.lit == frozenset())


@pytest.mark.slow  # real firmware timing over a pty: seconds per firmware
@pytest.mark.parametrize("profile", ["nab-rti-v1", "minirti"])
def test_cli_run_8_lights(profile: str, tmp_path: Path) -> None:
    out = tmp_path / "s"
    r = runner.invoke(
        app, ["run", str(CONFIGS / CONFIG[profile]), "--out", str(out), "--lights", "8"]
    )
    assert r.exit_code == 0, r.output
    assert len(read_lp(out / "lights.lp")) == 8


def with_faults(profile: str, tmp_path: Path, faults: str) -> Path:
    text = (CONFIGS / CONFIG[profile]).read_text() + "\n[emulator]\n" + faults
    path = tmp_path / "rig.toml"
    path.write_text(text)
    return path


@pytest.mark.parametrize("kind", ["drop_reply", "garble_reply", "delay_reply"])
def test_lost_garbled_late_reply_is_retried_and_the_session_completes(
    kind: str, tmp_path: Path
) -> None:
    # command 1 is the init all-off, 2 the connect all-off, 3 the controller's all-off, 4 light 0
    cfg = with_faults(
        "nab-rti-v1", tmp_path, f'faults = [{{at_command = 4, kind = "{kind}", delay_s = 4.0}}]\n'
    )
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", str(cfg), "--out", str(out), "--lights", "8"])
    assert r.exit_code == 0, r.output
    assert len(read_lp(out / "lights.lp")) == 8


def test_a_lost_reply_to_the_init_all_off_is_resent_and_the_session_completes(
    tmp_path: Path,
) -> None:
    """The nab sketch's reply to the connect's init all-off (command 1, after its ready text)
    is lost: the init is sent again and the run completes. It had failed at its start with "no
    handshake with the dome … check the port, the baud rate and the protocol profile"."""
    cfg = with_faults("nab-rti-v1", tmp_path, 'faults = [{at_command = 1, kind = "drop_reply"}]\n')
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", str(cfg), "--out", str(out), "--lights", "8"])
    assert r.exit_code == 0, r.output
    assert "no handshake" not in said(r)
    assert len(read_lp(out / "lights.lp")) == 8


def test_a_usb_drop_at_the_init_all_off_is_reconnected_and_the_session_completes(
    tmp_path: Path,
) -> None:
    """The nab sketch's port vanishes as the connect's init all-off (command 1, after its ready
    text) arrives, and comes back 0.3 s later: the port is reopened and the run completes. It
    had failed at its start with "no handshake with the dome … check the port, the baud rate
    and the protocol profile"."""
    cfg = with_faults(
        "nab-rti-v1", tmp_path, 'faults = [{at_command = 1, kind = "disconnect", delay_s = 0.3}]\n'
    )
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", str(cfg), "--out", str(out), "--lights", "8"])
    assert r.exit_code == 0, r.output
    assert "no handshake" not in said(r) and "port was lost" not in said(r)
    assert len(read_lp(out / "lights.lp")) == 8


def test_board_reset_mid_session_stops_naming_the_led_keeps_images_and_ends_dark(
    tmp_path: Path,
) -> None:
    cfg = with_faults("nab-rti-v1", tmp_path, 'faults = [{at_command = 7, kind = "reset"}]\n')
    loaded = load_rig_config(cfg)
    with build_rig(loaded) as rig:
        board = rig.emulator  # type: ignore[attr-defined]
        folder = SessionFolder.create(tmp_path / "s", 8)
        with pytest.raises(RtiRigError, match=r"LED \d+"):
            run_session(rig, plan_uniform(rig.geometry, 8), folder)
        assert eventually(lambda: board.lit == frozenset())  # it rebooted fully lit
    assert len(list((tmp_path / "s").glob("*.png")) + list((tmp_path / "s").rglob("*.tif*"))) >= 1
    r_text = (tmp_path / "s" / "manifest.json").read_text()
    assert "rebooted" in r_text


def test_a_board_that_reboots_again_at_its_rehandshake_is_not_said_off(tmp_path: Path) -> None:
    """The Nab sketch reboots (lit) while LED 1 is lit, and again at the init all-off of the
    handshake after it: the error said "the dome is off again" of a board with every LED on.
    It says the state is unknown until the closing all-off, which the lights line reports."""
    cfg = with_faults(
        "nab-rti-v1",
        tmp_path,
        'faults = [{at_command = 6, kind = "reset"}, {at_command = 7, kind = "reset"}]\n',
    )
    r = runner.invoke(app, ["check", str(cfg)], terminal_width=400)
    text = said(r)
    assert r.exit_code == 1, text
    assert re.search(
        r"the board rebooted while LED 1 \(az [-\d.]+°, el [-\d.]+°\) was meant", text
    ), text
    assert "the dome is off again" not in text
    assert "whether the dome is lit is unknown until the closing all-off" in text
    assert "lights: all-off sent and acknowledged by the dome: lights are off" in text


def test_a_reboot_during_check_speaks_of_the_led_not_of_an_image(tmp_path: Path) -> None:
    """The Nab sketch reboots at the all-off after LED 1 during ``rti-rig check``: the failure
    had said "the image taken under LED 1 may have had no light … repeat that capture", of a
    check that takes no image. It says that nothing is lost with the LED (not that it "went dark
    with it": the Nab sketch boots with every LED lit), and what to look at."""
    cfg = with_faults("nab-rti-v1", tmp_path, 'faults = [{at_command = 6, kind = "reset"}]\n')
    r = runner.invoke(app, ["check", str(cfg)], terminal_width=400)
    text = said(r)
    assert r.exit_code == 1, text
    assert re.search(
        r"the board rebooted while LED 1 \(az [-\d.]+°, el [-\d.]+°\) was meant", text
    ), text
    assert "image taken under" not in text and "repeat that capture" not in text
    assert "this check takes no image under LED 1, so nothing is lost with it" in text
    assert "went dark" not in text
    assert "power supply or its USB cable" in text


def test_port_gone_for_good_is_a_named_error_and_says_lights_unknown(tmp_path: Path) -> None:
    cfg = with_faults(
        "nab-rti-v1", tmp_path, 'faults = [{at_command = 6, kind = "disconnect", delay_s = 60}]\n'
    )
    # the shipped 4 attempts from 0.5 s (7.5 s, for a real replug) are the config's keys: a
    # port gone for good is gone for good in one short attempt too (two windows had cost 15 s)
    cfg.write_text(
        cfg.read_text()
        .replace("reconnect_attempts = 4", "reconnect_attempts = 1")
        .replace("reconnect_backoff_s = 0.5", "reconnect_backoff_s = 0.05")
    )
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", str(cfg), "--out", str(out), "--lights", "8"])
    assert r.exit_code == 2, r.output
    text = said(r)
    assert "did not come back within 1 reconnection attempt" in text, text
    assert "lights are off" not in text
    assert "could NOT be sent" in text or "not acknowledged" in text


@pytest.mark.parametrize(
    ("protocol", "key"),
    [
        ({"led_count": 4, "light": {"send": "L{idx}"}}, "light.send"),
        ({"led_count": 4, "light": {"send": "L", "reply": {"kind": "pattern"}}}, "light.reply"),
        ({"led_count": 4, "encoding": "bytes", "light": {"send": "4G"}}, "light.send"),
        ({"led_count": 0, "light": {"send": "L"}}, "led_count"),
        ({"led_count": 4, "light": {"send": "L"}, "reset_pattern": "(("}, "reset_pattern"),
    ],
)
def test_bad_descriptions_are_refused_naming_the_key(protocol: dict, key: str) -> None:
    with pytest.raises(ValueError, match=key.replace(".", r"\.")):
        DomeSerialSettings(port="x", profile="custom", protocol=protocol)


def test_custom_description_drives_a_dome_like_a_built_in(tmp_path: Path) -> None:
    from rti_rig.drivers.led_dome.dome_profiles import builtin_spec

    spec = builtin_spec("nab-rti-v1")
    s = DomeSerialSettings(port="x", profile="custom", protocol=spec)
    built = DomeSerialSettings(port="x", profile="nab-rti-v1").protocol_spec()
    assert s.protocol_spec().model_dump() == built.model_dump()


def test_unknown_profile_lists_the_known_ones() -> None:
    with pytest.raises(ValueError, match=r"nab-rti-v1.*rtipy"):
        DomeSerialSettings(port="x", profile="nab")


def test_a_stop_during_the_handshake_of_the_lit_nab_sketch_sends_all_off() -> None:
    """SIGTERM (or a second Ctrl-C) while the board that boots with every LED on answers the
    handshake: the all-off is sent before the stop goes on. It had been left fully lit and the
    user told "no all-off was attempted (the dome was never reached)"."""
    from rti_rig.app.dome_factory import build_dome
    from rti_rig.core.clock import VirtualClock
    from rti_rig.runtime.controller import EmergencyStop

    board = board_for("nab-rti-v1")
    with serve_on_pty(board, "nab") as link:
        settings = DomeSerialSettings(port=link.port, profile="nab-rti-v1")
        dome = build_dome(settings, VirtualClock())

        def stopped_here():  # type: ignore[no-untyped-def]
            assert eventually(lambda: len(board.lit) > 1)  # booted, every LED on
            raise EmergencyStop(signal.SIGTERM)

        dome.link.hello = stopped_here
        with pytest.raises(EmergencyStop):
            dome.connect()
        assert eventually(lambda: board.lit == frozenset())
        assert dome.off_report is not None
        assert "never reached" not in dome.off_report.sentence()


def test_a_stop_while_the_board_is_still_in_its_bootloader_leaves_it_dark() -> None:
    """SIGTERM (or a second Ctrl-C) before the board has booted: the all-off reaches the
    bootloader and is lost, then the sketch lights every LED in setup(). The link sees the boot
    banner and says RESET; the all-off is sent again, now to the sketch (the board had been
    left with all its LEDs on)."""
    from rti_rig.app.dome_factory import build_dome
    from rti_rig.core.clock import VirtualClock
    from rti_rig.runtime.controller import EmergencyStop

    board = board_for("nab-rti-v1")
    with serve_on_pty(board, "nab") as link:
        dome = build_dome(DomeSerialSettings(port=link.port, profile="nab-rti-v1"), VirtualClock())

        wait_boot, stops = dome.link._wait_boot, []

        def stopped_at_once():  # type: ignore[no-untyped-def]
            if not stops:  # one signal, as the port has just opened: the board is booting
                stops.append("SIGTERM")
                raise EmergencyStop(signal.SIGTERM)
            wait_boot()

        dome.link._wait_boot = stopped_at_once
        with pytest.raises(EmergencyStop):
            dome.connect()
        assert any(what == "boot" for _, what in board.events)
        # the pins float low in the bootloader, so "dark" means dark once the sketch runs
        # (read as the board will be once its boot is over: no fixed sleep, which a loaded
        # machine can outlast before the emulator has caught up)
        assert eventually(lambda: board.lit_once_booted() == frozenset())
        assert dome.off_report is not None
        assert "rebooted" not in dome.off_report.sentence()  # the second all-off got through


def test_a_stop_late_in_the_boot_wait_finishes_that_wait_not_a_new_one() -> None:
    """The all-off after a stop in the boot wait waits only for the rest of it: a fresh wait
    (4 s for the Nab profile) had delayed the all-off of a stop late in the boot by as much."""
    from rti_rig.app.dome_factory import build_dome
    from rti_rig.core.clock import VirtualClock
    from rti_rig.runtime.controller import EmergencyStop

    board = board_for("nab-rti-v1")
    with serve_on_pty(board, "nab") as link:
        dome = build_dome(DomeSerialSettings(port=link.port, profile="nab-rti-v1"), VirtualClock())
        boot_wait = dome.link.spec.boot_wait_s
        late = boot_wait - 1.0

        def stopped_late():  # type: ignore[no-untyped-def]
            time.sleep(late)  # most of the boot wait has passed
            raise EmergencyStop(signal.SIGTERM)

        dome.link._wait_boot = stopped_late
        waits = []  # the deadlines the waits for the ready banner were given
        wait_ready = dome.link._wait_ready

        def recorded(deadline, already):  # type: ignore[no-untyped-def]
            waits.append(deadline)
            return wait_ready(deadline, already)

        dome.link._wait_ready = recorded
        with pytest.raises(EmergencyStop):
            dome.connect()
        # judged by the deadline asked for, not by the time taken (which CPU load stretches):
        # the opening's own deadline, not a fresh one from the stop (late + boot_wait)
        opened = dome.link._opened_at
        assert waits, "the all-off went out without waiting out the boot"
        assert all(abs(d - (opened + boot_wait)) < 1e-6 for d in waits), (waits, opened)
        assert eventually(lambda: board.lit == frozenset())


def test_a_second_stop_during_that_all_off_says_it_was_not_sent_and_closes() -> None:
    """A further signal cuts the all-off of an interrupted connection short: the port is
    still closed, and the user is told the all-off was not sent (not "never reached")."""
    from rti_rig.app.dome_factory import build_dome
    from rti_rig.core.clock import VirtualClock
    from rti_rig.core.dome_link import OffOutcome
    from rti_rig.runtime.controller import EmergencyStop

    board = board_for("nab-rti-v1")
    with serve_on_pty(board, "nab") as link:
        dome = build_dome(DomeSerialSettings(port=link.port, profile="nab-rti-v1"), VirtualClock())

        def stopped(*args):  # type: ignore[no-untyped-def]
            raise EmergencyStop(signal.SIGTERM)

        dome.link.hello = stopped
        dome.link.all_off = stopped
        with pytest.raises(EmergencyStop):
            dome.connect()
        assert not dome.link.port_open
        assert dome.off_report is not None and dome.off_report.outcome is OffOutcome.NOT_SENT
        assert "switch the dome off at its power supply" in dome.off_report.sentence()


def test_failed_handshake_on_the_lit_nab_sketch_still_sends_all_off_and_says_so() -> None:
    """The issue's case: the project's 'framed' profile on the RTI v1.0 sketch, which boots with
    every LED on. The handshake fails; the all-off is sent anyway and reported unconfirmed."""
    from rti_rig.app.dome_factory import build_dome
    from rti_rig.core.clock import VirtualClock
    from rti_rig.core.dome_link import OffOutcome
    from rti_rig.core.errors import DeviceError

    board = board_for("nab-rti-v1")
    with serve_on_pty(board, "nab") as link:
        settings = DomeSerialSettings(
            port=link.port, profile="framed", baudrate=9600, ready_timeout_s=2.5
        )
        dome = build_dome(settings, VirtualClock())
        with pytest.raises(DeviceError, match="no handshake"):
            dome.connect()
        assert eventually(lambda: board.lit == frozenset())  # <0> reached the sketch
        assert dome.off_report is not None
        assert dome.off_report.outcome is OffOutcome.SENT_UNCONFIRMED
        assert "lights are off" not in dome.off_report.sentence()


def test_a_capture_outlasting_a_timed_led_is_refused_naming_the_led() -> None:
    from rti_rig.app.dome_factory import build_dome
    from rti_rig.core.clock import VirtualClock
    from rti_rig.core.dome_link import DomeLedError

    board = board_for("rtipy")
    with serve_on_pty(board, "rtipy") as link:
        settings = DomeSerialSettings(port=link.port, profile="rtipy", protocol={"light_on_s": 1})
        dome = build_dome(settings, VirtualClock())
        dome.connect()
        dome.light(15)
        assert eventually(lambda: board.lit == frozenset({15}))
        time.sleep(1.5)  # a capture far longer than the 1 s window (real time: the board's)
        with pytest.raises(DomeLedError, match="LED 15 went dark by itself") as info:
            dome.all_off()
        assert info.value.led == 15
        assert board.lit == frozenset()
        dome.close()


@pytest.mark.slow  # the rtipy dry run runs in real time: a connect, a window, three shots
def test_the_emulated_rtipy_window_runs_on_the_time_the_camera_takes() -> None:
    """A dry run on the emulated RTIPy dome spends the camera's time (exposure + readout +
    transfer, the config's [timing]: 1.05 s a shot at 0.05 s) on the board's clock, as the real
    rig does: the LED's 2 s window holds the first two shots of a series under one lighting,
    and the third, begun 2.2 s after the LED lit, is dark; the off after it refuses the series.
    The camera had taken its time on the dry run's simulated clock alone, none on the board's:
    every shot of any series was lit, and metering such a series showed nothing wrong."""
    from rti_rig.core.dome_link import DomeLedError

    with build_rig(load_rig_config(CONFIGS / "emulated_rtipy.toml")) as rig:
        board = rig.emulator  # type: ignore[attr-defined]
        rig.lighting.connect()
        rig.camera.connect()
        rig.lighting.set(plan_uniform(rig.geometry, 8).steps[0])
        rig.clock.sleep(rig.timing.settle_s)
        frames, lit = [], []
        for _ in range(3):
            lit.append(board.lit)  # as the shot begins (its exposure: 0.05 s of it)
            frames.append(rig.camera.capture(0.05))
        means = [float(f.pixels.mean()) for f in frames]
        assert lit[:2] == [frozenset({0})] * 2 and lit[2] == frozenset(), lit
        assert means[2] * 20 < min(means[:2]), means  # the third: the sensor's noise alone
        with pytest.raises(DomeLedError, match="LED 0 went dark by itself"):
            rig.lighting.off()


def elexol_with_map(tmp_path: Path, map_text: str, section: str = "Dome main") -> Path:
    (tmp_path / "maps.txt").write_text(map_text)
    text = (CONFIGS / "emulated_elexol.toml").read_text()
    text = text.replace("count = 12", "count = 8").replace("led_count = 12", "led_count = 8")
    text = text.replace(
        'profile = "elexol-24r1"',
        f'profile = "elexol-24r1"\nled_map_file = "maps.txt"\nled_map_section = "{section}"',
    )
    path = tmp_path / "rig.toml"
    path.write_text(text)
    return path


def test_elexol_led_map_file_relative_to_the_config_drives_the_mapped_outputs(
    tmp_path: Path,
) -> None:
    data = Path(__file__).resolve().parents[2] / "data" / "domes" / "led-maps.txt"
    cfg = elexol_with_map(tmp_path, data.read_text())
    r = runner.invoke(app, ["check", str(cfg)])
    assert r.exit_code == 0, r.output
    assert "RESULT: SENT, NOT VERIFIED" in r.output  # the Elexol answers no light command


def test_a_bad_led_map_file_is_refused_at_load_naming_file_and_line(tmp_path: Path) -> None:
    cfg = elexol_with_map(tmp_path, "** Dome main **\n0x01, zz, 0x00\n")
    r = runner.invoke(app, ["check", str(cfg)])
    assert r.exit_code == 2
    assert "maps.txt:2" in said(r) and "led_map_file" in said(r)


def test_a_misspelt_led_map_section_is_named_as_the_config_key(tmp_path: Path) -> None:
    """A section name the map file lacks was refused under led_map_file, as if the file were
    wrong; the fault is the rig config's led_map_section."""
    data = Path(__file__).resolve().parents[2] / "data" / "domes" / "led-maps.txt"
    cfg = elexol_with_map(tmp_path, data.read_text(), section="Dome mian")
    r = runner.invoke(app, ["check", str(cfg)])
    assert r.exit_code == 2
    text = said(r)
    assert "rig.toml" in text and "dome.serial.led_map_section" in text
    assert "no section 'Dome mian'" in text and "Dome main" in text


def test_more_leds_than_the_elexol_map_has_rows_says_what_to_do(tmp_path: Path) -> None:
    """30 LEDs on the default map (24 outputs, one LED each) had been refused with only "the LED
    map has 24 rows for led_count = 30"."""
    text = (CONFIGS / "emulated_elexol.toml").read_text()
    text = text.replace("count = 12", "count = 30").replace("led_count = 12", "led_count = 30")
    cfg = tmp_path / "rig.toml"
    cfg.write_text(text)
    r = runner.invoke(app, ["check", str(cfg)])
    assert r.exit_code == 2
    text = said(r)
    assert "the LED map has 24 rows for led_count = 30" in text
    assert "give led_count = 24 or fewer, or an led_map_file" in text


@pytest.mark.parametrize("kind", ["garble_reply", "drop_reply"])
def test_a_stepping_dome_rewinds_after_a_doubtful_step_and_labels_every_image_right(
    kind: str, tmp_path: Path
) -> None:
    from rti_rig.testing.verify import wrong_light_steps

    cfg = with_faults("nichlock", tmp_path, f'faults = [{{at_command = 8, kind = "{kind}"}}]\n')
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", str(cfg), "--out", str(out), "--lights", "8"])
    assert r.exit_code == 0, r.output
    assert wrong_light_steps(cfg, out) == []


def test_a_port_that_never_opened_says_this_run_lit_nothing(tmp_path: Path) -> None:
    """The shipped 48-LED dome config with no board attached: the port cannot be opened, so
    nothing was sent at all. Saying "all-off could NOT be sent: lights may still be on" claimed
    a failed all-off that never happened; the user is told what is known instead."""
    out = tmp_path / "s"
    cfg = Path(__file__).resolve().parents[3] / "rig_configs" / "example_dome_48.toml"
    r = runner.invoke(app, ["run", str(cfg), "--out", str(out), "--lights", "4"])
    assert r.exit_code == 2, r.output
    text = " ".join(said(r).split())
    assert "port could not be opened" in text
    assert "this run lit nothing" in text
    assert "could NOT be sent" not in text
    assert "no handshake" not in text
    assert "lights are off" not in text


def test_a_check_whose_port_never_opened_does_not_report_a_dome_of_0_leds() -> None:
    """`check` on the shipped 48-LED config with no board had printed "dome: unknown firmware,
    0 LEDs" and "LEDs stepped: 0, passed: 0, failed: 0 in 0.00 s": a dome that answered with no
    LEDs, where nothing was reached at all."""
    cfg = Path(__file__).resolve().parents[3] / "rig_configs" / "example_dome_48.toml"
    r = runner.invoke(app, ["check", str(cfg)], terminal_width=400)
    text = " ".join(r.output.split())
    assert r.exit_code == 1 and "RESULT: FAIL" in text, text
    assert "0 LEDs" not in text and "LEDs stepped: 0" not in text, text
    assert (
        "dome on /dev/serial/by-id/usb-Arduino_Mega_2560-if00: not reached, no LED stepped" in text
    ), text
    assert "port could not be opened" in text


@pytest.mark.slow  # rti-dome-m blocks 1.5 s per command over a real pty
def test_a_dry_run_counts_the_time_the_firmware_really_blocks(tmp_path: Path) -> None:
    """rti-dome-m blocks 1.5 s after every ``M<n>`` (docs/domes.md). The emulator does so in
    real time on its pty while the dry run's rig clock is simulated: the rig time the session
    reports (what the real rig would take) must count it. It reported 9.2 s for 8 lights."""
    out = tmp_path / "s"
    cfg = CONFIGS / CONFIG["rti-dome-m"]
    r = runner.invoke(app, ["run", str(cfg), "--out", str(out), "--lights", "2", "--no-verdict"])
    assert r.exit_code == 0, r.output
    timing = json.loads((out / "manifest.json").read_text())["timing"]
    # at least: 2 lights and 2 all-offs (start, end), each blocking 1.5 s
    assert timing["rig_time_s"] >= 4 * 1.5


@pytest.mark.slow  # real firmware timing over a pty
def test_check_fails_a_dome_whose_camera_does_not_connect(tmp_path: Path) -> None:
    """check walked the LEDs and said PASS; the session then failed at its first capture
    (gphoto2 missing, no camera found). The camera is now opened and released after the walk."""
    board = board_for("minirti")
    with serve_on_pty(board, "minirti") as link:
        cfg = _hardware(tmp_path, "emulated_minirti.toml", link.port, camera_connects=False)
        r = runner.invoke(app, ["check", str(cfg)], terminal_width=400)
    text = said(r)
    assert r.exit_code == 1, text
    assert "acknowledged by the board: 12, failed: 0" in text  # the lights were fine
    assert "camera: FAILED to connect" in text and str(tmp_path / "v9") in text
    assert r.output.rstrip().splitlines()[-1] == "RESULT: FAIL"


NICHLOCK = ("--profile", "nichlock")


@pytest.mark.slow  # a firmware served in another process, read over a real pty
def test_a_fault_asked_of_a_served_firmware_happens() -> None:
    """``python -m rti_rig.simulator.dome_firmware --profile nichlock --fault 1:reset``: the
    board resets as its first command arrives. Run as ``-m``, the module's faults were built
    from its ``__main__`` copy, whose FaultKind the boards never matched: every ``--fault`` on
    a real firmware's emulator was silently ignored (the board answered ``m`` as if asked)."""
    import subprocess

    import serial

    proc = subprocess.Popen(
        [sys.executable, "-m", "rti_rig.simulator.dome_firmware", *NICHLOCK, "--fault", "1:reset"],
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        line = line_within(proc, 120, "the served firmware's port")
        port = serial.Serial(line.split()[-1], 115200, timeout=0.1)
        banner = b"For help, press 'h'\n>"

        def read_until(end: bytes) -> bytes:
            got = b""
            deadline = time.monotonic() + 20.0
            while end not in got and time.monotonic() < deadline:
                got += port.read(256)
            return got

        assert banner in read_until(banner)
        port.write(b"m")  # command 1: the board resets instead of answering
        again = read_until(banner)
        port.close()
        assert b"Reflectance Transformation Imager Serial Interface" in again, again
        assert b"RAM bytes remaining" not in again
    finally:
        proc.terminate()  # the process this test started, by its own handle
        proc.wait(timeout=10)


def test_a_fault_a_firmware_emulator_does_not_emulate_is_refused(capsys) -> None:  # type: ignore[no-untyped-def]
    """A kind the boards do not apply (a garbled command) had been accepted and ignored."""
    from rti_rig.simulator.dome_firmware import main

    with pytest.raises(SystemExit) as stopped:
        main(["--profile", "nichlock", "--fault", "2:garble_command", "--seconds", "0.1"])
    assert stopped.value.code == 2
    err = " ".join(capsys.readouterr().err.split())
    assert "--fault garble_command: the nichlock firmware's emulator does not emulate it" in err
    with pytest.raises(SystemExit):
        main(["--profile", "nichlock", "--fault", "reset"])
    assert "give K:KIND" in capsys.readouterr().err


def test_a_served_firmware_boots_as_slowly_as_asked(monkeypatch: pytest.MonkeyPatch) -> None:
    """``--boot-delay-s`` sets a real firmware's bootloader time (an older or slower bootloader,
    whose banner comes after the profile's boot wait), so that case can be rehearsed through
    ``rti-rig probe``/``check``; it had been refused for every real firmware's emulator."""
    import contextlib

    from rti_rig.simulator import dome_firmware

    served = []

    @contextlib.contextmanager
    def serve(board, name):  # type: ignore[no-untyped-def]
        served.append(board)
        yield type("Link", (), {"port": "/dev/null", "alive": False})()

    monkeypatch.setattr(dome_firmware, "serve_on_pty", serve)
    assert dome_firmware.main(["--profile", "nab-rti-v1", "--boot-delay-s", "7"]) == 0
    assert served[0].boot_s == 7.0
    assert board_for("nab-rti-v1").boot_s == 1.6  # the firmware's own, untouched
    with pytest.raises(SystemExit):
        dome_firmware.main(["--profile", "nab-rti-v1", "--leds", "8"])


def test_an_elexol_board_whose_first_reply_is_lost_is_checked(tmp_path: Path) -> None:
    """The Elexol board sends no banner (nothing resets it when the port opens), so nothing had
    shown it there before its ``?``: the answer lost (a USB-serial adapter dropping bytes at
    the open) failed the check with "no handshake … check the port, the baud rate and the
    protocol profile". ``?`` lights nothing, so it is asked once more."""
    cfg = with_faults("elexol-24r1", tmp_path, 'faults = [{at_command = 1, kind = "drop_reply"}]\n')
    r = runner.invoke(app, ["check", str(cfg)])
    assert r.exit_code == 0, r.output
    assert "no handshake" not in said(r)
    assert "RESULT: SENT, NOT VERIFIED" in said(r) and "1 retries" in said(r)


@pytest.mark.slow  # real firmware timing over a pty
def test_a_nichlock_board_held_in_its_touch_calibration_is_said_so(tmp_path: Path) -> None:
    """An uncalibrated touch screen holds nichlock's boot in ``calTouch``, which answers each
    key ``Recieved: x``. The check had said "a board on this port sends bytes, but none this
    rig config's protocol profile understands: check the profile (rti-rig probe …)", and the
    probe then named this very profile; the all-off was resent into the calibration."""
    from rti_rig.simulator.domes.nichlock import NichlockBoard

    board = NichlockBoard(touch_calibrated=False)
    with serve_on_pty(board, "nichlock") as link:
        cfg = _hardware(tmp_path, "emulated_nichlock.toml", link.port)
        r = runner.invoke(app, ["check", str(cfg)], terminal_width=400)
        assert eventually(lambda: board.heard.count(b"x") == 2)  # its own, and the closing one
    assert r.exit_code == 1, r.output
    text = said(r)
    assert "the dome is in its touch-screen calibration" in text
    assert "tap the two red circles on its display" in text
    assert "check the profile" not in text and "lights are off" not in text
    assert board.heard == b"xx"  # not resent: each would be one more key into the calibration


@pytest.mark.slow  # real firmware timing over a pty
def test_a_check_whose_board_answered_before_its_all_off_failed_says_what_was_reached(
    tmp_path: Path,
) -> None:
    """The Nab sketch's banner came through and it acknowledged the init all-off; then the reply
    to the connect's all-off was lost. The check had said "not reached" and "nothing on this
    port has answered yet: check the port, the baud rate and the protocol profile", of a board
    that had just answered in its profile."""
    cfg = with_faults("nab-rti-v1", tmp_path, 'faults = [{at_command = 2, kind = "drop_reply"}]\n')
    cfg.write_text(cfg.read_text().replace("retries = 2", "retries = 0"))
    r = runner.invoke(app, ["check", str(cfg)], terminal_width=400)
    assert r.exit_code == 1, r.output
    text = said(r)
    assert "not reached" not in text and "nothing on this port has answered" not in text, text
    assert "connected (the board answered in its protocol profile), but the all-off" in text
    assert "no LED stepped" in text and "RESULT: FAIL" in text


@pytest.mark.slow  # real firmware timing over a pty
def test_a_check_whose_board_never_answered_is_not_said_to_be_connected(tmp_path: Path) -> None:
    """miniRTI has no handshake: its connect ends in an all-off whose ack is the first word
    heard. At a wrong baud rate none comes; that is a port that opened, not a dome reached."""
    board = board_for("minirti")
    with serve_on_pty(board, "minirti") as link:
        cfg = _hardware(tmp_path, "emulated_minirti.toml", link.port)
        text = cfg.read_text().replace('profile = "minirti"', 'profile = "minirti"\nretries = 0')
        cfg.write_text(text.replace("retries = 2", "baudrate = 57600"))
        r = runner.invoke(app, ["check", str(cfg)], terminal_width=400)
    assert r.exit_code == 1, r.output
    text = said(r)
    assert "connected" not in text.replace("camera: folder-camera connected", ""), text
    assert "port opened, but nothing came back that its protocol profile reads" in text
    assert "nothing on this port has answered yet" in text


@pytest.mark.slow  # real firmware timing over a pty
def test_a_profile_forced_onto_another_firmwares_board_is_refused_before_sending(
    tmp_path: Path,
) -> None:
    """The nab-rti-v1 profile (at the board's baud rate) on a nichlock board, whose boot banner
    names it: the Nab init ``<0>`` stepped the board to LED 0, the all-off after the failed
    connect to LED 1, and the user was told to check the port, the baud rate and the profile.
    Now none of the profile's commands is sent, the firmware is named, and nichlock's own
    all-off (``x``) alone is sent and its acknowledgement said."""
    from rti_rig.simulator.domes.nichlock import NichlockBoard

    board = NichlockBoard()
    with serve_on_pty(board, "nichlock") as link:
        cfg = _hardware(tmp_path, "emulated_nab_rti_v1.toml", link.port)
        cfg.write_text(cfg.read_text().replace("retries = 2", "retries = 2\nbaudrate = 115200"))
        r = runner.invoke(app, ["check", str(cfg)], terminal_width=400)
    assert r.exit_code == 1, r.output
    text = said(r)
    assert "printed the boot banner of the nichlock firmware" in text, text
    assert 'set profile = "nichlock"' in text
    assert "none of this profile's commands was sent to it" in text
    assert "lights: all-off sent and acknowledged by the dome: lights are off" in text, text
    assert bytes(board.heard) == b"x"
    assert all(not lit for _, lit in board.timeline)


@pytest.mark.slow  # real firmware timing over a pty
@pytest.mark.parametrize("profile", ["rtipy", "minirti", "rti-dome-m"])
def test_a_board_refused_for_the_nab_banner_is_switched_off_by_the_nab_all_off(
    tmp_path: Path, profile: str
) -> None:
    """The Nab sketch boots with every LED on. Under another 9600-baud profile its banner
    refused it, and it was left lit ("all-off could NOT be sent … switch the dome off at its
    power supply"). Now the sketch's own all-off, ``<0>``, alone is sent, and its
    acknowledgement is what the lights line says; the profile to set is named."""
    board = board_for("nab-rti-v1")
    shipped = {"rtipy": "emulated_rtipy.toml", "minirti": "emulated_minirti.toml"}
    with serve_on_pty(board, "nab-rti-v1") as link:
        cfg = _hardware(tmp_path, shipped.get(profile, "emulated_rti_dome.toml"), link.port)
        r = runner.invoke(app, ["check", str(cfg)], terminal_width=400)
        assert eventually(lambda: board.lit == frozenset())
    assert r.exit_code == 1, r.output
    text = said(r)
    assert "printed the boot banner of the nab-rti-v1 firmware" in text, text
    assert 'set profile = "nab-rti-v1"' in text
    assert "lights: all-off sent and acknowledged by the dome: lights are off" in text, text
    assert "Traceback" not in text
    # the heading names the firmware found, not the profile's name and the config's LED count
    # ("rti-dome-m, 8 LEDs" beside "LEDs stepped: 0" had read as a board identified, counted)
    assert "banner of the nab-rti-v1 firmware (see ABORTED below); its LED count is unknown" in (
        text
    ), text
    assert not re.search(r", \d+ LEDs$", text, re.M) and "LEDs stepped" not in text, text
    assert "light command round trip" not in text  # of another firmware's board
    # the sketch read one command, its own all-off: a banner later than the profile's boot
    # wait (minirti waits 1.5 s, rti-dome-m none, the sketch's bootloader 1.6 s) had been read
    # a byte at a time as acks, or dropped as stale input and the board said "most likely off"
    heard = bytes(board.heard)
    assert heard.endswith(b"<0>") and heard.count(b"<") == 1, heard


@pytest.mark.slow  # every probe, each listening 2.6 s after the port opens
def test_a_probe_that_heard_nothing_says_a_slow_booting_board_may_light_after_it(
    tmp_path: Path,
) -> None:
    """A Nab board whose bootloader outlasts each probe's listen answers none (each opening
    resets it), then lights every LED as it boots once the probe has closed the port: the probe
    had said only "nothing that lights an LED was sent"."""
    board = board_for("nab-rti-v1")
    board.boot_s = 30.0
    with serve_on_pty(board, "nab-rti-v1") as link:
        r = runner.invoke(app, ["probe", link.port], terminal_width=400)
    text = said(r)
    assert r.exit_code == 1, text
    assert "No known dome firmware answered" in text
    assert "takes longer than the 2.6 s each probe listens to boot" in text, text
    assert "(the Nab sketch: every LED): look at the dome" in text


@pytest.mark.slow  # real firmware timing over a pty, and a board 5 s in its bootloader
def test_a_banner_later_than_the_boot_wait_is_a_late_boot_and_the_board_is_switched_off(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    """A Nab board whose bootloader takes 5 s (the profile waits 4 s): the init ``<0>`` went
    into the bootloader, the banner then read as a reboot or, cut at a reply's deadline, as an
    unreadable reply ("check the port, the baud rate and the protocol profile"), and the board,
    lit at its boot, was said "may still be on". Now the init is sent again after the banner,
    and the late boot is said with the key to raise."""
    board = board_for("nab-rti-v1")
    board.boot_s = 5.0
    with serve_on_pty(board, "nab-rti-v1") as link:
        cfg = _hardware(tmp_path, "emulated_nab_rti_v1.toml", link.port)
        r = runner.invoke(app, ["check", str(cfg)], terminal_width=400)
        assert eventually(lambda: board.lit == frozenset())
    text = said(r)
    assert r.exit_code == 0, text
    assert "RESULT: PASS" in text and "lights are off" in text, text
    # said once, in the check's own report line; no raw log record at warning level (the
    # command line would print it on stderr)
    assert text.count("printed its boot banner only") == 1, text
    assert "slow boot: the board printed its boot banner only" in text, text
    assert "boot_wait_s = 4 s" in text and "set boot_wait_s = " in text, text
    assert "[dome.serial.protocol]" in text, text
    assert "rebooted" not in text and "check the port" not in text, text
    assert not [x for x in caplog.records if x.levelno >= logging.WARNING], caplog.text


@pytest.mark.slow  # real firmware timing over a pty, and a board 5 s in its bootloader
def test_a_run_on_a_board_later_than_the_boot_wait_says_it_once_in_words(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    """The same late boot under ``run``: the advice (the boot wait to raise) had reached the
    user only as a raw WARNING record on stderr; it is said once, as the product speaks."""
    board = board_for("nab-rti-v1")
    board.boot_s = 5.0
    with serve_on_pty(board, "nab-rti-v1") as link:
        cfg = _hardware(tmp_path, "emulated_nab_rti_v1.toml", link.port)
        argv = ["run", str(cfg), "--lights", "2", "--out", str(tmp_path / "S"), "--no-verdict"]
        r = runner.invoke(app, argv, terminal_width=400)
        assert eventually(lambda: board.lit == frozenset())
    text = said(r)
    # the hardware variant's folder camera gets no file, so the run ends at its first image:
    # the connect, which this is about, is behind it
    assert "no new file matching" in text, text
    assert text.count("Slow boot: the board printed its boot banner only") == 1, text
    assert "set boot_wait_s = " in text and "the session goes on" in text, text
    assert "failed while connecting" not in text, text
    assert not [x for x in caplog.records if x.levelno >= logging.WARNING], caplog.text


@pytest.mark.slow  # real firmware timing over a pty
def test_a_board_silent_through_the_connect_names_its_boot_wait(tmp_path: Path) -> None:
    """A Nab board still in its bootloader when the connect gave up: the advice was the port,
    the baud rate and the profile alone, where the board prints a banner at every opening and
    none came; the boot wait is named too (the lights are said unknown: it boots lit)."""
    board = board_for("nab-rti-v1")
    board.boot_s = 30.0
    with serve_on_pty(board, "nab-rti-v1") as link:
        cfg = _hardware(tmp_path, "emulated_nab_rti_v1.toml", link.port)
        text = cfg.read_text().replace("reply_timeout_s = 3.0", "reply_timeout_s = 0.5")
        cfg.write_text(text.replace("led_count = 12", "led_count = 12\nboot_wait_s = 0.5"))
        r = runner.invoke(app, ["check", str(cfg)], terminal_width=400)
    text = said(r)
    assert r.exit_code == 1, text
    assert "prints a boot banner each time its port opens, and none came" in text, text
    assert "boot_wait_s = 0.5 s" in text and "raise boot_wait_s in [dome.serial.protocol]" in text
    assert "lights may still be on" in text


@pytest.mark.slow  # real firmware timing over a pty
def test_a_timed_firmware_at_a_wrong_baud_rate_gets_the_port_baud_profile_advice(
    tmp_path: Path,
) -> None:
    """RTIPy's profile has no all-off to send: the connect's "all-off" is a wait, which had
    counted as the board answering, so the first light's garbled reply (a wrong baud rate)
    ended the check with "gave up after 3 attempts" and no word of the baud rate."""
    board = board_for("rtipy")
    with serve_on_pty(board, "rtipy") as link:
        cfg = _hardware(tmp_path, "emulated_rtipy.toml", link.port)
        cfg.write_text(cfg.read_text().replace("retries = 2", "retries = 0\nbaudrate = 57600", 1))
        r = runner.invoke(app, ["check", str(cfg)], terminal_width=400)
    assert r.exit_code == 1, r.output
    text = said(r)
    assert "none this rig config's protocol profile understands" in text, text
    assert "dome.serial.baudrate = 57600" in text and "set it to 9600" in text


@pytest.mark.slow  # real firmware timing over a pty
def test_a_custom_description_of_a_sketch_keeping_a_known_banner_is_not_refused() -> None:
    """Only the built-in profiles refuse another built-in firmware's banner: a custom
    description may be of a modified Nab sketch that still prints the Nab banner."""
    from rti_rig.drivers.led_dome.factory import build_driver

    spec = builtin_spec("nab-rti-v1")
    spec["name"] = "my-nab"
    del spec["ready_pattern"], spec["reset_pattern"]
    board = board_for("nab-rti-v1")
    with serve_on_pty(board, "nab-rti-v1") as link:
        driver = build_driver(DomeSerialSettings(port=link.port, profile="custom", protocol=spec))
        try:
            assert driver.connect().firmware_id == "my-nab"
        finally:
            driver.close()
    assert board.commands == 1  # its init all-off went through


def test_a_stop_inside_the_opening_whose_port_will_not_reopen_says_the_board_is_lit() -> None:
    """A stop inside the port's opening (which reset the board), and the port then does not
    open again for the all-off: the lights line says the Nab board, which boots with every LED
    lit, is lit and to cut its supply (it had said "the dome was never reached")."""
    from rti_rig.app.dome_factory import build_dome
    from rti_rig.core.clock import VirtualClock
    from rti_rig.core.dome_link import OffOutcome
    from rti_rig.drivers.led_dome.transport import TransportError
    from rti_rig.runtime.controller import EmergencyStop

    board = board_for("nab-rti-v1")
    with serve_on_pty(board, "nab") as link:
        dome = build_dome(DomeSerialSettings(port=link.port, profile="nab-rti-v1"), VirtualClock())
        transport = dome.link.transport
        real_open, opens = transport.open, []

        def open_port():  # type: ignore[no-untyped-def]
            opens.append(1)
            if len(opens) > 1:
                raise TransportError(f"cannot open serial port {link.port}: No such device")
            real_open()
            transport.close()  # as pyserial closes the port when a stop goes through its open
            raise EmergencyStop(signal.SIGTERM)

        transport.open = open_port
        with pytest.raises(EmergencyStop):
            dome.connect()
        assert len(opens) == 2  # the port was tried again for the all-off
        report = dome.off_report
        assert report is not None and report.outcome is OffOutcome.NOT_SENT
        said = report.sentence()
        assert "every LED is on now; switch the dome off at its power supply" in said, said
        assert said.count("power supply") == 1, said
        assert "never reached" not in said
