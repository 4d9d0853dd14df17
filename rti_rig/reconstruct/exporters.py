"""Files that viewers people already use open: ``.ptm``, HSH ``.rti``, relight ``.dome``, maps.

Formats, as published (no code copied):

* **PTM 1.2, ``PTM_FORMAT_RGB``** (Malzbender, Gelb, Wolters; HP Labs "PTM file format 1.2";
  the layout relight's ``LRti`` reader in cnr-isti-vclab/relight ``src/legacy_rti.cpp`` reads):
  text lines ``PTM_1.2``, ``PTM_FORMAT_RGB``, width, height, six scale floats, six integer
  biases, then bytes: for each colour plane R, G, B, for each scanline, for each pixel, the six
  coefficients a0..a5. Coefficient ``a_i = (byte - bias_i) × scale_i``. Scanlines run from the
  bottom of the image up (the origin of a PTM is its lower-left corner), and ``(l_u, l_v)`` are
  the light's projection with ``v`` up — the DESIGN.md frame.
* **HSH ``.rti``** (RTIViewer's format: its ``Hsh::loadData``, the ``.rti`` branch; relight's
  ``LRti::loadHSH`` in cnr-isti-vclab/relight ``src/legacy_rti.cpp``; CHI's Java HSH viewer
  ``org.thadeus.rtiviewer.RTI``; JedMills' RTIViewer ``RTIParser``): header lines ending in
  CRLF, as the HSH fitter RTIBuilder runs writes them (JedMills' parser counts 2 bytes per line
  end to find the data; the others read to the LF): comment lines starting ``#`` (the first
  is ``#HSH1.2``), the
  file type ``3`` (HSH), ``width height 3``, ``terms basis_type element_size`` (we write
  ``2 1``: the basis type is ignored by readers, one byte per element), then ``terms``
  little-endian float32 scales and ``terms`` biases, then bytes: scanlines **from the top
  down** (unlike a PTM: relight stores file row ``y`` of an HSH at row ``height - 1 - y`` of
  the same bottom-up buffer it reads a PTM's file rows into unflipped; RTIViewer reads row
  ``j`` to image row ``j``; the Java viewer flips ``j`` for OpenGL's bottom-up origin), for
  each pixel, for each colour, for each term. Coefficient ``c = byte / 255 × scale_k +
  bias_k``, in units where **1 is full scale**: the Java viewer clamps the relit sum to [0, 1]
  and multiplies by 255 for display, JedMills' RTIViewer shader writes it out as a 0–1 colour.
  Our basis is the true HSH
  (order-3 exponent 1.5, see :mod:`rti_rig.core.rti_bases`).
* **relight ``.dome``** (cnr-isti-vclab/relight): JSON as relight's ``Dome::fromJson``
  (src/dome.cpp) reads it — ``label``, ``notes``, ``imageWidth`` and ``domeDiameter`` (cm),
  ``verticalOffset`` (cm), ``lightConfiguration`` (``"directional"``) and ``directions`` as an
  array of objects ``{"x", "y", "z"}`` (unit vectors, z up, x right, y towards the top of the
  image). relight's format page names the diameter ``diameter`` and does not say how a
  direction is written; its reader wants ``domeDiameter`` and objects (a plain ``[x, y, z]``
  array reads as (0, 0, 0)), so the reader is followed and ``diameter`` is written too.
  Lengths: the format page and older ``dome.h`` say cm, newer ``dome.h`` says mm; rti-rig
  writes 0 (unknown) for them, which a ``"directional"`` dome never reads, so the unit
  question does not arise until a diameter is written.

Coefficients are written in the units each viewer displays — a PTM's relit value is shown
as the byte value itself (images × 255), an HSH's as the fraction of full scale (images × 1) —
quantised to 8 bits per coefficient with one scale and bias per coefficient index (over all
pixels and colours). Which images is the caller's choice (`rti-rig fit --export-encoding`):
viewers apply no transfer curve, so the sRGB-encoded observations look as the JPEGs do and the
linear ones darker.
"""

from __future__ import annotations

import json
import mmap
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from rti_rig.core import opencv_files
from rti_rig.core.qt_names import qt_name_key
from rti_rig.core.shell_words import shown_path
from rti_rig.reconstruct.errors import ReconstructionError

#: A PTM's coefficients are stored for images scaled to 0–255: PTM viewers show the relit
#: value as the byte itself (RTIViewer's ``evalPoly`` result goes straight to a byte).
DISPLAY_SCALE = 255.0
#: An HSH ``.rti``'s coefficients are stored for images in 0–1: the viewers display the relit
#: sum as a fraction of full scale (CHI's Java viewer clamps it to [0, 1], then × 255).
HSH_DISPLAY_SCALE = 1.0


def _rgb_planes(coefficients: NDArray[Any]) -> NDArray[np.float32]:
    """(p, H, W, 3) float32 from (p, H, W) grey or (p, H, W, C) colour coefficients."""
    c = np.asarray(coefficients, dtype=np.float32)
    if c.ndim == 3:
        c = np.repeat(c[..., None], 3, axis=-1)
    if c.shape[-1] != 3:
        raise ReconstructionError(f"export needs grey or RGB coefficients, got {c.shape}")
    return c


def ptm_quantisation(lo: ArrayLike, hi: ArrayLike) -> tuple[NDArray[np.float64], NDArray]:
    """PTM scale (float) and integer bias per coefficient for display-unit ranges lo..hi."""
    lo = np.minimum(np.asarray(lo, dtype=np.float64), 0.0)
    hi = np.maximum(np.asarray(hi, dtype=np.float64), 0.0)
    scale = np.maximum((hi - lo) / 255.0, 1e-12)
    bias = np.clip(np.round(-lo / scale), 0, 255).astype(int)
    return scale, bias


class PtmWriter:
    """``PTM_FORMAT_RGB`` written a band of rows at a time (file laid out first, then filled).

    ``lo``/``hi``: range of each of the 6 coefficients in display units (images × 255) over
    all pixels and colours; values outside are clipped. A fit that streams knows them from a
    pixel sample (:func:`coefficient_ranges`).
    """

    display_scale = DISPLAY_SCALE

    def __init__(self, path: Path, width: int, height: int, lo: ArrayLike, hi: ArrayLike) -> None:
        self.path, self.width, self.height = path, int(width), int(height)
        self.scale, self.bias = ptm_quantisation(lo, hi)
        header = (
            "PTM_1.2\nPTM_FORMAT_RGB\n"
            f"{self.width}\n{self.height}\n"
            + " ".join(f"{v:.9g}" for v in self.scale)
            + "\n"
            + " ".join(str(v) for v in self.bias)
            + "\n"
        ).encode("ascii")
        self._tmp = path.with_name(path.name + ".part")
        self._fh = open(self._tmp, "wb")  # noqa: SIM115 - open across bands, closed by close()
        self._fh.write(header)
        self._start = len(header)
        self._plane = self.width * self.height * 6
        self._fh.truncate(self._start + 3 * self._plane)

    def write_rows(self, top: int, coefficients: NDArray[Any]) -> None:
        """Coefficients (6, r, W[, 3]) of image rows ``top .. top + r`` (top-down)."""
        c = _rgb_planes(coefficients) * np.float32(self.display_scale)
        r = c.shape[1]
        sc = self.scale[:, None, None].astype(np.float32)
        bi = self.bias[:, None, None].astype(np.float32)
        first_file_row = self.height - (top + r)  # scanlines run bottom-up
        for ch in range(3):
            q = np.clip(np.round(c[..., ch] / sc + bi), 0, 255).astype(np.uint8)
            block = np.ascontiguousarray(np.moveaxis(q, 0, -1)[::-1])
            self._fh.seek(self._start + ch * self._plane + first_file_row * self.width * 6)
            self._fh.write(block.tobytes())

    def close(self) -> Path:
        self._fh.close()
        self._tmp.replace(self.path)
        return self.path

    def abort(self) -> None:
        """A fit that failed half-way: close the file and remove the partial ``.part``."""
        _abort(self._fh, self._tmp)


class RtiWriter:
    """HSH ``.rti`` written a band of rows at a time; ``lo``/``hi`` per term, in this format's
    display units (images × :data:`HSH_DISPLAY_SCALE`: ``coefficient_ranges(c, scale=...)``)."""

    display_scale = HSH_DISPLAY_SCALE

    def __init__(self, path: Path, width: int, height: int, lo: ArrayLike, hi: ArrayLike) -> None:
        self.path, self.width, self.height = path, int(width), int(height)
        self.lo = np.asarray(lo, dtype=np.float64)
        self.scale = np.maximum(np.asarray(hi, dtype=np.float64) - self.lo, 1e-12)
        self.terms = self.lo.size
        if self.terms not in (4, 9, 16):
            raise ReconstructionError(f"HSH has 4, 9 or 16 terms, got {self.terms}")
        # CRLF, as the HSH fitter RTIBuilder runs writes it (HshCore::hsh_save): JedMills'
        # RTIViewer (src/ptmCreation/RTIParser.java, getHeaderData) finds the scales at the sum
        # of each header line's length + 2, so LF-only lines had it read every scale, bias and
        # coefficient from a few bytes too far; readers that scan to LF take CRLF alike
        lines = ["#HSH1.2", "#written by rti-rig", "3", f"{self.width} {self.height} 3"]
        header = "".join(f"{line}\r\n" for line in [*lines, f"{self.terms} 2 1"]).encode("ascii")
        self._tmp = path.with_name(path.name + ".part")
        self._fh = open(self._tmp, "wb")  # noqa: SIM115 - open across bands, closed by close()
        self._fh.write(header)
        self._fh.write(self.scale.astype("<f4").tobytes())
        self._fh.write(self.lo.astype("<f4").tobytes())
        self._start = self._fh.tell()
        self._fh.truncate(self._start + self.width * self.height * 3 * self.terms)

    def write_rows(self, top: int, coefficients: NDArray[Any]) -> None:
        """Coefficients (terms, r, W[, 3]) of image rows ``top .. top + r`` (top-down, as the
        file's scanlines run)."""
        c = _rgb_planes(coefficients) * np.float32(self.display_scale)
        lo = self.lo[:, None, None, None].astype(np.float32)
        sc = self.scale[:, None, None, None].astype(np.float32)
        q = np.clip(np.round((c - lo) / sc * 255.0), 0, 255).astype(np.uint8)
        block = np.ascontiguousarray(np.transpose(q, (1, 2, 3, 0)))  # rows, x, colour, term
        self._fh.seek(self._start + top * self.width * 3 * self.terms)
        self._fh.write(block.tobytes())

    def close(self) -> Path:
        self._fh.close()
        self._tmp.replace(self.path)
        return self.path

    def abort(self) -> None:
        """A fit that failed half-way: close the file and remove the partial ``.part``."""
        _abort(self._fh, self._tmp)


def _abort(fh: Any, tmp: Path) -> None:
    """Close a writer's file and remove its ``.part`` (never the finished file: ``close``
    renames the ``.part`` only once every band is written)."""
    fh.close()
    tmp.unlink(missing_ok=True)


def coefficient_ranges(
    coefficients: NDArray[Any], margin: float = 0.0, scale: float = DISPLAY_SCALE
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Per-coefficient (lo, hi) of coefficients (p, ...) in display units (× ``scale``: a
    writer's ``display_scale``), widened by ``margin`` × the range on each side (for ranges
    taken from a sample)."""
    c = np.asarray(coefficients, dtype=np.float64).reshape(coefficients.shape[0], -1)
    c = c * scale
    lo, hi = np.nanmin(c, axis=1), np.nanmax(c, axis=1)
    pad = (hi - lo) * margin
    return lo - pad, hi + pad


def write_ptm_rgb(path: Path, coefficients: NDArray[Any]) -> Path:
    """Write PTM coefficients (6, H, W[, 3]) in Malzbender order as ``PTM_FORMAT_RGB``."""
    c = np.asarray(coefficients)
    if c.shape[0] != 6:
        raise ReconstructionError(f"a PTM has 6 coefficients, got {c.shape[0]}")
    writer = PtmWriter(path, c.shape[2], c.shape[1], *coefficient_ranges(c))
    writer.write_rows(0, c)
    return writer.close()


def write_hsh_rti(path: Path, coefficients: NDArray[Any]) -> Path:
    """Write HSH coefficients (terms, H, W[, 3]) in ``.rti`` index order as an HSH ``.rti``."""
    c = np.asarray(coefficients)
    ranges = coefficient_ranges(c, scale=RtiWriter.display_scale)
    writer = RtiWriter(path, c.shape[2], c.shape[1], *ranges)
    writer.write_rows(0, c)
    return writer.close()


def relight_listing_order(image_names: Sequence[str]) -> list[int]:
    """Indices of ``image_names`` (file names) in the order relight lists a folder's images.

    relightlab's ``Project::scanDir`` (cnr-isti-vclab/relight ``src/project.cpp``) lists the
    folder's ``*.jpg`` with a ``QDir``, whose default sort is ``Name | IgnoreCase``: by the
    lower-cased file name (the name itself breaking ties); its ``DomePanel::loadDome``
    (``relightlab/domepanel.cpp``) then gives image ``i`` the dome's direction ``i``.

    The names are compared as Qt compares them (:func:`~rti_rig.core.qt_names.qt_name_key`).
    Why: by code points and ``str.lower``, an emoji-named image had been listed after a
    full-width ``ｉmg`` one and ``ΑΣ_1.jpg`` before ``ασ.jpg``, where relight lists them the
    other way round: those images had been given each other's lights in relight.
    """
    return sorted(range(len(image_names)), key=lambda i: qt_name_key(image_names[i]))


def write_relight_dome(
    path: Path,
    directions: ArrayLike,
    *,
    diameter_cm: float | None = None,
    image_width_cm: float | None = None,
    label: str = "",
    image_names: Sequence[str] | None = None,
) -> Path:
    """relight's ``.dome`` JSON for these light ``directions`` (N, 3), z up, y to image top.

    With ``image_names`` (the file name of each direction's image), the directions are written
    in :func:`relight_listing_order`: relight pairs a dome's directions with the images by
    position only, so an acquisition listed in another order (``img1.jpg`` … ``img10.jpg``
    in shooting order, which relight lists ``img1``, ``img10``, ``img11``, …, ``img2``) had
    been given the wrong lights in relight without a word, where its ``.lp`` (paired by name)
    gave the right ones.
    """
    d = np.asarray(directions, dtype=np.float64).reshape(-1, 3)
    if image_names is not None:
        if len(image_names) != len(d):
            raise ReconstructionError(
                f"{len(image_names)} image names for {len(d)} light directions"
            )
        d = d[relight_listing_order(image_names)]
    diameter = float(diameter_cm) if diameter_cm else 0.0
    doc: dict[str, Any] = {
        "label": label,
        "notes": "written by rti-rig",
        "imageWidth": float(image_width_cm) if image_width_cm else 0.0,
        "domeDiameter": diameter,
        "diameter": diameter,  # the key relight's format page names
        "verticalOffset": 0.0,
        "lightConfiguration": "directional",
        "directions": [
            {"x": round(float(x), 6), "y": round(float(y), 6), "z": round(float(z), 6)}
            for x, y, z in d
        ],
    }
    path.write_text(json.dumps(doc, indent=1) + "\n", encoding="utf-8")
    return path


def _drop_pages(array: Any) -> None:
    """For a file-backed (memmap) map: drop the pages read so far from the resident set."""
    mm = getattr(array, "_mmap", None)
    if mm is not None and hasattr(mm, "madvise") and hasattr(mmap, "MADV_DONTNEED"):
        if getattr(array, "mode", "r") != "r":
            array.flush()
        mm.madvise(mmap.MADV_DONTNEED)


def _not_written(png: Path) -> str:
    """The refusal of a map OpenCV did not write: the file as a word that pastes (through
    :func:`shown_path`: a folder named in Latin-1 had been said with Python's lone surrogate,
    ``caf\\udce9``, which no shell reads back), and what to check. OpenCV says a failed write
    only by its return value, so no reason can be given."""
    return (
        f"could not write {shown_path(png)}: check the free space and that the folder is "
        "writable, then run again"
    )


#: Rows of a map converted at a time for its PNG: the float temporaries (and the file-backed
#: pages of a memmapped map, dropped after each chunk) stay around 1.5 MB at 2.5 MP instead of
#: 12 MB each; the result does not depend on it (every pixel is converted on its own).
ENCODE_ROWS = 64


def write_normal_map(stem: Path, normals: NDArray[Any], npy: bool = True) -> list[Path]:
    """``stem.png`` (16-bit RGB, ``(n + 1) / 2``) and ``stem.npy`` (float32 (H, W, 3)); with
    ``npy=False`` the ``.npy`` is taken to exist already (a memmap the fit wrote into)."""
    png = stem.with_suffix(".png")
    enc = np.empty(np.shape(normals), dtype=np.uint16)  # BGR, as OpenCV writes it: no copy
    for top in range(0, enc.shape[0], ENCODE_ROWS):  # bounded temporaries for large maps
        n = np.asarray(normals[top : top + ENCODE_ROWS], dtype=np.float32)
        enc[top : top + ENCODE_ROWS] = np.clip(
            np.round((n[..., ::-1] + 1.0) * 0.5 * 65535.0), 0, 65535
        )
        _drop_pages(normals)
    if not opencv_files.imwrite(png, enc):
        raise ReconstructionError(_not_written(png))
    path = stem.with_suffix(".npy")
    if npy:
        np.save(path, np.asarray(normals, dtype=np.float32))
    return [png, path]


def write_albedo(
    stem: Path, albedo: NDArray[Any], white: float = 1.0, npy: bool = True
) -> list[Path]:
    """``stem.png`` (16-bit, linear, white = ``white``) and ``stem.npy`` (float32)."""
    png = stem.with_suffix(".png")
    enc = np.empty(np.shape(albedo), dtype=np.uint16)  # BGR for colour, as OpenCV writes it
    for top in range(0, enc.shape[0], ENCODE_ROWS):
        a = np.asarray(albedo[top : top + ENCODE_ROWS], dtype=np.float32)
        if a.ndim == 3:
            a = a[..., ::-1]
        enc[top : top + ENCODE_ROWS] = np.clip(np.round(a / white * 65535.0), 0, 65535)
        _drop_pages(albedo)
    if not opencv_files.imwrite(png, enc):
        raise ReconstructionError(_not_written(png))
    path = stem.with_suffix(".npy")
    if npy:
        np.save(path, np.asarray(albedo, dtype=np.float32))
    return [png, path]
