r"""Packing multi-sphere grains with :class:`dem.clumps.ClumpSimulation`.

Procedure (the 'sediment' idea of :mod:`dem._procedures` for grains): N grains from the target
porosity, :math:`N = \lfloor(1-φ)V/V_g\rfloor`; their bounding spheres placed by random
sequential addition in the whole box under a lid at (1 + ``lid_headroom``) × the fill height, at
scale 1/m₀ (m₀ = ``initial_multiplier``, default the larger of 1.4 and the scale at which the
bounding spheres fill 20 % of that box: elongated grains' bounding spheres are 5 × their
volume), each with a random orientation (uniform on SO(3)); the whole templates grow to scale 1
and settle with the grain-grain friction ``deposition_friction`` (walls frictionless; 0, the
default, gives the densest bed, friction while the grains grow and fall loosens it: the
procedure's porosity lever, :func:`dem._grain_search.pack_grains_to_porosity`), then the material's friction is
restored, the lid removed and the bed settled to ``tol`` (or ``max_steps``).

Porosity: the union of all spheres by QMC (:func:`union_porosity_in_box`), with its standard
error, in two boxes: ``porosity_interior_union`` keeps one grain length from the walls and the
surface; ``porosity_network_region`` is the box ``network`` samples by default (the spheres'
bounding box shrunk by 1.5 volume-equivalent grain diameters on every side,
``network.pores.default_region``), the one :func:`dem._grain_search.pack_grains_to_porosity` aims at.

Output: :func:`write_grain_packing` writes ``x,y,z,r,grain_id`` (one row per sphere, what
``network`` reads), ``<stem>.grains.csv`` (one row per grain: id, centre, quaternion w,x,y,z,
template, volume) and the JSON summary.
"""

from __future__ import annotations

import json
import os
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
from scipy.spatial import cKDTree
from scipy.stats import qmc

from ._fill import check_sphere_count, generate_spheres
from ._io import summary_path
from ._material import SOYBEAN
from ._rigid import random_quaternions
from .clumps import ClumpSimulation

__all__ = ["pack_grains", "grain_number", "procedure_lever", "write_grain_packing",
           "union_porosity_in_box", "network_region", "DEPOSITION_FRICTION_RANGE"]

#: deposition friction searched by :func:`dem._grain_search.pack_grains_to_porosity`: frictionless (densest) to 1.0
DEPOSITION_FRICTION_RANGE = (0.0, 1.0)

#: :func:`pack_grains`'s default step limit of the settle stage
PACK_MAX_STEPS = 40000

#: grain sizes: the coefficient of variation is below this; normal deviates cut at SIZE_CUT sigma
SIZE_CV_MAX = 0.3
SIZE_CUT = 2.5


def _mean_cube(cv, n=20001):
    r"""Mean of :math:`(1 + c z)^3` for z standard normal cut at ±``SIZE_CUT`` (quadrature).

    >>> round(_mean_cube(0.0), 12), round(_mean_cube(0.1), 4)
    (1.0, 1.0273)
    """
    z = np.linspace(-SIZE_CUT, SIZE_CUT, n)
    w = np.exp(-0.5 * z * z)
    return float(np.sum(w * (1 + cv * z) ** 3) / np.sum(w))


#: margin of network's default sample region, in volume-equivalent grain diameters
NETWORK_MARGIN_DIAMETERS = 1.5


def network_region(centers, radii, grain_volume_m3):
    r"""The box ``network`` samples by default: the spheres' bounding box, :math:`[\min(x-r),
    \max(x+r)]` per axis, shrunk by 1.5 d_v on every side, :math:`d_v = (6V_g/\pi)^{1/3}` (m).

    >>> lo, hi = network_region(np.array([[0.0, 0, 0], [0.1, 0.1, 0.1]]), np.array([0.01, 0.01]),
    ...                         np.pi / 6 * 0.01**3)
    >>> lo.round(4).tolist(), hi.round(4).tolist()
    ([0.005, 0.005, 0.005], [0.095, 0.095, 0.095])
    """
    m = NETWORK_MARGIN_DIAMETERS * (6.0 * grain_volume_m3 / np.pi) ** (1 / 3)
    lo = (centers - radii[:, None]).min(axis=0) + m
    hi = (centers + radii[:, None]).max(axis=0) - m
    return lo, hi


def union_porosity_in_box(centers, radii, lo, hi, *, log2_points=14, replicates=4, seed=7):
    """Porosity of the box [lo, hi] outside the union of spheres (QMC), and its standard error."""
    tree = cKDTree(centers)
    rmax = float(np.max(radii))
    sol = []
    for k in range(replicates):
        p = lo + qmc.Sobol(3, scramble=True, seed=seed + k).random_base2(log2_points) * (hi - lo)
        d, i = tree.query(p, k=16, distance_upper_bound=rmax)
        ok = i < len(radii)
        rr = np.where(ok, radii[np.minimum(i, len(radii) - 1)], 0.0)
        sol.append(np.mean(np.any(ok & (d < rr), axis=1)))
    return 1.0 - float(np.mean(sol)), float(np.std(sol, ddof=1) / np.sqrt(replicates))


def interior_box(xs, r, template, container):
    """The interior box of a grain bed, (lo, hi) m: one grain length from the side walls (a
    cylinder: its inscribed square), the floor and the highest sphere top."""
    top = float(np.max(xs[:, 2] + r))
    margin = float(template.extent_m[0])
    if container.kind == "box":
        half = np.array(container.size_m) / 2 - margin
        return np.array([-half[0], -half[1], margin]), np.array([half[0], half[1], top - margin])
    h = container.size_m[0] / 2 / np.sqrt(2) - margin
    return np.array([-h, -h, margin]), np.array([h, h, top - margin])


def bed_porosities(xs, r, template, container, grain_volume_m3):
    """Porosity of the union of spheres (QMC, :func:`union_porosity_in_box`) in the interior box
    (:func:`interior_box`) and in network's sample region (:func:`network_region`), with errors
    (NaN where a box is empty), the boxes and the bed top, as summary entries."""
    lo, hi = interior_box(xs, r, template, container)
    phi, phi_err = (union_porosity_in_box(xs, r, lo, hi) if np.all(hi > lo) else (float("nan"), float("nan")))
    net_lo, net_hi = network_region(xs, r, grain_volume_m3)
    phi_net, phi_net_err = (union_porosity_in_box(xs, r, net_lo, net_hi) if np.all(net_hi > net_lo)
                            else (float("nan"), float("nan")))
    return {"porosity_interior_union": phi, "porosity_interior_error": phi_err,
            "interior_box_m": [lo.tolist(), hi.tolist()], "porosity_network_region": phi_net,
            "porosity_network_region_error": phi_net_err,
            "network_region_m": [net_lo.tolist(), net_hi.tolist()], "bed_top_m": float(np.max(xs[:, 2] + r))}


def grain_number(container, template, porosity, size_cv=0.0):
    r"""Grains of ``template`` that fill ``container`` to ``porosity``:
    :math:`N = \lfloor (1-φ) V / (V_t \overline{f^3}) \rfloor`, :math:`\overline{f^3}` the mean
    cube of the size factors (``size_cv``: :func:`pack_grains`)."""
    return int((1 - porosity) * container.volume_m3 / (template.volume_m3 * _mean_cube(size_cv)))


def pack_grains(container, template, *, material=SOYBEAN, porosity=0.408, n_grains=None, rng=None,
                initial_multiplier=None, deposition_friction=0.0, size_cv=0.0, mass_scale=100.0,
                lid_headroom=0.3, grow_steps=3000, sediment_steps=3000, tol=2e-3, max_steps=PACK_MAX_STEPS,
                check_every=200, progress=None):
    r"""Settled packing of grains of one template in ``container`` (procedure: module notes).

    ``deposition_friction`` is the grain-grain friction coefficient while the grains grow and
    fall (>= 0; walls frictionless then); the material's friction holds afterwards.
    ``size_cv`` spreads the grains' sizes: grain g is the template scaled by
    :math:`f_g = 1 + c\,z_g`, :math:`z_g` standard normal cut at ±2.5 (``c`` = ``size_cv`` in
    [0, 0.3), the coefficient of variation of a kernel's axes); the grain count uses the mean
    volume :math:`V_t\,\overline{f^3}`. 0 (default) draws nothing: every grain is its template.
    Returns (sphere centres (N, 3), radii (N,), grain_id (N,), grain table dict, summary dict).
    """
    if not (np.isfinite(deposition_friction) and deposition_friction >= 0):
        raise ValueError(f"deposition friction must be finite and >= 0, got {deposition_friction!r}")
    if not (np.isfinite(size_cv) and 0 <= size_cv < SIZE_CV_MAX):
        raise ValueError(f"size spread (coefficient of variation) must be in [0, {SIZE_CV_MAX}), got {size_cv!r}")
    t0 = time.perf_counter()
    rng = np.random.default_rng(rng)
    f3 = _mean_cube(size_cv)
    v_mean = template.volume_m3 * f3
    n = grain_number(container, template, porosity, size_cv) if n_grains is None else int(n_grains)
    if n < 1:
        raise ValueError(f"no grain of {v_mean:.3g} m^3 fits the container")
    check_sphere_count(n * template.n, f"spheres ({n:,} grains of {template.n})")
    lid = container.fill_height_m * (1 + lid_headroom)
    gen_box = replace(container, fill_height_m=lid)
    f_max = 1 + SIZE_CUT * size_cv
    if initial_multiplier is None:
        v_bound = n * 4 / 3 * np.pi * (template.bounding_radius_m * f_max) ** 3   # placed at the largest size
        initial_multiplier = max(1.4, float((v_bound / (0.2 * gen_box.volume_m3)) ** (1 / 3)))
    rb = template.bounding_radius_m * f_max / initial_multiplier
    x, _ = generate_spheres(gen_box, n, rb, rb, rng)
    q = random_quaternions(n, rng)
    size = np.ones(n)
    if size_cv > 0:
        z = rng.standard_normal(n)
        while np.any(np.abs(z) > SIZE_CUT):               # redraw past the cut
            bad = np.abs(z) > SIZE_CUT
            z[bad] = rng.standard_normal(int(bad.sum()))
        size = 1 + size_cv * z
    s0 = size / initial_multiplier
    deposition = replace(material, friction=float(deposition_friction), wall_friction=0.0)
    sim = ClumpSimulation([template], np.zeros(n, int), x, q, s0, container.walls(lid=True, lid_height_m=lid),
                          deposition, mass_scale=mass_scale)
    stages = {"grow": sim.run(max_steps=grow_steps, grow_from=s0, grow_to=size, check_every=check_every,
                              callback=progress)}
    stages["sediment"] = sim.run(max_steps=sediment_steps, check_every=check_every, callback=progress)
    sim.set_material(material)
    sim.set_walls(container.walls(lid=False))
    stages["settle"] = sim.run(max_steps=max_steps, tol=tol, check_every=check_every, callback=progress)
    xs = sim.sphere_centers()
    r = sim.radii.copy()
    measured = bed_porosities(xs, r, template, container, float(np.mean(sim.volume_m3)))
    wall = time.perf_counter() - t0
    steps = sum(s["steps"] for s in stages.values())
    summary = {"n_grains": n, "n_spheres": len(r), "template": template.name, "template_source": template.source,
               "spheres_per_grain": template.n, "grain_volume_m3": template.volume_m3,
               **measured,
               "deposition_friction": float(deposition_friction), "size_cv": float(size_cv),
               "grain_scale_range": [float(size.min()), float(size.max())],
               "initial_multiplier": float(initial_multiplier), "stages": stages,
               "steps": steps, "dt_s": sim.dt, "mass_scale": mass_scale, "wall_time_s": wall,
               "material": {k: getattr(material, k) for k in material.__dataclass_fields__},
               "engine": "dem.clumps (numba: the sphere step's kernels and a rigid-body update)"}
    grains = {"centers": sim.X.copy(), "quaternions": sim.q.copy(), "volume_m3": sim.volume_m3.copy(),
              "template": [template.name] * n}
    return xs, r, sim.gid.copy(), grains, summary


def procedure_lever(lam, *, headroom=0.3, friction_max=DEPOSITION_FRICTION_RANGE[1]):
    r"""(lid_headroom, deposition_friction) of the procedure lever λ in [-1, 1].

    λ in [-1, 0]: frictionless growth under a lid at (1 + 0.3(1 + λ)) × the fill height: at
    λ = -1 the grains grow in the closed box of the requested global porosity (thesis Appendix A
    style, the densest); λ in [0, 1]: free fall from 1.3 × the fill height with deposition
    friction λ μ_max (looser as λ grows).

    >>> procedure_lever(-1.0), procedure_lever(-0.5), procedure_lever(0.5)
    ((0.0, 0.0), (0.15, 0.0), (0.3, 0.5))
    """
    lam = float(np.clip(lam, -1.0, 1.0))
    if lam < 0:
        return round(headroom * (1 + lam), 12), 0.0
    return headroom, round(lam * friction_max, 12)


def write_grain_packing(path, centers, radii, grain_id, grains, summary=None):
    """``path``: x,y,z,r,grain_id; ``<stem>.grains.csv``: one row per grain; JSON summary beside."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(path.name + ".tmp")
    data = np.column_stack([centers, radii, grain_id])
    gp = grains_path(path)
    gtmp = gp.with_name(gp.name + ".tmp")
    rows = ["id,x,y,z,qw,qx,qy,qz,template,volume_m3"]
    for k, (c, q, v, t) in enumerate(zip(grains["centers"], grains["quaternions"], grains["volume_m3"],
                                         grains["template"])):
        rows.append(",".join([str(k)] + [f"{a:.9e}" for a in (*c, *q)] + [t, f"{v:.9e}"]))
    try:                                   # renamed when whole; no .tmp left on a failure
        np.savetxt(tmp, data, delimiter=",", header="x,y,z,r,grain_id", comments="",
                   fmt=["%.9e"] * 4 + ["%d"])
        os.replace(tmp, path)
        gtmp.write_text("\n".join(rows) + "\n")
        os.replace(gtmp, gp)
    finally:
        tmp.unlink(missing_ok=True)
        gtmp.unlink(missing_ok=True)
    if summary is not None:
        jp = summary_path(path)
        jp.write_text(json.dumps(summary, indent=1, default=lambda o: o.item() if hasattr(o, "item") else str(o)))


def grains_path(csv_path):
    """The per-grain companion of a packing CSV: ``<stem>.grains.csv``."""
    p = Path(csv_path)
    return p.with_name(p.stem + ".grains.csv")
