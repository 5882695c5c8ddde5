"""The command line of ``python -m network.report``: its options, their checks, the printed report.

:func:`main` parses and checks every option before any work (exit 2 naming it), plans or packs
the bed (:mod:`network.report.bed`), turns the options into a :class:`ReportOptions`, has
:func:`network.report.build.build_report` compute the report, prints it and writes the JSON,
the figures and the HTML page. Exit 0 done, 1 a solve failed, 2 bad input.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

from .._cli import (CliError, CliParser, add_air, add_sample, bad_input, check_common,
                    check_output_list, check_outputs, check_plot, computing, load_packing,
                    packing_inputs, progress_log, run, sample_box_m, warn_curve)
from .._grains import BED, D272, grains_with_d272, packing_grain
from ..curve import DEFAULT_VELOCITIES, parse_velocities
from ..flow import DEFAULT_DEPTH_M
from ..packing import UNITS, read_container
from .band import BAND_OFFSETS
from .bed import (TEMPLATE_GRAINS, add_bed_options, bed_json, bed_paths, check_bed_dir, plan_bed,
                  prepare_bed)
from .binbeds import bed_set_inputs, check_bin_depth, janssen_inputs, pack_bed_set, plan_bin_beds
from .build import build_report
from .figures import FIGURES, write_figures, write_html
from .options import ReportOptions, grain_key
from .porosity import (bundled_grains, bundled_packing, check_reachable, packing_meta,
                       reach_record, requested_porosity)
from .system import AIRFLOW_UNITS, parse_airflow, read_fan

__all__ = ["build_parser", "main", "print_report", "report_options"]


def build_parser() -> CliParser:
    ap = CliParser(prog="python -m network.report",
                   description="Airflow resistance report of a grain bed: inertial curve "
                               "(vertical and horizontal) beside D272 and Ergun, porosity band, "
                               "system curve of a bin and a fan's operating point. Exit status "
                               "0 done, 1 a solve failed, 2 bad input.")
    ap.add_argument("--grain", default=None,
                    help=f"crop: {', '.join(D272)} (any case, spaces or underscores; D272 "
                         f"constants sourced for {', '.join(grains_with_d272())}); default: "
                         "the grain template the --packing's companion JSON names, else "
                         "soybean. A --grain that contradicts that JSON is refused; a packing "
                         "without one is taken to be the --grain with a warning")
    ap.add_argument("--packing", default=None, metavar="FILE",
                    help="packing of that grain (any format the readers take), used as it is; "
                         f"default: the bundled one ({', '.join(bundled_grains())}), or a new "
                         "one (--seed, --porosity)")
    ap.add_argument("--units", default="m", type=str.lower, choices=list(UNITS),
                    help="length unit of the packing file")
    add_sample(ap, cylinder=False)
    add_air(ap)
    ap.add_argument("--velocities", default=DEFAULT_VELOCITIES,
                    help="superficial velocities, m/s: a,b,c or start:stop:n (log-spaced)")
    ap.add_argument("--porosity", type=float, default=None,
                    help="porosity the report is for (default: the grain's measured loose-fill "
                         "porosity, middle of its range); more than 0.005 from the bundled bed's "
                         "own, a grain with a dem template is packed anew at it (dem.pack, "
                         "minutes); else (or --move-along-band, --packing) the prediction moves "
                         "along the band's computed slope from the packing's own, within the "
                         "range a packing of the grain reaches")
    ap.add_argument("--particle-density", type=float, default=None,
                    help="kernel (true) density, kg/m^3, for the bulk density rho_p (1 - "
                         "porosity); default: the grain library's (network/_grains.py BED)")
    ap.add_argument("--depth", type=float, default=None,
                    help="grain the air crosses, m, > 0: the bed depth for --axis z, the bed's "
                         f"thickness across the airflow for --axis x (default {DEFAULT_DEPTH_M:g}). "
                         "With --diameter it is the bin's grain depth: a grain with a bed set "
                         "(rain-filled beds loaded to several stresses: bundled for soybean, "
                         "wheat, shelled corn; packed on first use for barley, canola) is also "
                         "reported through the whole depth, Janssen's stress at each depth")
    ap.add_argument("--axis", default="z", type=str.lower, choices=["z", "x"],
                    help="the bin's airflow for the system curve, --airflow and --fan: z vertical "
                         "(floor aeration, default) or x horizontal (cross-flow: the floor area "
                         "options then give the face the air enters); both curves are reported")
    area = ap.add_mutually_exclusive_group()
    area.add_argument("--diameter", type=float, default=None, help="round bin diameter, m, > 0 (default: none, the floor area's bin)")
    area.add_argument("--floor-area", type=float, default=None,
                      help="floor area, m^2, > 0 (default without --diameter: 1 m^2)")
    ap.add_argument("--airflow", nargs=2, default=None, metavar=("VALUE", "UNIT"),
                    help=f"an airflow to report, UNIT one of {', '.join(AIRFLOW_UNITS)} (any "
                         "case; per tonne, per m^3 of grain, and ft^3/min per US bushel, 1 "
                         "cfm/bu = 0.8036 m^3/(min m^3))")
    ap.add_argument("--fan", default=None, metavar="FILE",
                    help="fan curve CSV airflow_m3_s,static_pressure_pa: operating point")
    add_bed_options(ap)
    ap.add_argument("--no-band", action="store_true", help="skip the porosity band (~15 s)")
    ap.add_argument("--sphere-band", action="store_true",
                    help="band on sphere beds of the grain's volume-equivalent size even where "
                         "the grain's own DEM beds are bundled (wheat: data/band_wheat.json)")
    ap.add_argument("--json", dest="json_out", default=None, metavar="OUT.json",
                    help="write everything here")
    ap.add_argument("--html", default=None, metavar="OUT.html",
                    help="self-contained HTML report with embedded plots (needs matplotlib)")
    ap.add_argument("--plot-dir", default=None, metavar="DIR",
                    help="write the plots as PNG files into this existing folder (default: "
                         "report_<grain>/ in the current folder, made if missing)")
    ap.add_argument("--no-figures", action="store_true", help="write no PNG files")
    ap.add_argument("--quiet", "-q", action="store_true", help="no stage progress on stderr")
    return ap


def _check(args) -> dict:
    """Every option checked before any solve; returns the parsed pieces."""
    depth_given = args.depth is not None
    if not depth_given:
        args.depth = DEFAULT_DEPTH_M
    check_common(args)
    if args.packing is not None and args.sample is None \
            and packing_meta(args.packing).get("container") is not None:
        read_container(args.packing)        # its container bounds the sample: checked first
    if args.packing is not None:
        key = packing_grain(args.packing, args.grain, default="soybean")
    else:
        key = grain_key(args.grain or "soybean")
    for opt in ("particle_density", "diameter", "floor_area"):
        v = getattr(args, opt)
        if v is not None and not (np.isfinite(v) and v > 0):
            raise ValueError(f"--{opt.replace('_', '-')} must be finite and > 0, got {v!r}")
    rho_p, bed = args.particle_density, BED[key]
    rho_src = "--particle-density"
    if rho_p is None:
        if bed.particle_density_kg_m3 is None:
            raise ValueError(f"no sourced kernel density for {key} (docs/grain-library.md): "
                             "give --particle-density (kg/m^3)")
        rho_p, rho_src = bed.particle_density_kg_m3, bed.particle_density_source
    for opt in ("seed", "band_seed"):
        if getattr(args, opt) is not None and getattr(args, opt) < 0:
            raise ValueError(f"--{opt.replace('_', '-')} must be >= 0, got {getattr(args, opt)}")
    target, why = requested_porosity(key, args.porosity)
    if args.bed_dir is not None:
        check_bed_dir(args.bed_dir)
    bed_dir = args.bed_dir or Path(args.plot_dir or f"report_{key}") / "beds"
    other = next((opt for opt, v in (("--packing", args.packing), ("--porosity", args.porosity),
                                     ("--seed", args.seed),
                                     ("--move-along-band", args.move_along_band or None),
                                     ("--sample", getattr(args, "sample", None)))
                  if v is not None), None)
    bins = plan_bin_beds(key, depth_m=args.depth, diameter_m=args.diameter,
                         depth_given=depth_given, particle_density=rho_p, bed_dir=bed_dir,
                         other=other)
    if bins is not None:
        bins["grain"] = key
        if bins.get("used") and bins.get("source") == "packed":
            check_bed_dir(bed_dir)
    # a grain without a bundled bed whose bin set is packed on first use: its single bed is
    # the set's surface bed
    from_set = (bins is not None and bins["used"] and bins["source"] == "packed"
                and args.packing is None and bundled_packing(key) is None)
    if args.packing is None and bundled_packing(key) is None and args.seed is None \
            and args.porosity is None and not from_set:
        raise ValueError(f"no bundled packing for {key} (bundled: "
                         f"{', '.join(bundled_grains())}): give --porosity P or --seed N to pack "
                         f"one (dem.pack, minutes), "
                         + ("give a bin (--depth H --diameter B) to pack its bed set, "
                            if key in TEMPLATE_GRAINS and janssen_inputs(key) else "")
                         + f"or pack it with python -m dem.pack --scene "
                         f"box --grain {key} --porosity P --out bed.csv, then add --packing "
                         "bed.csv")
    if from_set:
        bed = {"grain": key, "action": "binset", "packing": None if bins["beds"] is None else
               str(bins["beds"][0][1]), "not_packed": None, "seed": None,
               "move_along_band": False, "bed_dir": str(bed_dir)}
    else:
        bed = plan_bed(key, porosity=args.porosity, seed=args.seed, packing=args.packing,
                       move_along_band=args.move_along_band, bed_box=args.bed_box,
                       bed_dir=bed_dir)
    if bed["action"] in ("bundled", "binset") and args.porosity is None and (
            from_set or packing_meta(bed["packing"]).get("fill", {}).get("method")
            in ("rain", "spout")):
        target, why = None, ("the poured bed's own (a rain-filled bed makes its own porosity; "
                             f"the single bed of {key} is the surface bed of its bin bed set)")
    reach = None
    if bed["action"] == "pack":
        target, why = None, "requested: " + bed["porosity_why"]  # the new bed's own
    elif bed["packing"] is None:        # the bin set's surface bed, packed in _main
        pass
    else:
        args.packing = bed["packing"]
        meta = packing_meta(args.packing)
        reach = reach_record(meta, Path(args.packing).with_suffix(".json"))
        if target is not None:
            check_reachable(target, meta.get("porosity_network_region"), reach, key)
    airflow = None
    if args.airflow is not None:
        airflow = parse_airflow(*args.airflow)
    fan = None
    if args.fan is not None:
        if args.diameter is None and args.floor_area is None:
            raise ValueError("--fan needs the bin: --diameter (round) or --floor-area")
        fan = read_fan(args.fan)
    inputs = (packing_inputs(args) + ([("--fan", args.fan)] if args.fan is not None else [])
              + bed_set_inputs(bins)
              + ([("the bed to pack", p) for c in [bed_paths(bed)]
                  for p in (c, c.with_suffix(".json"), c.with_name(c.stem + ".grains.csv"))]
                 if bed["action"] == "pack" else []))
    check_outputs(json=args.json_out, html=args.html, inputs=inputs)
    if args.plot_dir is not None and not Path(args.plot_dir).is_dir():
        raise ValueError(f"--plot-dir {args.plot_dir}: not an existing folder")
    if args.html or args.plot_dir:
        check_plot("--html/--plot-dir")
    plot_dir = args.plot_dir
    if plot_dir is None and not args.no_figures:
        plot_dir = f"report_{key}"
        if Path(plot_dir).exists() and not Path(plot_dir).is_dir():
            raise ValueError(f"{plot_dir} exists and is not a folder: give --plot-dir or "
                             "--no-figures")
        check_plot("the figures (or give --no-figures)")
    if plot_dir is not None:          # the figure files it names itself
        check_output_list([("--plot-dir", Path(plot_dir) / f"report_{n}.png") for n in FIGURES],
                          inputs, make_folders=True,
                          others=[("--json", args.json_out), ("--html", args.html)])
    return {"grain": key, "particle_density": rho_p, "particle_density_source": rho_src,
            "airflow": airflow, "fan": fan, "velocities": parse_velocities(args.velocities),
            "porosity": target, "porosity_source": why, "reachable": reach,
            "plot_dir": plot_dir, "bed": bed, "bin_beds": bins}


def _g(v, fmt="10.4g"):
    return f"{'-':>{fmt.split('.')[0]}}" if v is None else format(v, fmt)


def _not_converged(p) -> str:
    """The mark of a row whose nonlinear solve stopped short: which direction(s)."""
    bad = [ax for ax, ok in (("z", p["converged"]), ("x", p.get("converged_horizontal", True)))
           if not ok]
    return f"  NOT CONVERGED ({', '.join(bad)}): not a result" if bad else ""


def print_report(r) -> None:
    """The text report on stdout."""
    where = ""
    if r.get("porosity_packing_region", "sample") != "sample":
        where = (f", in the inset window where k is measured (whole sample "
                 f"{r['porosity_packing_sample']:.4f})")
    print(f"grain {r['grain']}: packing {r['packing']} ({r['n_grains']} grains, {r['n_spheres']} "
          f"spheres), own porosity {r['porosity_packing']:.4f} (std error "
          f"{r['porosity_packing_std']:.1e}){where}")
    b = r["bed"]
    print(f"bed: {b['how']}" + (f" with seed {b['seed']}" if b["how"] == "packed anew" else "")
          + (" (reused)" if b["reused"] else "")
          + (f", dem.pack {b['pack_seconds']:.0f} s" if b["pack_seconds"] else "")
          + (f"; not packed anew: {b['not_packed']}" if b["not_packed"] else ""))
    print(f"porosity of this report {r['porosity']:.4f}: {r['porosity_source']}; move: "
          f"{r['porosity_move']}")
    f = [p["porosity_shift_ln_stderr"] for p in r["points"]]
    if r["porosity"] != r["porosity_packing"]:
        sf = [p["porosity_shift_factor"] for p in r["points"]]
        print(f"  the move multiplies dP/L by {min(sf):.4f}-{max(sf):.4f}, uncertain by "
              f"+-{100 * max(f):.1f} % (|de| x the slope's standard error)")
    print(f"d32 {r['sauter_diameter_m'] * 1e3:.3f} mm, kernel density "
          f"{r['particle_density_kg_m3']:g} kg/m^3 ({r['particle_density_source']}), bulk "
          f"density {r['bulk_density_kg_m3']:.1f} kg/m^3")
    k = r["permeability_stokes_m2"]
    print(f"Stokes k at the packing's own porosity: vertical {k['z']:.4e} m^2, horizontal "
          f"{k['x']:.4e} m^2 (horizontal/vertical resistance "
          f"{r['horizontal_to_vertical_stokes']:.3f})")
    if r["d272"]["a_pa_s2_m3"] is None:
        print(f"D272: no sourced constants for {r['grain']} (column '-')")
    else:
        lo, hi = r["d272"]["velocity_range_m_s"]
        print(f"D272 holds for {lo:g}-{hi:g} m/s ({r['d272']['velocity_range_source']}); "
              "the figure draws it only there, the column outside it is the formula "
              "extrapolated")
    print(f"{'U m/s':>8} {'Re_p':>6} {'dP/L z':>10} {'dP/L x':>10} {'D272':>10} {'Ergun':>10} "
          f"{'e-0.02':>10} {'e-0.01':>10} {'e+0.01':>10} {'e+0.02':>10}   (Pa/m)")
    for p in r["points"]:
        b = p["pressure_gradient_band_pa_per_m"] or {}
        print(f"{p['velocity_m_s']:8.4g} {p['reynolds_particle']:6.3g} "
              f"{p['pressure_gradient_pa_per_m']:10.4g} "
              f"{p['pressure_gradient_horizontal_pa_per_m']:10.4g} "
              f"{_g(p['d272_pressure_gradient_pa_per_m'])} "
              f"{p['ergun_pressure_gradient_pa_per_m']:10.4g} "
              + " ".join(_g(b.get(f"{o:+.2f}")) for o in BAND_OFFSETS)
              + _not_converged(p))
    band = r["band"]
    if band:
        print("porosity band: d ln(dP/L)/d(porosity) = "
              + ", ".join(f"{s:.2f} +- {se:.2f} at {u:.3g} m/s" for s, se, u in
                          zip(band["slopes"], band["slope_stderrs"], band["velocities_m_s"]))
              + f"; {len(band['beds'])} beds of {band['packer']}, porosity "
              f"{min(b['porosity'] for b in band['beds']):.3f}-"
              f"{max(b['porosity'] for b in band['beds']):.3f}, {band['seconds']:.1f} s")
    for name, f in (("vertical", r["fits"]), ("horizontal", r["fits_horizontal"])):
        if f and f["permeability_m2"] is not None:
            print(f"fits {name}: k {f['permeability_m2']:.4e} m^2, beta "
                  f"{f['forchheimer_beta_per_m']:.4g} 1/m; D272-style a {f['d272_a']:.4g} "
                  f"Pa s^2/m^3, b {f['d272_b']:.4g} s/m; Ergun A {f['ergun_A']:.4g}, "
                  f"B {f['ergun_B']:.4g}")
    bn = r["bin"]
    way = ("vertical airflow (z): depth" if bn["flow_axis"] == "z"
           else "horizontal airflow (x): thickness crossed")
    print(f"system curve, {way} {bn['depth_m']:g} m, floor {bn['floor_area_m2']:.4g} m^2, "
          f"{bn['grain_mass_t']:.4g} t of grain (static pressure of the grain only)")
    print(f"{'U m/s':>8} {'Q m^3/s':>10} {'m^3/(min t)':>12} {'m^3/(min m^3)':>14} {'P Pa':>10}")
    for s in r["system_curve"]:
        print(f"{s['velocity_m_s']:8.4g} {s['airflow_m3_s']:10.4g} {s['airflow_m3_min_t']:12.4g} "
              f"{s['airflow_m3_min_m3']:14.4g} {s['static_pressure_pa']:10.4g}")
    if r["airflow"]:
        a = r["airflow"]
        print(f"airflow {a['airflow_m3_min_t']:.4g} m^3/(min t) = {a['velocity_m_s']:.4g} m/s: "
              f"{a['airflow_m3_s']:.4g} m^3/s, static pressure {a['static_pressure_pa']:.4g} Pa"
              + ("" if a.get("converged", True) else
                 "  NOT CONVERGED: the nonlinear solve stopped short, not a result"))
    op = r["operating_point"]
    if op and op["found"]:
        print(f"operating point: {op['airflow_m3_s']:.4g} m^3/s, {op['airflow_m3_min_t']:.4g} "
              f"m^3/(min t), {op['airflow_m3_min_m3']:.4g} m^3/(min m^3), static pressure "
              f"{op['static_pressure_pa']:.4g} Pa, U {op['velocity_m_s']:.4g} m/s")
    elif op:
        print(op["message"])
    print_bin_beds(r.get("bin_beds"))
    print(f"total {r['seconds']:.1f} s")


def print_bin_beds(bb) -> None:
    """The bin's beds: the stresses, porosities and the resistance through the whole depth."""
    if bb is None:
        return
    if not bb["used"]:
        print(f"bin's beds: not used: {bb['why']}")
        return
    j, st, e = bb["janssen"], bb["stress_pa"], bb["porosity"]
    print(f"bin's beds ({bb['source']}, rain-filled, {len(bb['beds'])} beds at "
          + ", ".join(f"{b['stress_pa'] / 1000:.3g}" for b in bb["beds"])
          + f" kPa): {bb['diameter_m']:g} m bin, {bb['depth_m']:g} m deep; Janssen (K "
          f"{j['lateral_ratio_K']:.3g}, mu_w {j['wall_friction_mu_w']:.3g}, bulk density "
          f"{j['bulk_density_kg_m3']:.1f} kg/m^3)")
    print("  stress surface / mid / bottom " + " / ".join(f"{st[k] / 1000:.3g}" for k in
                                                          ("surface", "mid", "bottom"))
          + " kPa; porosity " + " / ".join(f"{e[k]:.4f}" for k in ("surface", "mid", "bottom"))
          + f" (depth mean {bb['porosity_depth_mean']:.4f}); interpolated in stress between "
          "the beds")
    print(f"{'U m/s':>8} {'dP v Pa':>10} {'D272 Pa':>10} {'/D272':>6} {'g_z s/m/b':>22} "
          f"{'g_x mean':>9} {'h/v':>6}   (whole depth, layers in series; g in Pa/m)")
    for p in bb["points"]:
        g = p["vertical_gradient_pa_per_m"]
        print(f"{p['velocity_m_s']:8.4g} {p['vertical_pressure_drop_pa']:10.4g} "
              f"{_g(p['d272_pressure_drop_pa'])} "
              + ("     -" if p["ratio_to_d272"] is None else f"{p['ratio_to_d272']:6.3f}")
              + f" {g['surface']:7.4g}/{g['mid']:7.4g}/{g['bottom']:7.4g} "
              f"{p['horizontal_mean_gradient_pa_per_m']:9.4g} {p['horizontal_to_vertical']:6.3f}"
              + ("" if p["converged"] else "  NOT CONVERGED: not a result"))


def main(argv=None) -> int:
    """Run the command; exit status 0 done, 1 the computation failed, 2 bad input."""
    return run(_main, build_parser(), argv)


def report_options(args, checked: dict, path) -> ReportOptions:
    """The :class:`ReportOptions` of the checked command line (``checked``: :func:`_check`'s,
    after :func:`prepare_bed`) for the packing at ``path``."""
    box, margin = sample_box_m(args)
    fan = checked["fan"]
    return ReportOptions(
        grain=checked["grain"], velocities_m_s=tuple(checked["velocities"]),
        porosity=checked["porosity"], porosity_source=checked["porosity_source"],
        reachable=checked["reachable"], particle_density_kg_m3=checked["particle_density"],
        particle_density_source=checked["particle_density_source"], depth_m=args.depth,
        axis=args.axis, diameter_m=args.diameter, floor_area_m2=args.floor_area,
        airflow=checked["airflow"],
        fan_airflow_m3_s=None if fan is None else tuple(fan[0].tolist()),
        fan_static_pressure_pa=None if fan is None else tuple(fan[1].tolist()),
        fan_file=args.fan, band=not args.no_band, sphere_band=args.sphere_band,
        band_seed=args.band_seed, viscosity_pa_s=args.viscosity, density_kg_m3=args.density,
        sample_box_m=None if box is None else tuple(box),
        margin_m=margin, bed_label=checked["bed"]["label"],
        bed_record=bed_json(checked["bed"], path), bin_beds=checked["bin_beds"])


def _main(args) -> int:
    progress_log(args)
    with bad_input():
        opts = _check(args)
    bed = opts["bed"]
    bins = opts["bin_beds"]
    if bins is not None and bins["used"] and bins.get("beds") is None:
        if not args.quiet:
            print(f"packing the bin bed set of {opts['grain']} with dem.pack into "
                  f"{bins['bed_dir']} (once; reused next time): this takes tens of minutes",
                  file=sys.stderr, flush=True)
        with computing():
            bins["pack"] = pack_bed_set(bins, opts["grain"], quiet=args.quiet)
        with bad_input():
            check_bin_depth(bins)
        if bed["action"] == "binset":
            bed["packing"] = str(bins["beds"][0][1])
    args.packing = prepare_bed(bed, quiet=args.quiet)
    if bed["action"] == "pack":
        opts["reachable"] = reach_record(packing_meta(args.packing),
                                         Path(args.packing).with_suffix(".json"))
    with bad_input():
        path, packing = load_packing(args)
        options = report_options(args, opts, path)
    with computing():
        rep = build_report(packing, path, options)
    print_report(rep)
    warn_curve(rep["points"], args.depth, "pressure_gradient_pa_per_m" if args.axis == "z"
               else "pressure_gradient_horizontal_pa_per_m")
    with computing():
        if args.json_out:
            with open(args.json_out, "w") as f:
                json.dump(rep, f, indent=2)
            print(f"wrote {args.json_out}")
        plot_dir = opts["plot_dir"]
        if plot_dir is not None:
            Path(plot_dir).mkdir(exist_ok=True)
        figs = write_figures(rep, plot_dir) if (args.html or plot_dir) else {}
        for name in figs.get("files", []):
            print(f"wrote {name}")
        for name in figs.get("removed", []):
            print(f"removed {name} (an earlier run's; this report draws none)")
        if args.html:
            write_html(args.html, rep, figs.get("png", {}))
            print(f"wrote {args.html}")
    bad = [p["velocity_m_s"] for p in rep["points"]
           if not (p["converged"] and p["converged_horizontal"])]
    if bad:
        raise CliError(f"the nonlinear solve did not converge at U = {bad} m/s", 1)
    return 0
