r"""Container walls: infinite planes and an inner cylinder about the z axis.

A wall touches a particle when the overlap δ = r − (distance from centre to wall) > 0; the
contact normal points from the particle towards the wall (the same convention as
particle–particle contacts, so one contact law serves both; the contacts are found in
:func:`dem._kernels.particle_update`). The whole container may move vertically by ``z_offset``
(vibration, thesis Eq. 3.11); wall velocities enter the contact's relative velocity.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["PlaneWall", "CylinderWall"]


@dataclass(frozen=True)
class PlaneWall:
    """Infinite plane through ``point_m`` whose unit ``normal`` points into the container.

    ``moves`` says whether the plane follows the container's vertical motion (floor, side
    walls) or stays fixed (a lid).
    """

    point_m: tuple
    normal: tuple
    name: str = "plane"
    moves: bool = True

    def __post_init__(self):
        n = np.asarray(self.normal, dtype=float)
        if n.shape != (3,) or not np.isclose(np.linalg.norm(n), 1.0):
            raise ValueError(f"plane normal must be a unit 3-vector, got {self.normal}")
        if np.asarray(self.point_m, dtype=float).shape != (3,):
            raise ValueError(f"plane point must be a 3-vector, got {self.point_m}")


@dataclass(frozen=True)
class CylinderWall:
    """Inner surface of a vertical cylinder of radius ``radius_m`` about (cx, cy)."""

    radius_m: float
    center_xy_m: tuple = (0.0, 0.0)
    name: str = "cylinder"
    moves: bool = True

    def __post_init__(self):
        if not self.radius_m > 0:
            raise ValueError(f"cylinder radius must be positive, got {self.radius_m}")
