r"""The extension grid x1 against FE on the windows of clump beds that the shipped g1 cannot serve.

Research script behind ``cache/data/grid_x1.npz`` (``docs/cache-table.md``, "The extension
grid"). For each bed: the windows (pore-body faces, not inside a merged body) of its z sample
that g1 does not serve and that are not deep overlaps (two spheres of one grain, left to the
shape-factor estimate's own class), solved by FE (``cache.lookup_qstar``, policy 'fe-only',
stored in ``--db``: a second run solves nothing); their Q* from x1 (table-only lookup) and
from the shape-factor estimate against FE; and the bed's permeability (``network.solve
--stokes``, z) table-only with g1 alone (x1 switched off), with g1 and x1, and with those
windows by FE (x1 serving the conduits' reduced sections in the last two).

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
from cache import GridTable, lookup_qstar, read_grid_file, shipped_grid_path
from network.flow import solve_network
from network.packing import read_packing
from network.pores import default_region, merge_pores, select_sample, tessellate
from throats import deep_overlap, shape_factor_qstar

DATA = Path(__file__).resolve().parents[2] / "network" / "data"


def outside_g1(path):
    """(radii, sides) of the z sample's windows of a bed that g1 does not serve, no deep overlap."""
    t = tessellate(read_packing(path))
    merge = merge_pores(t)
    idx = np.flatnonzero(~np.asarray(merge.internal_throat))
    smp = select_sample(t, default_region(t.packing, axis="z"), axis="z",
                        groups=np.asarray(merge.labels))
    idx = np.intersect1d(idx, smp.throats)
    r, s = t.throat_radii[idx], t.throat_sides[idx]
    spec, _, values = read_grid_file(shipped_grid_path("g1"))
    g1 = GridTable(spec, *values())
    out = np.asarray(lookup_qstar(r, s, policy="table-only", table=g1).source) == "shape-factor"
    out &= ~deep_overlap(r, s)
    return r[out], s[out], len(idx)


def errors(q, q_fe):
    ok = (q_fe > 0) & (q > 0) & np.isfinite(q)
    e = q[ok] / q_fe[ok] - 1.0
    return {"n": int(ok.sum()), "median": float(np.median(e)), "p5": float(np.percentile(e, 5)),
            "p95": float(np.percentile(e, 95)), "mean_abs": float(np.mean(np.abs(e)))}


def check_bed(path, db, workers):
    r, s, n_windows = outside_g1(path)
    out = {"bed": str(path), "sample_windows": n_windows, "outside_g1": int(len(r))}
    if len(r):
        q_fe = np.asarray(lookup_qstar(r, s, policy="fe-only", db=db, workers=workers).qstar)
        x1 = lookup_qstar(r, s, policy="table-only", db=Path(db).with_suffix(".none"))
        served = np.asarray(x1.source) == "interp"
        out["served_by_x1"] = int(served.sum())
        out["x1"] = errors(np.asarray(x1.qstar)[served], q_fe[served])
        out["shape_factor_on_those"] = errors(shape_factor_qstar(r[served], s[served]),
                                              q_fe[served])
        out["left_to_shape_factor"] = errors(shape_factor_qstar(r[~served], s[~served]),
                                             q_fe[~served]) if (~served).any() else None
    pk = read_packing(path)
    k = {}
    grid = lookup_module.EXTENSION_GRID
    try:
        lookup_module.EXTENSION_GRID = "switched-off"        # no such file: g1 alone
        k["g1_only"] = solve_network(pk, axis="z", policy="table-only").permeability_m2
    finally:
        lookup_module.EXTENSION_GRID = grid
    k["g1_x1"] = solve_network(pk, axis="z", policy="table-only").permeability_m2
    k["fe_windows"] = solve_network(pk, axis="z", policy="table-only", db=db).permeability_m2
    out["permeability_m2"] = k
    out["error_g1_only"] = k["g1_only"] / k["fe_windows"] - 1.0
    out["error_g1_x1"] = k["g1_x1"] / k["fe_windows"] - 1.0
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
