"""Sample regions: a box, or a cylinder along the flow axis, in metres (the shape every
porosity and every sample of the project is measured in; ``dem`` describes its vertical
measurement regions with it too).
"""

from __future__ import annotations

import dataclasses

import numpy as np

__all__ = ["AXES", "Region", "axis_index"]

AXES = {"x": 0, "y": 1, "z": 2}


def axis_index(axis) -> int:
    """Axis number 0, 1, 2 of ``'x'``, ``'y'``, ``'z'`` (any case) or of 0, 1, 2; else ValueError."""
    if isinstance(axis, str) and axis.lower() in AXES:
        return AXES[axis.lower()]
    if isinstance(axis, (int, np.integer)) and 0 <= int(axis) <= 2:
        return int(axis)
    raise ValueError(f"axis must be one of 'x', 'y', 'z' (or 0, 1, 2), got {axis!r}")


@dataclasses.dataclass(frozen=True)
class Region:
    """A box (``lo``, ``hi`` (3,) m) or, when ``radius`` is set, a cylinder.

    The cylinder's axis is the flow axis; it spans ``lo[axis]``–``hi[axis]`` and is centred on
    the middle of the box's lateral extent, with radius ``radius`` (m).
    """

    lo: np.ndarray
    hi: np.ndarray
    radius: float | None = None

    def __post_init__(self):
        lo = np.asarray(self.lo, dtype=float)
        hi = np.asarray(self.hi, dtype=float)
        if lo.shape != (3,) or hi.shape != (3,):
            raise ValueError(f"region bounds must be 3 numbers each, got {lo.shape}, {hi.shape}")
        if not np.all(np.isfinite(lo)) or not np.all(np.isfinite(hi)) or np.any(hi <= lo):
            raise ValueError(f"region needs lo < hi on every axis, got lo={lo}, hi={hi}")
        if self.radius is not None and not self.radius > 0:
            raise ValueError(f"cylinder radius must be > 0, got {self.radius!r}")
        object.__setattr__(self, "lo", lo)
        object.__setattr__(self, "hi", hi)

    def contains(self, pts, axis: int) -> np.ndarray:
        """(N,) bool: points inside the region (cylinder along ``axis`` if a radius is set)."""
        pts = np.asarray(pts)
        s = pts[:, axis]
        inside = (s >= self.lo[axis]) & (s <= self.hi[axis])
        lat = [k for k in range(3) if k != axis]
        if self.radius is None:
            for k in lat:
                inside &= (pts[:, k] >= self.lo[k]) & (pts[:, k] <= self.hi[k])
        else:
            c = 0.5 * (self.lo[lat] + self.hi[lat])
            inside &= np.sum((pts[:, lat] - c) ** 2, axis=1) <= self.radius**2
        return inside

    def cross_section(self, axis: int) -> float:
        """Area normal to ``axis``, m²."""
        if self.radius is not None:
            return float(np.pi * self.radius**2)
        lat = [k for k in range(3) if k != axis]
        return float(np.prod(self.hi[lat] - self.lo[lat]))
