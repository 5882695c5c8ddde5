"""``python -m network.bin``: airflow through a grain bin and the fan that drives it.

Examples
--------
    python -m network.bin --grain wheat --diameter 8 --depth 5 --top peaked --floor full \\
        --airflow 0.1 m3/min/t
    python -m network.bin --grain wheat --diameter 8 --depth 5 --floor duct --duct 0.6 6 0 \\
        --pressure 800 --json bin.json --vtk bin.vtk
    python -m network.bin --grain wheat --diameter 8 --depth 5 --fan fan.csv --law d272

Steady Darcy-Forchheimer flow through the grain bulk, solved for the pressure with scikit-fem on
a gmsh mesh (r-z without ducts, 3-D with them): docs/bin.md. Exit 0 done, 1 the computation
failed (Newton's method at a named pressure, a fan curve that never crosses the bin's), 2 bad
input: one ``error:`` line.
"""

from __future__ import annotations

import json
import math
import time
from pathlib import Path

import numpy as np

from .._cli import (CliError, CliParser, add_air, bad_input, check_common, check_outputs,
                    check_plot, computing, finish, progress_log, run)
from .._grains import BED, D272, grain_key
from ..report.system import AIRFLOW_UNITS, M3_MIN_M3_PER_CFM_BU, parse_airflow, read_fan
from ._geometry import BinGeometry, Duct, default_size, duct_size, mesh_bin
from ._material import ANGLE_OF_REPOSE, JANSSEN, d272_material, network_material, read_profile
from ._outputs import aeration, write_figure, write_vtk
from ._solve import BinProblem
from ._system import fan_operating_point, pressure_for_airflow, solve_checked, system_curve

#: default element counts at the bulk's size: r-z triangles, 3-D tetrahedra (the ducts'
#: refinement adds to the latter: 215 000 in all for the documented 8 m duct bin)
ELEMENTS_RZ, ELEMENTS_3D = 8_000, 120_000
#: the refinement check's coarser mesh: element size times this
COARSE_FACTOR_RZ, COARSE_FACTOR_3D = 2.0, 1.5
#: the tolerance the refinement check is held to (relative airflow difference)
REFINEMENT_TOL = 0.005


def build_parser() -> CliParser:
    ap = CliParser(prog="python -m network.bin",
                   description="Steady airflow through a round grain bin (Darcy-Forchheimer "
                               "with tensor permeability from the pore network, or D272), "
                               "solved with scikit-fem on a gmsh mesh: static pressure, "
                               "airflow, system curve, uniformity, fan operating point. Exit "
                               "status 0 done, 1 the computation failed, 2 bad input.")
    ap.add_argument("--grain", default="wheat", help=f"crop: {', '.join(D272)}")
    ap.add_argument("--law", default="network", choices=["network", "d272"],
                    help="network: k_v, k_h, beta from the network's porosity band and "
                         "curves (grains with bundled band data: wheat); d272: the standard's "
                         "Shedd constants (loose fill, isotropic)")
    ap.add_argument("--report", default=None, metavar="FILE",
                    help="the network law from a python -m network.report --json file of the "
                         "grain (its bed's curves in z and x, its porosity band) instead of the "
                         "bundled data: any grain the report covers")
    ap.add_argument("--diameter", type=float, required=True, help="bin diameter, m, > 0")
    ap.add_argument("--depth", type=float, required=True,
                    help="eave depth: grain depth at the wall, m, > 0")
    ap.add_argument("--top", default="flat", choices=["flat", "peaked", "inverted"],
                    help="grain surface: flat, peaked (cone) or inverted (inverted cone)")
    ap.add_argument("--peak-angle", type=float, default=None,
                    help="cone angle, degrees, in (0, 90) (default: the grain's filling angle "
                         "of repose)")
    ap.add_argument("--floor", default="full", choices=["full", "duct"],
                    help="full: fully perforated floor (r-z); duct: solid floor with ducts (3-D)")
    ap.add_argument("--duct", nargs=3, type=float, action="append", default=None,
                    metavar=("DIAMETER", "LENGTH", "OFFSET"),
                    help="a perforated floor duct along x from the wall: diameter and length "
                         "(m), axis offset from the bin's centre line (m); repeat for more")
    ap.add_argument("--duct-shape", default="half-round", choices=["round", "half-round"],
                    help="duct cross-section")
    ap.add_argument("--porosity", type=float, default=None,
                    help="uniform porosity (default: the grain's measured loose-fill porosity)")
    ap.add_argument("--porosity-profile", default=None, metavar="FILE",
                    help="CSV depth_m,porosity: porosity against depth below the grain surface")
    ap.add_argument("--compaction", default=None, metavar="FILE",
                    help="CSV stress_pa,porosity: porosity against vertical stress, applied to "
                         "Janssen's stress (wall friction and K from the grain library or the "
                         "two options below)")
    ap.add_argument("--wall-friction", type=float, default=None,
                    help="grain-wall friction coefficient for Janssen, > 0 (default: the grain "
                         "library's on a smooth steel wall)")
    ap.add_argument("--lateral-ratio", type=float, default=None,
                    help="Janssen's lateral-to-vertical stress ratio K, in (0, 1] (default: the "
                         "grain library's)")
    ap.add_argument("--particle-density", type=float, default=None,
                    help="kernel density, kg/m^3 (default: the grain library's)")
    add_air(ap)
    drive = ap.add_mutually_exclusive_group(required=True)
    drive.add_argument("--pressure", type=float, default=None,
                       help="fan static pressure at the plenum/ducts, Pa above atmospheric")
    drive.add_argument("--airflow", nargs=2, default=None, metavar=("VALUE", "UNIT"),
                       help=f"wanted airflow, UNIT one of {', '.join(AIRFLOW_UNITS)} (m/s: "
                            "superficial velocity over the floor area)")
    drive.add_argument("--fan", default=None, metavar="FILE",
                       help="fan curve CSV airflow_m3_s,static_pressure_pa: operating point")
    ap.add_argument("--curve-points", type=int, default=10,
                    help="points of the system curve, 8-12")
    ap.add_argument("--elements", type=int, default=None,
                    help=f"about this many elements at the bulk's element size (default "
                         f"{ELEMENTS_RZ} r-z triangles, {ELEMENTS_3D} tetrahedra in 3-D, where "
                         "the refinement at the ducts adds about as many again)")
    ap.add_argument("--mesh-size", type=float, default=None,
                    help="element size, m (instead of --elements)")
    ap.add_argument("--no-refinement-check", action="store_true",
                    help="skip the solve on a coarser mesh that checks the airflow's "
                         "convergence")
    ap.add_argument("--grain-heat-capacity", type=float, default=None,
                    help="grain specific heat, J/(kg K): adds the temperature front's time to "
                         "the cooling estimate")
    ap.add_argument("--figure", default=None, metavar="OUT.png",
                    help="figure of the r-z section (default: bin_<grain>.png)")
    ap.add_argument("--no-figure", action="store_true", help="write no figure")
    ap.add_argument("--vtk", default=None, metavar="OUT.vtk", help="legacy VTK file for ParaView")
    ap.add_argument("--json", dest="json_out", default=None, metavar="OUT.json",
                    help="write everything here")
    ap.add_argument("--quiet", "-q", action="store_true", help="no stage progress on stderr")
    return ap


def _positive(name, v, upper=None):
    if v is not None and not (np.isfinite(v) and v > 0 and (upper is None or v <= upper)):
        rng = "> 0" if upper is None else f"in (0, {upper:g}]"
        raise ValueError(f"--{name} must be finite and {rng}, got {v!r}")


def _check(args) -> dict:
    """Every option checked before any mesh or solve."""
    check_common(args)
    try:
        key = grain_key(args.grain)
    except ValueError:
        raise ValueError(f"--grain {args.grain!r}: unknown; known grains: "
                         f"{', '.join(D272)}") from None
    for name in ("pressure", "particle_density", "wall_friction", "mesh_size",
                 "grain_heat_capacity"):
        _positive(name.replace("_", "-"), getattr(args, name))
    _positive("lateral-ratio", args.lateral_ratio, 1.0)
    if args.porosity is not None and not (np.isfinite(args.porosity) and 0 < args.porosity < 1):
        raise ValueError(f"--porosity must be in (0, 1), got {args.porosity!r}")
    if sum(x is not None for x in (args.porosity, args.porosity_profile, args.compaction)) > 1:
        raise ValueError("give one of --porosity, --porosity-profile, --compaction")
    if args.compaction is None and (args.wall_friction is not None
                                    or args.lateral_ratio is not None):
        raise ValueError("--wall-friction and --lateral-ratio go with --compaction")
    if args.compaction is not None:
        k_lat, mu_w = JANSSEN.get(key, (None, None))
        args.lateral_ratio = args.lateral_ratio if args.lateral_ratio is not None else k_lat
        args.wall_friction = args.wall_friction if args.wall_friction is not None else mu_w
        if args.wall_friction is None or args.lateral_ratio is None:
            raise ValueError(f"--compaction: the grain library has no Janssen "
                             f"{'K' if args.lateral_ratio is None else 'wall friction'} for "
                             f"{key}: give --lateral-ratio and --wall-friction")
    if not 8 <= args.curve_points <= 12:
        raise ValueError(f"--curve-points must be 8-12, got {args.curve_points}")
    if args.elements is not None and args.mesh_size is not None:
        raise ValueError("give --elements or --mesh-size, not both")
    if args.elements is not None and not 200 <= args.elements <= 3_000_000:
        raise ValueError(f"--elements must be 200-3000000, got {args.elements}")
    angle = args.peak_angle
    if args.top == "flat":
        if angle is not None:
            raise ValueError("--peak-angle needs --top peaked or inverted")
        angle = 0.0
    elif angle is None:
        if key not in ANGLE_OF_REPOSE:
            raise ValueError(f"no sourced angle of repose for {key}: give --peak-angle")
        angle = ANGLE_OF_REPOSE[key][0]
    ducts = tuple(Duct(d, l, o, args.duct_shape) for d, l, o in (args.duct or []))
    geom = BinGeometry(args.diameter, args.depth, args.top, angle, args.floor, ducts)
    profile = compaction = None
    if args.porosity_profile is not None:
        profile = read_profile(args.porosity_profile, "--porosity-profile")
    if args.compaction is not None:
        compaction = read_profile(args.compaction, "--compaction")
    airflow = None
    if args.airflow is not None:
        airflow = parse_airflow(*args.airflow)
    fan = read_fan(args.fan) if args.fan is not None else None
    if fan is not None and not np.any(fan[1] > 0):
        raise ValueError(f"--fan {args.fan}: no static pressure above 0")
    figure = None if args.no_figure else (args.figure or f"bin_{key}.png")
    inputs = [(f"--{o.replace('_', '-')}", getattr(args, o)) for o in
              ("porosity_profile", "compaction", "fan", "report") if getattr(args, o)]
    check_outputs(json=args.json_out, vtk=args.vtk, figure=figure, inputs=inputs)
    if figure is not None:
        check_plot("--figure", figure)
    kw = dict(viscosity_pa_s=args.viscosity, density_kg_m3=args.density,
              porosity=args.porosity, particle_density=args.particle_density)
    if profile is not None:
        kw["profile"] = profile
    if compaction is not None:
        rho_p = args.particle_density or BED[key].particle_density_kg_m3
        loose = BED[key].loose_fill_porosity
        if rho_p is None or loose is None:
            raise ValueError(f"--compaction: no kernel density or loose-fill porosity for {key} "
                             "(the surface's bulk density for Janssen)")
        kw["compaction"] = compaction
        kw["janssen"] = (rho_p * (1 - loose), geom.diameter_m, args.wall_friction,
                         args.lateral_ratio)
    if args.report is not None:
        if args.law != "network":
            raise ValueError("--report gives the network law: not with --law d272")
        kw["report"] = args.report
    make = network_material if args.law == "network" else d272_material
    material = make(key, **kw)
    angle_source = (None if args.top == "flat" else "--peak-angle" if args.peak_angle is not None
                    else ANGLE_OF_REPOSE[key][1])
    return {"grain": key, "geom": geom, "material": material, "airflow": airflow, "fan": fan,
            "figure": figure, "angle_source": angle_source}


def _mesh_size(args, geom):
    if args.mesh_size is not None:
        return args.mesh_size
    n = args.elements or (ELEMENTS_RZ if geom.axisymmetric else ELEMENTS_3D)
    return default_size(geom, n)


def _row(sol, mass_t):
    return {"static_pressure_pa": sol.pressure_pa, "airflow_m3_s": sol.inflow_m3_s,
            "airflow_m3_per_min_t": 60.0 * sol.inflow_m3_s / mass_t}


def build(args, opts) -> dict:
    """Mesh, solve, check: every number of the output."""
    import logging

    log = logging.getLogger("network.bin")
    t0 = time.perf_counter()
    geom, material = opts["geom"], opts["material"]
    size = _mesh_size(args, geom)
    mesh = mesh_bin(geom, size)
    t_mesh = time.perf_counter() - t0
    log.info("mesh: %d %s, %d nodes (%.1f s)", mesh.n_elements,
             "triangles (r-z)" if mesh.axisymmetric else "tetrahedra", mesh.points.shape[1],
             t_mesh)
    prob = BinProblem(mesh, material, geom.surface_height)
    mass_t = prob.grain_mass_kg() / 1000.0
    floor = math.pi * geom.radius_m**2
    n = args.curve_points
    fan_msg = None
    if args.pressure is not None:
        sol = solve_checked(prob, args.pressure)
        curve = system_curve(prob, args.pressure * np.geomspace(0.25, 2.0, n), start=sol)
    elif opts["airflow"] is not None:
        v, unit = opts["airflow"]
        q = {"m3/min/t": v * mass_t / 60.0, "m3/min/m3": v * geom.grain_volume_m3 / 60.0,
             "cfm/bu": v * M3_MIN_M3_PER_CFM_BU * geom.grain_volume_m3 / 60.0,
             "m/s": v * floor}[unit]
        eps0 = float(np.sum(prob.porosity * prob.volumes) / np.sum(prob.volumes))
        guess = float(material.gradient_1d(q / floor, eps0)[0]) * geom.grain_volume_m3 / floor
        sol = pressure_for_airflow(prob, q, guess)
        curve = system_curve(prob, sol.pressure_pa * np.geomspace(0.25, 2.0, n), start=sol)
    else:
        fq, fp = opts["fan"]
        top = float(fp.max())
        curve = system_curve(prob, top * np.geomspace(1.0 / 30.0, 1.0, n))
        sol, fan_msg = fan_operating_point(prob, curve, fq, fp)
    t_solve = time.perf_counter() - t0 - t_mesh
    log.info("solved (%.1f s)", t_solve)
    check = None
    if not args.no_refinement_check and sol is not None:
        f = COARSE_FACTOR_RZ if mesh.axisymmetric else COARSE_FACTOR_3D
        coarse = mesh_bin(geom, size * f, duct_size_m=duct_size(geom, size) * f)
        cs = solve_checked(BinProblem(coarse, material, geom.surface_height), sol.pressure_pa)
        rel = abs(cs.inflow_m3_s / sol.inflow_m3_s - 1.0)
        check = {"coarse_elements": coarse.n_elements, "coarse_size_m": size * f,
                 "coarse_airflow_m3_s": cs.inflow_m3_s, "relative_difference": rel,
                 "tolerance": REFINEMENT_TOL, "within_tolerance": bool(rel <= REFINEMENT_TOL)}
        log.info("refinement check: %d elements, airflow differs by %.3g %%",
                 coarse.n_elements, 100 * rel)
    out = {"grain": opts["grain"], "law": material.law,
           "geometry": {**geom.as_json(), "peak_angle_source": opts["angle_source"]},
           "material": material.as_json(), "grain_mass_t": mass_t,
           "system_curve": [_row(s, mass_t) for s in curve],
           "mesh": {"elements": mesh.n_elements, "nodes": int(mesh.points.shape[1]),
                    "size_m": size, "axisymmetric": mesh.axisymmetric,
                    "duct_size_m": None if mesh.axisymmetric else duct_size(geom, size),
                    "refinement_check": check}}
    if sol is None:
        out.update(converged=True, fan_message=fan_msg)
        out["seconds"] = time.perf_counter() - t0
        return out
    info = aeration(prob, sol, grain_heat_capacity=args.grain_heat_capacity)
    out.update(_row(sol, mass_t))
    out.update({
        "converged": bool(sol.converged and all(s.converged for s in curve)),
        "newton_iterations": sol.iterations, "newton_residual": sol.residual,
        "mass_balance": {"plenum_inflow_m3_s": sol.inflow_m3_s,
                         "surface_outflow_m3_s": sol.outflow_m3_s,
                         "relative_difference": abs(sol.inflow_m3_s - sol.outflow_m3_s)
                         / sol.inflow_m3_s},
        "underaerated_fraction": info["underaerated_fraction"],
        "least_aerated": info["least_aerated"], "cooling_estimate": info["cooling_estimate"],
        "porosity_range": [float(prob.porosity.min()), float(prob.porosity.max())],
        "superficial_velocity_max_m_s": float(np.linalg.norm(sol.velocity, axis=0).max())})
    if opts["fan"] is not None:
        out["fan_curve"] = {"file": args.fan, "airflow_m3_s": opts["fan"][0].tolist(),
                            "static_pressure_pa": opts["fan"][1].tolist()}
    out["seconds"] = {"mesh": t_mesh, "solve": t_solve, "total": time.perf_counter() - t0}
    out["_problem"], out["_solution"], out["_info"] = prob, sol, info
    return out


def print_result(r) -> None:
    g = r["geometry"]
    shape = g["top"] + ("" if g["top"] == "flat" else f" {g['peak_angle_deg']:g} deg")
    floor = "full floor" if g["floor"] == "full" else (
        f"{len(g['ducts'])} {g['ducts'][0]['shape']} duct(s)")
    m = r["mesh"]
    print(f"bin: {r['grain']}, diameter {g['diameter_m']:g} m, eave depth {g['depth_m']:g} m, "
          f"{shape} top, {floor}; {r['grain_mass_t']:.4g} t; law {r['law']}")
    print(f"mesh: {m['elements']} {'r-z triangles' if m['axisymmetric'] else 'tetrahedra'}, "
          f"{m['nodes']} nodes")
    print(f"{'static Pa':>10} {'Q m^3/s':>10} {'m^3/(min t)':>12}   system curve")
    for s in r["system_curve"]:
        print(f"{s['static_pressure_pa']:10.4g} {s['airflow_m3_s']:10.4g} "
              f"{s['airflow_m3_per_min_t']:12.4g}")
    if "static_pressure_pa" not in r:
        return
    print(f"operating point: static pressure {r['static_pressure_pa']:.4g} Pa, airflow "
          f"{r['airflow_m3_s']:.4g} m^3/s = {r['airflow_m3_per_min_t']:.4g} m^3/(min t)")
    mb = r["mass_balance"]
    print(f"mass balance: plenum {mb['plenum_inflow_m3_s']:.10g}, surface "
          f"{mb['surface_outflow_m3_s']:.10g} m^3/s (relative {mb['relative_difference']:.1e})")
    la = r["least_aerated"]
    print(f"uniformity: {100 * r['underaerated_fraction']:.2f} % of the grain below half the "
          f"mean airflow per tonne; least aerated at r {la['r_m']:.3g} m, z {la['z_m']:.3g} m "
          f"({la['depth_below_surface_m']:.3g} m deep): {la['airflow_m3_per_min_t']:.3g} "
          f"m^3/(min t), {la['ratio_to_mean']:.3g} of the mean")
    ce = r["cooling_estimate"]
    line = f"cooling estimate there: {ce['air_exchange_time_h']:.3g} h per grain volume of air"
    if "front_time_h" in ce:
        line += f"; temperature front {ce['front_time_h']:.3g} h"
    print(line + " (estimates)")
    c = m["refinement_check"]
    if c:
        print(f"refinement check: a coarser mesh ({c['coarse_elements']} elements) gives "
              f"{c['coarse_airflow_m3_s']:.6g} m^3/s, {100 * c['relative_difference']:.3f} % "
              f"from this one ({'within' if c['within_tolerance'] else 'NOT within'} "
              f"{100 * c['tolerance']:g} %)")
    s = r["seconds"]
    print(f"time: mesh {s['mesh']:.1f} s, solves {s['solve']:.1f} s, total {s['total']:.1f} s")


def main(argv=None) -> int:
    """Run the command; exit status 0 done, 1 the computation failed, 2 bad input."""
    return run(_main, build_parser(), argv)


def _main(args) -> int:
    progress_log(args)
    with bad_input():
        opts = _check(args)
    with computing():
        r = build(args, opts)
    print_result(r)
    if "static_pressure_pa" not in r:
        raise CliError(r["fan_message"], 1)
    prob, sol, info = r.pop("_problem"), r.pop("_solution"), r.pop("_info")
    with computing():
        if opts["figure"]:
            g = r["geometry"]
            title = (f"{r['grain']}, {g['diameter_m']:g} m x {g['depth_m']:g} m, {g['top']} "
                     f"top, {g['floor']} floor: {r['static_pressure_pa']:.4g} Pa, "
                     f"{r['airflow_m3_s']:.3g} m$^3$/s")
            write_figure(opts["figure"], prob, sol, info, opts["geom"], title)
            print(f"wrote {opts['figure']}")
        if args.vtk:
            write_vtk(args.vtk, prob, sol, info["local_airflow_m3_per_min_t"],
                      info["underaerated_mask"])
            print(f"wrote {args.vtk}")
        if args.json_out:
            Path(args.json_out).write_text(json.dumps(r, indent=2))
            print(f"wrote {args.json_out}")
    if not r["converged"]:
        raise CliError("a system-curve point did not converge", 1)
    return 0


if __name__ == "__main__":
    finish(main())
