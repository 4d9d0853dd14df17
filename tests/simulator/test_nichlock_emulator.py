"""nichlock/rti's emulator (``simulator/domes/nichlock.py``) against the firmware's source.

The source is ``arduino-program/src/main.cpp`` (``setup``, ``serialReact``), ``patterns.cpp``
and ``displayCtrl.cpp`` (``beginDisplay``, ``calTouch``). Its serial menus had not been
emulated: every key but ``0 . x m`` and a newline answered "Did nothing", where the firmware
opens a menu that waits for its next key, scans a channel for a minute or restarts. The board
runs in-process on a virtual clock, so its own waits cost no real time.
"""

from __future__ import annotations

from rti_rig.core.clock import VirtualClock
from rti_rig.simulator.domes.nichlock import NichlockBoard

PROMPT = "\nFor help, press 'h'\n>"


def booted(**kw: object) -> tuple[NichlockBoard, VirtualClock]:
    clock = VirtualClock()
    board = NichlockBoard(clock=clock, **kw)  # type: ignore[arg-type]
    board.on_port_opened()
    return board, clock


def send(board: NichlockBoard, clock: VirtualClock, data: bytes, seconds: float) -> str:
    """What the firmware prints within ``seconds`` of receiving ``data``."""
    out = board.receive(data) if data else []
    clock.sleep(seconds)
    out += board.tick()
    return b"".join(o.data for o in out).decode("latin-1")


def test_the_boot_says_what_begin_display_prints() -> None:
    board, clock = booted()
    said = send(board, clock, b"", 3.0)
    assert "Initialized Display.\r\n1\r\nSetting channel color names:" in said
    assert said.endswith(PROMPT)


def test_a_baud_rate_chosen_in_the_settings_menu_is_used_from_the_next_boot() -> None:
    board, clock = booted()
    send(board, clock, b"", 3.0)
    said = send(board, clock, b"a", 0.2)
    assert said.endswith("5. Default Channel/Color\r\n")  # waits for its key: no prompt
    said = send(board, clock, b"2", 0.2) + send(board, clock, b"4", 0.2)
    assert "4. 19200\r\n" in said and "Set serial baud rate to 19200. Restart to apply." in said
    assert said.endswith(">") and board.baudrate == 115200  # not before a restart
    board.on_port_opened()  # the next open resets the board
    send(board, clock, b"", 3.0)
    assert board.baudrate == 19200


def test_c_at_a_menu_cancels_it_without_a_prompt() -> None:
    board, clock = booted()
    send(board, clock, b"", 3.0)
    said = send(board, clock, b"ac", 0.5)
    assert said.endswith("Cancelled\r\n")
    assert send(board, clock, b"m", 0.2) == "m\r\nRAM bytes remaining: 4021\r\n>"


def test_a_column_scan_lights_each_led_of_its_channel_and_does_not_read_meanwhile() -> None:
    board, clock = booted()
    send(board, clock, b"", 3.0)
    start = clock.now()
    said = send(board, clock, b"2", 10.0)
    assert said == "2\r\nColumn scanning on channel 2: White   \r\n"  # still scanning
    said += send(board, clock, b"x", 70.0)  # read only once the scan has ended
    lit = [leds for t, leds in board.timeline if t >= start and leds]
    assert lit == [frozenset({i}) for i in range(64, 128)]
    assert said.endswith(">x\r\nAll LEDs shut off, active LED number reset to zero.\r\n>")


def test_the_ring_test_takes_any_key_as_its_number_and_lights_its_leds() -> None:
    board, clock = booted()
    send(board, clock, b"", 3.0)
    start = clock.now()
    said = send(board, clock, b"r12", 3.0)
    # the sketch names channel N by chNames[N], the next channel's name (its off-by-one)
    assert "Running column #1, on channel #2: IR      \r\n1\r\n2\r\n" in said
    lit = [leds for t, leds in board.timeline if t >= start and leds]
    assert lit == [frozenset({i}) for i in range(64, 128, 8)]
    assert said.endswith(": y" * 8 + ">")


def test_s_restarts_the_sketch_unless_c_comes_within_4_s() -> None:
    board, clock = booted()
    send(board, clock, b"", 3.0)
    said = send(board, clock, b"s", 1.0) + send(board, clock, b"c", 0.5)
    assert said.endswith("Cancelled.\n\r\n>")
    send(board, clock, b"00", 0.5)
    assert board.lit == frozenset({1})
    said = send(board, clock, b"s", 5.0)
    assert "Restarted.\n\n\r\n" + "~" * 38 in said and said.endswith(PROMPT)
    assert board.lit == frozenset()
    assert send(board, clock, b"0", 0.2).startswith("0\r\nLED number: 0;")  # counting anew


def test_an_uncalibrated_touch_screen_holds_the_boot_until_c() -> None:
    board, clock = booted(touch_calibrated=False)
    said = send(board, clock, b"", 5.0)
    assert "Touch screen was not calibrated. Starting Calibration.." in said
    assert PROMPT not in said  # waits for two taps on the display
    said = send(board, clock, b"x", 0.2)
    assert said == "Recieved: x\r\n"
    said = send(board, clock, b"c", 0.5)
    assert said.startswith("Recieved: c\r\nCancelled\r\nSetting channel color names:")
    assert said.endswith(PROMPT)


def test_er_clears_the_stored_baud_rate_and_the_calibration_for_the_next_boot() -> None:
    board, clock = booted(baudrate=9600)
    send(board, clock, b"", 3.0)
    said = send(board, clock, b"er", 0.2) + send(board, clock, b"Y", 0.2)
    assert said.endswith("(Y/N): Clearing. T-  Done.\r\n>")
    board.on_port_opened()
    said = send(board, clock, b"", 3.0)
    assert "Baud rate was NOT FOUND, and has been newly written into EEPROM" in said
    assert board.baudrate == 115200
    assert "Starting Calibration.." in said and PROMPT not in said


def test_verbose_serial_says_each_steps_shutter_inside_its_reply_and_after_the_prompt() -> None:
    """``setShutter`` (``shutterCtrl.cpp``) prints when verbose serial is on (the settings
    menu's option 4, kept in EEPROM): ``0``'s ``trigger(1, 1)`` says the shutter before the
    prompt, and ``loop``'s ``checkShutters`` says it again a moment after; the boot's
    ``beginShutters`` says it starts them after the boot prompt."""
    board, clock = booted(verbose=True)
    boot = send(board, clock, b"", 3.0)
    assert boot.endswith(PROMPT + "\tStartig shutters...\r\n")
    said = send(board, clock, b"0", 0.5)
    assert said.startswith("0\r\nLED number: 0; on pin 1\r\nShutter turning on at: ")
    head, tail = said.split(">", 1)
    assert head.endswith("ms)\r\n")
    assert tail == "Shutter turning off at: 0 seconds(1ms)\r\n"
    assert board.lit == frozenset({0})
    # quiet (the EEPROM's default): the reply as before, nothing after the prompt
    board, clock = booted()
    send(board, clock, b"", 3.0)
    assert send(board, clock, b"0", 0.5) == "0\r\nLED number: 0; on pin 1\r\n>"
