"""Camera-triggered domes (``[dome.flash_sync]``): config, composition and the slip guard.

A dome such as cceh/rti steps to its next LED on the camera's flash (PC-sync) signal and has no
link to the host (docs/domes.md). A session on it is the firmware's own sequence: image *i* is
LED *i* of the order the config lists (rings, Fibonacci or an `.lp`, in flash order). The host
only shoots. Each image is judged (:mod:`rti_rig.reconstruct.sequence_check`) before its label
is committed; on a missed or double step the image is kept in ``unlabelled/``, the session stops
with :class:`~rti_rig.runtime.flash_sync.LightSlipError` naming the image and the slip, and
``lights.lp`` lists only the images before it, which were correctly labelled as far as the
check can tell. After the last image of an order that lists all the firmware's LEDs, one more
frame is shot (:meth:`SlipGuard.end_of_run`): the firmware, run out, re-lights its last LED,
which proves no step was doubled unseen anywhere in the run
(:mod:`rti_rig.reconstruct.run_out_proof`); if it does not, the run is disowned (exit 2).

Everything that would fire the camera outside the sequence steps the dome too, so it is refused:
``--lights`` other than the whole order, ``--plan``, ``--adaptive``, ``--auto-exposure``
(metering shots), ``preview`` and ``--resume`` (the dome's count no longer matches the session's).
"""

from __future__ import annotations

import errno
import json
import tempfile
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field

from rti_rig.core.clock import Clock
from rti_rig.core.devices import Frame
from rti_rig.core.errors import ConfigError, DeviceError, RtiRigError
from rti_rig.core.out_folders import free_name
from rti_rig.core.rig_geometry import DomeGeometry
from rti_rig.core.shell_words import shell_word, shown_path
from rti_rig.runtime.disowned import MARKER as DISOWN_MARKER
from rti_rig.runtime.disowned import disown
from rti_rig.runtime.flash_sync import CameraTriggeredLighting, LightSlipError
from rti_rig.runtime.lighting import ActualLight
from rti_rig.runtime.session import SessionWriteError, linear_tiff_labels

#: What each known flash-stepped firmware does by itself (cceh/rti ``firmware/rti.cpp``).
FIRMWARES: dict[str, dict[str, Any]] = {
    "cceh-rti": {"led_count": 60, "timeout_s": 4.0},
}
UNLABELLED_DIR = "unlabelled"
#: The frame after a dark image names the LED it was lit by when that LED's residual is below
#: this fraction of the other candidate's (else the two are not told apart, and both are said).
DECIDE_RATIO = 0.8


class FlashSyncSettings(BaseModel):
    """``[dome.flash_sync]``: the dome steps on the camera's flash signal; the host only shoots.

    ``firmware`` names the firmware (its LED count and off-timeout come from its source);
    ``check_after_images``: the images accepted before the neighbour test of the slip guard
    runs (a dark image is caught from the first one).
    """

    model_config = ConfigDict(extra="forbid", frozen=True)

    firmware: Literal["cceh-rti"] = "cceh-rti"
    check_after_images: int = Field(default=3, ge=3, le=100)

    @property
    def timeout_s(self) -> float:
        return float(FIRMWARES[self.firmware]["timeout_s"])

    @property
    def firmware_led_count(self) -> int:
        return int(FIRMWARES[self.firmware]["led_count"])


class SyncFaultConfig(BaseModel):
    """``[[emulator.sync_faults]]``: a flash pulse lost, or bounced into a double step, or the
    dome's power cycled just before it, at the n-th exposure (1-based) of an emulated
    camera-triggered dome."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    at_image: int = Field(gt=0)
    kind: Literal["missed_pulse", "double_step", "power_cycle"]


def flash_sync_of(loaded) -> FlashSyncSettings | None:  # type: ignore[no-untyped-def]
    dome = loaded.config.dome
    return None if dome is None else dome.flash_sync


def check_exposure(loaded) -> None:  # type: ignore[no-untyped-def]
    """Refuse, at config load, an exposure the firmware's off-timeout would cut short, and a
    camera release through a dome link that does not exist."""
    fs = flash_sync_of(loaded)
    if fs is None:
        return
    device = loaded.config.camera.device or {}
    if device.get("trigger") == "dome_shutter":
        raise ConfigError(
            loaded.path,
            "camera.device.trigger",
            "'dome_shutter' fires the camera through the dome's serial link, and a "
            "camera-triggered dome has none: let rti-rig fire the camera itself (gphoto2) and "
            "plug its PC-sync output into the dome",
        )
    if loaded.config.camera.exposure_s > fs.timeout_s:
        raise ConfigError(
            loaded.path,
            "camera.exposure_s",
            f"{loaded.config.camera.exposure_s:g} s: the {fs.firmware} firmware switches its "
            f"LED off {fs.timeout_s:g} s after the flash pulse, so a longer exposure is partly "
            "dark",
        )


def flash_sync_lighting(loaded, geometry: DomeGeometry) -> CameraTriggeredLighting:  # type: ignore[no-untyped-def]
    fs = flash_sync_of(loaded)
    assert fs is not None
    if geometry.count > fs.firmware_led_count:
        raise ConfigError(
            loaded.path,
            "dome",
            f"{geometry.count} LEDs in the order, but the {fs.firmware} firmware fires "
            f"{fs.firmware_led_count}: after its last one every flash re-lights the same LED",
        )
    return CameraTriggeredLighting(geometry, fs.firmware, fs.timeout_s)


class SlipGuard:
    """The rig's capture check: judge each image; on a slip keep it unlabelled and stop."""

    def __init__(
        self, geometry: DomeGeometry, settings: FlashSyncSettings, layout: str = "lp"
    ) -> None:
        from rti_rig.reconstruct.sequence_check import SequenceChecker

        self.geometry = geometry
        self.settings = settings
        #: The config's ``[dome] layout``: "fibonacci" is what docs/guide.md has a new dome
        #: stand in with for its sphere calibration (:meth:`_stand_in_said`).
        self.layout = layout
        self.checker = SequenceChecker(geometry.directions, settings.check_after_images)
        self.verdicts: list[Any] = []
        #: Shoots one more frame (set by :func:`build_flash_sync_rig`): after a dark image it
        #: tells a missed pulse (the dome did not step) from a dead LED (it stepped on).
        self.shoot: Callable[[], Frame] | None = None

    def __call__(self, index: int, frame: Frame, actual: ActualLight, root: Path) -> None:
        if not self.verdicts and not (Path(root) / DISOWN_MARKER).exists():
            # the labels are proven only by the end-of-run proof: until it passes (it removes
            # this), a run stopped for any reason (a missed pulse caught at its own image after
            # an unseen double step, Ctrl-C, a camera or disk error) is not used by fit/export
            disown(Path(root), NOT_PROVEN)
        verdict = self.checker.check(index, frame.pixels, frame.white_level)
        self.verdicts.append(verdict)
        if not verdict.slip:
            return
        kept = _keep(Path(root), index, frame, verdict.to_json())
        what = "missed step" if verdict.kind == "missed-step" else "double step"
        rewind = (
            "The dome's count no longer matches the session: long-press its start button to "
            f"rewind it, then start a new session{self._stand_in_said()}"
        )
        if verdict.dark:
            raise LightSlipError(self._after_dark(index, verdict, kept, Path(root), rewind))
        if verdict.kind == "restarted":
            raise LightSlipError(self._restarted(index, verdict.reason, kept))
        last = self.settings.firmware_led_count - 1
        if verdict.fitted and verdict.best_position == index - 1 and index == last:
            # the firmware re-lights its last LED once its order is exhausted: it got there early
            raise LightSlipError(
                _disowned(
                    root,
                    f"image {index + 1} was lit again by the LED that lit image {index}, the "
                    f"firmware's last, {self._led(last)}: the dome reached the end of "
                    "its sequence one image early, so it stepped twice earlier, where the check "
                    "did not see it. The labels in lights.lp from that step on are WRONG: do not "
                    f"use this session. {kept.said('Image ' + str(index + 1))}.",
                )
                + f" {rewind}"
            )
        from rti_rig.reconstruct.sequence_check import SHIFT_FROM

        if verdict.since is not None or (verdict.fitted and index <= SHIFT_FROM):
            # a slip in the first images is seen only some images later (docs/domes.md)
            first = max(1, verdict.since or 1)  # the slip's own image is uncertain by one
            raise LightSlipError(
                _disowned(
                    root,
                    f"image {index + 1} was not lit by {self._led(index)} of the dome's order — "
                    f"{self._early_slip(verdict.since, what, verdict.reason)}. A slip in the first "
                    f"images is seen only some images later, so images {first}–{index} in "
                    "lights.lp may be mislabelled: do not use this session. "
                    f"{kept.said('Image ' + str(index + 1))}." + self._maybe_power_cut(first),
                )
                + f" {rewind}"
            )
        before = f"images 1–{index}" if index > 1 else ("image 1" if index == 1 else "no image")
        raise LightSlipError(
            f"image {index + 1} was not lit by {self._led(index)} of the dome's order — {what}: "
            f"{verdict.reason}. {kept.said('The image')}; lights.lp lists "
            f"{before} only. {rewind}"
        )

    def _stand_in_said(self) -> str:
        """For a dome whose layout is ``fibonacci``, what its slip may be instead: the
        stand-in's false alarm.

        Why: docs/guide.md has a new dome, whose directions no one measured, shoot its sphere
        under a fibonacci layout standing in for them. The check fits each image to the listed
        directions, and on the emulated cceh/rti dome (its LEDs where its design puts them)
        that stand-in stopped the sphere session at image 9 as a "missed step" that was not
        there; the design's own rings, a few degrees from the truth, shoot it through and
        measure the directions within 0.3°. The user was left rewinding the dome to the same
        false alarm."""
        if self.layout != "fibonacci":
            return ""
        return (
            '. This dome\'s layout is "fibonacci": if it stands in for directions not yet '
            "measured (a sphere shot for rti-rig lights-from-sphere), the check, which fits the "
            "images to the listed directions, may see a slip that is not there: list the LEDs "
            "as the dome's design places them, in the order its firmware steps them ([[dome."
            "rings]] or an .lp; docs/guide.md, section 3), and shoot the sphere again"
        )

    def _early_slip(self, since: int | None, what: str, reason: str) -> str:
        """The slip's name and the check's reason, for a slip in the first images: named as
        the check's best reading where the images fit best with it beginning (``since``,
        0-based) among those the check's fit was made from.

        Why: the check judges an image against a fit of the images before it, and a fit of
        images the slip had already mislabelled, all shifted alike, explains the later ones
        about as well one LED either way (a shift of the labels within a ring is close to a
        turn of the lights, which the fitted normals take up). A power cut before image 2 (the
        dome one LED behind from then on, as after a missed step) was named a "double step"
        the images "fit best" as beginning at image 1, and the user was pointed at the
        flash cable's bounces. Where the images fit best with the slip beginning at the image
        judged (no ``since``), the fit was made from images labelled right, and its step
        stands."""
        if since is None or since >= self.checker.min_fit_images:
            return f"{what}: {reason}"
        return (
            "a slip of the order that may have begun before the check had a fit to judge by "
            f"(from image {self.checker.min_fit_images + 1} on), so whether the dome missed a "
            "step, stepped twice or started again after a power cut cannot be told; the "
            f"check's best reading is a {what}: {reason}"
        )

    def _maybe_power_cut(self, first: int) -> str:
        """The clause for a slip that began before the check had a fit (images 1 to
        ``min_fit_images``): a power cut there looks like it.

        Why: the firmware lights LED 0 again after a power cut, which the check names only
        once it has a fit to compare LED 0 with. Before that, a cut before image 2 or 3 is
        seen images later as a shift of the order, and was named a "double step" or "missed
        step" alone: the user went after the flash cable when the dome's supply had dropped."""
        if first > self.checker.min_fit_images:
            return ""
        return (
            " Check the dome's power supply and its plug as well as the flash cable (a power cut "
            "starts its order again from LED 0)."
        )

    def _restarted(self, index: int, reason: str, kept: Kept) -> str:
        """The words for an image lit by the order's first LED far into the run.

        Why: the firmware starts its order again from LED 0 whenever its power comes back (a
        loose supply jack, a brown-out); the images before it stay in lights.lp as the other
        slips leave them, and the dome must be rewound. Said with :meth:`Kept.said`: the
        message had printed the record itself (``Kept(where=...)``), and claimed every image
        before "matched to its LED" where the first ones, shot before a fit, were never
        compared with one."""
        before = f"images 1–{index}" if index > 1 else "image 1"
        return (
            f"image {index + 1} was {reason}: the dome started its order again (its power was "
            f"cut and came back, or its start button was pressed). {kept.said('The image')}; "
            f"lights.lp lists {before} only. Check the dome's power supply and its plug, then "
            "long-press its start button to rewind it and start a new session"
        )

    def _led(self, index: int) -> str:
        """Order position ``index`` as every other word names a dome LED (``led_said``: ``LED 5
        (az 90.0°, el 44.7°)``, 0-based as ``dead_leds``, plans and manifests count them).

        Why: these words had said the firmware's 1-based ``LED 6`` for the LED the rest of the
        CLI calls ``LED 5``, so ``dead_leds = [5]`` came back as "Repair or replace LED 6"; the
        direction says which LED on the dome to look at."""
        if 0 <= index < self.geometry.count:
            return self.geometry.led_said(index)
        return f"LED {index}"

    def _after_dark(self, index: int, verdict: Any, kept: Kept, root: Path, rewind: str) -> str:
        """What a dark image was, from one more frame (:meth:`SequenceChecker.judge_after_dark`).

        A missed pulse and a dead LED both give a dark image, but a missed pulse leaves the
        dome one LED behind (the next frame is lit by the LED this image was due) while a dead
        LED was fired and the dome stepped on (the next frame is lit by the next LED, as the
        order says). Blaming the flash signal for a dead LED sent the user after a good cable
        and told them the dome's count was lost when it was not.
        """
        k, n = index + 1, self.geometry.count
        led, next_led = self._led(index), self._led(index + 1)
        head = f"image {k} was not lit by {led} of the dome's order — {verdict.reason}"
        listed = f"images 1–{index}" if index > 1 else ("image 1" if index == 1 else "no image")
        either = (
            f"either the flash pulse did not reach the dome (a missed step: it did not step, "
            f"and its count no longer matches the session) or {led} is dead (the dome "
            "stepped on)"
        )
        rewind_either = (
            "Either way the session stops here: long-press the dome's start button to rewind "
            "it, then start a new session"
        )
        if self.shoot is None:
            return (
                f"{head}: {either}. {kept.said('The image')}; lights.lp lists "
                f"{listed} only. {rewind_either}"
            )
        try:
            frame = self.shoot()
        except DeviceError as exc:  # the dark image's own message is what matters: say both
            return (
                f"{head}: {either}; the frame that would tell them apart could not be shot "
                f"({exc}). {kept.said('The image')}; lights.lp lists {listed} "
                f"only. Look at {led} during a flash and check the camera's PC-sync cable. "
                f"{rewind_either}"
            )
        ratio, residuals = self.checker.judge_after_dark(index, frame.pixels, frame.white_level)
        record = {
            "after_dark_image": k,
            "brightness_ratio": ratio,
            "residuals": None if residuals is None else {str(p): r for p, r in residuals.items()},
        }
        check = _keep(root, index + 1, frame, record, stem="check")
        shot = f"the frame shot after it to tell ({check.said('it')})"
        end = self.settings.firmware_led_count == n and index == n - 1
        due, nxt = (residuals or {}).get(index), (residuals or {}).get(index + 1)
        dead = missed = False
        if residuals is None and ratio < 1.0 and (end or ratio < 0.5):
            # dark again: the firmware re-lights its last (dead) LED; else no LED lit it either
            if end:
                dead, why = True, f"{shot} is dark too: the firmware re-lit its last LED, {led}"
            else:
                why = f"{shot} is dark too"
        elif due is not None and nxt is not None:
            vs = f"relative residual {min(due, nxt):.3f} against {max(due, nxt):.3f}"
            if nxt < DECIDE_RATIO * due:
                dead, why = True, f"{shot} was lit by {next_led}, as the order says ({vs})"
            elif due < DECIDE_RATIO * nxt:
                missed = True
                why = f"{shot} was lit by {led}, the one image {k} was due ({vs})"
            else:
                why = f"{shot} fits {led} and {next_led} alike ({vs})"
        elif due is not None and end:
            missed, why = True, f"{shot} was lit by {led}, the one image {k} was due"
        else:
            why = f"{shot} could not be judged (too few images before it to fit)"
        if dead:
            return (
                f"image {k} is dark: {led} did not light (dead LED?); the dome stepped on: "
                f"{why}. Image {k}: {verdict.reason}; {kept.said('it')}. The "
                f"session's other images are good as far as the per-image check can tell: "
                f"lights.lp lists {listed}, each matched to its LED (the run stopped before its "
                f"end-of-run proof, so {DISOWN_MARKER} stays in the session). Repair or replace "
                f"{led} (look at it during a flash), then long-press the dome's start button "
                "to rewind it and shoot the session again; the dome's count matched the session, "
                "the run stopped only for the dark image"
            )
        if missed:
            return (
                f"{head}: missed step — the flash pulse did not reach the dome, which therefore "
                f"did not step: {why}. Check the camera's PC-sync cable and flash-contact "
                f"setting. {kept.said('The image')}; lights.lp lists {listed} "
                f"only. {rewind}"
            )
        return (
            f"{head}: {either}; {why}. {kept.said('The image')}; lights.lp "
            f"lists {listed} only. Look at {led} during a flash and check the camera's "
            f"PC-sync cable. {rewind_either}"
        )

    def end_of_run(self, shoot: Callable[[], Frame], root: Path) -> list[str]:
        """The end-of-run proof (:mod:`rti_rig.reconstruct.run_out_proof`): one more frame after
        the last image; it must be the last LED again, and the image before must differ."""
        from rti_rig.reconstruct.run_out_proof import prove_run_out
        from rti_rig.reconstruct.sequence_check import reduce_image

        n, fw = self.geometry.count, self.settings.firmware_led_count
        images = self.checker.accepted_images
        if n < fw:
            return [
                f"end-of-run proof NOT done: the order lists {n} of the {self.settings.firmware} "
                f"firmware's {fw} LEDs, so the dome has not run out after image {n} and no frame "
                "can show that its order held. A double step the per-image check did not see "
                "would leave lights.lp mislabelled unnoticed (docs/domes.md); the run is not "
                f"verified, and {DISOWN_MARKER} in the session says so (fit and export-lp "
                f"refuse it). List all {fw} LEDs of the order to get the proof"
            ]
        if len(images) != n or n < 3:
            return [
                "end-of-run proof NOT done: the run's images were not all checked; "
                f"{DISOWN_MARKER} in the session says so (fit and export-lp refuse it)"
            ]
        frame = shoot()
        proof = prove_run_out(images, reduce_image(frame.pixels, frame.white_level))
        kept = _keep(Path(root), n, frame, proof.to_json(), stem="proof")
        if proof.proved:
            marker = Path(root) / DISOWN_MARKER
            if marker.read_text(encoding="utf-8").strip() == NOT_PROVEN.strip():
                marker.unlink()  # proven: only the "not yet proven" reason was in it
            return [f"end-of-run proof passed: {proof.reason}. {kept.said('The proof frame')}"]
        what = (
            "cannot verify the dome's order"
            if proof.kind == "cannot-verify"
            else ("a slip happened somewhere in the run")
        )
        raise LightSlipError(
            _disowned(
                root,
                f"end-of-run proof failed — {what}: {proof.reason}. The labels in lights.lp may "
                "be mislabelled (every image from the unseen slip on): do not use this session. "
                f"{kept.said('The proof frame')}.",
            )
            + " The dome's count no longer matches the session: long-press its start button to "
            "rewind it, then start a new session"
        )


#: What the marker says from a flash-sync run's first image until its end-of-run proof passes.
NOT_PROVEN = (
    "this camera-triggered run's labels are proven only by its end-of-run proof frame, and the "
    "run did not pass it (it stopped early, or its order is shorter than the firmware's, so no "
    "proof was possible): a double step the per-image check did not see would leave lights.lp "
    "mislabelled (docs/domes.md)"
)


@dataclass(frozen=True)
class Kept:
    """Where a slipped, check or proof frame went: ``where`` (shown as a shell word), or None
    when no disk took it; ``note`` says why it is not under ``unlabelled/`` and what to do.

    Why: a disk that refused ``unlabelled/`` had ended the run in that write error alone: the
    slip (which image, missed or double step) was never said, and the frame, in memory only,
    was lost with it."""

    where: str | None
    note: str = ""

    def said(self, subject: str) -> str:
        """``subject`` (``The image``, ``Image 4``, ``it``) with where it is kept, or why not."""
        if self.where is None:
            return f"{subject} could not be kept anywhere: {self.note}"
        return f"{subject} is kept, unlabelled, as {self.where}{self.note}"


def _keep(
    root: Path, index: int, frame: Frame, verdict: dict[str, Any], stem: str = "image"
) -> Kept:
    """:func:`keep_unlabelled`; if the session's disk refuses it, the same files in a folder of
    the system's temporary directory (another disk, often), said with the refusal and what to
    do; if that fails too, both refusals and where the camera's own file is, if it has one.
    Never raises for the disk: the slip that called this must still be said."""
    folder = root / UNLABELLED_DIR
    before = set(folder.iterdir()) if folder.is_dir() else set()
    try:
        return Kept(keep_unlabelled(root, index, frame, verdict, stem))
    except OSError as exc:
        refused = _refusal(folder, exc)
        fix = _fix_for(exc)
    # a folder of its own: another session of the same name may have left one there
    aside = free_name(Path(tempfile.gettempdir()) / f"rti-rig-unlabelled-{root.name}", folder=True)
    try:
        rel = keep_unlabelled(aside, index, frame, verdict, stem, folder=aside)
    except OSError as exc2:
        # what is left of the frame, said where it is: a TIFF written under unlabelled/ before
        # its JPEG was refused holds the whole frame (it had been said "in memory only and
        # is lost" beside it), and the camera's own file, if it has one
        left = sorted((set(folder.iterdir()) if folder.is_dir() else set()) - before)
        left += sorted(aside.iterdir()) if aside.is_dir() else []  # a folder of its own
        originals = [Path(item["path"]) for item in frame.metadata.get("originals") or []]
        still = [
            *([f"what was written of it stays as {_paths(left)}"] if left else []),
            *([f"the camera's own file stays as {_paths(originals)}"] if originals else []),
        ]
        where = "; ".join(still) or "the frame was in memory only and is lost"
        return Kept(None, f"{refused}; nor aside: {_refusal(aside, exc2)}; {where}")
    # what the refused attempt left under unlabelled/ (its TIFF, say, without its JPEG and
    # verdict) is a part of what is whole aside: removed, so that the move said has no clash
    for partial in (set(folder.iterdir()) if folder.is_dir() else set()) - before:
        partial.unlink(missing_ok=True)
    return Kept(
        shown_path(aside / Path(rel).name),
        f" (outside the session: {refused}; {fix}, then move the files of {shown_path(aside)} "
        f"into {shown_path(folder)}, before the temporary folder is emptied)",
    )


def _paths(paths: list[Path]) -> str:
    """``paths`` as shell words, comma-separated."""
    return ", ".join(shown_path(p) for p in paths)


def _refusal(folder: Path, exc: OSError) -> str:
    """``cannot write FILE: reason (ENOSPC)``, as a session's write error says it."""
    path = Path(exc.filename) if isinstance(exc.filename, str) else folder
    return str(SessionWriteError(path, exc))


def _fix_for(exc: OSError) -> str:
    if exc.errno in (errno.ENOSPC, errno.EDQUOT, errno.EFBIG):
        return "free space on that disk"
    if exc.errno == errno.EROFS:
        return "make that disk writable"
    if exc.errno in (errno.EACCES, errno.EPERM):
        return "check that you may write to that folder (ls -l shows its owner)"
    return "check that disk"


def _disowned(root: Path, reason: str) -> str:
    """Mark the session's labels as not to be used (``fit`` and ``export-lp`` then refuse it)
    and return the message, naming the marker."""
    marker = disown(Path(root), reason)
    return f"{reason} {marker.name} in the session says so; fit and export-lp refuse it."


def keep_unlabelled(
    root: Path,
    index: int,
    frame: Frame,
    verdict: dict[str, Any],
    stem: str = "image",
    folder: Path | None = None,
) -> str:
    """Write a slipped (or proof) image under ``unlabelled/`` (linear TIFF, sRGB JPEG, the
    verdict), its files labelled and tagged as a session's of the same decode are."""
    from rti_rig.core.image_colour import decode_colour
    from rti_rig.core.image_files import (
        linear_to_srgb8,
        write_linear_tiff,
        write_srgb_jpeg,
        write_untagged_jpeg,
    )

    folder = root / UNLABELLED_DIR if folder is None else folder
    folder.mkdir(parents=True, exist_ok=True)
    base = f"{stem}_{index + 1:03d}"
    tif = folder / f"{base}.tif"
    n = 2
    while tif.exists():  # never overwrite a kept image
        base = f"{stem}_{index + 1:03d}_{n}"
        tif, n = folder / f"{base}.tif", n + 1
    decode = dict(frame.metadata.get("decode") or {})
    # labelled as a session's linear TIFF of the same decode is (it had no description and no
    # profile, so viewers took it as sRGB-encoded and showed it dark)
    description, icc = linear_tiff_labels(decode, frame)
    write_linear_tiff(tif, frame.pixels, description=description, iccprofile=icc)
    # tagged sRGB only where it is: a RAW with no colour matrix gives camera RGB
    srgb = decode_colour(decode) == "srgb"
    writer = write_srgb_jpeg if srgb else write_untagged_jpeg
    writer(folder / f"{base}.jpg", linear_to_srgb8(frame.pixels, frame.white_level))
    (folder / f"{base}.json").write_text(json.dumps(verdict, indent=1) + "\n", encoding="utf-8")
    return f"{folder.name}/{base}.tif"


def emulated_flash_sync_camera(loaded, geometry: DomeGeometry, clock: Clock):  # type: ignore[no-untyped-def]
    """The cceh/rti emulator fired by a simulated camera's sync contact; returns the camera
    (its ``dome`` is the emulator). An LED of ``[emulator] dead_leds`` gives no light when the
    firmware fires it (accepted and ignored here, the one emulated dome left so, a dead LED
    could not be rehearsed on a camera-triggered dome)."""
    from rti_rig.app.compose import SIMULATED_SCENE_EXPOSURE_S, scene_renderer
    from rti_rig.app.config import emulated_led_directions
    from rti_rig.simulator.domes.cceh_rti import CcehRtiFirmware
    from rti_rig.simulator.flash_sync_camera import FlashSyncCamera, SyncFault

    cfg = loaded.config
    render = scene_renderer(loaded)
    powers = cfg.emulator.led_powers(geometry.count, cfg.scene.seed)
    dead = frozenset(cfg.emulator.dead_leds)
    # where the LEDs really are: [emulator] led_directions_file, a new dome's rehearsal on a
    # stand-in layout (it had been accepted here and ignored: the camera rendered the stand-in)
    real = emulated_led_directions(loaded, geometry.count)
    return FlashSyncCamera(
        render,
        CcehRtiFirmware(start=clock.now()),
        geometry.directions if real is None else real,
        clock,
        faults=tuple(SyncFault(f.at_image, f.kind) for f in cfg.emulator.sync_faults),
        power=lambda led: 0.0 if led in dead else float(powers[led]),
        reference_exposure_s=SIMULATED_SCENE_EXPOSURE_S,
        readout_s=cfg.timing.readout_s,
        transfer_s=cfg.timing.transfer_s,
        noise=cfg.scene.noise,
        seed=cfg.scene.seed,
        raw=cfg.scene.raw,
    )


def build_flash_sync_rig(loaded, geometry: DomeGeometry, clock: Clock, camera=None):  # type: ignore[no-untyped-def]
    """The rig of a camera-triggered dome: ``camera`` (hardware), else the emulated pair."""
    from rti_rig.runtime.rig import Rig

    fs = flash_sync_of(loaded)
    assert fs is not None
    lighting = flash_sync_lighting(loaded, geometry)
    emulated = camera is None
    if emulated:
        camera = emulated_flash_sync_camera(loaded, geometry, clock)
    guard = SlipGuard(geometry, fs, loaded.config.dome.layout)
    rig = Rig(
        loaded,
        geometry,
        lighting,
        camera,
        clock,
        capture_check=guard,
        end_check=guard.end_of_run,
    )

    def shoot() -> Frame:
        from rti_rig.runtime.controller import shoot_lit

        return shoot_lit(rig, rig.camera_config.exposure_s)

    guard.shoot = shoot
    if emulated:
        rig.emulator = camera.dome  # type: ignore[attr-defined]  # the truth, for tests
    return rig


def refuse_options(loaded, out: Path, **given: bool) -> None:  # type: ignore[no-untyped-def]
    """Refuse, by name, what would fire the camera outside the firmware's sequence, with the
    run that shoots the whole sequence on this config (its path as one shell word: the advice
    had said ``rti-rig run CONFIG``, leaving the user to find which config) into ``out``, or
    ``out`` with ``-2``… if that is taken (``--out DIR`` had been said, which pasted made a
    folder named DIR)."""
    fs = flash_sync_of(loaded)
    if fs is None:
        return
    why = {
        "--plan": "the firmware lights its LEDs in its own order; no plan can choose them",
        "--adaptive": "the firmware lights its LEDs in its own order; nothing can choose the next",
        "--until-error (an adaptive session)": "the firmware lights its LEDs in its own order; "
        "nothing can choose the next",
        "--auto-exposure": "each metering shot would step the dome to its next LED",
        "--resume": "the dome's own count no longer matches the session's",
        "preview": "a preview shot would step the dome to its next LED",
        "plan": "the firmware lights its LEDs in its own order, so no plan can be run on it",
    }
    for option, present in given.items():
        if present:
            # nothing was fired by this command: "long-press … to rewind it" had read as if it
            # had stepped the dome; only a resume's session has (its count went on)
            rewind = (
                "Long-press the dome's start button to rewind it, then run"
                if option == "--resume"
                else "Nothing was fired. Run, with the dome at its first LED (long-press its "
                "start button if it has flashed since it was last rewound),"
            )
            raise RtiRigError(
                f"{shown_path(loaded.path)}: {option} cannot be used with a camera-triggered dome "
                f"({fs.firmware}): {why[option]}. {rewind} the whole sequence: rti-rig run "
                f"{shell_word(str(loaded.path))} "
                f"--out {shell_word(str(free_name(Path(out), folder=True)))}"
            )


def check_lights(loaded, geometry: DomeGeometry, lights: int | None) -> None:  # type: ignore[no-untyped-def]
    """``--lights N`` must be the whole order: the firmware runs its own sequence."""
    fs = flash_sync_of(loaded)
    if fs is None or lights is None or lights == geometry.count:
        return
    raise RtiRigError(
        f"--lights {lights}: this camera-triggered dome ({fs.firmware}) lights its "
        f"{geometry.count} LEDs in its own order and rti-rig cannot choose which; a run shoots "
        "them all. To shoot fewer, list only the first N of the firmware's order in the config "
        "(its last flash then leaves the dome part-way: long-press start before the next run)"
    )


def check_lines(loaded, geometry: DomeGeometry) -> list[str]:  # type: ignore[no-untyped-def]
    """What ``rti-rig check`` can say of a dome it cannot command."""
    fs = flash_sync_of(loaded)
    assert fs is not None
    return [
        f"dome: camera-triggered ({fs.firmware}); rti-rig cannot light its LEDs, so none was "
        "tested",
        f"  {geometry.count} LEDs in the order of the config, lit one per flash pulse of the "
        f"camera (the firmware fires {fs.firmware_led_count})",
        f"  the firmware switches an LED off at the end of the pulse, or {fs.timeout_s:g} s "
        "after it at the latest; exposure "
        f"{loaded.config.camera.exposure_s:g} s is within that",
        "  before a run: long-press the dome's start button (rewinds it to its first LED) and "
        "leave its camera-trigger cable unplugged, so that only rti-rig fires the camera",
        "  each image is checked against its LED before it is labelled (a missed or double "
        "step, or a dark image, stops the run; after a dark image one more frame tells a missed "
        f"step from a dead LED; the neighbour test starts after {fs.check_after_images} images)",
        (
            "  after the last image one more flash is shot, the proof frame (kept in "
            "unlabelled/, never labelled): the firmware must re-light its last LED, which proves "
            "no step was doubled anywhere in the run"
            if geometry.count == fs.firmware_led_count
            else f"  the order stops before the firmware's last LED ({geometry.count} of "
            f"{fs.firmware_led_count}): the end-of-run proof cannot be done, so a double step "
            "the per-image check misses would go unnoticed (the run says 'not verified')"
        ),
    ]


def check_new_session(req, loaded) -> None:  # type: ignore[no-untyped-def]
    """A new session's options, checked against a camera-triggered dome (nothing if not one)."""
    if flash_sync_of(loaded) is None:
        return
    from rti_rig.app.config import rig_geometry

    refuse_options(
        loaded,
        req.out_dir,  # nothing was written to it
        **{
            "--plan": req.plan is not None,
            req.adaptive_option: req.is_adaptive,
            "--auto-exposure": req.auto_exposure,
        },
    )
    check_lights(loaded, rig_geometry(loaded), req.lights)


class FlashSyncCheckReport:
    """``rti-rig check`` on a camera-triggered dome: what is known without firing a flash."""

    def __init__(self, lines: list[str], ok: bool) -> None:
        self._lines, self.ok = lines, ok

    def lines(self) -> list[str]:
        # ends, as every check does, with its result: what was tested (the camera) passed or not
        result = "PASS (the camera; the LEDs cannot be tested)" if self.ok else "FAIL"
        return [*self._lines, f"RESULT: {result}"]


def flash_sync_check(loaded) -> FlashSyncCheckReport:  # type: ignore[no-untyped-def]
    """Build the rig (the order is checked against the firmware), open and release the camera
    without shooting (a shot would step the dome), and say what cannot be tested."""
    from rti_rig.app.compose import build_rig
    from rti_rig.app.usecases.check import camera_line, config_note_lines

    with build_rig(loaded) as rig:
        assert isinstance(rig.geometry, DomeGeometry)
        lines = [*check_lines(loaded, rig.geometry), *config_note_lines(loaded)]
        camera, ok = camera_line(rig, "it would step the dome")
    return FlashSyncCheckReport([*lines, camera], ok)
