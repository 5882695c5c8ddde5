r"""Measurements of a finished packing, as JSON-ready summaries.

* :func:`surface_height`: the bed surface (median over columns of the highest sphere top).
* :func:`summarize`: global, interior and measurement-sphere porosities, coordination
  distributions and the diameter range of a packing.
* :func:`interior_porosity`, :func:`overlap_fractions`: the same measurements on a running
  :class:`~dem._integrate.Simulation` (packing stages report them).
"""

from __future__ import annotations

import numpy as np

from ._container import default_measure_spheres
from ._material import SOYBEAN
from ._measure import coordination_numbers, porosity_in_region, porosity_in_spheres, sphere_volume

__all__ = ["summarize", "surface_height", "interior_porosity", "overlap_fractions"]


def summarize(centers, radii, container, *, material=SOYBEAN, measure_spheres=None, interior_margin_m=None,
              coordination_box=None):
    """JSON-ready measurements of a packing (porosities, coordination distributions)."""
    centers = np.asarray(centers, float)
    radii = np.asarray(radii, float)
    vp = float(sphere_volume(radii).sum())
    top = float(np.max(centers[:, 2] + radii))
    rbar = 0.5 * (material.radius_min_m + material.radius_max_m)
    bhtf = float(np.max(centers[:, 2]) + rbar)
    dmean = float(2 * radii.mean())
    margin = interior_margin_m if interior_margin_m is not None else 2 * dmean
    # bed surface: mean top of the highest sphere in each column of the cross-section
    surface = surface_height(centers, radii, container)
    region = container.interior(margin, surface)
    if measure_spheres is None:
        measure_spheres = default_measure_spheres(container)
    mc, mr = measure_spheres
    local = porosity_in_spheres(centers, radii, mc, mr)
    dmax = float(2 * radii.max())
    if coordination_box is None:
        if container.kind == "box":
            lx, ly = container.size_m
            coordination_box = ((-min(0.05, lx / 2), -ly / 2, 0.02), (min(0.05, lx / 2), ly / 2, surface - 0.02))
        else:
            coordination_box = ((-0.05, -0.05, 0.02), (0.05, 0.05, surface - 0.02))
    lo, hi = map(np.asarray, coordination_box)
    sel = np.all((centers >= lo) & (centers <= hi), axis=1)
    z_cut = coordination_numbers(centers, radii, cutoff_m=1.05 * dmax, select=sel)
    z_true = coordination_numbers(centers, radii, contact_tol_m=0.0, select=sel)
    d_all = 2 * radii
    return {
        "n_spheres": int(len(radii)),
        "container": container.to_dict(),
        "solid_volume_m3": vp,
        "porosity_closed_volume": 1.0 - vp / container.volume_m3,
        "bed_height_max_m": top,
        "bed_height_surface_m": surface,
        "porosity_global_surface": 1.0 - vp / (container.area_m2 * surface),
        "porosity_global_thesis": 1.0 - vp / (container.area_m2 * bhtf),
        "porosity_interior": porosity_in_region(centers, radii, region),
        "interior_region": region.to_dict(),
        "measure_spheres": {"centers_m": mc.tolist(), "radius_m": float(mr), "porosity": local.tolist(),
                            "mean": float(local.mean())},
        "coordination": {
            "box_m": [lo.tolist(), hi.tolist()],
            "n_particles": int(sel.sum()),
            "cutoff_m": 1.05 * dmax,
            "cutoff_mean": float(z_cut.mean()) if len(z_cut) else None,
            "cutoff_hist": np.bincount(z_cut).tolist() if len(z_cut) else [],
            "contact_mean": float(z_true.mean()) if len(z_true) else None,
            "contact_hist": np.bincount(z_true).tolist() if len(z_true) else [],
        },
        "diameter_m": {"min": float(d_all.min()), "max": float(d_all.max()), "mean": float(d_all.mean()),
                       "fraction_outside_nominal": float(np.mean((d_all < 2 * material.radius_min_m * (1 - 1e-9))
                                                                 | (d_all > 2 * material.radius_max_m * (1 + 1e-9))))},
    }


def surface_height(centers, radii, container, cell=None):
    """Bed surface height, m: median over a grid of columns of the highest sphere top."""
    cell = cell or 2 * float(radii.mean())
    top = centers[:, 2] + radii
    ix = np.floor(centers[:, 0] / cell).astype(np.int64)
    iy = np.floor(centers[:, 1] / cell).astype(np.int64)
    key = (ix - ix.min()) * (iy.max() - iy.min() + 1) + (iy - iy.min())
    order = np.lexsort((top, key))
    last = np.r_[np.flatnonzero(np.diff(key[order])), len(order) - 1]
    return float(np.median(top[order][last]))


def interior_porosity(sim, container):
    """Porosity of a running simulation's bed, four mean radii in from the walls, floor and surface."""
    c, r = sim.centers, sim.radii
    region = container.interior(4 * float(r.mean()), surface_height(c, r, container))
    return porosity_in_region(c, r, region)


def overlap_fractions(sim):
    """Particle-particle overlaps of the touching pairs, as fractions of the smaller radius."""
    pairs = sim.touching_pairs
    if len(pairs) == 0:
        return np.zeros(1)
    i, j = pairs[:, 0], pairs[:, 1]
    d = np.linalg.norm(sim.centers[j] - sim.centers[i], axis=1)
    return (sim.radii[i] + sim.radii[j] - d) / np.minimum(sim.radii[i], sim.radii[j])

