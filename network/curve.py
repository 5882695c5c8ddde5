"""``python -m network.curve``: the airflow-resistance curve of a packing, Stokes to drying speeds.

Examples
--------
    python -m network.curve                                   # the bundled soybean scene
    python -m network.curve bed.csv --velocities 0.01:0.3:8 --json c.json --plot curve.png
    python -m network.curve --velocities 0.005,0.013,0.027 --csv c.csv

Per velocity: Re_p, the pressure gradient with inertia (:mod:`network.flow._inertial`) and
the apparent permeability μU/(ΔP/L); fits over the run: Darcy-Forchheimer, ASABE D272 and
Ergun refitted (:func:`network.flow.fit_curve`). The packing is read in ``--units`` (``--sample``,
``--margin`` too). Exit 0 done, 1 a velocity did not converge (its point is written with
``converged: false``), 2 bad input: one ``error:`` line (docs/cli.md).
"""

from __future__ import annotations

import csv
import json
import time

import numpy as np

from ._air import check_positive
from ._cli import (CliError, CliParser, add_air, add_packing, add_sample, add_table,
                   available_cores, bad_input, check_common, check_outputs, check_plot, computing,
                   finish, load_packing, packing_inputs, progress_log, run, sample_box_m, warn,
                   warn_curve)
from .conductance import POLICIES
from ._grains import d272_constants, d272_velocity_range, grains_with_d272, packing_grain
from .flow import (DEFAULT_DEPTH_M, GRAINS, INERTIAL_LAW, ConductanceOptions, FlowOptions,
                   SampleOptions, asabe_d272_gradient, ergun_gradient,
                   solve_network)
from .packing import default_packing_path, read_container
from .pores import sample_region

#: Default: 12 velocities spaced logarithmically over aeration and drying, m/s.
DEFAULT_VELOCITIES = "0.005:0.3:12"
#: Thesis section 4.2.3: measured drops over 0.25 m of soybeans, (m/s, Pa/m).
THESIS_POINTS = [(0.013, 2.44 / 0.25), (0.027, 6.80 / 0.25)]
#: Fewest distinct velocities the fits take (:func:`network.flow.fit_curve`: each fit has two
#: constants; with fewer every fit is None).
MIN_FIT_VELOCITIES = 2
#: what the fits' permeability is, printed and written beside them (measured: +2.6 % over the
#: Stokes k on the bundled scene at the default velocities, against a 0.7 % fit residual)
FITS_NOTE = ("permeability_m2 is the Darcy-Forchheimer fit's (dP/L = mu U/k + beta rho U^2 over "
             "the run): the network's excess over Darcy grows like U^2 at small Re and about "
             "like U above, which that form cannot follow, so its k is not the network's own "
             "Darcy k, permeability_stokes_m2")
KEYS = ["velocity_m_s", "reynolds_particle", "pressure_gradient_pa_per_m",
        "apparent_permeability_m2", "converged"]


#: Most velocities one run solves (``--velocities``): a curve is drawn well by a dozen
MAX_VELOCITIES = 200
#: What ``--velocities`` takes, for its messages
VELOCITY_FORMS = ("a comma-separated list (0.01,0.05,0.1) or start:stop:n, n log-spaced points "
                  "from start to stop (0.01:0.3:8), m/s")


def parse_velocities(text: str) -> list[float]:
    """``'a,b,c'`` or ``'start:stop:n'`` (n log-spaced points) → velocities, m/s (> 0), each once
    (a repeated value is solved once), at most :data:`MAX_VELOCITIES`; ValueError saying which
    form is expected.

    >>> parse_velocities("0.01:1:3")
    [0.01, 0.1, 1.0]
    >>> parse_velocities("0.1, 0.01, 0.1")
    [0.1, 0.01]
    """
    where = f"--velocities {text!r}"
    if ":" in text:
        parts = [p.strip() for p in text.split(":")]
        if len(parts) != 3:
            raise ValueError(f"{where}: {len(parts)} parts; give {VELOCITY_FORMS}")
        ends = []
        for name, part in zip(("start", "stop"), parts):
            try:
                ends.append(float(part))
            except ValueError:
                raise ValueError(f"{where}: {name} {part!r} is not a number; give "
                                 f"{VELOCITY_FORMS}") from None
            check_positive(f"--velocities {name}", ends[-1])
        try:
            n = int(parts[2])
        except ValueError:
            raise ValueError(f"{where}: n {parts[2]!r} is not a whole number of points; give "
                             f"{VELOCITY_FORMS}") from None
        if not 1 <= n <= MAX_VELOCITIES:
            raise ValueError(f"{where}: n must be 1 to {MAX_VELOCITIES} points, got {n}")
        vals = [float(v) for v in np.geomspace(ends[0], ends[1], n)]
    else:
        vals = []
        for part in (p.strip() for p in text.split(",")):
            if not part:
                continue
            try:
                vals.append(float(part))
            except ValueError:
                raise ValueError(f"{where}: {part!r} is not a number; give "
                                 f"{VELOCITY_FORMS}") from None
    if not vals:
        raise ValueError(f"{where} is empty; give {VELOCITY_FORMS}")
    for v in vals:
        check_positive(f"--velocities value {v!r}", v)
    vals = list(dict.fromkeys(round(v, 15) for v in vals))       # each velocity solved once
    if len(vals) > MAX_VELOCITIES:
        raise ValueError(f"{where}: {len(vals)} velocities, at most {MAX_VELOCITIES}")
    return vals


def build_parser() -> CliParser:
    ap = CliParser(prog="python -m network.curve",
                   description="Pressure gradient against airflow with inertia (per-conduit "
                               "contraction/expansion losses), with Darcy-Forchheimer, ASABE "
                               "D272 and Ergun fits. Exit status 0 done, 1 a velocity did not "
                               "converge or the solve failed, 2 bad input (docs/cli.md).")
    add_packing(ap)
    ap.add_argument("--axis", default="z", type=str.lower, choices=["x", "y", "z"],
                    help="flow direction, any case")
    add_sample(ap)
    add_air(ap)
    ap.add_argument("--velocities", default=DEFAULT_VELOCITIES,
                    help="superficial velocities, m/s, > 0: a,b,c or start:stop:n "
                         "(n log-spaced points)")
    ap.add_argument("--depth", type=float, default=DEFAULT_DEPTH_M,
                    help="bed depth, m, > 0 (reported; the gradient does not depend on it)")
    ap.add_argument("--grain", default=None,
                    help=f"the crop the bed is of, for the D272 line of --plot (grains with "
                         f"sourced constants: {', '.join(GRAINS)}); default: the grain "
                         "template its companion JSON names (the bundled scene: soybean); a bed "
                         "of unknown grain gets no D272 line. A --grain that contradicts the "
                         "JSON is refused")
    ap.add_argument("--policy", default="table-only", choices=POLICIES,
                    help="Q* source (see python -m network.solve --help)")
    add_table(ap)
    ap.add_argument("--json", dest="json_out", default=None, metavar="OUT.json",
                    help="write points, fits and timings here (default: not written)")
    ap.add_argument("--csv", dest="csv_out", default=None, metavar="OUT.csv",
                    help=f"write the points, columns {','.join(KEYS)} (default: not written)")
    ap.add_argument("--plot", default=None, metavar="OUT.png",
                    help="write the D272-style log-log plot (needs matplotlib: "
                         "pip install '.[plot]'; default: not drawn)")
    ap.add_argument("--workers", type=int, default=available_cores(),
                    help="processes for the nonlinear solves: the velocities are dealt into "
                         "this many continuation chains (at least 4 velocities each) solved "
                         "side by side; also the threads of the conductance stage "
                         "(default: the cores this process may use, "
                         f"{available_cores()} here)")
    ap.add_argument("--quiet", "-q", action="store_true", help="no stage progress on stderr")
    return ap


def plot_curve(path, points, *, grain, porosity, diameter_m, viscosity_pa_s, density_kg_m3):
    """Log-log ΔP/L against U: our points, D272 and Ergun for the grain, the thesis points."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    u = np.array([p["velocity_m_s"] for p in points])
    gr = np.array([p["pressure_gradient_pa_per_m"] for p in points])
    uu = np.geomspace(u.min() / 1.5, u.max() * 1.5, 100)
    fig, ax = plt.subplots(figsize=(5.5, 4.2))
    ax.loglog(u, gr, "o-", label="network (inertial)")
    if grain in grains_with_d272():       # only over the velocities D272 is stated for
        a, b = d272_constants(grain)
        (lo, hi), _ = d272_velocity_range(grain)
        ud = uu[(uu >= lo) & (uu <= hi)]
        if ud.size:
            ax.loglog(ud, [asabe_d272_gradient(v, a=a, b=b) for v in ud], "--",
                      label=f"ASABE D272 {grain} ({lo:g}-{hi:g} m/s)")
    if 0 < porosity < 1:
        ax.loglog(uu, [ergun_gradient(v, porosity=porosity, diameter_m=diameter_m,
                                      viscosity_pa_s=viscosity_pa_s,
                                      density_kg_m3=density_kg_m3) for v in uu], ":",
                  label="Ergun")
    if grain == "soybean":
        tu, tg = zip(*THESIS_POINTS)
        ax.loglog(tu, tg, "ks", label="thesis measured")
    ax.set_xlabel("airflow U (m/s)")
    ax.set_ylabel("pressure gradient (Pa/m)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def _check_options(args) -> list[float]:
    check_common(args)
    if args.grain is not None:
        d272_constants(args.grain)      # an unknown or unsourced grain: ValueError naming them
    check_outputs(json=args.json_out, csv=args.csv_out, plot=args.plot,
                  inputs=packing_inputs(args))
    if args.plot:
        check_plot(path=args.plot)
    us = parse_velocities(args.velocities)
    _warn_fits(len(set(us)), f"--velocities {args.velocities} gives")
    return us


def _warn_fits(n_distinct: int, what: str) -> None:
    """A ``warning:`` line when ``n_distinct`` velocities are too few for the fits."""
    if n_distinct < MIN_FIT_VELOCITIES:
        warn(f"the fits (Darcy-Forchheimer, D272, Ergun) need at least {MIN_FIT_VELOCITIES} "
             f"distinct velocities; {what} {n_distinct}: they are reported as None")


def _write_outputs(args, out, pts, ok, res, grain) -> None:
    """--json, --csv and --plot (paths checked before the solve)."""
    if args.json_out:
        with open(args.json_out, "w") as f:
            json.dump(out, f, indent=2)
        print(f"wrote {args.json_out}")
    if args.csv_out:
        with open(args.csv_out, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=KEYS)
            w.writeheader()
            for p in pts:
                w.writerow({k: p[k] for k in KEYS})
        print(f"wrote {args.csv_out}")
    if args.plot and ok:
        plot_curve(args.plot, ok, grain=grain, porosity=res.porosity,
                   diameter_m=res.sauter_diameter_m, viscosity_pa_s=args.viscosity,
                   density_kg_m3=args.density)
        print(f"wrote {args.plot}")


def main(argv=None) -> int:
    """Run the command; exit status 0 done, 1 the computation failed, 2 bad input."""
    return run(_main, build_parser(), argv)


def _main(args) -> int:
    progress_log(args)
    t0 = time.perf_counter()
    with bad_input():
        us = _check_options(args)
        grain = packing_grain(args.packing or default_packing_path(), args.grain)
        path, packing = load_packing(args)
        box, margin = sample_box_m(args)
        container = None if box else read_container(path)
        region = sample_region(packing, box=box, margin=margin, cylinder=args.cylinder,
                               container=container, axis=args.axis)
        conductance = ConductanceOptions(policy=args.policy, rtol=args.rtol, db=args.db)
        flow = FlowOptions(viscosity_pa_s=args.viscosity, velocity_m_s=us[0],
                           depth_m=args.depth, inertia=True, density_kg_m3=args.density,
                           curve_velocities_m_s=us[1:], inertial_workers=args.workers)
    with computing():
        res = solve_network(packing, axis=args.axis, sample=SampleOptions(region=region),
                            conductance=conductance, flow=flow, threads=args.workers)
        pts = [{k: p[k] for k in KEYS} | {"newton_iterations": p["newton_iterations"],
                                          "cg_iterations": p["cg_iterations"]}
               for p in res.curve_points()]
        ok = [p for p in pts if p["converged"]]
        fits = res.curve_fits()
    if len(set(us)) >= MIN_FIT_VELOCITIES:
        _warn_fits(len({p["velocity_m_s"] for p in ok}), "the converged points have")
    print(f"packing {path} ({packing.n} spheres), axis {args.axis}: k (Stokes) = "
          f"{res.permeability_m2:.4e} m2, porosity {res.porosity:.4f}, d32 "
          f"{res.sauter_diameter_m:.4g} m")
    print(f"{'U m/s':>9} {'Re_p':>8} {'dP/L Pa/m':>11} {'k_app m2':>11} {'k/k_app':>8} "
          f"{'Newton':>6} {'CG':>5}  converged")
    for p in pts:
        print(f"{p['velocity_m_s']:9.4g} {p['reynolds_particle']:8.3g} "
              f"{p['pressure_gradient_pa_per_m']:11.5g} {p['apparent_permeability_m2']:11.4e} "
              f"{res.permeability_m2 / p['apparent_permeability_m2']:8.4f} "
              f"{p['newton_iterations']:6d} {p['cg_iterations']:5d}  {p['converged']}")
    for k, v in fits.items():
        print(f"  {k} = {v:.5g}" if isinstance(v, float) else f"  {k} = {v}")
    print(f"  ({FITS_NOTE})")
    warn_curve(pts, args.depth)
    total = time.perf_counter() - t0
    print(f"total {total:.2f} s")
    out = {"packing": str(path), "units": args.units, "n_spheres": packing.n, "axis": args.axis,
           "grain": grain, "workers": args.workers, "density_kg_m3": args.density,
           "inertial_law": INERTIAL_LAW,
           "viscosity_pa_s": args.viscosity,
           "porosity": res.porosity, "porosity_sample": res.porosity_sample,
           "sauter_diameter_m": res.sauter_diameter_m,
           "permeability_stokes_m2": res.permeability_m2, "points": pts} | fits | {
           "fits_note": FITS_NOTE,
           "seconds": dict(res.timings_s, wall=total)}
    with computing():
        _write_outputs(args, out, pts, ok, res, grain)
    bad = [p["velocity_m_s"] for p in pts if not p["converged"]]
    if bad:
        raise CliError(f"the nonlinear solve did not converge at U = {bad} m/s (marked "
                       "converged: false)", 1)
    return 0


if __name__ == "__main__":
    finish(main())
