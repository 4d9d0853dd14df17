"""What a session's images depend on in its rig, so a resume can refuse another rig.

A session shot half on one rig and half on another is not one session: a dome finished by an
arm, 512² images next to 256² ones, or a different exposure make the images disagree with each
other and with the `.lp`. The identity lists what changes the images — the rig's kind and
backend, where its lights can be, the LEDs' intensity correction, a dome's firmware profile,
the camera's size, exposure, gain and RAW decoding, and (for a dry run) the simulated scene —
and nothing that does not (a serial port's name, timing, parking policy), so a rig moved to
another USB port resumes.

The firmware profile names the dome's controller board: another board drives its LEDs with
another command set, timing and possibly numbering (a stepping nichlock board counts LEDs in
its wiring's order, a minirti board addresses a 64-bit mask), so the same LED index may not
be the same light. A resume on another profile had gone on without a word. A session recorded
before the profile was part of the identity has no ``dome_firmware`` key and is not asked.
Where the config describes the protocol (``custom``, or a protocol table or LED map over a
built-in), a digest of its commands and LED addressing is the ``dome_protocol`` key: the name
"custom" alone said nothing of which board it was.

A dome's light positions are compared as positions, not as a digest: a re-measured dome
whose ``.lp`` differs from the session's by rounding (written again with four decimals or
more: :data:`POSITION_TOLERANCE_RAD`) is the same rig, and one whose LEDs really moved is
named by how many moved and by how much (a digest of rounded positions had called both
"changed", and could not say which).
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from rti_rig.app.config import LoadedRig, rig_geometry
from rti_rig.core.geometry import angle_between_deg
from rti_rig.core.rig_geometry import DomeGeometry

if TYPE_CHECKING:
    from rti_rig.drivers.led_dome.protocol_spec import CommandSpec, ProtocolSpec

#: How each identity key is named in a refusal.
LABELS = {
    "kind": "rig kind",
    "backend": "backend",
    "lights": "lights",
    "light_positions": "light positions",
    "intensity_correction": "LED intensity correction",
    "dome_firmware": "dome firmware profile",
    "dome_protocol": "dome protocol described in the config",
    "arm_reach": "arm reach",
    "camera_size": "camera size",
    "exposure_s": "exposure (s)",
    "gain": "camera gain",
    "camera_device": "camera driver",
    "decode": "RAW decoding",
    "scene": "simulated scene",
    "recorded_images": "recorded images",
}


#: The largest angle (rad) between a light's recorded and current position that is rounding
#: noise, not a change. Rounding a unit vector's components to d decimals moves it by at most
#: √3·0.5·10⁻ᵈ rad: 8.7e-7 at the six decimals RTIBuilder, relight and rtiacquire write,
#: 8.7e-6 at five, 8.7e-5 at four (a calibration saved again with fewer digits, or by a tool
#: that writes floats short). An LED that really moved does so by a tenth of a degree or more
#: (1.7e-3 rad). 2e-4 rad (0.011°) accepts any rewrite at four decimals or more with a
#: margin of two, and stays a ninth of the smallest real move. Three decimals (up to 8.7e-4
#: rad, 0.05°) is half a real move, too close to tell apart: no known writer uses so few, and
#: such a refusal says that rounding could explain it (:data:`THREE_DECIMALS_RAD`). It had been
#: 5e-6 (six decimals only): a calibration written again with five refused the resume,
#: "moved by up to 0.00°".
POSITION_TOLERANCE_RAD = 2e-4

#: The most rounding an ``.lp``'s positions to three decimals moves a light (rad): a refusal
#: within it says so, since an ``.lp`` written with three decimals may be all that changed.
THREE_DECIMALS_RAD = 3**0.5 * 0.5e-3

#: The keys that change what the images are, not where the light comes from: a session cannot
#: take images that differ in them, accepted or not (nothing downstream corrects for them). A
#: dry run's scene is its object (name, seed), its noise and its lamps' distance: another one
#: had been accepted with --accept-rig-change, and an adaptive session then chose its lights
#: from images of two objects, fitted as one ("QA verdict: good").
IMAGE_KEYS = (
    "camera_size",
    "exposure_s",
    "gain",
    "camera_device",
    "decode",
    "recorded_images",
    "scene",
)


def _digest(value: Any) -> str:
    text = json.dumps(value, sort_keys=True, default=str)
    return hashlib.sha256(text.encode("utf-8")).hexdigest()[:16]


def rig_identity(loaded: LoadedRig) -> dict[str, Any]:
    """The rig's identity as a flat JSON-able dict (see the module docstring)."""
    cfg = loaded.config
    geometry = rig_geometry(loaded)
    ident: dict[str, Any] = {"kind": cfg.kind, "backend": cfg.backend}
    if isinstance(geometry, DomeGeometry):
        ident["lights"] = f"{geometry.count} LEDs"
        ident["light_positions"] = _digest(
            [[round(float(x), 5) for x in d] for d in geometry.directions]
        )
        # the positions themselves, as the session's decisions saw them (the digest stays for
        # sessions recorded before): compared with a tolerance, a change named by LED
        # (:func:`_moved_lights`), and an adaptive resume decides on them (:func:`same_rig`)
        ident["light_directions"] = [[float(x) for x in d] for d in geometry.directions]
        serial = cfg.dome.serial if cfg.dome else None
        corr = getattr(serial, "intensity_correction", None)
        ident["intensity_correction"] = None if corr is None else _digest(list(corr))
        ident["dome_firmware"] = getattr(serial, "profile", None)
        ident["dome_protocol"] = _dome_protocol_digest(serial)
    else:
        ident["lights"] = "one lamp on an arm"
        ident["arm_reach"] = {
            k: round(float(v), 6)
            for k, v in dataclasses.asdict(geometry).items()
            # words only (the config's own limit past the keep-out cone): the reach is the same
            if k != "configured_max_elevation_deg"
        }
    cam = cfg.camera
    ident["camera_size"] = f"{cam.width}×{cam.height}"
    ident["exposure_s"] = cam.exposure_s
    ident["gain"] = cam.gain
    device = cam.device or {}
    ident["camera_device"] = device.get("kind")
    ident["decode"] = None if device.get("decode") is None else _digest(device.get("decode"))
    if cfg.backend != "hardware":
        ident["scene"] = _digest(cfg.scene.model_dump())
    if cfg.backend == "replay":
        assert isinstance(geometry, DomeGeometry)
        ident["recorded_images"], ident["recorded_files"] = _recorded_images_digest(
            loaded, geometry
        )
    return ident


def _dome_protocol_digest(serial: Any) -> str | None:
    """A digest of what defines the dome's protocol where the config describes it
    (``profile = "custom"``, or a ``[dome.serial.protocol]`` table or LED map laid over a
    built-in firmware), None for a protocol fixed by its profile's name.

    Why: two different custom protocols are both called "custom", so the profile's name
    alone had passed a board with another command set or LED numbering as the same rig, and
    its LED indices as the same lights. A session recorded before has no ``dome_protocol``
    key and is not asked (:func:`identity_differences`)."""
    if serial is None or not getattr(serial, "is_described", False):
        return None
    if serial.profile != "custom" and serial.protocol is None and serial.led_map_file is None:
        return None
    from rti_rig.drivers.led_dome.factory import protocol_for

    return _protocol_digest(protocol_for(serial))


def _protocol_digest(spec: ProtocolSpec) -> str:
    """The digest of what ``spec`` sends to light each LED and to address the board: every
    command's bytes, the light command's for each LED (its count, numbering, addressing and
    map as the board receives them), and a stepping board's number for each LED.

    Why the bytes, not the description's keys: a key that no template uses changes nothing
    the board receives. A digest of keys had refused a resume as "its commands or LED
    numbering differ" for a renamed protocol (``name`` is a label) or for ``columns`` set on
    a mask-addressed board (no ``{row}``/``{col}`` in its commands: the mask alone says which
    LED lights). Timeouts, delays, the baud rate, a timed LED's window and the reply patterns
    are left out (they change how the board is talked to, not which light an LED index is),
    as a port's name and timing are; a stepping board's numbering is kept (the number its
    reply names an LED by is what says which LED a step lit)."""
    # a timed LED's window ({secs}) is timing, not which light: rendered without it
    bare = spec.model_copy(update={"light_on_s": None})
    leds = range(spec.led_count)

    def sent(command: CommandSpec | None, index: int | None, lit: frozenset[int]) -> str | None:
        return None if command is None else bare.render(command.send, index, lit).hex()

    defining: dict[str, Any] = {
        "light": [sent(spec.light, i, frozenset({i})) for i in leds],
        "all_off": sent(spec.all_off, None, frozenset()),
        "handshake": sent(spec.handshake, None, frozenset()),
        "init": [sent(c, None, frozenset()) for c in spec.init],
        "shutter": [sent(spec.shutter, None, frozenset({i})) for i in leds],
        "stepping": [i + spec.index_base for i in leds] if spec.stepping else None,
    }
    return _digest(defining)


def _builtin_protocol_digest(profile: Any) -> str | None:
    """The digest a built-in firmware's own protocol has (no table or LED map laid over it),
    None for a profile that is not a built-in description.

    Why: a built-in profile without a ``[dome.serial.protocol]`` table is recorded as None. A
    table that changes nothing defining (a timeout, a delay, the built-in's own LED count)
    laid over it on resume had been refused as "dome protocol described in the config:
    none → 4d016391974ed4e4", though it is the same protocol."""
    from rti_rig.drivers.led_dome.dome_profiles import builtin_spec, described_profiles
    from rti_rig.drivers.led_dome.protocol_spec import ProtocolSpec

    if not isinstance(profile, str) or profile not in described_profiles():
        return None
    return _protocol_digest(ProtocolSpec.model_validate(builtin_spec(profile)))


def _recorded_images_digest(loaded: LoadedRig, geometry: DomeGeometry) -> tuple[str, dict]:  # type: ignore[type-arg]
    """The content of a replayed acquisition's images, in light order: they are what its
    camera returns. An image edited or replaced between an interruption and the resume had
    been mixed into the session without a word (the resume's images then came from another
    acquisition than the first part's). Hashed in full (a fraction of a second for a 72-image
    acquisition of 5 MB JPEGs; seconds for one of 16-bit TIFFs not in the page cache), with
    each file's stamp (:func:`recorded_images_stamped`), recorded beside the digest so that a
    verdict need not hash them again."""
    return recorded_images_stamped(Path(loaded.path).parent, geometry.names)


def recorded_images_digest(
    folder: Path,
    names: Sequence[str],
    stamps: Any = None,
) -> str:
    """:func:`_recorded_images_digest` of the images ``names`` (an `.lp`'s, in its order) in
    ``folder``: also what a replay's verdict checks before it names the recorded files, with
    the ``stamps`` its session recorded (:func:`recorded_images_stamped`)."""
    return recorded_images_stamped(folder, names, stamps)[0]


def recorded_images_stamped(
    folder: Path,
    names: Sequence[str],
    stamps: Any = None,
) -> tuple[str, dict[str, list[Any]]]:
    """:func:`recorded_images_digest` of ``names`` in ``folder``, and each file's stamp
    ``{name: [size, mtime_ns, ctime_ns, sha256]}`` (a missing file has none). A file whose
    size, mtime and ctime are those ``stamps`` (a session's ``recorded_files``) holds for it is
    not read again: its recorded SHA-256 stands.

    Why: a replayed session's verdict (on every ``run`` and ``fit`` of it) checks that the
    acquisition is still the one replayed before naming its files, and had hashed every image
    of it each time: seconds for 72 16-bit TIFFs. Why that is safe enough: any write to a file
    sets its mtime and ctime to the clock, and a file replaced (an editor's save, a re-export,
    a copy over it) changes them too; ``touch -r``/``os.utime`` can set the mtime back, but the
    ctime only the kernel sets, to now. An edit that kept size, mtime *and* ctime (a write to
    the disk beneath the filesystem, the system clock set back to the instant of the stamp, or
    a FAT/exFAT card, which stores no ctime: once mounted again its ctime reads as the mtime
    a tool kept, ``touch -r`` or ``exiftool -P``) would go unseen here: the verdict would then
    name the recorded file a clipped image replays from its light, as for an unchanged
    acquisition; a resume hashes every file in full, and
    refuses such an acquisition. A folder copied elsewhere (a new ctime) is hashed in full on
    each verdict: its stamps are not written back (a verdict writes nothing to the session)."""
    from rti_rig.core.lp_format import image_path

    known = stamps if isinstance(stamps, dict) else {}
    total = hashlib.sha256()
    stamped: dict[str, list[Any]] = {}
    for name in names:
        path = image_path(folder, name)
        try:
            st = path.stat()
            stamp = [st.st_size, st.st_mtime_ns, st.st_ctime_ns]
            was = known.get(name)
            if isinstance(was, list) and len(was) == 4 and was[:3] == stamp:
                hexdigest = str(was[3])
            else:
                hexdigest = _file_digest(path)
            stamped[name] = [*stamp, hexdigest]
        except OSError:
            hexdigest = hashlib.sha256(b"missing").hexdigest()  # refused where images are read
        total.update(f"{name}\0{hexdigest}\n".encode())
    return total.hexdigest()[:16], stamped


def _file_digest(path: Path) -> str:
    """The SHA-256 of the file at ``path`` (OSError when it cannot be read), through the
    process's checksum cache (:func:`rti_rig.runtime.session.file_sha256`): the replay rig's
    build asks again for the digests the identity has just taken, and reads nothing twice."""
    from rti_rig.runtime.session import file_sha256

    digest = file_sha256(path)
    if digest is None:
        raise FileNotFoundError(2, "not a file", str(path))
    return digest


def identity_differences(before: dict[str, Any], now: dict[str, Any]) -> list[str]:
    """Each difference as ``"camera size: 512×512 → 256×256"`` (empty if the rigs agree)."""
    out = []
    other_kind = before.get("kind") != now.get("kind")
    for key in [*before, *(k for k in now if k not in before)]:
        old, new = before.get(key), now.get(key)
        if old == new:
            continue
        if other_kind and key in (
            "light_positions",
            "intensity_correction",
            "dome_firmware",
            "dome_protocol",
            "arm_reach",
        ):
            continue  # a dome and an arm differ in these by nature: the kind says it all
        if key == "recorded_images" and old is None:
            continue  # a session begun before the images were part of the identity
        if key in ("dome_firmware", "dome_protocol") and key not in before:
            continue  # a session begun before the firmware profile (protocol) was part of it
        if key == "dome_protocol" and before.get("dome_firmware") != now.get("dome_firmware"):
            continue  # another profile: "dome firmware profile" says it
        if key == "dome_protocol":
            builtin = _builtin_protocol_digest(now.get("dome_firmware"))
            if (old or builtin) == (new or builtin):
                continue  # a built-in's own protocol, with or without a table restating it
        if key == "light_directions":
            continue  # said under "light positions"
        if key == "recorded_files":
            continue  # the files' stamps and checksums: "recorded images" says a change
        if key == "light_positions":
            moved = _moved_lights(before.get("light_directions"), now.get("light_directions"))
            if moved is not None:  # both sides hold the positions: compared, not digested
                if moved:
                    out.append(moved)
                continue
        label = LABELS.get(key, key)
        if key in ("light_positions", "intensity_correction", "decode", "scene", "recorded_images"):
            out.append(f"{label}: changed" if old and new else f"{label}: {old} → {new}")
        elif isinstance(old, dict) and isinstance(new, dict):
            changed = [k for k in {**old, **new} if old.get(k) != new.get(k)]
            out.append(
                f"{label}: "
                + ", ".join(f"{k} {_show(old.get(k))} → {_show(new.get(k))}" for k in changed)
            )
        elif key == "dome_protocol":
            out.append(
                f"{label}: changed (its commands or LED numbering differ under the same "
                f"profile name '{now.get('dome_firmware') or before.get('dome_firmware')}': the "
                "same LED index may be another light)"
            )
        elif key == "dome_firmware":
            out.append(
                f"{label}: {_show(old)} → {_show(new)} (another controller board: its LEDs "
                "are driven, timed and possibly numbered otherwise)"
            )
        else:
            out.append(f"{label}: {_show(old)} → {_show(new)}")
    return out


def same_rig(recorded: dict[str, Any], identity: dict[str, Any]) -> dict[str, Any]:
    """``identity`` (a rig that differs from ``recorded`` in nothing
    :func:`identity_differences` names), with the light positions ``recorded`` holds: those
    of a re-measured ``.lp`` that differ by rounding alone are the same lights, and the
    session keeps the positions it began with. An adaptive session's decisions are made on
    them (a symmetric dome's ties between equally good LEDs are broken by the last digit,
    so rounding noise had chosen another starting LED and the resume was refused)."""
    if "light_directions" in recorded and "light_directions" in identity:
        for key in ("light_positions", "light_directions"):
            identity = {**identity, key: recorded[key]}
    return identity


def _moved_lights(before: Any, now: Any) -> str | None:
    """How the lights moved between two identities' ``light_directions``, in words; ``""``
    when none moved beyond :data:`POSITION_TOLERANCE_RAD` (rounding noise: the same rig);
    None when it cannot be told (a side without positions, or another number of lights,
    which the ``lights`` key names)."""
    if not isinstance(before, list) or not isinstance(now, list) or len(before) != len(now):
        return None
    moved = moved_lights(before, now)
    if not moved:
        return ""
    worst = max(moved, key=lambda i: moved[i])
    text = (
        f"light positions: {len(moved)} of {len(before)} LEDs moved, by up to "
        f"{degrees_text(moved[worst])} (LED index {worst})"
    )
    if np.radians(moved[worst]) <= THREE_DECIMALS_RAD:
        text += ", no more than rounding the .lp to 3 decimals moves a light"
    return text


def moved_lights(before: Any, now: Any) -> dict[int, float]:
    """The lights of ``now`` that moved from ``before`` (two equally long sequences of
    directions) by more than :data:`POSITION_TOLERANCE_RAD`: ``{index: angle in degrees}``.

    Why one function: a resume (:func:`identity_differences`) and a batch fit's refit-on-change
    record (:mod:`rti_rig.app.usecases.fit_inputs`) must agree on what a moved light is; the
    fit had compared a digest of positions rounded to 6 decimals, so an ``.lp`` written again
    with 5 was "changed" there and the same rig here."""
    # exact for the tiny angles rounding gives (an acos is not)
    angles = angle_between_deg(np.asarray(before, dtype=float), np.asarray(now, dtype=float))
    limit = np.degrees(POSITION_TOLERANCE_RAD)
    return {i: float(t) for i, t in enumerate(np.atleast_1d(angles)) if t > limit}


def degrees_text(angle: float) -> str:
    """``angle`` in degrees with the digits that tell it from zero: two decimals from a tenth
    of a degree (``0.30°``), two significant digits below (``0.012°``; ``.2f`` had printed a
    refusal's angle as ``0.00°``)."""
    return f"{angle:.2f}°" if angle >= 0.1 else f"{angle:.2g}°"


def _show(value: Any) -> str:
    if isinstance(value, float):
        return f"{value:g}"
    return "none" if value is None else str(value)
