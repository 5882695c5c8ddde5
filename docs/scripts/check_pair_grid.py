r"""The deep-pair grid p1 against FE on real grain-bed windows.

Research script behind ``cache/data/grid_p1.npz`` (``docs/cache-table.md``, "p1"). For each bed:
the windows of its z sample (pore-body faces) that g1, x1 and d1 do not serve (the rows the
lookup asks p1), ``--n`` of them drawn at random (seed 1), solved by FE at rtol 1e-4
(``throats.solve_fem``); p1's Q* and the shape-factor estimate against FE on the rows p1
serves, and what is left. ``--sample CSV`` writes the drawn windows with their FE values (the
test's stored sample).

    python docs/scripts/check_pair_grid.py network/data/wheat_grains.csv \
        network/data/soybean_grains.csv shelled_corn.csv --n 300 --json p1_check.json
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from fit_deep_overlap import bed_windows           # noqa: E402  (beside this script)

import throats                                      # noqa: E402
from cache import load_grid_table, table_routes     # noqa: E402


def _pct(e):
    e = np.abs(e)
    return {"n": int(e.size), "median": float(np.median(e)), "p95": float(np.percentile(e, 95)),
            "max": float(e.max())} if e.size else None


def check_bed(path, n, seed, workers):
    r, s = bed_windows(path, sample_only=True)
    routes = table_routes(r, s)
    name, rows, rr, ss, served = routes[-1]
    if name != "p1":
        raise SystemExit(f"the last table asked is {name}, not p1")
    rng = np.random.default_rng(seed)
    pick = np.sort(rng.choice(len(rows), min(n, len(rows)), replace=False))
    rp, sp, sv = rr[pick], ss[pick], served[pick]
    fe = throats.solve_fem(rp, sp, rtol=1e-4, workers=workers)
    q_fe = np.where(fe.status == "closed", 0.0, fe.qstar)
    q_p1 = load_grid_table(grid="p1").at_throats(rp, sp)[0]
    q_sf = throats.shape_factor_qstar(rp, sp)
    open_fe = q_fe > 0
    ok = sv & open_fe
    out = {"bed": str(path), "sample_windows": int(len(r)),
           "served_by_g1_x1_d1": int(len(r) - len(rows)),
           "reach_p1": int(len(rows)), "p1_serves": int(served.sum()),
           "drawn": int(len(pick)), "drawn_served": int(sv.sum()),
           "drawn_fe_closed": int((~open_fe).sum()),
           "drawn_served_fe_closed": int((sv & ~open_fe).sum()),
           "p1_vs_fe": _pct(q_p1[ok] / q_fe[ok] - 1),
           "shape_factor_vs_fe_same_rows": _pct(q_sf[ok] / q_fe[ok] - 1),
           "p1_signed_median": float(np.median(q_p1[ok] / q_fe[ok] - 1)) if ok.any() else None,
           "unserved_open_fe": int((~sv & open_fe).sum()),
           "shape_factor_vs_fe_unserved": _pct(q_sf[~sv & open_fe] / q_fe[~sv & open_fe] - 1)}
    rows_out = np.column_stack([rp, sp, q_fe, sv])
    return out, rows_out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("beds", nargs="+")
    ap.add_argument("--n", type=int, default=300)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--json", default=None)
    ap.add_argument("--sample", default=None, help="CSV of the drawn windows and their FE Q*")
    a = ap.parse_args(argv)
    res, rows = [], []
    for b in a.beds:
        o, w = check_bed(b, a.n, a.seed, a.workers)
        print(json.dumps(o, indent=1))
        res.append(o)
        rows.append(w)
    if a.json:
        Path(a.json).write_text(json.dumps(res, indent=1))
    if a.sample:
        np.savetxt(a.sample, np.vstack(rows), delimiter=",", fmt="%.17g",
                   header="r1,r2,r3,l12,l13,l23,qstar_fe,served_by_p1", comments="")
    return 0


if __name__ == "__main__":
    sys.exit(main())
