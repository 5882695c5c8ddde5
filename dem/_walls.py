r"""Container walls: infinite planes and an inner cylinder about the z axis, vectorised.

Every wall returns, for the particles it touches, the particle index, the overlap
δ = r − (distance from centre to wall) > 0 and the unit normal pointing from the
particle towards the wall (the same convention as particle–particle contacts, so one
contact law serves both). The whole container may move vertically by ``z_offset``
(vibration, thesis Eq. 3.11); wall velocities enter the contact's relative velocity.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["PlaneWall", "CylinderWall", "wall_contacts"]


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


def wall_contacts(walls, centers_t, radii, z_offset=0.0):
    """Contacts of N spheres with a list of walls.

    Parameters
    ----------
    walls : sequence of PlaneWall | CylinderWall
    centers_t : (3, N) array, m
        Centres, component-first.
    radii : (N,) array, m
    z_offset : float, m
        Vertical displacement of the moving walls.

    Returns
    -------
    wall_index : (Nw,) int
    particle : (Nw,) int
    overlap : (Nw,) array, m
    normal : (3, Nw) array
        Unit vector from the particle centre towards the wall.
    moves : (Nw,) bool
        Whether the wall of this contact follows the container motion.
    """
    w_idx, p_idx, ov, nrm, mv = [], [], [], [], []
    x, y, z = centers_t
    for k, wall in enumerate(walls):
        if isinstance(wall, PlaneWall):
            p = np.asarray(wall.point_m, dtype=float).copy()
            if wall.moves:
                p[2] += z_offset
            n = np.asarray(wall.normal, dtype=float)
            dist = -float(p @ n)
            for c, comp in zip(n, (x, y, z)):
                if c != 0.0:
                    dist = dist + c * comp
            o = radii - dist
            hit = np.flatnonzero(o > 0.0)
            normals = np.repeat(-n[:, None], len(hit), axis=1)
        elif isinstance(wall, CylinderWall):
            cx, cy = wall.center_xy_m
            dx = x - cx
            dy = y - cy
            rho = np.sqrt(dx * dx + dy * dy)
            o = radii - (wall.radius_m - rho)
            hit = np.flatnonzero(o > 0.0)
            rh = np.maximum(rho[hit], 1e-300)
            normals = np.stack([dx[hit] / rh, dy[hit] / rh, np.zeros(len(hit))])
        else:
            raise TypeError(f"unknown wall type {type(wall).__name__}")
        w_idx.append(np.full(len(hit), k, dtype=np.int64))
        p_idx.append(hit)
        ov.append(o[hit])
        nrm.append(normals)
        mv.append(np.full(len(hit), wall.moves))
    if not walls:
        e = np.empty(0)
        return np.empty(0, np.int64), np.empty(0, np.int64), e, np.empty((3, 0)), np.empty(0, bool)
    return (
        np.concatenate(w_idx),
        np.concatenate(p_idx),
        np.concatenate(ov),
        np.concatenate(nrm, axis=1),
        np.concatenate(mv),
    )
