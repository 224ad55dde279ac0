"""The colour scale of RP_l maps: viridis between a stated minimum and maximum [µm]."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from matplotlib import colormaps

#: colour of map points whose value is NaN (target unreachable), RGB in [0, 1].
UNREACHABLE_RGB = (0.62, 0.62, 0.62)


@dataclass(frozen=True)
class ColourScale:
    """Viridis from ``low_um`` (dark purple) to ``high_um`` (yellow); NaN is grey."""

    low_um: float
    high_um: float
    name: str = "viridis"

    @classmethod
    def spanning(cls, *values_um: np.ndarray) -> ColourScale:
        """The scale from the smallest to the largest finite value of ``values_um`` (0–1 µm if none)."""
        finite = np.concatenate([np.ravel(v)[np.isfinite(np.ravel(v))] for v in values_um] + [np.empty(0)])
        if finite.size == 0:
            return cls(0.0, 1.0)
        return cls(float(finite.min()), float(finite.max()))

    def rgb(self, values_um: np.ndarray) -> np.ndarray:
        """(N, 3) colours in [0, 1] of ``values_um`` (N,); NaN gives :data:`UNREACHABLE_RGB`."""
        values = np.asarray(values_um, dtype=float)
        span = self.high_um - self.low_um
        fraction = np.clip((values - self.low_um) / span, 0, 1) if span > 0 else np.full(values.shape, 0.5)
        colours = colormaps[self.name](np.nan_to_num(fraction))[:, :3]
        colours[~np.isfinite(values)] = UNREACHABLE_RGB
        return colours

    def css_gradient(self, stops: int = 11) -> str:
        """A CSS ``linear-gradient`` from low (left) to high (right), for a colour bar."""
        fractions = np.linspace(0, 1, stops)
        colours = colormaps[self.name](fractions)[:, :3]
        parts = [f"rgb({r * 255:.0f},{g * 255:.0f},{b * 255:.0f}) {f * 100:.0f}%"
                 for (r, g, b), f in zip(colours, fractions, strict=True)]
        return f"linear-gradient(to right, {', '.join(parts)})"
