"""Row tiles: how a reconstruction streams through an acquisition in bounded memory.

Every model here is fitted per pixel, independently, so an acquisition can be processed a band
of rows at a time. A 24-megapixel, 100-light stack is 9.6 GB as float32; a band of 64 rows of a
6000-pixel-wide image across 100 lights is 150 MB. Only the band is ever converted to float.
"""

from __future__ import annotations

from collections.abc import Iterator

#: Default working-set budget for one band of the stack, in bytes (float32 copy of the band).
DEFAULT_TILE_BUDGET_BYTES = 256 * 1024 * 1024


def rows_for_budget(
    n_images: int, width: int, channels: int, budget_bytes: int = DEFAULT_TILE_BUDGET_BYTES
) -> int:
    """Rows per band so that one float32 band of all images stays within ``budget_bytes``.

    The fit needs a few more arrays of the band's size (residuals, masks), so the budget is the
    band itself and the peak is a small multiple of it; never fewer than one row.
    """
    per_row = max(1, n_images * width * channels * 4)
    return max(1, budget_bytes // per_row)


def row_tiles(height: int, tile_rows: int) -> Iterator[slice]:
    """Consecutive row slices of at most ``tile_rows`` rows covering ``range(height)``."""
    if tile_rows < 1:
        raise ValueError(f"tile_rows must be at least 1, got {tile_rows}")
    for start in range(0, height, tile_rows):
        yield slice(start, min(height, start + tile_rows))
