"""``python -m network.solve``: permeability and pressure drop of a packing by the network model.

Examples
--------
    python -m network.solve                                  # the bundled soybean scene
    python -m network.solve bed.csv --axis all --policy shape-factor --json out.json
    python -m network.solve bed.csv --sample 0.01 0.09 0.01 0.09 0.02 0.2 --vtk bed.vtu

Lengths are in the packing's own unit (metres by default); ``--sample`` overrides the automatic
interior box (packing extent less ``--margin`` on every side, default 1.5 mean diameters).
"""

from __future__ import annotations

import argparse
import json
import logging
import sys
import time
from pathlib import Path

import numpy as np

from ._air import MU_AIR_PA_S, RHO_AIR_KG_M3, check_positive
from .conductance import MODELS, POLICIES
from .flow import (DEFAULT_DEPTH_M, DEFAULT_VELOCITY_M_S, combined_summary, solve_axes,
                   write_network_vtu)
from .packing import default_packing_path, read_container, read_packing
from .pores import sample_region

# Thesis section 4.2.3 and Table 4.5: pressure drop over 0.25 m at 0.013 m/s (Pa)
THESIS_LSV = {"measured": 2.44, "measured_sd": 0.20, "asabe_d272": 2.28, "thesis_network": 2.20,
              "ergun": 1.27, "branched_model": 2.74}


def build_parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(
        prog="python -m network.solve",
        description="Permeability, pressure gradient and pressure drop of a sphere packing by "
                    "the Delaunay pore-network model (thesis 3.5.2), solved with pyamg.")
    ap.add_argument("packing", nargs="?", default=None,
                    help="CSV x,y,z,r / .npz / LIGGGHTS dump (default: the bundled soybean "
                         f"scene {default_packing_path().name})")
    ap.add_argument("--axis", default="z", choices=["x", "y", "z", "all"],
                    help="flow direction; 'all' solves x, y and z (default z)")
    ap.add_argument("--sample", nargs=6, type=float, metavar=("XMIN", "XMAX", "YMIN", "YMAX",
                                                              "ZMIN", "ZMAX"),
                    help="sample box (packing units); default: the interior box")
    ap.add_argument("--margin", type=float, default=None,
                    help="wall margin of the default box (default 1.5 mean diameters)")
    ap.add_argument("--cylinder", action="store_true",
                    help="use the cylinder inscribed in the sample box (axis = flow axis)")
    ap.add_argument("--viscosity", type=float, default=MU_AIR_PA_S,
                    help=f"dynamic viscosity, Pa s (default {MU_AIR_PA_S})")
    ap.add_argument("--velocity", type=float, default=DEFAULT_VELOCITY_M_S,
                    help=f"superficial velocity, m/s (default {DEFAULT_VELOCITY_M_S})")
    ap.add_argument("--density", type=float, default=RHO_AIR_KG_M3,
                    help=f"air density for the inertial loss, kg/m^3 (default {RHO_AIR_KG_M3})")
    ap.add_argument("--stokes", action="store_true",
                    help="Stokes (linear) answer only; default: pressure gradient and drop "
                         "with inertia (conduit model), the Stokes values beside them")
    ap.add_argument("--depth", type=float, default=DEFAULT_DEPTH_M,
                    help=f"bed depth for the pressure drop, m (default {DEFAULT_DEPTH_M})")
    ap.add_argument("--policy", default="table-only", choices=POLICIES,
                    help="Q* source: table-only (default: the precomputed table, the "
                         "shape-factor estimate where it cannot answer; never runs FE), "
                         "table+fe (FE for rows the table cannot answer to --rtol), fe-only, "
                         "shape-factor (fast closed form)")
    ap.add_argument("--conductance-model", default="conduit", choices=MODELS,
                    help="throat conductance model (default conduit; thesis = Eq. 3.41, L = 2 r̄)")
    ap.add_argument("--rtol", type=float, default=1e-3, help="Q* relative tolerance (1e-3)")
    ap.add_argument("--db", default=None, help="throat table (default: the cache's default)")
    ap.add_argument("--workers", type=int, default=1, help="processes for FE solves")
    ap.add_argument("--json", dest="json_out", default=None, help="write every number here")
    ap.add_argument("--vtk", default=None,
                    help="write pores (pressure) and throats (flow, conductance) as .vtu "
                         "(with --axis all: one file per axis, suffixed _x/_y/_z)")
    ap.add_argument("--quiet", "-q", action="store_true", help="no stage progress on stderr")
    return ap


def _vtk_path(base: str, axis: str, multi: bool) -> Path:
    p = Path(base)
    return p.with_name(f"{p.stem}_{axis}{p.suffix or '.vtu'}") if multi else p


def _print_result(res, out):
    s = res.summary()
    c = s["comparisons"]
    print(f"axis {res.axis}: {s['n_pores']} pores, {s['n_throats']} throats "
          f"({s['n_inlet_pores']} inlet, {s['n_outlet_pores']} outlet, "
          f"{s['n_dropped_pores']} disconnected dropped)", file=out)
    print(f"  sample H = {s['sample_length_m']:.4g} m, A = {s['sample_area_m2']:.4g} m², "
          f"porosity {s['porosity']:.4f} ± {s['porosity_std']:.4f}", file=out)
    print(f"  permeability k = {s['permeability_m2']:.4e} m²   k/d32² = {s['k_over_d2']:.4e}",
          file=out)
    if s["permeability_core_m2"] is not None:
        print(f"  core ({s['core_margin_m']:.3g} m in from every face, no boundary layer): "
              f"k = {s['permeability_core_m2']:.4e} m² "
              f"({s['permeability_core_m2'] / s['permeability_m2']:.3f} of the whole sample)",
              file=out)
    print(f"  at v = {s['velocity_m_s']:g} m/s: gradient {s['pressure_gradient_pa_per_m']:.4g} "
          f"Pa/m, drop over {s['depth_m']:g} m = {s['pressure_drop_pa']:.4g} Pa", file=out)
    if "pressure_drop_stokes_pa" in s:
        print(f"    with inertia (Re_p {s['reynolds_particle']:.3g}; Stokes "
              f"{s['pressure_gradient_stokes_pa_per_m']:.4g} Pa/m, "
              f"{s['pressure_drop_stokes_pa']:.4g} Pa; "
              f"{s['inertial_solver']['newton_iterations']} Newton iterations)", file=out)
    print(f"    Ergun {c['ergun']['pressure_drop_pa']:.4g} Pa, Kozeny-Carman "
          f"{c['kozeny_carman']['pressure_drop_pa']:.4g} Pa, ASABE D272 (soybeans) "
          f"{c['asabe_d272']['pressure_drop_pa']:.4g} Pa", file=out)
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


def _check_options(args) -> None:
    """Every numeric option checked before any work (ValueError names the option)."""
    for name in ("viscosity", "velocity", "depth", "rtol", "density"):
        check_positive(f"--{name}", getattr(args, name))
    if args.margin is not None and not args.margin >= 0:
        raise ValueError(f"--margin must be >= 0, got {args.margin!r}")
    if args.workers < 1:
        raise ValueError(f"--workers must be >= 1, got {args.workers!r}")


def main(argv=None) -> int:
    args = build_parser().parse_args(argv)
    if not args.quiet:
        logging.basicConfig(level=logging.INFO, format="[%(relativeCreated)7.0f ms] %(message)s",
                            stream=sys.stderr)
    t0 = time.perf_counter()
    path = Path(args.packing) if args.packing else default_packing_path()
    axes = ["x", "y", "z"] if args.axis == "all" else [args.axis]
    try:
        _check_options(args)
        packing = read_packing(path)
        container = None if args.sample else read_container(path)
        regions = {ax: sample_region(packing, box=args.sample, margin=args.margin,
                                     cylinder=args.cylinder, container=container, axis=ax)
                   for ax in axes}
    except (OSError, ValueError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    t_read = time.perf_counter() - t0
    if container is not None:
        print(f"container from {container['source']}: {container['kind']} {container['size_m']}")
    try:
        results = solve_axes(
            packing, regions, conductance_model=args.conductance_model, policy=args.policy,
            viscosity_pa_s=args.viscosity, velocity_m_s=args.velocity, depth_m=args.depth,
            rtol=args.rtol, db=args.db, workers=args.workers, progress=not args.quiet,
            inertia=not args.stokes and args.conductance_model == "conduit",
            density_kg_m3=args.density)
    except (ValueError, RuntimeError, NotImplementedError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 1
    if args.vtk:
        for res in results:
            p = _vtk_path(args.vtk, res.axis, len(axes) > 1)
            write_network_vtu(p, res.pore_xyz, res.conns,
                              point_data={"pressure": res.pressure_pa},
                              cell_data={"flow": np.abs(res.throat_flow_m3_s),
                                         "conductance": res.throat_conductance})
            print(f"wrote {p}")
    total = time.perf_counter() - t0
    print(f"packing {path} ({packing.n} spheres), model {args.conductance_model}, "
          f"policy {args.policy}")
    for res in results:
        _print_result(res, sys.stdout)
    out = combined_summary(results, seconds={"read": t_read, "wall": total})
    out["packing"] = str(path)
    out["n_spheres"] = packing.n
    out["thesis_lsv_reference_pa"] = THESIS_LSV
    if len(results) > 1:
        k = out["by_axis"]
        print("anisotropy: k_x : k_y : k_z = " + " : ".join(
            f"{k[a]['permeability_m2'] / out['permeability_m2']:.3f}" for a in axes)
            + " (relative to the mean)")
    if np.isclose(args.velocity, 0.013) and np.isclose(args.depth, 0.25):
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
    bad = [r.axis for r in results if not r.check["ok"]]
    if bad:
        print(f"error: mass balance check failed along {', '.join(bad)} (see mass_balance)",
              file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
