r"""Packing multi-sphere grains (issue 15 items 1 and 3) with :class:`dem.clumps.ClumpSimulation`.

Procedure (the 'sediment' idea of :mod:`dem._procedures` for grains): N grains from the target
porosity, :math:`N = \lfloor(1-φ)V/V_g\rfloor`; their bounding spheres placed by random
sequential addition in the whole box under a lid at (1 + ``lid_headroom``) × the fill height, at
scale 1/m₀, each with a random orientation (uniform on SO(3)); the whole templates grow to scale 1
without friction, settle frictionless, then the material's friction is restored, the lid removed
and the bed settled to ``tol`` (or ``max_steps``). Porosity: the union of all spheres, by QMC in
an interior box (walls and surface one grain length away), with its standard error.

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

from ._fill import generate_spheres
from ._io import summary_path
from ._material import SOYBEAN
from ._rigid import random_quaternions
from .clumps import ClumpSimulation

__all__ = ["pack_grains", "write_grain_packing", "union_porosity_in_box"]


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


def pack_grains(container, template, *, material=SOYBEAN, porosity=0.408, n_grains=None, rng=None,
                initial_multiplier=1.4, mass_scale=100.0, lid_headroom=0.3, grow_steps=3000, sediment_steps=3000,
                tol=2e-3, max_steps=40000, check_every=200, progress=None):
    """Settled packing of grains of one template in ``container`` (procedure: module notes).

    Returns (sphere centres (N, 3), radii (N,), grain_id (N,), grain table dict, summary dict).
    """
    t0 = time.perf_counter()
    rng = np.random.default_rng(rng)
    n = int((1 - porosity) * container.volume_m3 / template.volume_m3) if n_grains is None else int(n_grains)
    if n < 1:
        raise ValueError(f"no grain of {template.volume_m3:.3g} m^3 fits the container")
    lid = container.fill_height_m * (1 + lid_headroom)
    rb = template.bounding_radius_m / initial_multiplier
    gen_box = replace(container, fill_height_m=lid)
    x, _ = generate_spheres(gen_box, n, rb, rb, rng)
    q = random_quaternions(n, rng)
    s0 = np.full(n, 1 / initial_multiplier)
    frictionless = replace(material, friction=0.0, wall_friction=0.0)
    sim = ClumpSimulation([template], np.zeros(n, int), x, q, s0, container.walls(lid=True, lid_height_m=lid),
                          frictionless, mass_scale=mass_scale)
    stages = {"grow": sim.run(max_steps=grow_steps, grow_from=s0, grow_to=np.ones(n), check_every=check_every,
                              callback=progress)}
    stages["sediment"] = sim.run(max_steps=sediment_steps, check_every=check_every, callback=progress)
    sim.set_material(material)
    sim.set_walls(container.walls(lid=False))
    stages["settle"] = sim.run(max_steps=max_steps, tol=tol, check_every=check_every, callback=progress)
    xs = sim.sphere_centers()
    r = sim.radii.copy()
    top = float(np.max(xs[:, 2] + r))
    margin = float(template.extent_m[0])
    if container.kind == "box":
        half = np.array(container.size_m) / 2 - margin
        lo, hi = np.array([-half[0], -half[1], margin]), np.array([half[0], half[1], top - margin])
    else:
        h = container.size_m[0] / 2 / np.sqrt(2) - margin
        lo, hi = np.array([-h, -h, margin]), np.array([h, h, top - margin])
    phi, phi_err = (union_porosity_in_box(xs, r, lo, hi) if np.all(hi > lo) else (float("nan"), float("nan")))
    wall = time.perf_counter() - t0
    steps = sum(s["steps"] for s in stages.values())
    summary = {"n_grains": n, "n_spheres": len(r), "template": template.name, "template_source": template.source,
               "spheres_per_grain": template.n, "grain_volume_m3": template.volume_m3,
               "porosity_interior_union": phi, "porosity_interior_error": phi_err,
               "interior_box_m": [lo.tolist(), hi.tolist()], "bed_top_m": top, "stages": stages,
               "steps": steps, "dt_s": sim.dt, "mass_scale": mass_scale, "wall_time_s": wall,
               "material": {k: getattr(material, k) for k in material.__dataclass_fields__},
               "engine": "dem.clumps (numpy; separate from the compiled sphere step)"}
    grains = {"centers": sim.X.copy(), "quaternions": sim.q.copy(), "volume_m3": sim.volume_m3.copy(),
              "template": [template.name] * n}
    return xs, r, sim.gid.copy(), grains, summary


def write_grain_packing(path, centers, radii, grain_id, grains, summary=None):
    """``path``: x,y,z,r,grain_id; ``<stem>.grains.csv``: one row per grain; JSON summary beside."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(path.name + ".tmp")
    data = np.column_stack([centers, radii, grain_id])
    np.savetxt(tmp, data, delimiter=",", header="x,y,z,r,grain_id", comments="",
               fmt=["%.9e"] * 4 + ["%d"])
    os.replace(tmp, path)
    gp = grains_path(path)
    rows = ["id,x,y,z,qw,qx,qy,qz,template,volume_m3"]
    for k, (c, q, v, t) in enumerate(zip(grains["centers"], grains["quaternions"], grains["volume_m3"],
                                         grains["template"])):
        rows.append(",".join([str(k)] + [f"{a:.9e}" for a in (*c, *q)] + [t, f"{v:.9e}"]))
    gp.with_name(gp.name + ".tmp").write_text("\n".join(rows) + "\n")
    os.replace(gp.with_name(gp.name + ".tmp"), gp)
    if summary is not None:
        jp = summary_path(path)
        jp.write_text(json.dumps(summary, indent=1, default=lambda o: o.item() if hasattr(o, "item") else str(o)))


def grains_path(csv_path):
    """The per-grain companion of a packing CSV: ``<stem>.grains.csv``."""
    p = Path(csv_path)
    return p.with_name(p.stem + ".grains.csv")
