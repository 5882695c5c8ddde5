r"""The extension grids x1 and d1 against FE on the windows of clump beds that g1 cannot serve.

Research script behind ``cache/data/grid_x1.npz`` and ``grid_d1.npz`` (``docs/cache-table.md``,
"The extension grids"). For each bed: the windows (pore-body faces, not inside a merged body) of its z sample
that g1 does not serve, solved by FE (``cache.lookup_qstar``, policy 'fe-only', stored in
``--db``: a second run solves nothing); their Q* from the extension grids (table-only lookup)
and from the shape-factor estimate against FE, apart for the deep overlaps (two spheres of one
grain, d1's) and the rest (x1's); and the bed's permeability (``network.solve --stokes``, z)
table-only with g1 alone, g1 and x1, g1, x1 and d1, and the last with those windows by FE
(``--db`` must hold FE rows of these windows only: the reduced sections come from the tables).

    python docs/scripts/check_extension.py --db /tmp/x1check.sqlite shelled_corn.csv barley.csv

The bundled wheat bed is always included. Prints JSON; the numbers of the commit are in the doc.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

import cache._lookup as lookup_module
from cache import lookup_qstar
from fit_deep_overlap import DATA, bed_windows, outside_g1     # beside this script
from network.flow import ConductanceOptions, solve_network
from network.packing import read_packing
from throats import deep_overlap, shape_factor_qstar


def windows_beyond_g1(path):
    """(radii, sides, deep overlap, sample windows) of the z sample's windows of a bed that g1
    does not serve."""
    r, s = bed_windows(path, sample_only=True)
    out = outside_g1(r, s)
    return r[out], s[out], deep_overlap(r[out], s[out]), len(r)


def errors(q, q_fe):
    ok = (q_fe > 0) & (q > 0) & np.isfinite(q)
    if not ok.any():
        return None
    e = q[ok] / q_fe[ok] - 1.0
    return {"n": int(ok.sum()), "median": float(np.median(e)), "p5": float(np.percentile(e, 5)),
            "p95": float(np.percentile(e, 95)), "mean_abs": float(np.mean(np.abs(e)))}


def permeability(pk, grids, db=None):
    """k_zz of ``pk``, table-only, with the extension grids ``grids`` (and ``db``'s FE rows)."""
    kept = lookup_module.EXTENSION_GRIDS
    try:
        lookup_module.EXTENSION_GRIDS = grids
        return solve_network(pk, axis="z",
                             conductance=ConductanceOptions(db=db)).permeability_m2
    finally:
        lookup_module.EXTENSION_GRIDS = kept


def check_bed(path, db, workers):
    r, s, deep, n_windows = windows_beyond_g1(path)
    out = {"bed": str(path), "sample_windows": n_windows, "outside_g1": int(len(r))}
    q_fe = np.asarray(lookup_qstar(r, s, policy="fe-only", db=db, workers=workers).qstar)
    tab = lookup_qstar(r, s, policy="table-only", db=Path(db).with_suffix(".none"))
    served = np.asarray(tab.source) == "interp"
    q_tab, q_sf = np.asarray(tab.qstar), shape_factor_qstar(r, s)
    for name, cls in (("not_deep", ~deep), ("deep", deep)):
        out[name] = {"n": int(cls.sum()), "served_by_tables": int((cls & served).sum()),
                     "tables": errors(q_tab[cls & served], q_fe[cls & served]),
                     "shape_factor_on_those": errors(q_sf[cls & served], q_fe[cls & served]),
                     "left_to_shape_factor": errors(q_sf[cls & ~served], q_fe[cls & ~served])}
    pk = read_packing(path)
    k = {"g1_only": permeability(pk, ()), "g1_x1": permeability(pk, ("x1",)),
         "g1_x1_d1": permeability(pk, ("x1", "d1")),
         "fe_windows": permeability(pk, ("x1", "d1"), db)}
    out["permeability_m2"] = k
    out["errors"] = {key: k[key] / k["fe_windows"] - 1.0 for key in k if key != "fe_windows"}
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("beds", nargs="*", help="more clump beds (x, y, z, r files)")
    ap.add_argument("--db", required=True, help="Q* table for the FE solves (reused)")
    ap.add_argument("--workers", type=int, default=2)
    a = ap.parse_args(argv)
    res = [check_bed(b, a.db, a.workers) for b in [DATA / "wheat_grains.csv", *a.beds]]
    print(json.dumps(res, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
