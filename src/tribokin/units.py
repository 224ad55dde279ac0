"""Units at the edges: SI inside, micrometres and millidegrees in reports, bytes for people."""

from __future__ import annotations

import math

#: Micrometres per metre and millidegrees per radian: reports' units (``_um``, ``_mdeg`` in names).
UM_PER_M = 1e6
MDEG_PER_RAD = 180e3 / math.pi


def um(value_m: float | None) -> float | None:
    """``value_m`` [m] in micrometres as a plain float, ``None`` kept (a figure that could not be computed)."""
    return None if value_m is None else float(value_m * UM_PER_M)


def gib(size: float) -> str:
    """``size`` [bytes] for people: ``"48 GiB"``, ``"310 MiB"``."""
    for unit, scale in (("TiB", 2 ** 40), ("GiB", 2 ** 30), ("MiB", 2 ** 20)):
        if size >= scale:
            value = size / scale
            return f"{value:.0f} {unit}" if value >= 100 else f"{value:.3g} {unit}"
    return f"{size / 2 ** 20:.2g} MiB"
