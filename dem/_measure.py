r"""Porosity and coordination measurements on sphere packings.

* Local porosity in measurement spheres (thesis B1–B5, PFC3D ``measure``): exact
  sphere–sphere lens volumes.
* Porosity of a box or vertical cylinder region: the project's one estimator,
  :func:`network.core.region_porosity` (exact sphere-region volumes, overlapping pairs'
  lenses counted once), on the region as :class:`network.core.Region` (:meth:`Region.to_core`).
* Coordination numbers: neighbours within a cutoff distance (thesis: 1.05 d_max) and
  true contacts (overlap > −tol).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from network.core import Packing, region_porosity
from network.core import Region as CoreRegion

__all__ = [
    "Region",
    "lens_volume",
    "porosity_in_spheres",
    "porosity_in_region",
    "coordination_numbers",
    "sphere_volume",
]


def sphere_volume(radii):
    """Volume 4/3 π r³ of each sphere, m³."""
    return 4.0 / 3.0 * np.pi * np.asarray(radii, dtype=float) ** 3


def lens_volume(big_r, small_r, dist):
    r"""Intersection volume of spheres of radii R and r whose centres are ``dist`` apart, m³.

    .. math:: V = \frac{\pi (R + r - d)^2 (d^2 + 2dr - 3r^2 + 2dR + 6rR - 3R^2)}{12 d}

    for |R − r| < d < R + r; the smaller sphere's volume when one contains the other;
    0 when they are apart.

    >>> round(float(lens_volume(1.0, 1.0, 1.0) / (5 * np.pi / 12)), 12)
    1.0
    """
    R = np.asarray(big_r, dtype=float)
    r = np.asarray(small_r, dtype=float)
    d = np.asarray(dist, dtype=float)
    R, r, d = np.broadcast_arrays(R, r, d)
    out = np.zeros(d.shape)
    inside = d <= np.abs(R - r)
    out[inside] = sphere_volume(np.minimum(R, r)[inside])
    part = (~inside) & (d < R + r)
    Rp, rp, dp = R[part], r[part], d[part]
    out[part] = (
        np.pi * (Rp + rp - dp) ** 2
        * (dp**2 + 2 * dp * rp - 3 * rp**2 + 2 * dp * Rp + 6 * rp * Rp - 3 * Rp**2)
        / (12 * dp)
    )
    return out


def porosity_in_spheres(centers, radii, sphere_centers, sphere_radius):
    """Porosity inside each measurement sphere (thesis B1–B5 style), shape (M,).

    Parameters
    ----------
    centers : (N, 3) array, m
    radii : (N,) array, m
    sphere_centers : (M, 3) array, m
    sphere_radius : float or (M,) array, m
    """
    centers = np.asarray(centers, dtype=float)
    radii = np.asarray(radii, dtype=float)
    sc = np.atleast_2d(np.asarray(sphere_centers, dtype=float))
    sr = np.broadcast_to(np.asarray(sphere_radius, dtype=float), (len(sc),))
    tree = cKDTree(centers)
    out = np.empty(len(sc))
    for k in range(len(sc)):  # a handful of measurement spheres
        idx = np.asarray(tree.query_ball_point(sc[k], sr[k] + radii.max()), dtype=np.int64)
        if len(idx) == 0:
            out[k] = 1.0
            continue
        d = np.linalg.norm(centers[idx] - sc[k], axis=1)
        solid = lens_volume(sr[k], radii[idx], d).sum()
        out[k] = 1.0 - solid / sphere_volume(sr[k])
    return out


@dataclass(frozen=True)
class Region:
    """Box ``lo``–``hi`` or vertical cylinder (``radius`` about ``center_xy``, z in lo[2]–hi[2])."""

    kind: str
    lo: tuple
    hi: tuple
    radius: float = 0.0
    center_xy: tuple = (0.0, 0.0)

    def __post_init__(self):
        if self.kind not in ("box", "cylinder"):
            raise ValueError(f"region kind must be 'box' or 'cylinder', got {self.kind!r}")
        if not np.all(np.asarray(self.hi, float)[2:] > np.asarray(self.lo, float)[2:]):
            raise ValueError(f"empty region {self.lo}–{self.hi}")

    @property
    def volume(self):
        lo, hi = np.asarray(self.lo, float), np.asarray(self.hi, float)
        if self.kind == "box":
            return float(np.prod(hi - lo))
        return float(np.pi * self.radius**2 * (hi[2] - lo[2]))

    def signed_distance(self, p):
        """Distance from points (…, 3) to the region boundary, positive inside."""
        lo, hi = np.asarray(self.lo, float), np.asarray(self.hi, float)
        dz = np.minimum(p[..., 2] - lo[2], hi[2] - p[..., 2])
        if self.kind == "box":
            dxy = np.minimum(
                np.minimum(p[..., 0] - lo[0], hi[0] - p[..., 0]),
                np.minimum(p[..., 1] - lo[1], hi[1] - p[..., 1]),
            )
        else:
            rho = np.hypot(p[..., 0] - self.center_xy[0], p[..., 1] - self.center_xy[1])
            dxy = self.radius - rho
        return np.minimum(dxy, dz)

    def to_core(self) -> CoreRegion:
        """The same region as the project's :class:`network.core.Region` (a cylinder along z
        about ``center_xy``)."""
        lo, hi = np.asarray(self.lo, float), np.asarray(self.hi, float)
        if self.kind == "box":
            return CoreRegion(lo, hi)
        cx, cy, rad = float(self.center_xy[0]), float(self.center_xy[1]), float(self.radius)
        return CoreRegion([cx - rad, cy - rad, lo[2]], [cx + rad, cy + rad, hi[2]], radius=rad)

    def to_dict(self):
        return {"kind": self.kind, "lo": list(map(float, self.lo)), "hi": list(map(float, self.hi)),
                "radius": float(self.radius), "center_xy": list(map(float, self.center_xy))}


def porosity_in_region(centers, radii, region):
    """Porosity of a Region, 1 − (solid volume inside)/(region volume): the project's one
    estimator, :func:`network.core.region_porosity` (exact volumes of the spheres the region
    cuts, overlapping pairs' lenses counted once), along z."""
    packing = Packing(np.asarray(centers, dtype=float), np.asarray(radii, dtype=float))
    return region_porosity(packing, region.to_core(), 2)[0]


#: relative distance within which two spheres touch for :func:`coordination_numbers`: spheres
#: placed touching (a lattice written to a file) land within rounding of r_i + r_j, either side
CONTACT_RTOL = 1e-9


def coordination_numbers(centers, radii, *, cutoff_m=None, contact_tol_m=0.0, select=None):
    """Coordination number of each selected particle.

    Parameters
    ----------
    centers : (N, 3) array, m
    radii : (N,) array, m
    cutoff_m : float, optional
        Count neighbours whose centre distance is below this (thesis: 1.05 d_max).
        If None, count true contacts: distance < (r_i + r_j)(1 + :data:`CONTACT_RTOL`)
        + contact_tol_m (touching to rounding counts: a file's simple cubic lattice gives 6).
    select : (N,) bool array, optional
        Particles whose coordination is returned (neighbours are counted among all).

    Returns
    -------
    (n_selected,) int array
    """
    centers = np.asarray(centers, dtype=float)
    radii = np.asarray(radii, dtype=float)
    n = len(radii)
    reach = (cutoff_m if cutoff_m is not None
             else 2 * radii.max() * (1 + CONTACT_RTOL) + contact_tol_m)
    pairs = cKDTree(centers).query_pairs(reach, output_type="ndarray")
    if cutoff_m is None and len(pairs):
        i, j = pairs[:, 0], pairs[:, 1]
        d = np.linalg.norm(centers[j] - centers[i], axis=1)
        pairs = pairs[d < (radii[i] + radii[j]) * (1 + CONTACT_RTOL) + contact_tol_m]
    z = np.bincount(pairs.ravel(), minlength=n)
    return z if select is None else z[select]
