r"""Shape-factor constants of deeply overlapping throats (two spheres of one multi-sphere grain).

Research script behind ``throats._shape_factor.FIT["deep"]`` (``docs/throats-shape-factor.md``,
"Deep overlaps"). The shipped Q* table spans gaps (l_ij - r_i - r_j)/r̄ >= -0.2; a window of a
clump bed whose face holds two spheres of one grain overlaps far deeper (-1.6 to -0.2) and is
answered by the shape-factor estimate :math:`Q^* \approx c_t A^{*3}/P^{*2}`, whose constants
were fitted on sphere-packing throats. Here:

1. **fit** on the bundled soybean clump bed (``network/data/soybean_grains.csv``): every
   window the shipped table does not serve is solved by FE (``cache.lookup_qstar``, policy
   'fe-only', stored in ``--db``: a second run solves nothing), and for contact types b and c
   with a deep overlap (smallest gap < -0.2 r̄) :math:`c_t = c_t^{old}\exp(\mathrm{median}
   \ln(Q_{FE}/Q_{sf}^{old}))`, the rule of ``throats.bench --fit``;
2. **check** (``--check``) on the bundled wheat bed (``network/data/wheat_grains.csv``, another
   grain, eight spheres): its sample windows outside the table solved by FE, the error of the
   estimate before and after, and the bed's permeability (``network.solve --stokes``, z) with
   the table-only policy against the same with those FE windows.

    python docs/scripts/fit_deep_overlap.py --db /tmp/deep.sqlite --check

Prints the constants and the errors; the numbers of the commit are in the doc.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

from cache import load_grid_table, lookup_qstar
from network.flow import ConductanceOptions, solve_network
from network.packing import read_packing
from network.pores import default_region, merge_pores, select_sample, tessellate
from throats import contact_type, deep_overlap, shape_factor_qstar
from throats._shape_factor import FIT

DATA = Path(__file__).resolve().parents[2] / "network" / "data"


def bed_windows(path, sample_only=False):
    """(radii, sides) of a bed's windows (throats not inside a merged pore body;
    ``sample_only``: the z sample's only)."""
    t = tessellate(read_packing(path))
    merge = merge_pores(t)
    idx = np.flatnonzero(~np.asarray(merge.internal_throat))
    if sample_only:
        s = select_sample(t, default_region(t.packing, axis="z"), axis="z",
                          groups=np.asarray(merge.labels))
        idx = np.intersect1d(idx, s.throats)
    return t.throat_radii[idx], t.throat_sides[idx]


def outside_g1(r, s):
    """Rows the shipped table g1 alone does not serve (table-only), as when the constants were
    fitted (the extension grids x1 and d1 came later)."""
    g1 = load_grid_table(grid="g1")
    return np.asarray(lookup_qstar(r, s, policy="table-only", table=g1).source) == "shape-factor"


def fallback_windows(path, sample_only=False):
    """(radii, sides) of the windows of a bed that g1 does not serve (:func:`bed_windows`)."""
    r, s = bed_windows(path, sample_only)
    out = outside_g1(r, s)
    return r[out], s[out]


def old_estimate(r, s):
    """The estimate with the sphere-packing constants for every type (no deep class)."""
    q = shape_factor_qstar(r, s)
    deep, kind = _deep(r, s)
    for t, c in FIT["deep"]["c"].items():
        m = deep & (kind == t)
        q[m] *= FIT["c"][t] / c
    return q


def _deep(r, s):
    """(deep-overlap rows, contact type) of the throats."""
    return deep_overlap(r, s), np.asarray(contact_type(r, s))


def errors(q_est, q_fe):
    ok = (q_fe > 0) & (q_est > 0)
    e = q_est[ok] / q_fe[ok] - 1.0
    return {"n": int(ok.sum()), "median": float(np.median(e)),
            "p5": float(np.percentile(e, 5)), "p95": float(np.percentile(e, 95))}


def fit(db, workers):
    r, s = fallback_windows(DATA / "soybean_grains.csv")
    q_fe = np.asarray(lookup_qstar(r, s, policy="fe-only", db=db, workers=workers).qstar)
    q_old = old_estimate(r, s)
    deep, kind = _deep(r, s)
    out = {"windows": int(len(q_fe)), "c": {}}
    for t in FIT["deep"]["c"]:
        m = deep & (kind == t) & (q_fe > 0) & (q_old > 0)
        out["c"][t] = round(FIT["c"][t] * float(np.exp(np.median(np.log(q_fe[m] / q_old[m])))), 4)
        out[f"n_{t}"] = int(m.sum())
    out["before"] = errors(q_old, q_fe)
    out["after"] = errors(shape_factor_qstar(r, s), q_fe)
    return out


def check(db, workers):
    path = DATA / "wheat_grains.csv"
    r, s = fallback_windows(path, sample_only=True)
    q_fe = np.asarray(lookup_qstar(r, s, policy="fe-only", db=db, workers=workers).qstar)
    out = {"windows": int(len(q_fe)), "before": errors(old_estimate(r, s), q_fe),
           "after": errors(shape_factor_qstar(r, s), q_fe)}
    pk = read_packing(path)
    k = {pol: solve_network(pk, axis="z", conductance=ConductanceOptions(db=d)).permeability_m2
         for pol, d in (("table", None), ("fe_windows", db))}
    out["permeability_m2"] = k
    out["permeability_error"] = k["table"] / k["fe_windows"] - 1.0
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--db", required=True, help="Q* table for the FE solves (reused)")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--check", action="store_true", help="also the wheat bed's check")
    a = ap.parse_args(argv)
    res = {"fit": fit(a.db, a.workers)}
    if a.check:
        res["check"] = check(a.db, a.workers)
    print(json.dumps(res, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
