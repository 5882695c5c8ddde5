"""``python -m network.solve``: permeability and pressure drop of a packing by the network model.

Examples
--------
    python -m network.solve                                  # the bundled soybean scene
    python -m network.solve bed.csv --axis all --policy shape-factor --json out.json
    python -m network.solve bed.csv --sample 0.01 0.09 0.01 0.09 0.02 0.2 --vtk bed.vtu

The packing is read in ``--units`` (m, cm or mm; default m) and converted to metres; ``--sample``
and ``--margin`` are in that unit too; ``--sample`` overrides the automatic interior box (packing
extent less ``--margin`` on every side, default 1.5 mean diameters). ``--pores-csv`` and
``--throats-csv`` write the per-pore and per-throat tables, ``--vtk`` the ParaView file. Exit 0
done, 1 the computation failed, 2 bad input: one ``error:`` line (docs/cli.md).
"""

from __future__ import annotations

import dataclasses
import json
import sys
import time
from pathlib import Path

import numpy as np

from ._cli import (CliError, CliParser, add_air, add_packing, add_sample, add_table,
                   available_cores, bad_input, check_common, check_output_list, computing,
                   finish, load_packing, packing_inputs, progress_log, run,
                   sample_box_m, warn_validity)
from ._grains import D272, d272_line, grain_key, packing_grain
from .conductance import MODELS, POLICIES, throat_qstar
from .flow import (DEFAULT_DEPTH_M, DEFAULT_VELOCITY_M_S, ConductanceOptions, FlowOptions,
                   combined_summary, solve_axes, write_network_vtu)
from .packing import default_packing_path, read_container
from .pores import sample_region, tessellate

# Thesis section 4.2.3 and Table 4.5: pressure drop over 0.25 m at 0.013 m/s (Pa)
THESIS_LSV = {"measured": 2.44, "measured_sd": 0.20, "asabe_d272": 2.28, "thesis_network": 2.20,
              "ergun": 1.27, "branched_model": 2.74}
PORES_HEADER = "pore,x_m,y_m,z_m,volume_m3,pressure_pa"
THROATS_HEADER = "throat,pore1,pore2,area_m2,qstar,conductance_m3_per_pa_s,flow_m3_s"


def build_parser() -> CliParser:
    ap = CliParser(
        prog="python -m network.solve",
        description="Permeability, pressure gradient and pressure drop of a sphere packing by "
                    "the Delaunay pore-network model (thesis 3.5.2), solved with pyamg. Exit "
                    "status 0 done, 1 the computation failed, 2 bad input (docs/cli.md).")
    add_packing(ap)
    ap.add_argument("--axis", default="z", type=str.lower, choices=["x", "y", "z", "all"],
                    help="flow direction, any case; 'all' solves x, y and z")
    add_sample(ap)
    add_air(ap)
    ap.add_argument("--velocity", type=float, default=DEFAULT_VELOCITY_M_S,
                    help="superficial air velocity, m/s, > 0")
    ap.add_argument("--stokes", action="store_true",
                    help="Stokes (linear) answer only; default: pressure gradient and drop "
                         "with inertia (conduit model), the Stokes values beside them")
    ap.add_argument("--depth", type=float, default=DEFAULT_DEPTH_M,
                    help="bed depth for the pressure drop, m, > 0 (the thesis's comparison "
                         "is printed only at 0.25 m and 0.013 m/s)")
    ap.add_argument("--policy", default="table-only", choices=POLICIES,
                    help="Q* source: table-only (the precomputed table, the "
                         "shape-factor estimate where it cannot answer; never runs FE), "
                         "table+fe (FE for rows the table cannot answer to --rtol), fe-only, "
                         "shape-factor (fast closed form)")
    ap.add_argument("--conductance-model", default="conduit", choices=MODELS,
                    help="throat conductance model (thesis = Eq. 3.41, L = 2 r̄)")
    ap.add_argument("--grain-mates", default=None, type=str.lower,
                    choices=["off", "window", "all"],
                    help="conduit model on multi-sphere grains: take the other spheres of a "
                         "window's grains out of its section, at the window (default) or at "
                         "every section, or leave them in (off) (docs/validation-grains.md: the "
                         "bundled wheat bed's Stokes k against resolved flow -1.0 %% window, "
                         "+7.4 %% off, -13.9 %% all); sphere packings are unchanged")
    add_table(ap)
    ap.add_argument("--workers", type=int, default=1, help="processes for FE solves, >= 1")
    ap.add_argument("--threads", type=int, default=available_cores(),
                    help="threads for the conductances and the porosity (beside the "
                         "tessellation), >= 1; the result does not depend on it (default: "
                         "the cores this process may use)")
    ap.add_argument("--json", dest="json_out", default=None, metavar="OUT.json",
                    help="write every number here (default: not written)")
    ap.add_argument("--vtk", default=None, metavar="OUT.vtu",
                    help="VTK XML unstructured grid (.vtu; a legacy .vtk name is refused): "
                         "pores (pressure Pa, volume m^3) and throats (signed flow m^3/s, "
                         "conductance, area m^2, Q*), and the spheres (radius m) in "
                         "OUT_spheres.vtu; with --axis all one file per axis, _x/_y/_z "
                         "(default: not written)")
    ap.add_argument("--pores-csv", default=None, metavar="OUT.csv",
                    help=f"per-pore table {PORES_HEADER} (m, m^3, Pa of the Stokes "
                         "flow-imposed field); suffixed _x/_y/_z with --axis all "
                         "(default: not written)")
    ap.add_argument("--throats-csv", default=None, metavar="OUT.csv",
                    help=f"per-throat table {THROATS_HEADER} (pore ids as in --pores-csv; "
                         "area of the throat triangle; Q* of its window in mean-radius units; "
                         "flow > 0 from pore1 to pore2, Stokes field); suffixed with --axis "
                         "all (default: not written)")
    ap.add_argument("--grain", default=None,
                    help="the crop the bed is of, for the ASABE D272 line (any case, spaces "
                         f"or underscores: {', '.join(D272)}); default: the grain template its "
                         "companion JSON names (the bundled scene: soybean); a bed of unknown "
                         "grain gets no D272 line. A --grain that contradicts the JSON is "
                         "refused")
    ap.add_argument("--quiet", "-q", action="store_true", help="no stage progress on stderr")
    return ap


def _per_axis(base, axis: str, multi: bool, suffix: str) -> Path:
    p = Path(base)
    return p.with_name(f"{p.stem}_{axis}{p.suffix or suffix}") if multi else p


def _empirical_line(s: dict, grain) -> str:
    """Ergun, Kozeny-Carman and the grain's D272 drop (or why there is none)."""
    c = s["comparisons"]
    text = (f"    Ergun {c['ergun']['pressure_drop_pa']:.4g} Pa, Kozeny-Carman "
            f"{c['kozeny_carman']['pressure_drop_pa']:.4g} Pa, ")
    _, label = d272_line(grain)
    if c.get("asabe_d272") is not None:
        return text + f"{label} {c['asabe_d272']['pressure_drop_pa']:.4g} Pa"
    return text + label


def _print_result(res, out):
    s = res.summary()
    print(f"axis {res.axis}: {s['n_pores']} pores, {s['n_throats']} throats "
          f"({s['n_inlet_pores']} inlet, {s['n_outlet_pores']} outlet, "
          f"{s['n_dropped_pores']} disconnected dropped)", file=out)
    where = ""
    if s["sample_estimator"] == "inset" and s.get("porosity_sample") is not None:
        where = (f" (inset window, where k is measured; whole sample "
                 f"{s['porosity_sample']:.4f})")
    print(f"  sample H = {s['sample_length_m']:.4g} m, A = {s['sample_area_m2']:.4g} m², "
          f"porosity {s['porosity']:.4f} ± {s['porosity_std']:.4f}{where}", file=out)
    print(f"  permeability k = {s['permeability_m2']:.4e} m²   k/d32² = {s['k_over_d2']:.4e}",
          file=out)
    if s["permeability_core_m2"] is not None:
        print(f"  core ({s['core_margin_m']:.3g} m in from every face, no boundary layer): "
              f"k = {s['permeability_core_m2']:.4e} m² "
              f"({s['permeability_core_m2'] / s['permeability_m2']:.3f} of the whole sample)",
              file=out)
    warn_validity(s["reynolds_particle"] if "pressure_drop_stokes_pa" in s else None,
                  s["pressure_drop_pa"])
    print(f"  at v = {s['velocity_m_s']:g} m/s: gradient {s['pressure_gradient_pa_per_m']:.4g} "
          f"Pa/m, drop over {s['depth_m']:g} m = {s['pressure_drop_pa']:.4g} Pa", file=out)
    if "inertial_solver" in s and not s["inertial_solver"]["converged"]:
        print("    NOT CONVERGED: the nonlinear solve stopped short; the gradient and drop "
              "above (and Ergun beside them) are not a result", file=out)
    if "pressure_drop_stokes_pa" in s:
        print(f"    with inertia (Re_p {s['reynolds_particle']:.3g}; Stokes "
              f"{s['pressure_gradient_stokes_pa_per_m']:.4g} Pa/m, "
              f"{s['pressure_drop_stokes_pa']:.4g} Pa; "
              f"{s['inertial_solver']['newton_iterations']} Newton iterations)", file=out)
    print(_empirical_line(s, res.grain), file=out)
    src = s.get("qstar", {}).get("sources")
    if src:
        print("  Q* sources: " + ", ".join(f"{k} {v}" for k, v in src.items())
              + f" ({s['qstar'].get('seconds', float('nan')):.2f} s)", file=out)
    sv, mb = s["solver"], s["mass_balance"]
    print(f"  solver {sv['method']}: {sv['iterations']} it, residual {sv['residual']:.1e}; "
          f"inlet/outlet mismatch {mb['balance_error']:.1e} ({'ok' if mb['ok'] else 'FAILED'})",
          file=out)
    print("  seconds: " + ", ".join(f"{k} {v:.2f}" for k, v in s["seconds"].items()
                                     if isinstance(v, float)), file=out)


def _check_inputs(args, axes) -> None:
    """Every option and output path, before any work (ValueError names the option)."""
    check_common(args)
    if args.grain is not None:
        grain_key(args.grain)
    if args.grain_mates not in (None, "off") and args.conductance_model != "conduit":
        raise ValueError(f"--grain-mates {args.grain_mates}: grain mates are taken out of the "
                         f"conduit model's sections; --conductance-model "
                         f"{args.conductance_model} has none (leave --grain-mates out or give off)")
    if args.vtk and Path(args.vtk).suffix.lower() not in ("", ".vtu"):
        raise ValueError(f"--vtk {args.vtk}: the writer makes VTK XML (.vtu, read by ParaView "
                         f"and meshio), not legacy VTK; name the file "
                         f"{Path(args.vtk).with_suffix('.vtu')}")
    multi, pairs = len(axes) > 1, [("--json", args.json_out)]
    for ax in axes:
        vtu = args.vtk and _per_axis(args.vtk, ax, multi, ".vtu")
        pairs += [("--vtk", vtu),
                  ("--vtk (spheres)", vtu and vtu.with_name(f"{vtu.stem}_spheres.vtu")),
                  ("--pores-csv", args.pores_csv and _per_axis(args.pores_csv, ax, multi, ".csv")),
                  ("--throats-csv",
                   args.throats_csv and _per_axis(args.throats_csv, ax, multi, ".csv"))]
    check_output_list(pairs, packing_inputs(args))


def _pore_volume(res, tess):
    """(Ns,) volume of each sample pore (its tetrahedra, spheres included), m³."""
    if res.pore_groups is None:
        return tess.pore_volume[res.pore_ids]
    return np.bincount(res.pore_groups, weights=tess.pore_volume)[res.pore_ids]


def _throat_qstar(res, tess, args):
    """(Ms,) window Q* of the sample throats, r̄ units: the result's own when it carries them,
    else the same policy asked again (the table answers at once; FE rows come from --db)."""
    q = getattr(res, "throat_qstar", None)
    if q is not None:
        return np.asarray(q)
    ids = res.throat_ids
    return throat_qstar(tess.throat_radii[ids], tess.throat_sides[ids], policy=args.policy,
                        rtol=args.rtol, db=args.db, workers=args.workers).qstar


def _write_tables(res, tess, args, multi):
    """--vtk, --pores-csv, --throats-csv of one axis; the paths written."""
    out = []
    ids, conns = res.throat_ids, res.conns
    volume = _pore_volume(res, tess)
    qstar = _throat_qstar(res, tess, args) if args.vtk or args.throats_csv else None
    if args.vtk:
        p = _per_axis(args.vtk, res.axis, multi, ".vtu")
        write_network_vtu(p, res.pore_xyz, conns,
                          point_data={"pressure": res.pressure_pa, "volume": volume},
                          cell_data={"flow": res.throat_flow_m3_s,
                                     "conductance": res.throat_conductance,
                                     "area": tess.throat_area[ids], "qstar": qstar})
        sp = p.with_name(f"{p.stem}_spheres.vtu")
        pk = tess.packing
        write_network_vtu(sp, pk.centers, np.zeros((0, 2), dtype=np.int64),
                          point_data={"radius": pk.radii})
        out += [p, sp]
    if args.pores_csv:
        p = _per_axis(args.pores_csv, res.axis, multi, ".csv")
        np.savetxt(p, np.column_stack([res.pore_ids, res.pore_xyz, volume, res.pressure_pa]),
                   delimiter=",", header=PORES_HEADER, comments="",
                   fmt=["%d"] + ["%.10g"] * 5)
        out.append(p)
    if args.throats_csv:
        p = _per_axis(args.throats_csv, res.axis, multi, ".csv")
        np.savetxt(p, np.column_stack([ids, res.pore_ids[conns], tess.throat_area[ids], qstar,
                                       res.throat_conductance, res.throat_flow_m3_s]),
                   delimiter=",", header=THROATS_HEADER, comments="",
                   fmt=["%d"] * 3 + ["%.10g"] * 4)
        out.append(p)
    return out


def main(argv=None) -> int:
    """Run the command; exit status 0 done, 1 the computation failed, 2 bad input."""
    return run(_main, build_parser(), argv)


def _main(args) -> int:
    progress_log(args)
    t0 = time.perf_counter()
    axes = ["x", "y", "z"] if args.axis == "all" else [args.axis]
    with bad_input():
        _check_inputs(args, axes)
        grain = packing_grain(args.packing or default_packing_path(), args.grain)
        path, packing = load_packing(args)
        box, margin = sample_box_m(args)
        container = None if box else read_container(path)
        regions = {ax: sample_region(packing, box=box, margin=margin, cylinder=args.cylinder,
                                     container=container, axis=ax) for ax in axes}
        # no --grain-mates: the conduit model's default ('window'), nothing for 'thesis'
        mates = ({"grain_mates": args.grain_mates}
                 if args.grain_mates is not None and args.conductance_model == "conduit" else None)
        conductance = ConductanceOptions(model=args.conductance_model, policy=args.policy,
                                         rtol=args.rtol, db=args.db, workers=args.workers,
                                         progress=not args.quiet, model_options=mates)
        flow = FlowOptions(viscosity_pa_s=args.viscosity, velocity_m_s=args.velocity,
                           depth_m=args.depth, density_kg_m3=args.density,
                           inertia=not args.stokes and args.conductance_model == "conduit")
    t_read = time.perf_counter() - t0
    if container is not None:
        print(f"container from {container['source']}: {container['kind']} {container['size_m']}")
    tables = args.vtk or args.pores_csv or args.throats_csv
    with computing():
        tess = tessellate(packing) if tables else None
        results = solve_axes(packing, regions, conductance=conductance, flow=flow,
                             tessellation=tess, threads=args.threads)
        results = [dataclasses.replace(r, grain=grain) for r in results]
        written = [p for res in results for p in (_write_tables(res, tess, args, len(axes) > 1)
                                                  if tables else [])]
    for p in written:
        print(f"wrote {p}")
    total = time.perf_counter() - t0
    print(f"packing {path} ({packing.n} spheres, read in {args.units}), model "
          f"{args.conductance_model}, policy {args.policy}")
    for res in results:
        _print_result(res, sys.stdout)
    out = combined_summary(results, seconds={"read": t_read, "wall": total}, packing=packing)
    out["packing"] = str(path)
    out["units"] = args.units
    out["n_spheres"] = packing.n
    out["grain"] = grain
    out["converged"] = all(r.summary().get("inertial_solver", {}).get("converged", True)
                           for r in results)
    if grain == "soybean":
        out["thesis_lsv_reference_pa"] = THESIS_LSV
    if len(results) > 1:
        k = out["by_axis"]
        print("anisotropy: k_x : k_y : k_z = " + " : ".join(
            f"{k[a]['permeability_m2'] / out['permeability_m2']:.3f}" for a in axes)
            + " (relative to the mean)")
    if "permeability_tensor_m2" in out:
        kt = out["permeability_tensor_m2"]
        print(f"permeability tensor (diagonal): k_xx {kt['xx']:.4e}, k_yy {kt['yy']:.4e}, "
              f"k_zz {kt['zz']:.4e} m²; horizontal/vertical resistance "
              f"{out['horizontal_to_vertical_resistance']:.3f}")
    if out.get("orientation_order") is not None:
        print(f"grains: {packing.n_grains}, long-axis order S against the vertical "
              f"{out['orientation_order']:.3f} (1 vertical, -0.5 horizontal, 0 random)")
    if grain == "soybean" and np.isclose(args.velocity, 0.013) and np.isclose(args.depth, 0.25):
        t = THESIS_LSV
        print(f"thesis (soybeans, 0.25 m at 0.013 m/s; section 4.2.3, Table 4.5): measured "
              f"{t['measured']} ± {t['measured_sd']} Pa, ASABE {t['asabe_d272']} Pa, thesis network "
              f"{t['thesis_network']} Pa, Ergun {t['ergun']} Pa; this run: "
              f"{out['pressure_drop_pa']:.3g} Pa")
    print(f"total {total:.2f} s")
    if args.json_out:
        with open(args.json_out, "w") as f:
            json.dump(out, f, indent=2)
        print(f"wrote {args.json_out}")
    stopped = [r.axis for r in results
               if not r.summary().get("inertial_solver", {}).get("converged", True)]
    if stopped:
        raise CliError(f"the nonlinear solve did not converge along {', '.join(stopped)} at "
                       f"{args.velocity:g} m/s (the JSON says converged: false)", 1)
    bad = [r.axis for r in results if not r.check["ok"]]
    if bad:
        raise CliError(f"mass balance check failed along {', '.join(bad)} (see mass_balance)",
                       1)
    return 0


if __name__ == "__main__":
    finish(main())
