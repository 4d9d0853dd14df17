"""Emulators of real dome firmwares, one module each, written from their published behaviour
(never from this project's driver); :func:`board_for` picks a serial one by profile name.

``cceh_rti`` has no serial link: the camera's flash contact steps it, so it is fired by
:class:`rti_rig.simulator.flash_sync_camera.FlashSyncCamera`, not served on a pty."""

from __future__ import annotations

from rti_rig.core.clock import Clock
from rti_rig.simulator.dome_firmware import FaultPlan
from rti_rig.simulator.domes.board import Board

#: The built-in firmware profiles with a serial emulator here (``board_for`` serves each).
SERIAL_FIRMWARES = ("nab-rti-v1", "rtipy", "minirti", "elexol-24r1", "rti-dome-m", "nichlock")


def board_for(
    profile: str,
    *,
    clock: Clock | None = None,
    faults: FaultPlan | None = None,
    led_map: tuple[tuple[int, ...], ...] | None = None,
) -> Board:
    """The emulated board of built-in profile ``profile``."""
    from rti_rig.simulator.domes.elexol import ElexolBoard
    from rti_rig.simulator.domes.minirti import MiniRtiBoard
    from rti_rig.simulator.domes.nab_rti_v1 import NabRtiV1Board
    from rti_rig.simulator.domes.nichlock import NichlockBoard
    from rti_rig.simulator.domes.rti_dome import RtiDomeBoard
    from rti_rig.simulator.domes.rtipy import RtiPyBoard

    boards: dict[str, type[Board]] = {
        "nab-rti-v1": NabRtiV1Board,
        "rtipy": RtiPyBoard,
        "minirti": MiniRtiBoard,
        "rti-dome-m": RtiDomeBoard,
        "nichlock": NichlockBoard,
    }
    if profile == "elexol-24r1":
        from rti_rig.drivers.led_dome.dome_profiles.elexol import DEFAULT_MAP

        rows = led_map or tuple(tuple(r) for r in DEFAULT_MAP)
        return ElexolBoard(rows, clock=clock, faults=faults)
    if profile not in boards:
        raise KeyError(f"no emulator for dome profile '{profile}'")
    return boards[profile](clock=clock, faults=faults)
