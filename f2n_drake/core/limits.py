"""What a run accepts before it starts the work: a building's size, and a drawing that fits in
memory.

A drawing at a scale that makes it smaller than ``MIN_PLAN_M`` or larger than ``MAX_PLAN_M``
across is no building (usually centimetres typed for metres); it is refused with the scale that
was probably meant, before the planner grids it (at 5 m/px a 1000 px drawing would be a 5 km
planning grid of 2 cm cells). The memory a parse needs grows with the drawing's pixels
(``PARSE_BYTES_PER_PX``, measured: see docs/robustness.md); a drawing that needs more than the
machine has free is refused from its file header, before it is decoded.
"""

from __future__ import annotations

import math
import os

from f2n_drake.core.errors import InputError

MIN_PLAN_M = 2.0
"""Smallest building accepted, across its longer side [m]."""
MAX_PLAN_M = 2000.0
"""Largest building accepted, across its longer side [m]."""
TYPICAL_PLAN_M = 20.0
"""Size a suggested scale aims at [m]: a flat or a house."""

PARSE_BYTES_PER_PX = 90
"""Peak memory of ``python -m f2n_drake.run --no-sim`` per pixel of the drawing, above
``PARSE_BASE_BYTES`` (measured on drawings of 0.4 to 26 megapixels: 75 to 89 bytes a pixel;
docs/robustness.md)."""
PARSE_BASE_BYTES = 640 * 2**20
"""Peak memory of a run on a small drawing (Python, Drake, torch and the network) [bytes]."""

_UNITS = {
    0.01: "centimetres",
    0.001: "millimetres",
    0.0254: "inches",
    100.0: "metres per 100 px",
    1000.0: "metres per 1000 px",
}


def check_plan_extent(shape_px: tuple[int, int], metres_per_px: float, *, source: str) -> None:
    """Refuse a scale that makes a drawing of ``shape_px`` (rows, cols) no building's size.

    Args:
        source: where the scale came from, for the message (``"--scale 5"``, ``"the door-width
            estimate"``).

    Raises:
        InputError: non-finite or non-positive scale, or the drawing under ``MIN_PLAN_M`` or
            over ``MAX_PLAN_M`` across; the message suggests the scale probably meant.
    """
    if not (math.isfinite(metres_per_px) and metres_per_px > 0):
        raise InputError(f"{source}: the scale must be a positive number of metres per pixel")
    extent_m = max(shape_px) * metres_per_px
    if MIN_PLAN_M <= extent_m <= MAX_PLAN_M:
        return
    rows, cols = shape_px
    message = (
        f"{source} ({metres_per_px:g} m/px) makes this {cols}x{rows} px drawing "
        f"{_length(extent_m)} across; a building is {MIN_PLAN_M:g} m to "
        f"{MAX_PLAN_M / 1000:g} km across"
    )
    raise InputError(message + _suggestion(extent_m, metres_per_px, max(shape_px)))


def check_render_size(extent_m: float, metres_per_px: float, *, max_side_px: int) -> None:
    """Refuse drawing a plan ``extent_m`` across at ``metres_per_px`` on more than
    ``max_side_px`` pixels a side, or fewer than 16 (vector input rendered at ``--scale``).

    Raises:
        InputError: as described, naming the scale range that works.
    """
    side = extent_m / metres_per_px if metres_per_px > 0 else math.inf
    if 16 <= side <= max_side_px:
        return
    low, high = extent_m / max_side_px, extent_m / 16
    raise InputError(
        f"--scale {metres_per_px:g} m/px would draw this {extent_m:.1f} m plan "
        f"{side:,.0f} px across; give a scale of {low:.3g} to {high:.3g} m/px "
        f"(about {extent_m / 1000:.3g} m/px draws it 1000 px across)"
    )


def _suggestion(extent_m: float, metres_per_px: float, side_px: int) -> str:
    best = None
    for factor, unit in _UNITS.items():
        size = extent_m * factor
        if 5.0 <= size <= 500.0:
            score = abs(math.log(size / TYPICAL_PLAN_M))
            if best is None or score < best[0]:
                best = (score, factor, unit)
    if best is not None:
        _, factor, unit = best
        meant = metres_per_px * factor
        what = f"{metres_per_px:g} {unit} per pixel" if factor < 1 else f"a scale in {unit}"
        return f". Did you mean --scale {meant:.4g} ({what}: {_length(extent_m * factor)} across)?"
    return (
        f". Give --scale in metres per pixel: for a {TYPICAL_PLAN_M:g} m flat drawn "
        f"{side_px} px across, about {TYPICAL_PLAN_M / side_px:.3g}"
    )


def _length(metres: float) -> str:
    if metres >= 1000:
        return f"{metres / 1000:,.3g} km"
    if metres >= 1:
        return f"{metres:.3g} m"
    return f"{metres * 100:.3g} cm"


def parse_memory_bytes(shape_px: tuple[int, int]) -> int:
    """Estimated peak memory [bytes] of a run on a drawing of ``shape_px`` (rows, cols)."""
    return int(PARSE_BASE_BYTES + PARSE_BYTES_PER_PX * shape_px[0] * shape_px[1])


def available_memory_bytes() -> int | None:
    """Memory the system can give without swapping (``MemAvailable``), None if unknown."""
    try:
        with open("/proc/meminfo") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    try:
        return os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (ValueError, OSError, AttributeError):
        return None


def check_parse_memory(shape_px: tuple[int, int], *, name: str) -> None:
    """Refuse a drawing whose parse would need more memory than is free.

    Raises:
        InputError: the estimate (``parse_memory_bytes``) exceeds ``available_memory_bytes``;
            the message gives both and the largest size that fits.
    """
    need = parse_memory_bytes(shape_px)
    free = available_memory_bytes()
    if free is None or need <= free:
        return
    rows, cols = shape_px
    fits = max(0, free - PARSE_BASE_BYTES) / PARSE_BYTES_PER_PX
    side = int(math.sqrt(fits * max(rows, cols) / max(min(rows, cols), 1)))
    raise InputError(
        f"{name} is {cols}x{rows} px; parsing it needs about {need / 2**30:.1f} GiB of memory "
        f"and {free / 2**30:.1f} GiB is free. Downscale it to at most {side} px on its long "
        f"side (1000 to 2000 px is plenty for a flat)"
    )
