"""Rig capability interfaces: what the controller may ask of a light source and a camera.

Capabilities, not classes: a dome is a *discrete* light source (fire LED *i*), an arm is a
*continuous* light carrier (move the lamp to a direction). Real drivers and simulated devices
implement the same protocols, so the controller never knows which it is talking to.

Every device has a documented **safe state** that the controller restores in ``finally``, after
success, cancellation or any error:

* discrete light source: all LEDs off;
* light carrier: lamp off, motion stopped, then parked (parking may be refused by policy);
* camera: no exposure in progress, device released by ``close``.

Devices open their transport in ``connect()`` (never in ``__init__``) and release it in
``close()``; ``close`` must be safe to call twice and after a failed ``connect``.
"""

from __future__ import annotations

from abc import abstractmethod
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, Protocol, runtime_checkable

import numpy as np
from numpy.typing import NDArray


@dataclass(frozen=True)
class Frame:
    """One captured image as linear data.

    ``pixels`` is linear (proportional to scene radiance, black level removed), ``uint16``,
    shape (H, W) or (H, W, 3); ``white_level`` is the code value at which the sensor saturates.
    ``gain`` is in the camera's own unit (ISO for still cameras, the V4L2 gain value for UVC
    cameras, 1.0 for the simulated sensor); ``metadata["gain_unit"]`` says which where known.
    """

    pixels: NDArray[np.uint16]
    exposure_s: float
    gain: float
    white_level: int
    timestamp_s: float
    metadata: dict[str, Any] = field(default_factory=dict)

    @property
    def saturated_fraction(self) -> float:
        """Fraction of pixels (any channel) at or above the white level."""
        return float(np.mean(_channel_max(self.pixels) >= self.white_level))

    @property
    def black_fraction(self) -> float:
        """Fraction of pixels (all channels) at zero: underexposed or in full shadow."""
        return float(np.mean(_channel_max(self.pixels) == 0))


def _channel_max(pixels: NDArray[Any]) -> NDArray[Any]:
    """Each pixel's largest channel (the pixels themselves when grey): ``pixels.max(axis=-1)``,
    value for value, channel against channel. Why: a reduction over a last axis of 3 runs its
    inner loop 3 elements long; this is ~10x faster, and a session asks it twice an image."""
    if pixels.ndim == 2:
        return pixels
    out = np.array(pixels[..., 0])
    for c in range(1, pixels.shape[-1]):
        np.maximum(out, pixels[..., c], out=out)
    return out


@runtime_checkable
class DiscreteLightSource(Protocol):
    """A set of fixed, calibrated lights fired one at a time (an LED dome).

    Safe state: all lights off.
    """

    name: str

    def connect(self) -> None: ...

    def close(self) -> None: ...

    def light_count(self) -> int: ...

    def light(self, index: int, intensity: float = 1.0) -> None:
        """Turn on light ``index`` (0-based) alone; any other light goes off."""
        ...

    def all_off(self) -> None: ...


@runtime_checkable
class KnownStateLightSource(Protocol):
    """What a :class:`DiscreteLightSource` whose lit state is known exactly (a simulated dome:
    its state is the simulation's) says of itself: whether its link is open, and what its
    last commands left lit.

    Why: a simulated dome had no link to ask (``link_open`` False), so a session closed before
    the controller's teardown sent it no all-off, and the run said "lights were switched off"
    of a dome its last command had left lit. A dry run rehearses the real teardown: the
    all-off a dome on a port gets, said only when it was sent. Declared by the concrete class
    (``class SimulatedDome(KnownStateLightSource)``), its members abstract, as
    :class:`ReadBackCarrier` is.
    """

    @property
    @abstractmethod
    def link_open(self) -> bool:
        """Whether it is connected now, so that an all-off can be sent on it."""

    @abstractmethod
    def lit_now(self) -> int | None:
        """The light its last command left lit (None: none is lit)."""

    @abstractmethod
    def switched_off(self) -> bool:
        """Whether an all-off reached it after the last light it lit (False: none did, or it
        never lit one)."""


@runtime_checkable
class LightCarrier(Protocol):
    """A lamp moved to arbitrary directions (a servo arm).

    Safe state: lamp off, stopped. ``close`` switches the lamp off and stops but never moves the
    arm; parking is a move that the caller's policy decides (``ArmLighting.safe``).
    """

    name: str

    def connect(self) -> None: ...

    def close(self) -> None: ...

    def unreachable_reason(self, direction: NDArray[np.float64]) -> str | None:
        """``None`` if ``direction`` can be reached safely, else why not (limits, keep-out)."""
        ...

    def move_to(self, direction: NDArray[np.float64]) -> NDArray[np.float64]:
        """Move and wait until in position; return the direction actually reached."""
        ...

    def lamp(self, on: bool) -> None: ...

    def stop(self) -> None: ...

    def park(self, cancelled: Callable[[], bool] | None = None) -> None:
        """Move to the park pose; once ``cancelled()`` says True, hold where it stands and
        raise :class:`~rti_rig.core.errors.MoveCancelled` (a stop during the teardown)."""
        ...

    @property
    def park_pose_deg(self) -> tuple[float, float]:
        """(azimuth, elevation) of the park pose: what a read-back position is compared to."""
        ...

    def reached_direction(self) -> NDArray[np.float64]:
        """The lamp's direction as read back from the joints now (may raise: a silent or
        faulted servo). Where the teardown says the arm was left (``runtime.arm_end``)."""
        ...


@dataclass(frozen=True)
class TorqueAtClose:
    """What a carrier's close established of its joints' torque, for the session's manifest
    (``runner.arm_end.torque_at_close``).

    ``policy``: the torque policy the close applied (``"hold"``, ``"release_on_close"``);
    ``off_sent``: whether the close sent a torque-off; ``read_back``: Torque Enable as read
    back from each servo after it (servo id → ``"on"``, ``"off"`` or ``"unread"``), None where
    the close read nothing back (``"hold"`` touches no torque: it stays as the session left it).

    Why: ``release_on_close`` keeps the torque on away from the park pose, which the user was
    told in words while the manifest said nothing of the torque, as of an arm whose close
    released nothing: a script could not tell an arm held under torque from a limp one."""

    policy: str
    off_sent: bool
    read_back: dict[int, str] | None = None

    def to_dict(self) -> dict[str, Any]:
        read = None if self.read_back is None else {str(k): v for k, v in self.read_back.items()}
        return {"policy": self.policy, "off_sent": self.off_sent, "read_back": read}


@runtime_checkable
class ReadBackCarrier(Protocol):
    """What a :class:`LightCarrier` that reads its servos back (a Dynamixel arm) can say of
    itself beyond moving: the commands it sent again, a torque its close released, whether
    the arm still holds the pose an image is recorded under.

    Declared by the concrete class (``class DynamixelArm(ReadBackCarrier)``), its methods
    abstract: a class that declares it and renames or drops one of them cannot be built (a
    ``TypeError`` at construction), where the caller's ``getattr`` had silently answered "none"
    for a misspelt name. A carrier that does not declare it (the simulated arm, whose moves are
    exact and which has no bus to lose a packet on) is answered for by
    :class:`rti_rig.runtime.lighting.ArmLighting`'s documented defaults, on purpose.
    """

    @abstractmethod
    def resends(self) -> tuple[list[str], str | None]:
        """The commands sent once more after a lost or damaged reply that then got their
        answer, and the one line that counts them for the user (None: none)."""

    @abstractmethod
    def torque_release_note(self) -> str | None:
        """What the last close's release of the torque (at the park pose) leaves the user to
        know, or None when it released nothing."""

    @abstractmethod
    def torque_at_close(self) -> TorqueAtClose | None:
        """What the last close established of the joints' torque (None: that close did not
        get as far as its torque policy, or the arm was not connected)."""

    @abstractmethod
    def lamp_servo(self) -> int | None:
        """The id of the servo whose LED output the lamp hangs on, whose writes the servo
        answers (None: the lamp's switch is outside the bus, and no command reaches it)."""

    @property
    @abstractmethod
    def ever_connected(self) -> bool:
        """Whether a connect ever completed: what a stop may say of an arm it never reached."""

    @property
    @abstractmethod
    def commanded(self) -> bool:
        """Whether anything was ever written to a servo: an arm whose connect failed after its
        first write may hold under torque, so nothing may be said to have been commanded."""

    @property
    @abstractmethod
    def driven(self) -> bool:
        """Whether anything that could leave a servo driven was ever sent (any write but a
        torque-off or an EEPROM write)."""

    def holding_after_failed_connect(self) -> str | None:
        """What a failed connect read of the torque before letting the port go, as a clause
        for the user ("but the arm is still powered and holding the lamp …"); None: nothing
        was read (no connect failed, or its port never opened). Not abstract: a carrier that
        reads nothing back at a failed connect says nothing more than before."""
        return None

    @abstractmethod
    def check_held(self) -> None:
        """Raise unless the arm still holds, fault-free, the pose its last move reached."""

    @abstractmethod
    def listen(self, say: Callable[[str], None] | None) -> None:
        """Have what a user must know as it happens (a search at other baud rates, a torque
        kept on at the close, a second failure while making the arm safe) said through
        ``say``; ``None`` stops it."""


@runtime_checkable
class Camera(Protocol):
    """A camera that captures one linear frame at a fixed exposure.

    Safe state: idle and released (``close``). Nothing automatic: exposure, gain and white
    balance stay as set.
    """

    name: str

    def connect(self) -> None: ...

    def close(self) -> None: ...

    def capture(self, exposure_s: float) -> Frame: ...


@runtime_checkable
class ExposureJudgingCamera(Protocol):
    """A camera whose driver, once connected, can tell why an exposure cannot be shot on it
    (a DSLR's fixed list of shutter speeds, a UVC camera's frame period and exposure units):
    ``exposure_problem`` says why, None when it can.

    Why declared: ``check`` had probed for it with ``getattr``, so a driver that misspelt
    it passed every exposure unchecked."""

    def exposure_problem(self, exposure_s: float) -> str | None: ...


@runtime_checkable
class ExposureRefusingCamera(Protocol):
    """A camera that refuses, before anything lights, an exposure it would not shoot as asked
    (``refuse_exposure`` raises a DeviceError naming ``before``, what was not done)."""

    def refuse_exposure(self, exposure_s: float, before: str) -> None: ...


@runtime_checkable
class ShutterSpeedCamera(Protocol):
    """A camera that offers its own list of exposures (a DSLR's shutter speeds): metering
    starts at the one nearest the config's, never between two."""

    def available_exposures_s(self) -> list[float]: ...


@runtime_checkable
class TrialShotCamera(Protocol):
    """A camera that ``check`` has take one shot and decode it (a tethered DSLR: a body whose
    RAW the installed LibRaw cannot read fails the check, not the session's first step; a UVC
    camera: one frame read, its size and bit depth checked); ``test_shot`` returns what the
    shot established, as a phrase."""

    def test_shot(self) -> str: ...


@runtime_checkable
class ConnectNotingCamera(Protocol):
    """A camera whose connect could not establish everything (a gphoto2 image format whose
    name does not say whether it gives a RAW): ``connect_notes`` says what, to be said."""

    def connect_notes(self) -> tuple[str, ...]: ...


@runtime_checkable
class CardListingCamera(Protocol):
    """A camera that shoots to a card and lists it before the session's first shot, so that a
    picture taken before then is told apart (what it finds said through ``say``)."""

    def list_card(self, say: Callable[[str], None]) -> None: ...


@runtime_checkable
class ExposingCamera(Protocol):
    """A camera whose exposure is over well before its image is in hand, in two calls.

    Why: a DSLR's download and RAW decode, or a tethered file's transfer over USB or Wi-Fi,
    take seconds after the shutter has closed. Held lit through them, an LED cast several times
    the light the image needs on the object (a light dose a conservator counts) and ran into
    the dome's thermal limit ``max_on_s``, which stopped the session and lost a good shot.

    ``expose`` fires the shutter and returns the time (on the rig's clock) by which the exposure
    has surely ended, or None when the camera cannot tell (then the light stays on until
    ``collect`` returns). ``collect`` returns the frame of that exposure. The controller
    switches the light off in between; ``capture`` is the two in one call.
    """

    def expose(self, exposure_s: float) -> float | None: ...

    def collect(self) -> Frame: ...


@runtime_checkable
class FramePacedCamera(Protocol):
    """A camera whose capture reads frames off a stream, at its frame rate, with the light lit.

    Why: a UVC camera streams continuously and queues frames exposed before the light settled
    or the exposure changed; a capture discards them (the queue and a few fresh frames) before
    it keeps one, all with the LED lit. At 5 fps with a 4-buffer queue that is 8 frames, 1.6 s:
    a config whose settle + exposure + readout + transfer fitted ``max_on_s`` then stopped at
    the thermal limit with the object lit. ``capture_time_s(exposure_s)`` says, once the
    camera is connected (frame rate and queue known), the longest a capture of ``exposure_s``
    reads frames for and how that is counted (a phrase for a message), or None when the camera
    cannot tell (no frame rate reported).
    """

    name: str

    def capture_time_s(self, exposure_s: float) -> tuple[float, str] | None: ...


@runtime_checkable
class BusyAwareCamera(Protocol):
    """An :class:`ExposingCamera` that can be told by when it must fire.

    Why: a DSLR still writing its previous shot to a slow card answers "busy" and is retried
    with growing waits; fired with the step's LED lit, those waits had to fit in the time an
    LED may stay lit (the dome's ``max_on_s``), and a camera busy longer stopped the session.
    ``expose_within(exposure_s, fire_by)`` waits for a busy camera only while the next try
    can still be made by ``fire_by`` (on the rig's clock); past it, it raises
    :class:`rti_rig.core.errors.CameraBusyError` having taken no picture, so that the
    controller can switch the light off, wait in the dark and light it again for the shot.
    ``fire_by = None`` waits as ``expose`` does.
    """

    def expose_within(self, exposure_s: float, fire_by: float | None) -> float | None: ...

    def collect(self) -> Frame: ...
