"""What a poured bed measures (``docs/dem-fill.md``, Companion JSON): the long-axis order S, the
surface heights, a spout pile's angle of repose, porosity by depth, and the summary entries
:func:`poured_bed_summary` gathers for the companion JSON of :mod:`dem._pour`'s beds.
"""

from __future__ import annotations

import numpy as np

from ._clump_pack import bed_porosities, union_porosity_in_box
from ._rigid import quat_to_matrix

__all__ = ["angle_of_repose", "orientation_order", "porosity_by_depth", "poured_bed_summary", "surface_heights"]


def orientation_order(quaternions):
    r"""Long-axis order about the vertical, :math:`S = \langle\tfrac32\cos^2\theta - \tfrac12\rangle`
    (θ between the body x axis, a kernel's long axis, and z): 0 random, -1/2 all horizontal.

    >>> orientation_order(np.array([[1.0, 0, 0, 0]]))   # x horizontal
    -0.5
    """
    q = np.asarray(quaternions, dtype=float).reshape(-1, 4)
    cz = quat_to_matrix(q)[:, 2, 0]
    return float(np.mean(1.5 * cz**2 - 0.5))


def surface_heights(centers, radii, lo_xy, hi_xy, cell_m):
    """Highest sphere top in each lateral cell (cell size ``cell_m``) over [lo_xy, hi_xy], m;
    NaN where a cell holds no sphere. Returns (cell centres (M, 2), heights (M,))."""
    lo_xy, hi_xy = np.asarray(lo_xy, float), np.asarray(hi_xy, float)
    nxy = np.maximum(1, np.floor((hi_xy - lo_xy) / cell_m).astype(int))
    idx = np.floor((centers[:, :2] - lo_xy) / (hi_xy - lo_xy) * nxy).astype(int)
    ok = np.all((idx >= 0) & (idx < nxy), axis=1)
    flat = idx[ok, 0] * nxy[1] + idx[ok, 1]
    top = np.full(nxy[0] * nxy[1], -np.inf)
    np.maximum.at(top, flat, centers[ok, 2] + radii[ok])
    top[np.isinf(top)] = np.nan
    ix, iy = np.divmod(np.arange(nxy[0] * nxy[1]), nxy[1])
    cxy = lo_xy + (np.column_stack([ix, iy]) + 0.5) * (hi_xy - lo_xy) / nxy
    return cxy, top


def angle_of_repose(centers, radii, container, *, inner_m, cell_m):
    r"""Angle of repose of a centre pile, degrees, and the fit: the highest sphere top h in
    lateral cells (:func:`surface_heights`) against the distance r from the axis, a straight line
    :math:`h = h_0 - r\tan\alpha` fitted by least squares over the cells farther than ``inner_m``
    from the axis and at least one cell from every wall (a box's corners included).

    Returns dict: ``angle_deg``, ``r_range_m``, ``cells``, ``rms_m`` (residual).
    """
    if container.kind == "box":
        hx, hy = container.size_m[0] / 2, container.size_m[1] / 2
        cxy, h = surface_heights(centers, radii, (-hx, -hy), (hx, hy), cell_m)
        away = (np.abs(cxy[:, 0]) < hx - cell_m) & (np.abs(cxy[:, 1]) < hy - cell_m)
    else:
        rad = container.size_m[0] / 2
        cxy, h = surface_heights(centers, radii, (-rad, -rad), (rad, rad), cell_m)
        away = np.hypot(cxy[:, 0], cxy[:, 1]) < rad - cell_m
    r = np.hypot(cxy[:, 0], cxy[:, 1])
    sel = np.isfinite(h) & (r > inner_m) & away
    rng = [float(inner_m), float(r[sel].max()) if sel.any() else float(inner_m)]
    if sel.sum() < 3 or np.ptp(r[sel]) < cell_m:
        return {"angle_deg": None, "r_range_m": rng, "cells": int(sel.sum()), "rms_m": None}
    a, b = np.polyfit(r[sel], h[sel], 1)
    res = h[sel] - (a * r[sel] + b)
    return {"angle_deg": float(np.degrees(np.arctan(-a))), "r_range_m": rng,
            "cells": int(sel.sum()), "rms_m": float(np.sqrt(np.mean(res**2)))}


def porosity_by_depth(centers, radii, lo_xy, hi_xy, surface_m, *, layers=10, porosity_fn):
    """Porosity in ``layers`` equal horizontal slabs from the floor to ``surface_m`` over the
    lateral box [lo_xy, hi_xy]; ``porosity_fn(lo, hi) -> (porosity, error)``. Listed from the
    surface down: ``depth_m`` is each slab's middle below the surface."""
    edges = np.linspace(0.0, surface_m, layers + 1)
    out = []
    for k in range(layers - 1, -1, -1):
        lo = np.array([lo_xy[0], lo_xy[1], edges[k]])
        hi = np.array([hi_xy[0], hi_xy[1], edges[k + 1]])
        phi, err = porosity_fn(lo, hi)
        out.append({"z_lo_m": float(edges[k]), "z_hi_m": float(edges[k + 1]),
                    "depth_m": float(surface_m - 0.5 * (edges[k] + edges[k + 1])),
                    "porosity": phi, "error": err})
    return out


def poured_bed_summary(sim, template, container, record):
    """The summary entries of a poured bed: the porosities of :func:`dem._clump_pack.bed_porosities`,
    ``orientation_order_S`` (grains with their centre in the interior box) and
    ``orientation_order_S_all``, ``surface_m`` (mean of the highest sphere tops in cells one
    grain diameter wide over the interior box), ``porosity_by_depth`` (10 layers from the floor
    to ``surface_m`` over the interior box) and, for a spout, ``angle_of_repose``
    (:func:`angle_of_repose`, from one spout radius plus one grain diameter out)."""
    xs = sim.sphere_centers()
    r = sim.radii.copy()
    out = bed_porosities(xs, r, template, container, float(np.mean(sim.volume_m3)))
    lo, hi = (np.array(b) for b in out["interior_box_m"])
    inside = np.all((sim.X >= lo) & (sim.X <= hi), axis=1)
    d_v = 2 * template.equivalent_radius_m
    _, tops = surface_heights(xs, r, lo[:2], hi[:2], d_v)
    surface = float(np.nanmean(tops)) if np.any(np.isfinite(tops)) else out["bed_top_m"]
    out.update({
        "orientation_order_S": orientation_order(sim.q[inside]) if inside.any() else None,
        "orientation_order_S_all": orientation_order(sim.q),
        "orientation_order_grains": int(inside.sum()),
        "surface_m": surface,
        "porosity_by_depth": porosity_by_depth(
            xs, r, lo[:2], hi[:2], surface, layers=10,
            porosity_fn=lambda a, b: union_porosity_in_box(xs, r, a, b, log2_points=12)),
    })
    if record["method"] == "spout":
        out["angle_of_repose"] = angle_of_repose(xs, r, container, inner_m=record["spout_diameter_m"] / 2 + d_v,
                                                 cell_m=d_v)
    return out
