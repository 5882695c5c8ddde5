r"""Safety factor c_s of the extension grids' error estimate (x1, d1) for the 'table+fe' policy.

Research script behind ``cache._interp.CALIBRATED_SAFETY`` for x1 and d1
(``docs/cache-table.md``, "Calibrating the extension grids' error estimate"). Under 'table+fe'
a row the table serves with estimate :math:`e \le` rtol is answered by the table, else by FE;
the estimate of a cell is :math:`e = c_s A + B` (:mod:`cache._interp`: :math:`A` the coarse
sub-grid's difference over :math:`2^3`, :math:`B` the corners' own FE error, or the curvature
size where the sub-grid cannot judge). A grid without a measured :math:`c_s` takes
``ERROR_SAFETY`` = 2. Here, as g1's 0.85 was measured:

1. **calibration** on two populations of windows beyond g1: the two bundled clump beds
   (``network/data/soybean_grains.csv``, ``wheat_grains.csv``: every window not inside a
   merged pore body) and a random packing of 400 spheres of 1-6 mm (seed 2). Each window g1
   does not serve goes, reordered as the lookup does (:func:`cache.table_routes`),
   to x1, and what x1 does not serve to d1 (at most ``--max-rows`` per set and grid, a random
   subset); each is solved by FE at rtol 1e-4 and its table error is
   :math:`t = |\ln Q^*_{table} - \ln Q^*_{FE}|`. :math:`c_s` is the smallest factor whose
   estimate covers 95 % of each population (the rule of g1's), the larger of the two;
2. **check** on another packing of spheres (seed 3) and another grain's bed (``--check BED``,
   a shelled-corn bed: unequal spheres): the share the estimate covers at that :math:`c_s`,
   and at 2.

    python docs/scripts/calibrate_extension.py --check /tmp/rr/shelled_corn.csv --json out.json

Prints per grid and bed: rows, error quantiles, :math:`c_s` at 95 %, coverage at :math:`c_s`
and 2, and the share 'table+fe' at rtol 1e-3 would send to FE with each.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

import network
import throats
from cache import (ERROR_SAFETY, EXTENSION_GRIDS, GridTable, read_grid_file, shipped_grid_path,
                   table_routes)
from fit_deep_overlap import DATA, bed_windows

COVER = 0.95          # share of the errors the estimate must cover (as for g1)
RTOL = 1e-3           # the policy's default tolerance, for the FE share


def served_rows(r, s):
    """Per extension grid, (radii, sides) of the windows it serves, as the lookup asks it
    (:func:`cache.table_routes`)."""
    return {name: (rr[served], ss[served])
            for name, _, rr, ss, served in table_routes(r, s) if name in EXTENSION_GRIDS}


def estimate_parts(name, r, s):
    """(ln Q* of the table, A, B) at the rows: the estimate is c_s A + B."""
    spec, _, values = read_grid_file(shipped_grid_path(name))
    q, fe = values()
    est = {}
    for c in (1.0, 2.0):
        v, est[c] = GridTable(spec, q, fe, safety=c).at_throats(r, s, errors=True)
    A = est[2.0] - est[1.0]
    return np.log(v), A, est[1.0] - A


def needed_factor(t, A, B):
    """Smallest c_s with c_s A + B >= t, per row (0 where B covers it; inf where A = 0)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(t <= B, 0.0, np.where(A > 0, (t - B) / A, np.inf))


def smallest_covering(c):
    """The smallest factor covering COVER of the rows (an order statistic: inf where more
    than 1 - COVER of them need an infinite one)."""
    c = np.sort(c)
    return float(c[max(int(np.ceil(COVER * c.size)) - 1, 0)])


def grid_errors(name, r, s, workers):
    """Table error t, the estimate's parts A, B and the FE seconds of one grid's rows."""
    t0 = time.perf_counter()
    ref = throats.solve_fem(r, s, rtol=1e-4, workers=workers)
    fe_s = time.perf_counter() - t0
    good = (ref.status == "ok") & np.isfinite(ref.qstar) & (ref.qstar > 0)
    lnq, A, B = estimate_parts(name, r[good], s[good])
    return {"t": np.abs(lnq - np.log(ref.qstar[good])), "A": A, "B": B,
            "n_fe_failed": int((~good).sum()), "fe_s": fe_s}


def summary(e, c_s):
    """Quantiles of the error, coverage and the FE share at c_s and at ERROR_SAFETY."""
    t, A, B = e["t"], e["A"], e["B"]
    row = {"n": int(t.size), "n_fe_failed": e["n_fe_failed"], "fe_seconds": round(e["fe_s"], 1),
           "error_p50": float(np.median(t)), "error_p95": float(np.quantile(t, 0.95)),
           "error_max": float(t.max()),
           "c_s_95": smallest_covering(needed_factor(t, A, B))}
    for label, c in (("calibrated", c_s), ("safety_2", ERROR_SAFETY)):
        est = c * A + B
        row[f"covered_{label}"] = float(np.mean(t <= est))
        row[f"fe_share_{label}"] = float(np.mean(est > RTOL))
    return row


def sphere_windows(seed):
    """Windows of a random packing of 400 spheres of 1-6 mm (solid fraction 0.55): unequal
    spheres, whose windows beyond g1 x1 serves too."""
    t = network.tessellate(network.random_packing(400, diameter_range_m=(0.001, 0.006),
                                                  solid_fraction=0.55, rng=seed))
    return t.throat_radii, t.throat_sides


def rows_by_grid(sets, max_rows, rng):
    """{set: {grid: (radii, sides)}}, at most ``max_rows`` per grid (a random subset)."""
    out = {}
    for label, (r, s) in sets.items():
        out[label] = {}
        for name, (rr, ss) in served_rows(r, s).items():
            if len(rr) > max_rows:
                pick = np.sort(rng.choice(len(rr), max_rows, replace=False))
                rr, ss = rr[pick], ss[pick]
            out[label][name] = (rr, ss)
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--check", type=Path, default=None, help="bed of another grain to check on")
    ap.add_argument("--max-rows", type=int, default=4000, help="FE rows per set and grid")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--json", type=Path, default=None)
    args = ap.parse_args(argv)
    rng = np.random.default_rng(2026)
    clumps = [bed_windows(DATA / n) for n in ("soybean_grains.csv", "wheat_grains.csv")]
    calib = {"soybean + wheat beds": tuple(np.vstack(a) for a in zip(*clumps)),
             "spheres 1-6 mm, seed 2": sphere_windows(2)}
    check = {"spheres 1-6 mm, seed 3": sphere_windows(3)}
    if args.check is not None:
        check[args.check.name] = bed_windows(args.check)
    out = {"cover": COVER, "rtol": RTOL, "grids": {}}
    errors = {part: {label: {name: grid_errors(name, *rows, args.workers)
                             for name, rows in grids.items()}
                     for label, grids in rows_by_grid(sets, args.max_rows, rng).items()}
              for part, sets in (("calibration", calib), ("check", check))}
    for name in EXTENSION_GRIDS:
        # each population covered: the largest of the calibration sets' factors
        need = [smallest_covering(needed_factor(e[name]["t"], e[name]["A"], e[name]["B"]))
                for e in errors["calibration"].values()]
        c_s = float(np.ceil(max(need) * 100) / 100) if np.all(np.isfinite(need)) else None
        g = out["grids"][name] = {"c_s": c_s}
        for part, sets in errors.items():
            g[part] = {label: summary(e[name], c_s if c_s is not None else ERROR_SAFETY)
                       for label, e in sets.items()}
            for label, m in g[part].items():
                print(f"{name} {part} {label}: {m['n']} windows (FE failed {m['n_fe_failed']}, "
                      f"{m['fe_seconds']} s), |d ln Q*| median {m['error_p50']:.4f} p95 "
                      f"{m['error_p95']:.4f} max {m['error_max']:.3f}; c_s for 95 % "
                      f"{m['c_s_95']:.2f}; at c_s {c_s}: covered {m['covered_calibrated']:.3f}, "
                      f"to FE at rtol 1e-3 {m['fe_share_calibrated']:.3f}; at 2: covered "
                      f"{m['covered_safety_2']:.3f}, to FE {m['fe_share_safety_2']:.3f}",
                      flush=True)
    if args.json is not None:
        args.json.write_text(json.dumps(out, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
