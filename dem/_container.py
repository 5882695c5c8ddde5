r"""Containers: the thesis's bins, the scene defaults and the walls a simulation gets.

A :class:`Container` is a box or a vertical cylinder with its floor at z = 0, centred on the
z axis; :data:`SCENES` names the thesis's two bins (Appendix A rectangular bin, Appendices B–C
cylinder) and :data:`SCENE_DEFAULTS` the packing options each uses (measurements behind the
choice: ``docs/dem-packing.md``). :func:`default_measure_spheres` places the B1–B5 measurement
spheres of Appendix C; :func:`make_simulation` builds a :class:`~dem._integrate.Simulation`
inside a container's walls.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._integrate import Simulation
from ._material import SOYBEAN
from ._measure import Region
from ._walls import CylinderWall, PlaneWall

__all__ = [
    "Container",
    "SCENES",
    "SCENE_DEFAULTS",
    "scene_container",
    "default_measure_spheres",
    "make_simulation",
]


@dataclass(frozen=True)
class Container:
    """A bin with its floor at z = 0, centred on the z axis.

    ``kind`` 'box': ``size_m`` = (length_x, width_y); 'cylinder': ``size_m`` = (diameter,).
    ``fill_height_m`` is the height the bed is filled to (lid height during expansion).
    """

    kind: str
    size_m: tuple
    fill_height_m: float

    def __post_init__(self):
        if self.kind not in ("box", "cylinder"):
            raise ValueError(f"container kind must be 'box' or 'cylinder', got {self.kind!r}")
        need = 2 if self.kind == "box" else 1
        if len(self.size_m) != need:
            raise ValueError(f"{self.kind} needs {need} size value(s), got {self.size_m}")
        dims = (*self.size_m, self.fill_height_m)
        if not all(np.isfinite(d) and d > 0 for d in dims):
            raise ValueError(f"container dimensions must be finite and positive, got "
                             f"{tuple(float(d) for d in self.size_m)}, {float(self.fill_height_m)}")

    @property
    def area_m2(self):
        if self.kind == "box":
            return float(self.size_m[0] * self.size_m[1])
        return float(np.pi * self.size_m[0] ** 2 / 4)

    @property
    def volume_m3(self):
        return self.area_m2 * self.fill_height_m

    @property
    def min_dimension_m(self):
        return float(min(min(self.size_m), self.fill_height_m))

    def walls(self, *, lid=True, lid_height_m=None):
        """Wall list: side walls and floor move with the container; the lid (at the fill
        height unless ``lid_height_m`` is given) is fixed."""
        h = self.fill_height_m if lid_height_m is None else float(lid_height_m)
        if self.kind == "box":
            lx, ly = self.size_m
            walls = [
                PlaneWall((-lx / 2, 0, 0), (1, 0, 0), "x-"),
                PlaneWall((lx / 2, 0, 0), (-1, 0, 0), "x+"),
                PlaneWall((0, -ly / 2, 0), (0, 1, 0), "y-"),
                PlaneWall((0, ly / 2, 0), (0, -1, 0), "y+"),
            ]
        else:
            walls = [CylinderWall(self.size_m[0] / 2, (0.0, 0.0), "cylinder")]
        walls.append(PlaneWall((0, 0, 0), (0, 0, 1), "floor"))
        if lid:
            walls.append(PlaneWall((0, 0, h), (0, 0, -1), "lid", moves=False))
        return walls

    def bounds(self, r_max, *, headroom=1.0):
        """Box every centre must stay in (escape detection)."""
        h = self.fill_height_m
        if self.kind == "box":
            lx, ly = self.size_m
            half = np.array([lx / 2, ly / 2])
        else:
            half = np.array([self.size_m[0] / 2] * 2)
        lo = np.array([-half[0] - r_max, -half[1] - r_max, -r_max - 0.02])
        hi = np.array([half[0] + r_max, half[1] + r_max, h * (1 + headroom) + 0.05])
        return np.array([lo, hi])

    def interior(self, margin_m, top_m):
        """Region at least ``margin_m`` from the side walls (x only for a slab: y thinner than
        4 margins and than half of x, as the thesis's rect-bin), the floor and the bed top
        ``top_m``."""
        z = (margin_m, top_m - margin_m)
        if self.kind == "box":
            lx, ly = self.size_m
            slab = ly <= 4 * margin_m and (ly < 0.5 * lx or ly <= 2 * margin_m)
            my = 0.0 if slab else margin_m     # a small square box keeps its y margin too
            return Region("box", (-lx / 2 + margin_m, -ly / 2 + my, z[0]), (lx / 2 - margin_m, ly / 2 - my, z[1]))
        return Region("cylinder", (0, 0, z[0]), (0, 0, z[1]), radius=self.size_m[0] / 2 - margin_m)

    def sample_centers(self, radii, rng):
        """Uniform random centres such that each sphere lies inside the closed container."""
        h = self.fill_height_m
        z = rng.uniform(radii, h - radii)
        if self.kind == "box":
            lx, ly = self.size_m
            x = rng.uniform(-lx / 2 + radii, lx / 2 - radii)
            y = rng.uniform(-ly / 2 + radii, ly / 2 - radii)
        else:
            rad = self.size_m[0] / 2 - radii
            rho = rad * np.sqrt(rng.uniform(0, 1, len(radii)))
            phi = rng.uniform(0, 2 * np.pi, len(radii))
            x, y = rho * np.cos(phi), rho * np.sin(phi)
        return np.column_stack([x, y, z])

    def to_dict(self):
        return {"kind": self.kind, "size_m": list(map(float, self.size_m)), "fill_height_m": float(self.fill_height_m)}

    @classmethod
    def from_dict(cls, d):
        """The container of a packing's JSON summary; ValueError when an entry is missing or
        not a number, or the kind is not 'box' or 'cylinder' (checked by the constructor)."""
        try:
            return cls(str(d["kind"]).lower(), tuple(float(v) for v in np.atleast_1d(d["size_m"])),
                       float(d["fill_height_m"]))
        except (KeyError, TypeError, ValueError) as e:
            raise ValueError(f"the summary's container {d!r} is not a box or cylinder with size_m and "
                             f"fill_height_m (m): {e}") from e


#: The thesis's bins: Appendix A (rectangular, 0.25 × 0.02 m, filled to 0.25 m) and
#: Appendices B–C (cylinder 0.15 m in diameter, filled to 0.25 m).
SCENES = {
    "rect-bin": Container("box", (0.25, 0.02), 0.25),
    "cyl-bin": Container("cylinder", (0.15,), 0.25),
}


#: Packing options each named scene uses by default (``python -m dem.pack --scene NAME``); the
#: measurements behind the rect-bin choice are in ``docs/dem-packing.md``.
SCENE_DEFAULTS = {
    "rect-bin": dict(procedure="sediment", lid_headroom=0.3, sediment_steps=3000, tap_freq_hz=30.0,
                     tap_amplitude_m=1.6e-3, tap_duration_s=0.6, tap_decay=True),
    "cyl-bin": dict(procedure="lid", lid_headroom=0.2),
}


def scene_container(name):
    """Container of a named scene ('rect-bin' | 'cyl-bin')."""
    try:
        return SCENES[name]
    except KeyError:
        raise ValueError(f"unknown scene {name!r}; choose from {sorted(SCENES)} or 'box'/'cylinder'") from None


def default_measure_spheres(container):
    """Thesis B1–B5 measurement spheres (Appendix C: x = 3/7·width, radius width/14).

    For a box the sphere radius is capped at 0.99 × half the thinner side so it stays inside.
    """
    zs = np.array([0.119, 0.129, 0.130, 0.136, 0.146]) * container.fill_height_m / 0.25
    if container.kind == "cylinder":
        w = container.size_m[0]
        r = w / 14.0
        x = 3.0 / 7.0 * w
        x = min(x, w / 2 - r)
    else:
        r = min(0.15 / 14.0, 0.99 * min(container.size_m) / 2)
        x = min(0.0643, container.size_m[0] / 2 - r)
    centers = np.column_stack([np.full(5, x), np.zeros(5), zs])
    return centers, r


def make_simulation(container, centers, radii, *, material=SOYBEAN, lid=True, lid_height_m=None, **kw):
    """Simulation of spheres in a container's walls (lid optional), with escape bounds."""
    return Simulation(
        centers, radii, container.walls(lid=lid, lid_height_m=lid_height_m), material,
        bounds_m=container.bounds(material.radius_max_m * 1.2), **kw,
    )
