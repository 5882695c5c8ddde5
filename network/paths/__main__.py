"""Airflow paths, tortuosity, widths and the branched-path model of a packing (thesis 3.4, 3.5.1).

Usage::

    python -m network.paths PACKING [--entry X Y | --entries N] [--kind widest|narrowest|
        maximin|shortest|all] [--axis z] [--method build|delaunay] [--seed S]
        [--velocity U ...] [--depth D] [--branches path|all] [--pressure [--policy P]]
        [--grain G] [--units m|cm|mm] [--json OUT.json] [--plot OUT.png] [--standin LX LY LZ]

``widest``/``narrowest`` are the thesis's step-increment paths (``--method build``: tetrahedra
built sphere by sphere as in Appendices D-E; ``--method delaunay``: the same rule walked on the
Delaunay tessellation); ``maximin`` is the optimal widest (maximin-bottleneck) path and
``shortest`` the shortest path on the tessellation. Entry points are (X, Y) in metres in the
plane normal to ``--axis`` (the other two axes in x, y, z order); ``--entries N`` draws N at
random (``--seed``) away from the walls. The branched-path model (Table 4.4 layout, then the
Table 4.5 comparison with the bed's grain's ASABE D272 line and Ergun) is evaluated on every
widest/narrowest path at each ``--velocity``; ``--pressure`` solves the network model
(``network.flow.solve_network``) and prints the pressure drop along every path that lies on the
tessellation (thesis 4.2.3). Conventions (:data:`CONVENTIONS`): T is Eq. 3.27's smoothed length
over L0, the bed depth for built paths and the path's own axial span for paths on the
tessellation (they start and end inside the bed); pressure drops beside ASABE D272 and Ergun
are over ``--depth`` (0.25 m, as ``network.solve``); a path traced twice counts once. The grain
is the bed's, as in ``network.solve`` (its companion JSON, else ``--grain``; the stand-in's is
soybean): no D272 row where it is unknown, and the thesis's soybean values (tortuosity, widths,
2.44 Pa at 0.25 m) only beside a soybean bed. Timings, load average and platform go into the
JSON. ``--standin LX LY LZ`` replaces PACKING by a stand-in from
``network.packing.random_packing`` at porosity 0.408.
Exit 0 done, 1 failed, 2 bad input (an entry outside the bed, ``--entries 0``, ...): one
``error:`` line on stderr (docs/cli.md).
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
import platform
import time

import numpy as np

from .._cli import (CliParser, add_air, add_packing, bad_input, check_common, check_outputs,
                    check_plot, computing, finish, load_packing, packing_inputs, run)
from .._grains import D272, d272_line, grain_key, packing_grain
from . import (bed_depth, branched_table, face_graph, plot_paths, pore_pressure_array,
               pressure_along_path, random_entry_points, trace_paths)
from ._reference import CONVENTIONS, THESIS, THESIS_DEPTH_M
from ._standin import STANDIN_MAX_SPHERES, STANDIN_MIN_SIDE_M, standin_packing, standin_size
from ..conductance import POLICIES
from ..flow import (DEFAULT_DEPTH_M, ConductanceOptions, FlowOptions, SampleOptions,
                    asabe_d272_gradient, ergun_gradient, inset_window, solve_network)
from ..packing import UNITS, Packing
from ..pores import (NoInteriorError, Region, axis_index, default_region, region_porosity,
                     tessellate)

_ALL = ("widest", "narrowest", "maximin", "shortest")
#: Most entry points (each traces up to four paths; 1e8 ran out of memory, 1e6 took minutes)
MAX_ENTRIES = 10_000


def _parser():
    p = CliParser(prog="python -m network.paths",
                  description=__doc__.split("\n")[0] + " Exit status 0 done, 1 failed, 2 bad "
                  "input (docs/cli.md).")
    add_packing(p, bundled=False)
    g = p.add_mutually_exclusive_group()
    g.add_argument("--entry", nargs=2, type=float, action="append", metavar=("X", "Y"),
                   help="entry point in the packing's unit (--units), the two axes normal to "
                        "--axis in x, y, z order; must lie inside the bed; repeat for several")
    g.add_argument("--entries", type=int, default=None, metavar="N",
                   help="N >= 1 random entry points away from the walls (--seed; default 3)")
    p.add_argument("--kind", default="all", choices=_ALL + ("all",),
                   help="widest/narrowest: step-increment paths; maximin: optimal widest; "
                        "shortest: shortest on the tessellation; all: the four")
    p.add_argument("--axis", default="z", type=str.lower, choices=("x", "y", "z"),
                   help="flow direction, any case")
    p.add_argument("--method", default="build", choices=("build", "delaunay"),
                   help="how widest/narrowest paths are made: build (the thesis's "
                        "construction) or delaunay (the same rule on the tessellation)")
    p.add_argument("--seed", type=int, default=0,
                   help="seed of the random entry points and of --standin")
    p.add_argument("--velocity", type=float, nargs="+", default=[0.013, 0.027],
                   help="superficial velocities for the branched model, m/s, > 0")
    p.add_argument("--depth", type=float, default=DEFAULT_DEPTH_M,
                   help="bed depth of the Table 4.5 comparison (branched model, ASABE D272, "
                        "Ergun) and of --pressure, m, > 0; as network.solve")
    add_air(p, density=False)
    p.add_argument("--branches", default="path", choices=("all", "path"),
                   help="daughter losses counted: the path's (Eq. 3.28) or all three "
                        "(Appendix F)")
    p.add_argument("--no-branched", action="store_true", help="skip the branched model")
    p.add_argument("--pressure", action="store_true",
                   help="solve the network model (network.solve) and report the pressure along "
                        "the paths on the tessellation (thesis 4.2.3) at the first --velocity")
    p.add_argument("--policy", default="shape-factor",
                   choices=POLICIES,
                   help="Q* source of the network model for --pressure")
    p.add_argument("--grain", default=None,
                   help="the crop the bed is of, for the ASABE D272 row and the thesis's soybean "
                        f"values (any case, spaces or underscores: {', '.join(D272)}); default: "
                        "the grain template its companion JSON names (the bundled scene and "
                        "the stand-in: soybean); a bed of unknown grain gets no D272 row. A "
                        "--grain that contradicts the JSON is refused")
    p.add_argument("--json", metavar="OUT.json", help="write every number here (default: not "
                                                      "written)")
    p.add_argument("--plot", metavar="OUT.png",
                   help="draw the paths (needs matplotlib: pip install '.[plot]'; default: "
                        "not drawn)")
    p.add_argument("--standin", nargs=3, type=float, metavar=("LX", "LY", "LZ"),
                   help=f"instead of PACKING, a geometric stand-in packing in this box (m, "
                        f"sides >= {STANDIN_MIN_SIDE_M:g}, at most {STANDIN_MAX_SPHERES} "
                        "spheres): diameters 5.5-7.5 mm, porosity 0.408, by "
                        "network.packing.random_packing (--seed)")
    return p


def main(argv=None) -> int:
    """Run the command; exit status 0 done, 1 the computation failed, 2 bad input."""
    return run(_main, _parser(), argv)


def _check_options(args) -> None:
    """Options and output paths, before the packing is read (ValueError names the option)."""
    if args.entries is not None and not 1 <= args.entries <= MAX_ENTRIES:
        raise ValueError(f"--entries n must be 1-{MAX_ENTRIES} (entry points: 1e8 ran out of "
                         f"memory), got {args.entries}")
    if any(not (math.isfinite(u) and u > 0) for u in args.velocity):
        raise ValueError(f"--velocity must be finite and > 0 m/s, got {args.velocity}")
    if args.seed < 0:
        raise ValueError(f"--seed must be an integer >= 0, got {args.seed}")
    if args.standin:
        standin_size(args.standin)
        if min(args.standin) < STANDIN_MIN_SIDE_M:
            raise ValueError(f"--standin {' '.join(f'{v:g}' for v in args.standin)}: every side "
                             f"must be >= {STANDIN_MIN_SIDE_M:g} m (6 mean diameters: the "
                             "interior sample keeps 1.5 from each face)")
    if args.grain is not None:
        grain_key(args.grain)
    check_common(args)
    check_outputs(json=args.json, plot=args.plot, inputs=packing_inputs(args))
    if args.plot:
        check_plot(path=args.plot)


def _read(args):
    """(centres (N, 3) m, radii (N,) m, source) of --standin or PACKING."""
    if args.standin:
        x, r = standin_packing(args.standin, rng=args.seed)
        return x, r, f"stand-in {args.standin} seed {args.seed}"
    if not args.packing:
        raise ValueError("give PACKING or --standin LX LY LZ")
    _, pk = load_packing(args)
    args.grain_id = pk.grain_id            # every later Packing of this bed keeps its grains
    return np.asarray(pk.centers), np.asarray(pk.radii), str(args.packing)


def _packing(args, x, r, source: str = "") -> Packing:
    """The bed as a Packing again, with the grain ids :func:`_read` found (None: spheres)."""
    return Packing(x, r, source, grain_id=getattr(args, "grain_id", None))


def _grain(args):
    """The bed's grain (a key of ``network._grains.D272``) or None: the stand-in's is soybean
    (its diameters); a packing's comes from its companion JSON or ``--grain``
    (``network._grains.packing_grain``); ValueError when ``--grain`` contradicts either."""
    if not args.standin:
        return packing_grain(args.packing, args.grain) if args.packing else None
    if args.grain is not None and grain_key(args.grain) != "soybean":
        raise ValueError(f"--grain {args.grain}: the stand-in (--standin) has soybean's "
                         "diameters; give --grain soybean, or a packing of "
                         f"{grain_key(args.grain)}")
    return "soybean"


def _entries(args, x, r):
    """(n, 2) entry points, m: --entry (checked inside the bed) or --entries at random."""
    if not args.entry:
        return random_entry_points(x, r, 3 if args.entries is None else args.entries,
                                   axis=args.axis, rng=args.seed)
    scale = UNITS[args.units]
    xy = np.array(args.entry, dtype=float) * scale
    plane = [k for k in range(3) if k != axis_index(args.axis)]
    lo, hi = (x - r[:, None]).min(axis=0)[plane], (x + r[:, None]).max(axis=0)[plane]
    for e, pt in zip(args.entry, xy):
        if not (np.all(np.isfinite(pt)) and np.all(pt >= lo) and np.all(pt <= hi)):
            names = ["xyz"[k] for k in plane]
            raise ValueError(f"--entry {e[0]:g} {e[1]:g} lies outside the bed, which spans "
                             + ", ".join(f"{n} {a / scale:.6g}..{b / scale:.6g}"
                                         for n, a, b in zip(names, lo, hi))
                             + f" ({args.units}): give a point inside it")
    return xy


def _own_span(p):
    """A path on the tessellation measured over its own axial span (it starts and ends
    inside the bed); built paths keep the bed depth (thesis 3.4.2)."""
    if p.method == "build" or p.points.shape[0] < 2:
        return p
    span = float(np.ptp(p.points[:, axis_index(p.axis)]))
    return dataclasses.replace(p, depth_m=span) if span > 0 else p


def _duplicates(paths):
    """(n,) index of the first identical path (same kind and tetrahedra), -1 if none."""
    first, out = {}, []
    for i, p in enumerate(paths):
        key = (p.kind, p.status, p.tetra_vertices.tobytes())
        out.append(first.setdefault(key, i) if key in first else -1)
        first.setdefault(key, i)
    return np.array(out, dtype=int)


def _main(args) -> int:
    t0 = time.perf_counter()
    with bad_input():
        _check_options(args)
        grain = _grain(args)
        x, r, source = _read(args)
        t_read = time.perf_counter() - t0
        xy = _entries(args, x, r)
        region = None if args.no_branched else _interior(args, x, r, source)
        kinds = _ALL if args.kind == "all" else (args.kind,)
        need_graph = any(k in ("maximin", "shortest") for k in kinds) or args.method == "delaunay"
        graph = tess = None
        t1 = time.perf_counter()
        if need_graph or args.pressure:
            tess = tessellate(_packing(args, x, r, source))
            graph = face_graph(tess)
        t_graph = time.perf_counter() - t1
    paths, t_kind = [], {}
    with computing():
        for kind in kinds:
            tk = time.perf_counter()
            paths += [_own_span(p) for p in trace_paths(x, r, xy, kind=kind, method=args.method,
                                                         graph=graph, axis=args.axis)]
            t_kind[kind] = time.perf_counter() - tk
    depth = bed_depth(x, r, args.axis)
    dup = _duplicates(paths)
    distinct = [p for p, d in zip(paths, dup) if d < 0]

    print(f"{source}: {len(r)} spheres, bed depth {depth:.4f} m along {args.axis}, "
          f"{len(xy)} entries; read {t_read:.2f} s, tessellation+open areas {t_graph:.2f} s, "
          + ", ".join(f"{k} {v:.2f} s" for k, v in t_kind.items()))
    print(f"tortuosity T: {CONVENTIONS['tortuosity']}")
    print(f"{'kind':10s} {'entry (m)':>18s} {'status':>9s} {'tetra':>6s} {'L (m)':>7s} "
          f"{'L0 (m)':>7s} {'T raw':>6s} {'T':>6s} {'T span':>6s} {'W (mm)':>7s} "
          f"{'<30deg':>7s}")
    for i, p in enumerate(paths):
        s = p.summary()
        print(f"{p.kind:10s} ({p.entry_xy[0]:7.4f},{p.entry_xy[1]:7.4f}) {p.status:>9s} "
              f"{p.n_tetrahedra:6d} {p.length_m:7.3f} {p.depth_m:7.4f} {p.tortuosity_raw:6.3f} "
              f"{p.tortuosity:6.3f} {p.tortuosity_span:6.3f} "
              f"{p.mean_width_m * 1e3:7.2f} {s['turning_below_30deg']:7.2f}"
              + (f"  same as path {dup[i]}" if dup[i] >= 0 else ""))
    thesis = THESIS if grain == "soybean" else {"tortuosity": {}, "mean_width_mm": {}}
    for kind in kinds:
        ok = [p for p in distinct if p.kind == kind and p.status == "ok"]
        if not ok:
            continue
        ref = thesis["tortuosity"].get(kind)
        refw = thesis["mean_width_mm"].get(kind)
        print(f"mean {kind} ({len(ok)} distinct paths): tetrahedra "
              f"{np.mean([p.n_tetrahedra for p in ok]):.0f}, "
              f"tortuosity {np.mean([p.tortuosity for p in ok]):.3f}"
              + (f" (thesis {ref})" if ref else "")
              + f", width {np.mean([p.mean_width_m for p in ok]) * 1e3:.2f} mm"
              + (f" (thesis {refw[0]}-{refw[1]})" if refw else "")
              + f", turns < 30 deg "
                f"{np.mean(np.concatenate([p.turning_angles_deg for p in ok]) < 30):.2f}"
              + (" (thesis > 0.5, turns drawn in 2-D: docs/airpaths.md)" if ref else ""))

    branched, table45 = [], {}
    if not args.no_branched:
        with computing():
            branched, table45 = _branched(args, x, r, paths, dup, region, grain)

    along = []
    if args.pressure:
        with computing():
            along = _pressure_along(args, x, r, source, tess, graph, paths)

    with computing():
        if args.json:
            out = {
                "source": source, "units": args.units, "n_spheres": int(len(r)), "grain": grain,
                "axis": args.axis, "depth_m": depth, "comparison_depth_m": args.depth,
                "conventions": CONVENTIONS, "method": args.method, "entries_xy_m": xy.tolist(),
                "seconds": {"read": t_read, "tessellation": t_graph, **t_kind},
                "paths": [{**p.summary(), "duplicate_of": int(d) if d >= 0 else None,
                           "points_m": p.points.tolist(), "widths_m": p.widths_m.tolist(),
                           "turning_angles_deg": p.turning_angles_deg.tolist()}
                          for p, d in zip(paths, dup)],
                "branched": branched, "table_4_5_pa": table45,
                "pressure_along_paths": along,
                "thesis": THESIS if grain == "soybean" else None,
                "platform": platform.platform(), "cpu_count": os.cpu_count(),
                "loadavg": os.getloadavg(), "timestamp": time.strftime("%Y-%m-%dT%H:%M:%SZ",
                                                                       time.gmtime()),
            }
            with open(args.json, "w") as f:
                json.dump(out, f, indent=1)
        if args.plot:
            plot_paths(x, paths, args.plot, axis=args.axis, title=source)
    return 0


def _thesis_point(args, u: str, grain) -> bool:
    """Whether the thesis's 0.25 m soybean pressures apply to a bed of ``grain`` at velocity
    ``u`` and --depth."""
    return (grain == "soybean" and np.isclose(args.depth, THESIS_DEPTH_M)
            and u in THESIS["measured_pa"])


def _interior(args, x, r, source):
    """The default interior sample, whose porosity enters Ergun (:func:`_table_4_5`), found
    before any work; ValueError when the bed has none."""
    try:
        return default_region(_packing(args, x, r), axis=args.axis)
    except NoInteriorError as exc:
        raise ValueError(f"{source}: {exc.reason}; network.paths needs an interior sample for "
                         "the Ergun porosity of its Table 4.5 (--no-branched skips it)") from exc


def _branched(args, x, r, paths, dup, region, grain):
    """The branched model on every distinct ok widest/narrowest path: Table 4.4 (Pa along the
    path) and the Table 4.5 layout (Pa over --depth, D272 of ``grain``)."""
    t2 = time.perf_counter()
    branched = []
    for i, p in enumerate(paths):
        if p.kind in ("widest", "narrowest") and p.status == "ok" and dup[i] < 0:
            tab = branched_table(x, r, p, velocities_m_s=args.velocity, branches=args.branches,
                                 mu_pa_s=args.viscosity)
            branched.append({"path": i, "kind": p.kind, "entry_xy_m": p.entry_xy.tolist(),
                             "path_depth_m": p.depth_m, **tab})
    if not branched:
        return [], {}
    print(f"branched model (Pa along each path; branches={args.branches}, Q0 = U x mean face "
          f"area; {time.perf_counter() - t2:.2f} s)")
    us = [f"{u:g}" for u in args.velocity]
    print(f"{'kind':10s} {'LFPW':8s} " + " ".join(f"MFx3@{u:<7s}" for u in us) + " "
          + " ".join(f"MFx2@{u:<7s}" for u in us))
    for b in branched:
        for w in ("max", "min", "average"):
            print(f"{b['kind']:10s} {w:8s} "
                  + " ".join(f"{b[w]['MFx3'][u]:12.3g}" for u in us) + " "
                  + " ".join(f"{b[w]['MFx2'][u]:12.3g}" for u in us))
    table45 = _table_4_5(args, x, r, branched, region, grain)
    for u in us:
        along = np.mean([b["average"]["MFx3"][u] for b in branched])
        print(f"mean MFx3 average-width at {u} m/s: {along:.3g} Pa along the paths, "
              f"{table45['branched model'][u]:.3g} Pa over {args.depth:g} m"
              + (f" (thesis {THESIS['branched_mfx3_average_pa'][u]} Pa, measured "
                 f"{THESIS['measured_pa'][u]} Pa)" if _thesis_point(args, u, grain) else ""))
    ab, label = d272_line(grain)
    print(f"Table 4.5 layout (Pa over {args.depth:g} m): "
          + "; ".join(f"{label if k == 'ASABE D272' else k} "
                      + " ".join(f"{v:.3g}" for v in vals.values())
                      for k, vals in table45.items())
          + ("" if ab else f"; {label}"))
    return branched, table45


def _table_4_5(args, x, r, branched, region, grain):
    """Pressure drops over --depth (Pa): measured (thesis, only for soybean at its 0.25 m),
    branched model (ours, mean of the MFx3 average-width paths, each drop / its L0 x depth),
    ASABE D272 with ``grain``'s constants (no row where it has none: ``d272_line``) and
    Ergun (thesis 4.2.2) with the porosity and Sauter diameter that ``network.solve`` uses (the
    exact porosity of the sample's inset window where its k is measured), so both commands
    print one Ergun value for one bed."""
    depth, velocities = args.depth, args.velocity
    pk, ax = _packing(args, x, r), axis_index(args.axis)    # porosity where network.solve's k is:
    porosity, _ = region_porosity(pk, inset_window(region, ax, pk.grain_diameter) or region, ax)
    us = [f"{u:g}" for u in velocities]
    out = {}
    if any(_thesis_point(args, u, grain) for u in us):
        out["measured (thesis)"] = {u: THESIS["measured_pa"].get(u, float("nan")) for u in us}
    out["branched model"] = {u: float(np.mean([b["average"]["MFx3"][u] / b["path_depth_m"]
                                               for b in branched]) * depth) for u in us}
    ab, _ = d272_line(grain)
    if ab is not None:
        out["ASABE D272"] = {f"{u:g}": float(asabe_d272_gradient(u, a=ab[0], b=ab[1]) * depth)
                             for u in velocities}
    out[f"Ergun (porosity {porosity:.3f})"] = {
        f"{u:g}": float(ergun_gradient(u, porosity=porosity, diameter_m=pk.sauter_diameter,
                                       viscosity_pa_s=args.viscosity) * depth)
        for u in velocities}
    return out


def _pressure_along(args, x, r, source, tess, graph, paths):
    """Network-model pressures along the paths that lie on the tessellation."""
    t = time.perf_counter()
    # sample: 1.5 mean diameters from the side walls (less in a thin bin), 4 mean diameters
    # (the thesis's 0.026 m) from the floor and from the highest centre, so a loose top surface
    # still leaves outlet pores
    d, lo, hi = 2.0 * r.mean(), x.min(axis=0), x.max(axis=0)
    m = np.minimum(1.5 * d, 0.2 * (hi - lo))
    m["xyz".index(args.axis)] = 4.0 * d
    res = solve_network(_packing(args, x, r, source), axis=args.axis, tessellation=tess,
                        sample=SampleOptions(region=Region(lo + m, hi - m), porosity_points=0),
                        conductance=ConductanceOptions(policy=args.policy),
                        flow=FlowOptions(velocity_m_s=args.velocity[0], depth_m=args.depth,
                                         viscosity_pa_s=args.viscosity))
    # the solver's own pore bodies (merged tetrahedra): its pore_ids are their labels
    p_all = pore_pressure_array(tess.n_pores, res.pore_ids, res.pressure_pa, res.pore_groups)
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
    finish(main())
