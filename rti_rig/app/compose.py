"""The composition root: turns a validated rig config into devices.

This is the one place in the core that imports ``simulator`` (and, as backends arrive,
``drivers``): the backend is chosen by the config's ``backend`` key, never by magic port names.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

from rti_rig.app.config import LoadedRig, emulated_led_directions, rig_geometry
from rti_rig.core.clock import Clock, SystemClock, VirtualClock
from rti_rig.core.rig_geometry import ArmGeometry, DomeGeometry, LampGeometry
from rti_rig.runtime.duty_ledger import DutyLedger
from rti_rig.runtime.lighting import ArmLighting, DomeLighting
from rti_rig.runtime.rig import Rig, RigResources

if TYPE_CHECKING:
    from rti_rig.simulator.dynamixel_emulator import DynamixelBusEmulator
    from rti_rig.simulator.servo_latch import LatchedErrors


def build_rig(loaded: LoadedRig, clock: Clock | None = None) -> Rig:
    """Build the rig a config describes.

    Simulated and emulated rigs run on a virtual clock (a dry run reports the real rig's time
    without waiting for it); hardware runs on the system clock. So does, unless ``clock`` is
    given, an emulated firmware that switches its LEDs on its own clock (RTIPy's self-timed
    window): see :func:`_build_emulated_firmware_dome`. Use the rig as a context manager (or
    call ``close``) to release emulators and ports afterwards.
    """
    from rti_rig.app.disk_estimate import bytes_per_image, size_from_frame

    cfg = loaded.config
    if cfg.backend == "hardware":
        rig = _build_hardware(loaded, clock or SystemClock())
    elif cfg.backend == "replay":
        rig = _build_replay(loaded, clock or VirtualClock())
    else:
        rig = _build_simulated(loaded, clock)
    rig.bytes_per_image = bytes_per_image(loaded)  # what the controller's disk checks count
    rig.size_from_frame = size_from_frame(loaded)  # the first real frame's size, counted
    rig.lamps = lamp_geometry(loaded)
    return rig


def lamp_geometry(loaded: LoadedRig) -> LampGeometry | None:
    """The lamps' distance and the frame's field on the object: the config's ``[lamps]``, else
    a simulated or emulated scene's own (its point lamps' ``light_distance_mm``, the library
    scene's field at the camera's width); None: neither (distant lamps assumed)."""
    cfg = loaded.config
    if cfg.lamps is not None:
        return LampGeometry(cfg.lamps.distance_mm, cfg.lamps.field_width_mm)
    if cfg.backend in ("simulated", "emulated") and cfg.scene.light_distance_mm is not None:
        from rti_rig.simulator.sim_scene import field_width_mm

        return LampGeometry(cfg.scene.light_distance_mm, field_width_mm(cfg.camera.width))
    return None


#: The simulated scenes are lit so that this exposure fills 3/4 of the sensor's well with a white
#: surface facing the light: a config's exposure_s over- or under-exposes them as on a real rig.
SIMULATED_SCENE_EXPOSURE_S = 0.05


def scene_renderer(loaded: LoadedRig):  # type: ignore[no-untyped-def]
    """The simulator's renderer of the config's ``[scene]`` at the camera's size."""
    from rti_rig.simulator.sim_scene import renderer_for

    cfg = loaded.config
    return renderer_for(
        cfg.scene.name,
        cfg.camera.height,
        cfg.camera.width,
        cfg.scene.seed,
        cfg.scene.light_distance_mm,
    )


def _simulated_camera(loaded: LoadedRig, state, clock: Clock):  # type: ignore[no-untyped-def]
    """A camera that renders the scene under whatever light ``state`` says is really on."""
    from rti_rig.simulator.sim_camera import SimulatedCamera

    cfg = loaded.config
    render = scene_renderer(loaded)

    return SimulatedCamera(
        render,
        state,
        clock,
        reference_exposure_s=SIMULATED_SCENE_EXPOSURE_S,
        readout_s=cfg.timing.readout_s,
        transfer_s=cfg.timing.transfer_s,
        noise=cfg.scene.noise,
        seed=cfg.scene.seed,
        raw=cfg.scene.raw,
    )


def _where_leds_are(loaded: LoadedRig, geometry: DomeGeometry) -> Any:
    """Where the emulated dome's LEDs really are: ``[emulator] led_directions_file`` if set
    (a dome shot on a stand-in layout), else where its config says."""
    real = emulated_led_directions(loaded, geometry.count)
    return geometry.directions if real is None else real


class _FirmwareLight:
    """The light state the emulated dome firmware really produces, for the simulated camera."""

    def __init__(self, firmware, directions, max_level: int, power) -> None:  # type: ignore[no-untyped-def]
        self._fw, self._directions, self._max = firmware, directions, max_level
        self._power = power  # each emulated LED's output relative to nominal

    @property
    def direction(self):  # type: ignore[no-untyped-def]
        lit = self._fw.lit
        return None if lit is None else self._directions[lit[0]]

    @property
    def intensity(self) -> float:
        lit = self._fw.lit
        return 0.0 if lit is None else lit[1] / self._max * float(self._power[lit[0]])


def _build_emulated_dome(loaded: LoadedRig, geometry: DomeGeometry, clock: Clock | None) -> Rig:
    """The real dome driver over real pyserial, talking to the firmware emulator on a pty
    (``clock``: the rig's, None for the dry run's own)."""
    from rti_rig.app.dome_factory import build_dome
    from rti_rig.simulator.dome_firmware import (
        Fault,
        FaultKind,
        FaultPlan,
        emulated_dome_on_pty,
        firmware_for,
    )

    cfg = loaded.config
    assert cfg.dome is not None and cfg.dome.serial is not None
    serial = cfg.dome.serial
    if serial.is_described:
        return _build_emulated_firmware_dome(loaded, geometry, clock)
    clock = clock or VirtualClock()
    firmware = firmware_for(
        serial,
        led_count=geometry.count,
        dead_leds=frozenset(cfg.emulator.dead_leds),
        reports_dead_leds=cfg.emulator.reports_dead_leds,
        faults=FaultPlan(
            tuple(Fault(f.at_command, FaultKind(f.kind), f.delay_s) for f in cfg.emulator.faults)
        ),
        clock=SystemClock(),
    )
    stack = RigResources()
    link = stack.enter_context(emulated_dome_on_pty(firmware), "dome emulator")
    try:
        dome = build_dome(
            serial.model_copy(update={"port": link.port}),
            clock,
            directions=geometry.directions,
            name=f"dome on {link.port} (emulated)",
            ledger=DutyLedger.for_emulated(Path(loaded.path)),
        )
        camera = _simulated_camera(
            loaded,
            _FirmwareLight(
                firmware,
                _where_leds_are(loaded, geometry),
                serial.max_level,
                cfg.emulator.led_powers(geometry.count, cfg.scene.seed),
            ),
            clock,
        )
    except BaseException:
        stack.close_said(cfg.name)
        raise
    rig = Rig(loaded, geometry, DomeLighting(dome, geometry), camera, clock, stack)
    rig.emulator = firmware  # type: ignore[attr-defined]  # for tests and the fault campaign
    return rig


class _BoardLight:
    """The light a real-firmware emulator really produces (one LED, or none/ambiguous).

    The LED is lit at full light (no described firmware can dim one) times its own output
    (``[emulator] led_power`` / ``led_power_spread``: these had been accepted for a firmware
    dome and ignored, so an on/off dome's uneven LEDs could not be rehearsed). An LED of
    ``[emulator] dead_leds`` gives no light (it had been accepted and ignored here too, so a
    dead LED could not be rehearsed on these domes); the board answers as for a working LED,
    as these emulators model no current sensing (``reports_dead_leds`` concerns the project's
    own protocols)."""

    def __init__(
        self, board, geometry: DomeGeometry, link, power, dead=frozenset(), directions=None
    ) -> None:  # type: ignore[no-untyped-def]
        self._board, self._geometry, self._link = board, geometry, link
        self._directions = geometry.directions if directions is None else directions
        self._power = power  # each emulated LED's output relative to nominal
        self._dead = frozenset(dead)  # LEDs that give no light when switched on

    def _led(self) -> int | None:
        self._link.wait_delivered()  # what a UART would have delivered by now, whatever the load
        lit = self._board.lit
        if len(lit) != 1 or next(iter(lit)) >= self._geometry.count:
            return None  # dark, or several LEDs at once (a boot-lit dome): no single light
        return next(iter(lit))

    @property
    def direction(self):  # type: ignore[no-untyped-def]
        led = self._led()
        return None if led is None else self._directions[led]

    @property
    def intensity(self) -> float:
        led = self._led()
        return 0.0 if led is None or led in self._dead else float(self._power[led])


def _build_emulated_firmware_dome(
    loaded: LoadedRig, geometry: DomeGeometry, clock: Clock | None
) -> Rig:
    """The scripted driver over real pyserial, against a real firmware's emulator on a pty.

    The emulator runs in real time (the pty's bytes and the firmware's own waits really pass).
    Without a ``clock`` of the caller's, the rig runs on a virtual clock, the link's real time
    counted on it (``DomePolicy``), unless the firmware switches its LEDs on its own clock
    (``Board.self_timed``: RTIPy's LED goes dark 2 s after it lit). There what is lit when the
    camera exposes depends on the time the rig spends between two commands (settle, the
    camera's exposure, readout and transfer), so the whole rig runs on the real clock, the
    board's: each shot takes its [timing] on it, as on the real dome. On the virtual clock the
    camera had taken no time on the board's: a dry run metered a series of test shots under
    one LED window that the real camera outlasts (its later shots dark).
    """
    from rti_rig.app.dome_factory import build_dome
    from rti_rig.drivers.led_dome.factory import protocol_for
    from rti_rig.simulator.dome_firmware import Fault, FaultKind, FaultPlan
    from rti_rig.simulator.domes import board_for
    from rti_rig.simulator.pty_link import serve_on_pty

    cfg = loaded.config
    assert cfg.dome is not None and cfg.dome.serial is not None
    serial = cfg.dome.serial
    spec = protocol_for(serial)
    board = board_for(
        serial.profile,
        clock=SystemClock(),
        faults=FaultPlan(
            tuple(Fault(f.at_command, FaultKind(f.kind), f.delay_s) for f in cfg.emulator.faults)
        ),
        led_map=spec.led_map,
    )
    if clock is None:
        clock = SystemClock() if board.self_timed else VirtualClock()
    stack = RigResources()
    link = stack.enter_context(serve_on_pty(board, serial.profile), "dome emulator")
    try:
        dome = build_dome(
            serial.model_copy(update={"port": link.port}),
            clock,
            directions=geometry.directions,
            name=f"dome on {link.port} (emulated {serial.profile})",
            ledger=DutyLedger.for_emulated(Path(loaded.path)),
        )
        power = cfg.emulator.led_powers(geometry.count, cfg.scene.seed)
        light = _BoardLight(
            board, geometry, link, power, cfg.emulator.dead_leds, _where_leds_are(loaded, geometry)
        )
        camera = _simulated_camera(loaded, light, clock)
    except BaseException:
        stack.close_said(cfg.name)
        raise
    rig = Rig(loaded, geometry, DomeLighting(dome, geometry), camera, clock, stack)
    rig.emulator = board  # type: ignore[attr-defined]  # for tests and the fault campaign
    return rig


class _ArmLamp:
    """Where the emulated servos really hold the lamp (even mid-move), if it is on."""

    def __init__(self, arm, emulator, settings) -> None:  # type: ignore[no-untyped-def]
        self._arm, self._emulator, self._settings = arm, emulator, settings

    @property
    def direction(self):  # type: ignore[no-untyped-def]
        from rti_rig.simulator.dynamixel_emulator import lamp_direction

        if not self._arm.lamp_is_on:
            return None
        return lamp_direction(self._emulator, self._settings)

    @property
    def intensity(self) -> float:
        return 1.0 if self._arm.lamp_is_on else 0.0


def _arm_lighting(loaded: LoadedRig, carrier, clock: Clock) -> ArmLighting:  # type: ignore[no-untyped-def]
    arm = loaded.config.arm
    assert arm is not None
    return ArmLighting(
        carrier,
        park_after_session=arm.park_after_session,
        park_on_emergency=arm.park_on_emergency_stop,
        config=str(loaded.path),
        clock=clock,
    )


def _build_emulated_arm(loaded: LoadedRig, geometry: ArmGeometry, clock: Clock) -> Rig:
    """The real Dynamixel driver and SDK against emulated servos (pty or in-process)."""
    from rti_rig.drivers.dynamixel.arm import DynamixelArm
    from rti_rig.simulator.dynamixel_emulator import emulated_arm_port

    arm_cfg = loaded.config.arm
    assert arm_cfg is not None and arm_cfg.dynamixel is not None
    settings = arm_cfg.dynamixel
    stack = RigResources()
    port, emulator = stack.enter_context(
        emulated_arm_port(settings, clock, transport=arm_cfg.transport), "arm emulator"
    )
    # [[emulator.faults]]: the status of the K-th instruction packet lost or damaged, or a
    # servo's hardware error (overload …) raised as that packet arrives
    for f in loaded.config.emulator.faults:
        emulator.add_fault(f.at_command, f.kind, f.servo_id, f.delay_s)
    # the chain stays powered between commands: what its servos hold (torque, pose, RAM, an
    # error latched by an earlier command on this rig) is still there until a Reboot or a
    # power cycle (the recovery, check --reboot-faulted, had found a fresh servo with nothing
    # to reboot; a session that kept torque on had left the next command a limp arm)
    latch = _keep_powered_state(loaded, emulator)
    # and kept as the rig closes, after the arm's own close (its torque policy applied)
    stack.callback(lambda: _keep_state(latch, emulator), "arm emulator state")
    try:
        # the advice's power cycle is what clears the emulated chain's kept state
        arm = DynamixelArm(
            settings,
            port,
            clock,
            config_path=loaded.path,
            power_cycle=latch.power_cycle_said(),
        )
        camera = _simulated_camera(loaded, _ArmLamp(arm, emulator, settings), clock)
    except BaseException:
        stack.close_said(loaded.config.name)
        raise
    rig = Rig(loaded, geometry, _arm_lighting(loaded, arm, clock), camera, clock, stack)
    rig.emulator = emulator  # type: ignore[attr-defined]  # for tests and the fault campaign
    return rig


def _keep_powered_state(loaded: LoadedRig, emulator: DynamixelBusEmulator) -> LatchedErrors:
    """Give the emulated servos what an earlier command on this rig left them (a real servo
    keeps its control table, torque, pose and Hardware Error Status while powered), and keep
    it for the next at each change of an error (as the status goes out, so a crash after it
    loses none; the caller keeps it again as the rig closes); the state file it is kept in."""
    from rti_rig.simulator.servo_latch import LatchedErrors

    latch = LatchedErrors(Path(loaded.path))
    states = latch.load_state()
    if states:
        emulator.restore_powered(states)
    else:
        # power-cycled (the powered state deleted): the EEPROM and the rest pose outlive it
        emulator.restore_eeprom(latch.load_eeprom())
        # a state file of errors alone (kept by an earlier version)
        for dxl_id, bits in latch.load().items():
            if dxl_id in emulator.servos:
                emulator.inject_hardware_error(dxl_id, bits)

    def keep(_errors: object = None) -> None:
        _keep_state(latch, emulator)

    emulator.on_errors_changed = keep
    return latch


def _keep_state(latch: LatchedErrors, emulator: DynamixelBusEmulator) -> None:
    """Keep the chain's powered state and, apart, what outlives a power cycle (EEPROM); a
    chain whose supply went (``power_lost``) keeps only the latter, as a power cycle does.

    Why: after a ``power_lost`` rehearsal the state file still said the servos were powered
    (torque on, the goal held, any error latched), so the next command met a holding arm that
    had in fact lost its supply: a stale claim a real chain cannot make (its RAM is "reset to
    initial values when the power is reset", ROBOTIS e-manual, X-series control table, Area).
    A held joint falls to its stop without power (:meth:`EmulatedServo.eeprom_state`)."""
    latch.save_eeprom(emulator.eeprom_state())
    if emulator.supply_lost():
        latch.forget_powered()
    else:
        latch.save_state(emulator.powered_state())


def _refuse_missing_watch_folder(loaded: LoadedRig, settings: object) -> None:
    """Refuse a watched-folder camera whose folder is not there, before any port opens.

    Why: the camera connects after the dome, so a missing folder was found only once the dome's
    port had opened: a Nab board resets there and boots with every LED lit (light dose on the
    object) to be switched off again, for a session that could never take a picture."""
    from rti_rig.core.errors import ConfigError
    from rti_rig.core.shell_words import shown_path
    from rti_rig.drivers.cameras.settings import FolderWatchSettings

    if isinstance(settings, FolderWatchSettings) and not settings.folder.is_dir():
        raise ConfigError(
            loaded.path,
            "camera.device.folder",
            f"the watched folder {shown_path(settings.folder)} does not exist or is not a "
            "folder: create it, or set 'folder' to the one the camera's tethering program "
            "saves into (no port was opened, nothing lit)",
        )


def _build_hardware(loaded: LoadedRig, clock: Clock) -> Rig:
    """Real devices: the dome or arm on its port, the camera from [camera.device]."""
    from rti_rig.app.config import camera_device_settings
    from rti_rig.drivers.cameras.factory import build_camera

    cfg = loaded.config
    geometry = rig_geometry(loaded)
    camera_settings = camera_device_settings(loaded)
    _refuse_missing_watch_folder(loaded, camera_settings)
    if cfg.dome is not None and cfg.dome.flash_sync is not None:  # the camera steps the dome
        from rti_rig.app.flash_sync import build_flash_sync_rig

        assert isinstance(geometry, DomeGeometry)
        camera = build_camera(camera_settings, clock=clock)
        rig = build_flash_sync_rig(loaded, geometry, clock, camera)
        rig.session_hooks.append(_session_hook(camera))
        return rig
    if isinstance(geometry, DomeGeometry):
        from rti_rig.app.dome_factory import build_dome

        assert cfg.dome is not None and cfg.dome.serial is not None
        # the port in the name: every line about the dome (check's heading, an ABORTED or
        # stopped session's error) then says which port was opened; "dome" alone had left a
        # user with two boards plugged in no way to tell the wrong port from a silent board
        dome = build_dome(
            cfg.dome.serial,
            clock,
            directions=geometry.directions,
            name=f"dome on {cfg.dome.serial.port}",
            ledger=DutyLedger.for_port(cfg.dome.serial.port),
        )
        camera = build_camera(
            camera_settings, clock=clock, trigger=_camera_trigger(camera_settings, dome)
        )
        rig = Rig(loaded, geometry, DomeLighting(dome, geometry), camera, clock)
    else:
        import dynamixel_sdk

        from rti_rig.drivers.dynamixel.arm import DynamixelArm

        assert cfg.arm is not None and cfg.arm.dynamixel is not None
        settings = cfg.arm.dynamixel
        # the port in the name, as a hardware dome's: "arm during 'ping': servo 3: no servo
        # with id 3 answers at 57600 baud" had named no port, on a bench with two adapters
        named = settings.model_copy(update={"name": f"{settings.name} on {settings.port}"})
        arm = DynamixelArm(
            named, dynamixel_sdk.PortHandler(settings.port), clock, config_path=loaded.path
        )
        camera = build_camera(camera_settings, clock=clock)
        rig = Rig(loaded, geometry, _arm_lighting(loaded, arm, clock), camera, clock)
    rig.session_hooks.append(_session_hook(camera))
    return rig


def _camera_trigger(settings, dome):  # type: ignore[no-untyped-def]
    """The release that fires a watched-folder camera: the dome's shutter verb (a pulse on the
    camera's remote line, never resent), when the config asks for it."""
    if getattr(settings, "trigger", "none") != "dome_shutter":
        return None
    from rti_rig.core.dome_link import DomeLinkError, LinkFault
    from rti_rig.drivers.cameras.folder_watch import TriggerUnconfirmed

    def fire(_exposure_s: float) -> None:
        try:
            dome.shutter()
        except DomeLinkError as exc:
            if exc.fault is LinkFault.TIMEOUT:  # sent, reply lost: the camera may have fired
                raise TriggerUnconfirmed(f"{exc.device}: {exc.message}") from exc
            raise

    return fire


def _session_hook(camera):  # type: ignore[no-untyped-def]
    """Tell a downloading camera (a DSLR) to stage its files inside the session folder.

    The session then moves them to ``raw/`` under its own names when the step is committed;
    whatever a crash leaves in ``raw/.incoming`` is set aside by ``--resume``, never lost.
    """
    from rti_rig.runtime.session import RAW_INCOMING

    def hook(root: Path) -> None:
        if hasattr(camera, "output_dir"):
            camera.output_dir = root / RAW_INCOMING
        if hasattr(camera, "session_root"):  # its messages name the command that resumes
            camera.session_root = root

    return hook


def _build_replay(loaded: LoadedRig, clock: Clock) -> Rig:
    """A recorded acquisition: a dome with exactly its lights, a camera that returns the image
    recorded for the LED fired (:mod:`rti_rig.simulator.replay`)."""
    from rti_rig.core.lp_format import image_path, lp_name_from
    from rti_rig.simulator.replay import ReplayCamera
    from rti_rig.simulator.sim_lights import LightState, SimulatedDome

    cfg = loaded.config
    geometry = rig_geometry(loaded)
    assert isinstance(geometry, DomeGeometry)
    folder = Path(loaded.path).parent
    dome = SimulatedDome(geometry, LightState(), clock, cfg.timing.light_switch_s)
    dome.name = "replayed dome"
    images = [image_path(folder, name) for name in geometry.names]
    from rti_rig.app.rig_identity import recorded_images_stamped

    # each file's digest as the run begins (the identity's, from the process's cache): a
    # file whose stamp changes during the run is judged by its bytes against it
    _, stamped = recorded_images_stamped(folder, geometry.names)
    camera = ReplayCamera(
        images,
        dome,
        clock,
        shape=(cfg.camera.height, cfg.camera.width),
        readout_s=cfg.timing.readout_s,
        transfer_s=cfg.timing.transfer_s,
        # recorded as the path relative to the .lp: unambiguous where two subfolders hold a
        # file of one name (RTIBuilder's ../jpeg-exports/… climbs out of assembly-files/)
        names=[lp_name_from(folder, p) for p in images],
        digests=[(stamped.get(name) or [None] * 4)[3] for name in geometry.names],
        white_reading=lambda: _replay_white(loaded, images, list(geometry.names)),
    )
    rig = Rig(loaded, geometry, DomeLighting(dome, geometry), camera, clock)
    rig.session_hooks.append(camera.bind_session)  # a resumed session keeps its white
    return rig


def _replay_white(
    loaded: LoadedRig, images: list[Path], names: list[str]
) -> tuple[int, str | None]:
    """The white level the replay hands the recorded codes over with, and the notice that says
    so (None at 65535): 16-bit files of 10- or 12-bit camera data keep their own white, read
    from the files as ``rti-rig fit`` reads an imported acquisition's."""
    from rti_rig.app.usecases.fit_full_scale import recorded_full_scale
    from rti_rig.core.shell_words import shown_path

    full = recorded_full_scale(Path(loaded.path).parent, images, names)
    if full is None:
        return 65535, None
    said = full.words(len(images), shown_path(Path(loaded.path)), fit="fit the session")
    return full.level, f"replayed with white level {full.level}, not 65535: {said}"


def _build_simulated(loaded: LoadedRig, clock: Clock | None) -> Rig:
    from rti_rig.simulator.sim_lights import LightState, SimulatedArm, SimulatedDome

    cfg = loaded.config
    geometry = rig_geometry(loaded)
    if cfg.dome is not None and cfg.dome.flash_sync is not None:  # the emulated cceh/rti
        from rti_rig.app.flash_sync import build_flash_sync_rig

        assert isinstance(geometry, DomeGeometry)
        return build_flash_sync_rig(loaded, geometry, clock or VirtualClock())
    if cfg.backend == "emulated" and isinstance(geometry, DomeGeometry):
        return _build_emulated_dome(loaded, geometry, clock)  # it chooses its dry run's clock
    clock = clock or VirtualClock()
    if cfg.backend == "emulated":
        assert isinstance(geometry, ArmGeometry)
        return _build_emulated_arm(loaded, geometry, clock)
    state = LightState()
    if isinstance(geometry, DomeGeometry):
        lighting = DomeLighting(
            SimulatedDome(geometry, state, clock, cfg.timing.light_switch_s), geometry
        )
    else:
        assert isinstance(geometry, ArmGeometry) and cfg.arm is not None
        lighting = _arm_lighting(
            loaded,
            SimulatedArm(
                geometry,
                state,
                clock,
                speed_deg_s=cfg.arm.speed_deg_s,
                acceleration_deg_s2=cfg.arm.acceleration_deg_s2,
                resolution_deg=cfg.arm.resolution_deg,
                switch_s=cfg.timing.light_switch_s,
            ),
            clock,
        )
    camera = _simulated_camera(loaded, state, clock)
    return Rig(loaded=loaded, geometry=geometry, lighting=lighting, camera=camera, clock=clock)


def arm_order_for(loaded: LoadedRig, progress=None):  # type: ignore[no-untyped-def]
    """The move-time-optimal stop order for an arm, else None (a dome); ``progress(done,
    total)`` is told the order search's steps (:data:`rti_rig.planner.arm_order.Progress`).

    The move-time model is the arm that runs: an emulated or hardware arm's servos
    (``[arm.dynamixel]``), or the simulated arm's ``[arm]`` speed, acceleration and limits
    (:func:`simulated_arm_motion`). Why: a simulated arm had been ordered nearest neighbour by
    angle, which ignores that its azimuth cannot wrap past ±180°: a 12-light plan on
    virtual_arm.toml took a 6.0 s move from -170° to 157.6°."""
    arm = loaded.config.arm
    if arm is None:
        return None
    from rti_rig.planner.arm_order import order_for_arm

    settings = simulated_arm_motion(loaded)
    if settings is None:
        settings = arm.dynamixel
    return lambda directions, start: order_for_arm(directions, start, settings, progress)


def simulated_arm_motion(loaded: LoadedRig):  # type: ignore[no-untyped-def]
    """The simulated arm's move-time model (:class:`rti_rig.core.arm_motion.ArmMotion`), or
    None when the rig's arm is not simulated (its servos' settings are the model).

    It is :class:`rti_rig.simulator.sim_lights.SimulatedArm` as built above: both joints at
    ``[arm]`` ``speed_deg_s`` / ``acceleration_deg_s2``, the azimuth joint within [-180°, 180°)
    (no wrap), the elevation joint within the config's elevation limits, from the park pose.
    The settle after each move (``[timing] settle_s``) is the same for every order and left out.
    """
    arm = loaded.config.arm
    if arm is None or loaded.config.backend != "simulated":
        return None
    from rti_rig.core.arm_motion import ArmMotion, JointMotion

    v, a = arm.speed_deg_s, arm.acceleration_deg_s2
    return ArmMotion(
        # just under 180: the simulated joint turns to -180° for a light at 180°
        azimuth=JointMotion(-180.0, 180.0 - 1e-6, v, a),
        elevation=JointMotion(arm.min_elevation_deg, arm.max_elevation_deg, v, a),
        park_azimuth_deg=arm.park_azimuth_deg,
        park_elevation_deg=arm.park_elevation_deg,
    )


def _on_full_scale(img, path: Path):  # type: ignore[no-untyped-def]
    """A session's linear TIFF labelled with a white below 65535 (a replay of 12-bit data keeps
    its codes) scaled onto 65535, as the planner reads every 16-bit preview: it had planned
    from the image 16x too dark."""
    import numpy as np

    from rti_rig.core.image_files import linear_tiff_white_level

    if getattr(img, "dtype", None) != np.uint16 or path.suffix.lower() not in (".tif", ".tiff"):
        return img
    white = linear_tiff_white_level(path)
    if white is None or white >= 65535:
        return img
    scaled = (img.astype(np.uint64) * 65535 + white // 2) // white
    return np.minimum(scaled, 65535).astype(np.uint16)


def read_preview_image(path: Path):  # type: ignore[no-untyped-def]
    """The preview file as the planner takes it, RAW files included.

    A DSLR rig's preview is often a RAW file (DNG, CR2, NEF, ARW…). It is decoded here, in the
    composition root, because the decoder is the camera drivers' (the planner may not import
    drivers, :func:`rti_rig.drivers.cameras.raw_decode.decode_raw`, the DSLR path's): LibRaw's 2×2
    super-pixels, linear 16-bit RGB, unity white balance, nothing automatic (half resolution
    is plenty: the planner works at 256 px). The rig's own decode settings are not applied:
    they live in its camera driver's config, and white balance barely moves the luminance the
    planner reads. Every other file goes to
    :func:`rti_rig.planner.topography.read_preview`.
    """
    from rti_rig.core.errors import CaptureError, ScheduleError
    from rti_rig.core.image_files import is_camera_raw
    from rti_rig.planner.topography import read_preview

    p = Path(path)
    if not is_camera_raw(p) or not p.is_file():
        # which also refuses a folder or a missing file, by name
        return _on_full_scale(read_preview(p), p)
    from rti_rig.drivers.cameras.raw_decode import MonochromeRawError, decode_raw
    from rti_rig.drivers.cameras.settings import RawDecodeSettings

    try:
        settings = RawDecodeSettings(mode="half", white_balance="unity", output_color="raw")
        return decode_raw(p, settings).pixels
    except MonochromeRawError as exc:
        # its own words are for a camera's [camera.device.decode] mode and a watched folder,
        # neither of which plan has (it had named a mode = "half" no config set); a grey
        # picture is a preview the planner reads, as a 16-bit TIFF
        raise ScheduleError(
            f"RAW preview {p}: it is a monochrome sensor's file (LibRaw reads one colour and "
            "no colour filter array), which the RAW decode does not read. Give a 16-bit "
            "linear grey TIFF of it (a RAW converter's linear output), or the camera's JPEG, "
            "as the preview"
        ) from exc
    except CaptureError as exc:  # its message names the file and LibRaw's reason
        raise ScheduleError(
            f"RAW preview {exc.message} Otherwise give the camera's JPEG or a 16-bit linear "
            "TIFF of it as the preview"
        ) from exc
