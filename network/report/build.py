"""The numbers of a report: :func:`build_report` solves a packing for :class:`ReportOptions`.

Both flow directions are solved over the options' velocities (:func:`network.flow.solve_network`
with inertia), the porosity is moved along the band (:mod:`network.report.porosity`,
:mod:`network.report.band`), and the bin's system curve, airflow and fan operating point follow
(:mod:`network.report.system`). The result is the report's JSON document as a dict.
"""

from __future__ import annotations

import logging
import time

import numpy as np

from .._cli import available_cores
from .._grains import D272, d272_velocity_range
from ..flow import (INERTIAL_LAW, FlowOptions, SampleOptions, asabe_d272_gradient, ergun_gradient,
                    fit_curve, inset_window, solve_network)
from ..packing import read_container, read_packing
from ..pores import region_porosity, sample_region
from .band import BAND_OFFSETS, band_gradients, measured_band, pack_band, slope_at
from .bed import user_bed_json
from .binbeds import bin_section, bin_velocities, solve_set
from .options import ReportOptions
from .porosity import check_reachable, shift_factor
from .system import (bulk_density, curve_range, dense_system, floor_area, operating_point,
                     system_rows, velocity_from_airflow)

__all__ = ["build_report", "KEYS", "SAME_POROSITY"]

#: below this porosity difference the packing's own porosity is the report's (no move)
SAME_POROSITY = 5e-4
log = logging.getLogger(__name__)
KEYS = ["velocity_m_s", "reynolds_particle", "pressure_gradient_pa_per_m",
        "apparent_permeability_m2", "converged"]


def _solve(o: ReportOptions, packing, container, axis, us, porosity=None):
    region, us = sample_region(packing, box=o.sample_box_m, margin=o.margin_m, container=container,
                               axis=axis), sorted(us)
    flow = FlowOptions(viscosity_pa_s=o.viscosity_pa_s, velocity_m_s=us[0], depth_m=o.depth_m,
                       inertia=True, density_kg_m3=o.density_kg_m3, curve_velocities_m_s=us[1:],
                       inertial_workers=available_cores())
    return solve_network(packing, axis=axis, sample=SampleOptions(region=region, porosity=porosity),
                         flow=flow, threads=available_cores())


def _fits(o: ReportOptions, pts, porosity, d32):
    """fit_curve over the converged points (as reported, at the report's porosity)."""
    ok = [p for p in pts if p["converged"]]
    if not ok:
        return {}
    return fit_curve([p["velocity_m_s"] for p in ok], [p["pressure_gradient_pa_per_m"] for p in ok],
                     viscosity_pa_s=o.viscosity_pa_s, density_kg_m3=o.density_kg_m3,
                     porosity=porosity, diameter_m=d32)


def _points(res):
    return [{k: p[k] for k in KEYS} for p in res.curve_points()]


def solve_bin_bed(o: ReportOptions, path, us) -> dict:
    """One bed of the bin's set solved at velocities ``us`` in both directions: its porosity
    (where k is measured, as the report's own) and gradients, Pa/m."""
    packing = read_packing(path)
    container = None if o.sample_box_m else read_container(path)
    rz = _solve(o, packing, container, "z", us)
    rx = _solve(o, packing, container, "x", us)
    pz, px = rz.curve_points(), rx.curve_points()
    return {"porosity": float(rz.porosity),
            "gradient_z_pa_per_m": [float(p["pressure_gradient_pa_per_m"]) for p in pz],
            "gradient_x_pa_per_m": [float(p["pressure_gradient_pa_per_m"]) for p in px],
            "converged": [bool(a["converged"] and b["converged"]) for a, b in zip(pz, px)]}


def _bin_beds(o: ReportOptions) -> dict | None:
    """The ``bin_beds`` entry: the set solved (or read from its cache) and integrated over the
    bin's depth (:mod:`network.report.binbeds`); the plan's one line where it is not used."""
    plan = o.bin_beds
    if plan is None:
        return None
    if not plan["used"]:
        return {"used": False, "why": plan["why"]}
    us = bin_velocities(o.velocities_m_s)
    inputs = {"velocities_m_s": us, "viscosity_pa_s": o.viscosity_pa_s,
              "density_kg_m3": o.density_kg_m3, "sample_box_m": o.sample_box_m,
              "margin_m": o.margin_m}
    solved = solve_set(plan, lambda path: solve_bin_bed(o, path, us), inputs)
    c = D272[o.grain]
    out = bin_section(plan, solved, us, None if c.a_pa_s2_m3 is None else (c.a_pa_s2_m3, c.b_s_m))
    if plan.get("pack"):
        out["packed"] = plan["pack"]
    return out


def _porosity_plan(o: ReportOptions, e_p: float):
    """(porosity of the report, why, whether to move along the band, bulk density kg/m^3) for a
    packing of porosity ``e_p``; UnreachablePorosity where the report's is out of reach."""
    why = o.porosity_source
    e = e_p if o.porosity is None else o.porosity
    check_reachable(e, e_p, o.reachable, o.grain)
    move = abs(e - e_p) > SAME_POROSITY
    if move and not o.band:
        why = (f"the packing's own: --no-band gives no computed slope to move it to {e:.4f} "
               f"({why})")
        e, move = e_p, False
    return e, why, move, bulk_density(o.particle_density_kg_m3, e)


def build_report(packing, path, options: ReportOptions) -> dict:
    """All the numbers of the report (the JSON document) of ``packing`` (read from ``path``).

    Parameters
    ----------
    packing : network.packing.Packing
        The bed, in metres.
    path : str or Path
        Its file (the companion JSON's container bounds the sample where no box is given).
    options : ReportOptions
        Grain, velocities, porosity, bin, air (see the class).

    Returns
    -------
    dict
        The report (``docs/report.md`` lists the keys). ValueError (``bad_input``) where the
        report's porosity lies outside the range a packing of the grain reaches.
    """
    o = options
    t0 = time.perf_counter()
    container = None if o.sample_box_m else read_container(path)
    us = list(o.velocities_m_s)
    # the porosity first (solve_network's): the airflow's velocity needs the bulk density. It is
    # the porosity of the region k is measured in: the inset window where the sample is wide
    # enough for one (network.flow.inset_window), else the whole sample
    reg_z = sample_region(packing, box=o.sample_box_m, margin=o.margin_m, container=container,
                          axis="z")
    eps_z = region_porosity(packing, reg_z, 2, n_points=200_000)
    win = inset_window(reg_z, 2, packing.grain_diameter)
    e_p = (eps_z if win is None else region_porosity(packing, win, 2, n_points=200_000))[0]
    e, why, move, rho_b = _porosity_plan(o, e_p)
    u_air = None
    if o.airflow:
        u_air = velocity_from_airflow(*o.airflow, depth_m=o.depth_m,
                                      bulk_density_kg_m3=rho_b)
        if all(abs(u_air - u) > 1e-12 * u for u in us):
            us.append(u_air)
    rz = _solve(o, packing, container, "z", us, eps_z)
    if rz.porosity != e_p:      # the window's k could not be measured: the sample's pair
        log.warning("the inset window's permeability could not be measured: the report uses "
                    "the whole sample's k and porosity %.4f (the airflow's bulk density was "
                    "taken at %.4f)", rz.porosity, e_p)
        e_p = rz.porosity
        e, why, move, rho_b = _porosity_plan(o, e_p)
    rx, d32 = _solve(o, packing, container, "x", us), rz.sauter_diameter_m
    pts, pts_x = _points(rz), _points(rx)
    band = None
    if o.band and packing.n_grains < packing.n and not o.sphere_band:
        band = measured_band(o.grain)     # the grain's own DEM beds, where bundled
    if o.band and band is None:
        ub = sorted(us)
        band = pack_band(packing, e_p, velocities_m_s=[ub[0], float(np.sqrt(ub[0] * ub[-1])),
                                                     ub[-1]],
                         seeds=(o.band_seed, o.band_seed + 1),
                         viscosity_pa_s=o.viscosity_pa_s,
                         density_kg_m3=o.density_kg_m3)
    c = D272[o.grain]
    d272_range, d272_range_source = d272_velocity_range(o.grain)
    for p, px in zip(pts, pts_x):
        u = p["velocity_m_s"]
        f, sig = 1.0, 0.0
        if move:
            f, sig = shift_factor(slope_at(u, band["velocities_m_s"], band["slopes"]),
                                  slope_at(u, band["velocities_m_s"], band["slope_stderrs"]),
                                  e - e_p)
        p["pressure_gradient_packing_pa_per_m"] = p["pressure_gradient_pa_per_m"]
        p["pressure_gradient_pa_per_m"] *= f
        p["apparent_permeability_m2"] = o.viscosity_pa_s * u / p["pressure_gradient_pa_per_m"]
        px["pressure_gradient_pa_per_m"] *= f
        p["porosity_shift_factor"], p["porosity_shift_ln_stderr"] = f, sig
        p["d272_pressure_gradient_pa_per_m"] = (
            None if c.a_pa_s2_m3 is None else
            float(asabe_d272_gradient(u, a=c.a_pa_s2_m3, b=c.b_s_m)))
        p["ergun_pressure_gradient_pa_per_m"] = float(ergun_gradient(
            u, porosity=e, diameter_m=d32, viscosity_pa_s=o.viscosity_pa_s,
            density_kg_m3=o.density_kg_m3))
        p["pressure_gradient_horizontal_pa_per_m"] = px["pressure_gradient_pa_per_m"]
        p["converged_horizontal"] = px["converged"]
        p["band_slope"] = None if band is None else slope_at(u, band["velocities_m_s"],
                                                             band["slopes"])
        p["pressure_gradient_band_pa_per_m"] = (
            None if band is None else
            dict(zip([f"{o:+.2f}" for o in BAND_OFFSETS],
                     band_gradients(p["pressure_gradient_pa_per_m"], p["band_slope"]))))
    area = floor_area(o.diameter_m, o.floor_area_m2)
    flow = pts if o.axis == "z" else pts_x          # the direction the bin's air takes
    ok = [p for p in flow if p["converged"]]
    su = [p["velocity_m_s"] for p in ok]
    sg = [p["pressure_gradient_pa_per_m"] for p in ok]
    system = system_rows(su, sg, depth_m=o.depth_m, area_m2=area, bulk_density_kg_m3=rho_b)
    out = {"grain": o.grain, "packing": str(path), "n_spheres": packing.n,
           "n_grains": packing.n_grains, "porosity": e, "inertial_law": INERTIAL_LAW,
           "porosity_source": f"{o.bed_label}; {why}",
           "bed": dict(o.bed_record) if o.bed_record is not None else user_bed_json(path),
           "porosity_packing": e_p, "porosity_packing_std": rz.porosity_std,
           "porosity_packing_sample": rz.porosity_sample,
           "porosity_packing_region": ("inset window (where k is measured)"
                                       if rz.sample_estimator == "inset" else "sample"),
           "porosity_reachable": None if o.reachable is None else list(o.reachable["range"]),
           "porosity_reachable_tol": None if o.reachable is None else o.reachable["tol"],
           "porosity_reachable_source": None if o.reachable is None else o.reachable["source"],
           "porosity_move": ("none: the packing's own porosity" if not move else
                             f"along the band's computed slope from the packing's {e_p:.4f} to "
                             f"{e:.4f} (g exp(S de); not packed anew)"),
           "sauter_diameter_m": d32, "viscosity_pa_s": o.viscosity_pa_s,
           "air_density_kg_m3": o.density_kg_m3,
           "particle_density_kg_m3": o.particle_density_kg_m3,
           "particle_density_source": o.particle_density_source,
           "bulk_density_kg_m3": rho_b,
           "d272": {"a_pa_s2_m3": c.a_pa_s2_m3, "b_s_m": c.b_s_m, "source": c.source,
                    "note": c.note, "velocity_range_m_s": list(d272_range),
                    "velocity_range_source": d272_range_source},
           "permeability_stokes_m2": {"z": rz.permeability_m2, "x": rx.permeability_m2},
           "horizontal_to_vertical_stokes": rz.permeability_m2 / rx.permeability_m2,
           "permeability_stokes_note": "as solved, at the packing's own porosity",
           "fits": _fits(o, pts, e, d32), "fits_horizontal": _fits(o, pts_x, e, d32),
           "points": pts, "band": band,
           "bin": {"depth_m": o.depth_m, "diameter_m": o.diameter_m, "floor_area_m2": area,
                   "flow_axis": o.axis,
                   "grain_mass_t": rho_b * area * o.depth_m / 1000.0},
           "system_curve": system, "airflow": None, "operating_point": None}
    if u_air is not None:
        at = next(p for p in flow if abs(p["velocity_m_s"] - u_air) <= 1e-12 * u_air)
        out["airflow"] = system_rows([u_air], [at["pressure_gradient_pa_per_m"]],
                                     depth_m=o.depth_m, area_m2=area,
                                     bulk_density_kg_m3=rho_b)[0]
        out["airflow"]["converged"] = bool(at["converged"])
    if o.fan is not None:
        sq, sp = dense_system(su, sg, depth_m=o.depth_m, area_m2=area)
        op = operating_point(sq, sp, *o.fan)
        out["fan_curve"] = {"airflow_m3_s": list(o.fan_airflow_m3_s),
                            "static_pressure_pa": list(o.fan_static_pressure_pa),
                            "file": o.fan_file}
        if op is None:
            out["operating_point"] = {"found": False, "message": (
                "no operating point: " + curve_range("system curve", sq, sp) + "; "
                + curve_range("fan", *o.fan))}
        else:
            row = system_rows([op[0] / area], [op[1] / o.depth_m], depth_m=o.depth_m,
                              area_m2=area, bulk_density_kg_m3=rho_b)[0]
            out["operating_point"] = {"found": True, **row}
    out["bin_beds"] = _bin_beds(o)
    out["seconds"] = time.perf_counter() - t0
    return out
