"""Airflow paths, tortuosity, widths and the branched-path model of a packing (thesis 3.4, 3.5.1).

Usage::

    python -m network.paths PACKING [--entry X Y | --entries N] [--kind widest|narrowest|
        maximin|shortest|all] [--axis z] [--method build|delaunay] [--seed S]
        [--velocity U ...] [--branches path|all] [--pressure [--policy P]]
        [--json OUT.json] [--plot OUT.png] [--standin LX LY LZ]

``widest``/``narrowest`` are the thesis's step-increment paths (``--method build``: tetrahedra
built sphere by sphere as in Appendices D-E; ``--method delaunay``: the same rule walked on the
Delaunay tessellation); ``maximin`` is the optimal widest (maximin-bottleneck) path and
``shortest`` the shortest path on the tessellation. Entry points are (X, Y) in metres in the
plane normal to ``--axis`` (the other two axes in x, y, z order); ``--entries N`` draws N at
random (``--seed``) away from the walls. The branched-path model (Table 4.4 layout, then the
Table 4.5 comparison with ASABE D272 and Ergun) is evaluated on every widest/narrowest path at
each ``--velocity``; ``--pressure`` solves the network model (``network.flow.solve_network``)
and prints the pressure drop along every path that lies on the tessellation (thesis 4.2.3).
Timings, load average and platform go into the JSON. ``--standin LX LY LZ`` replaces PACKING
by a geometric stand-in from ``network.packing.random_packing`` (no gravity) at porosity 0.408.
A bad input (no packing, an unreadable file, a bad option value) exits with status 2 and one
line on stderr.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import time

import numpy as np

from .airpaths import (bed_depth, branched_table, face_graph, plot_paths, pore_pressure_array,
                       pressure_along_path, random_entry_points, trace_paths)
from .flow import asabe_d272_gradient, ergun_gradient, solve_network
from .packing import Packing, random_packing, read_packing
from .pores import Region, tessellate, tie_groups

_ALL = ("widest", "narrowest", "maximin", "shortest")
#: Thesis values (Tables 4.1-4.5) printed beside ours.
THESIS = {
    "tortuosity": {"widest": 1.39, "narrowest": 1.40},
    "mean_width_mm": {"widest": (2.73, 2.91), "narrowest": (1.85, 2.00)},
    "tetrahedra": {"widest": (152, 162), "narrowest": (142, 154)},
    "branched_mfx3_average_pa": {"0.013": 2.74, "0.027": 5.65},
    "measured_pa": {"0.013": 2.44, "0.027": 6.80},
}


def _parser():
    p = argparse.ArgumentParser(prog="python -m network.paths", description=__doc__.split("\n")[0])
    p.add_argument("packing", nargs="?", help="CSV x,y,z,r (m), .npz or LAMMPS dump")
    g = p.add_mutually_exclusive_group()
    g.add_argument("--entry", nargs=2, type=float, action="append", metavar=("X", "Y"),
                   help="entry point (m); repeat for several")
    g.add_argument("--entries", type=int, default=None, metavar="N",
                   help="N random entry points (default 3)")
    p.add_argument("--kind", default="all", choices=_ALL + ("all",))
    p.add_argument("--axis", default="z", choices=("x", "y", "z"))
    p.add_argument("--method", default="build", choices=("build", "delaunay"),
                   help="how widest/narrowest paths are made (default build, as the thesis)")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--velocity", type=float, nargs="+", default=[0.013, 0.027],
                   help="superficial velocities for the branched model (m/s)")
    p.add_argument("--branches", default="path", choices=("all", "path"),
                   help="daughter losses counted: the path's (Eq. 3.28, default) or all three "
                        "(Appendix F)")
    p.add_argument("--no-branched", action="store_true", help="skip the branched model")
    p.add_argument("--pressure", action="store_true",
                   help="solve the network model (network.solve) and report the pressure along "
                        "the paths on the tessellation (thesis 4.2.3) at the first --velocity")
    p.add_argument("--policy", default="shape-factor",
                   choices=("shape-factor", "table-only", "table+fe", "fe-only"),
                   help="Q* source of the network model for --pressure (default shape-factor)")
    p.add_argument("--json", metavar="OUT.json")
    p.add_argument("--plot", metavar="OUT.png")
    p.add_argument("--standin", nargs=3, type=float, metavar=("LX", "LY", "LZ"),
                   help="instead of PACKING, a geometric stand-in packing in this box (m): "
                        "diameters 5.5-7.5 mm, porosity 0.408, by network.packing.random_packing "
                        "(--seed)")
    return p


#: Stand-in packing (``--standin``): soybean diameters (thesis Table 3.1) and the thesis's bin
#: porosity.
STANDIN_DIAMETERS_M = (5.5e-3, 7.5e-3)
STANDIN_POROSITY = 0.408


def standin_packing(box_m, *, rng=None):
    """Geometric stand-in packing of about the box ``box_m`` (m): (centers, radii).

    As many spheres (diameters uniform in :data:`STANDIN_DIAMETERS_M`) as give porosity
    :data:`STANDIN_POROSITY` in the box, packed by ``network.packing.random_packing`` with the
    box's aspect ratio; its box has the volume of the drawn spheres at that porosity, so it
    differs from ``box_m`` by the sampling error of the mean sphere volume.
    """
    box = np.asarray(box_m, dtype=float)
    if box.shape != (3,) or not np.all(box > 0):
        raise ValueError(f"--standin needs three box sides > 0 (m), got {box_m}")
    d0, d1 = STANDIN_DIAMETERS_M
    mean_vol = np.pi / 6.0 * (d1**4 - d0**4) / (4.0 * (d1 - d0))  # E[pi d^3 / 6], d uniform
    n = int(round((1.0 - STANDIN_POROSITY) * box.prod() / mean_vol))
    pk = random_packing(n, diameter_range_m=STANDIN_DIAMETERS_M,
                        solid_fraction=1.0 - STANDIN_POROSITY, aspect=box, rng=rng)
    return np.asarray(pk.centers), np.asarray(pk.radii)


def main(argv=None) -> int:
    args = _parser().parse_args(argv)
    t0 = time.perf_counter()
    try:
        if args.standin:
            x, r = standin_packing(args.standin, rng=args.seed)
            source = f"stand-in {args.standin} seed {args.seed}"
        elif args.packing:
            pk = read_packing(args.packing)
            x, r = np.asarray(pk.centers), np.asarray(pk.radii)
            source = str(args.packing)
        else:
            raise ValueError("give PACKING or --standin LX LY LZ")
        if any(u <= 0 for u in args.velocity):
            raise ValueError(f"--velocity must be > 0 m/s, got {args.velocity}")
        t_read = time.perf_counter() - t0
        if args.entry:
            xy = np.array(args.entry, dtype=float)
        else:
            xy = random_entry_points(x, r, 3 if args.entries is None else args.entries,
                                     axis=args.axis, rng=args.seed)
    except (OSError, ValueError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    kinds = _ALL if args.kind == "all" else (args.kind,)
    need_graph = any(k in ("maximin", "shortest") for k in kinds) or args.method == "delaunay"
    graph = tess = None
    t1 = time.perf_counter()
    if need_graph or args.pressure:
        tess = tessellate(Packing(x, r, source))
        graph = face_graph(tess)
    t_graph = time.perf_counter() - t1
    paths, t_kind = [], {}
    for kind in kinds:
        tk = time.perf_counter()
        paths += trace_paths(x, r, xy, kind=kind, method=args.method, graph=graph,
                             axis=args.axis)
        t_kind[kind] = time.perf_counter() - tk
    depth = bed_depth(x, r, args.axis)

    print(f"{source}: {len(r)} spheres, depth {depth:.4f} m along {args.axis}, "
          f"{len(xy)} entries; read {t_read:.2f} s, tessellation+open areas {t_graph:.2f} s, "
          + ", ".join(f"{k} {v:.2f} s" for k, v in t_kind.items()))
    print(f"{'kind':10s} {'entry (m)':>18s} {'status':>9s} {'tetra':>6s} {'L (m)':>7s} "
          f"{'T raw':>6s} {'T':>6s} {'T span':>6s} {'W (mm)':>7s} {'<30deg':>7s}")
    for p in paths:
        s = p.summary()
        print(f"{p.kind:10s} ({p.entry_xy[0]:7.4f},{p.entry_xy[1]:7.4f}) {p.status:>9s} "
              f"{p.n_tetrahedra:6d} {p.length_m:7.3f} {p.tortuosity_raw:6.3f} {p.tortuosity:6.3f} "
              f"{p.tortuosity_span:6.3f} "
              f"{p.mean_width_m * 1e3:7.2f} {s['turning_below_30deg']:7.2f}")
    for kind in kinds:
        ok = [p for p in paths if p.kind == kind and p.status == "ok"]
        if not ok:
            continue
        ref = THESIS["tortuosity"].get(kind)
        refw = THESIS["mean_width_mm"].get(kind)
        print(f"mean {kind}: tetrahedra {np.mean([p.n_tetrahedra for p in ok]):.0f}, "
              f"tortuosity {np.mean([p.tortuosity for p in ok]):.3f}"
              + (f" (thesis {ref})" if ref else "")
              + f", width {np.mean([p.mean_width_m for p in ok]) * 1e3:.2f} mm"
              + (f" (thesis {refw[0]}-{refw[1]})" if refw else "")
              + f", turns < 30 deg "
                f"{np.mean(np.concatenate([p.turning_angles_deg for p in ok]) < 30):.2f}"
              + (" (thesis > 0.5)" if ref else ""))

    branched, table45 = [], {}
    if not args.no_branched:
        t2 = time.perf_counter()
        for i, p in enumerate(paths):
            if p.kind in ("widest", "narrowest") and p.status == "ok":
                tab = branched_table(x, r, p, velocities_m_s=args.velocity,
                                     branches=args.branches)
                branched.append({"path": i, "kind": p.kind, "entry_xy_m": p.entry_xy.tolist(),
                                 **tab})
        if branched:
            print(f"branched model (Pa; branches={args.branches}, Q0 = U x mean face area; "
                  f"{time.perf_counter() - t2:.2f} s)")
            us = [f"{u:g}" for u in args.velocity]
            print(f"{'kind':10s} {'LFPW':8s} " + " ".join(f"MFx3@{u:<7s}" for u in us) + " "
                  + " ".join(f"MFx2@{u:<7s}" for u in us))
            for b in branched:
                for w in ("max", "min", "average"):
                    print(f"{b['kind']:10s} {w:8s} "
                          + " ".join(f"{b[w]['MFx3'][u]:12.3g}" for u in us) + " "
                          + " ".join(f"{b[w]['MFx2'][u]:12.3g}" for u in us))
            for u in us:
                avg = np.mean([b["average"]["MFx3"][u] for b in branched])
                ref = THESIS["branched_mfx3_average_pa"].get(u)
                meas = THESIS["measured_pa"].get(u)
                print(f"mean MFx3 average-width at {u} m/s: {avg:.3g} Pa"
                      + (f" (thesis {ref} Pa, measured {meas} Pa)" if ref else ""))
            table45 = _table_4_5(x, r, depth, args.velocity, branched)
            print("Table 4.5 layout (Pa over the bed depth): "
                  + "; ".join(f"{k} " + " ".join(f"{v:.3g}" for v in vals.values())
                              for k, vals in table45.items()))

    along = []
    if args.pressure:
        along = _pressure_along(args, x, r, source, tess, graph, paths)

    if args.json:
        out = {
            "source": source, "n_spheres": int(len(r)), "axis": args.axis, "depth_m": depth,
            "method": args.method, "entries_xy_m": xy.tolist(),
            "seconds": {"read": t_read, "tessellation": t_graph, **t_kind},
            "paths": [{**p.summary(), "points_m": p.points.tolist(),
                       "widths_m": p.widths_m.tolist(),
                       "turning_angles_deg": p.turning_angles_deg.tolist()} for p in paths],
            "branched": branched, "table_4_5_pa": table45, "pressure_along_paths": along, "thesis": THESIS,
            "platform": platform.platform(), "cpu_count": os.cpu_count(),
            "loadavg": os.getloadavg(), "timestamp": time.strftime("%Y-%m-%dT%H:%M:%SZ",
                                                                   time.gmtime()),
        }
        with open(args.json, "w") as f:
            json.dump(out, f, indent=1)
    if args.plot:
        plot_paths(x, paths, args.plot, axis=args.axis, title=source)
    return 0


def _table_4_5(x, r, depth, velocities, branched):
    """Pressure drops over the bed depth (Pa): measured (thesis), branched model (ours, mean of
    the MFx3 average-width paths), ASABE D272 and Ergun at the bed's porosity (thesis 4.2.2)."""
    lo, hi = (x - r[:, None]).min(axis=0), (x + r[:, None]).max(axis=0)
    porosity = 1.0 - float(np.sum(4.0 / 3.0 * np.pi * r**3) / np.prod(hi - lo))
    us = [f"{u:g}" for u in velocities]
    return {
        "measured (thesis)": {u: THESIS["measured_pa"].get(u, float("nan")) for u in us},
        "branched model": {u: float(np.mean([b["average"]["MFx3"][u] for b in branched]))
                           for u in us},
        "ASABE D272": {f"{u:g}": float(asabe_d272_gradient(u) * depth) for u in velocities},
        f"Ergun (porosity {porosity:.3f})": {
            f"{u:g}": float(ergun_gradient(u, porosity=porosity, diameter_m=2 * r.mean()) * depth)
            for u in velocities},
    }


def _pressure_along(args, x, r, source, tess, graph, paths):
    """Network-model pressures along the paths that lie on the tessellation."""
    t = time.perf_counter()
    # sample: 1.5 mean diameters from the side walls (less in a thin bin), 4 mean diameters
    # (the thesis's 0.026 m) from the floor and from the highest centre, so a loose top surface
    # still leaves outlet pores
    ax = "xyz".index(args.axis)
    d = 2.0 * r.mean()
    lo, hi = x.min(axis=0), x.max(axis=0)
    m = np.minimum(1.5 * d, 0.2 * (hi - lo))
    m[ax] = 4.0 * d
    res = solve_network(Packing(x, r, source), axis=args.axis, tessellation=tess,
                        policy=args.policy, velocity_m_s=args.velocity[0], porosity_points=0,
                        region=Region(lo + m, hi - m))
    labels, n_groups = tie_groups(tess)
    p_all = pore_pressure_array(tess.n_pores, res.pore_ids, res.pressure_pa,
                                None if n_groups == tess.n_pores else labels)
    grad = res.pressure_gradient_pa_per_m
    print(f"network model ({args.policy}) at {args.velocity[0]:g} m/s: gradient {grad:.4g} Pa/m, "
          f"{res.pressure_drop_pa:.4g} Pa over {res.depth_m:g} m ({time.perf_counter() - t:.1f} s)")
    out = []
    for i, p in enumerate(paths):
        if p.status != "ok" or np.any(p.pores < 0):
            continue
        pos, pr = pressure_along_path(graph, p, p_all, axis=args.axis)
        inside = np.isfinite(pr)
        if inside.sum() < 2:
            continue
        span = float(pos[inside][-1] - pos[inside][0])
        dp = float(pr[inside][0] - pr[inside][-1])
        out.append({"path": i, "kind": p.kind, "entry_xy_m": p.entry_xy.tolist(),
                    "n_tetrahedra_in_sample": int(inside.sum()), "span_m": span, "dp_pa": dp,
                    "dp_per_m": dp / span if span > 0 else float("nan"),
                    "position_m": pos[inside].tolist(), "pressure_pa": pr[inside].tolist()})
        print(f"  {p.kind:9s} path {i}: {inside.sum()} tetrahedra in the sample, "
              f"{dp:.4g} Pa over {span:.4f} m ({dp / span:.4g} Pa/m)")
    return out


if __name__ == "__main__":
    sys.exit(main())
