"""Command line: dimensionless flow Q* of throats.

One throat (prints one JSON object)::

    python -m throats.solve --radii 1 1 1 --sides 2.2 2.2 2.2 [--rtol 1e-3]
                            [--method fem|shape-factor]

A CSV of throats with columns ``r1,r2,r3,l12,l13,l23`` (any consistent length unit)::

    python -m throats.solve --csv IN.csv --out OUT.csv [--method ...] [--rtol ...] [--workers N]

writes the input columns back with ``qstar, open_area, contact_type, error_estimate, status,
message`` added (the columns of ``python -m cache.lookup``, with the same meanings):

* ``qstar``: dimensionless Q*, in units of the mean radius (g = Q* r̄⁴/(μL));
* ``open_area``: open (fluid) area of the cross-section in the input's length unit squared
  (m² for a CSV in metres), not scaled by r̄.

Default method ``fem``.  A bad row (unparsable, NaN, non-positive radius, impossible or collinear
triangle) is reported on stderr with its row and line number; the valid rows are still
written.  Exit status: 0 when every row is 'ok' or 'closed', 1 when some row is invalid or
failed, 2 for usage errors.
"""

from __future__ import annotations

import argparse
import csv
import json
import sys
import time

import numpy as np

from ._area import open_area
from ._geometry import contact_type, validate_throats
from ._shape_factor import FIT, shape_factor_qstar
from ._solve import solve_fem

COLUMNS = ["r1", "r2", "r3", "l12", "l13", "l23"]
METHODS = ("fem", "shape-factor")


def _parser():
    p = argparse.ArgumentParser(
        prog="python -m throats.solve",
        description="Dimensionless throat flow Q* (units of the mean radius) by finite "
                    "elements or the shape-factor estimate.")
    src = p.add_mutually_exclusive_group(required=True)
    src.add_argument("--radii", nargs=3, type=float, metavar=("R1", "R2", "R3"),
                     help="radii of the three spheres (with --sides)")
    src.add_argument("--csv", metavar="IN.csv",
                     help="CSV with columns r1,r2,r3,l12,l13,l23")
    p.add_argument("--sides", nargs=3, type=float, metavar=("L12", "L13", "L23"),
                   help="side lengths between the sphere centres (with --radii)")
    p.add_argument("--out", metavar="OUT.csv", help="output CSV (with --csv)")
    p.add_argument("--method", choices=METHODS, default="fem",
                   help="fem (default: finite elements to --rtol) or shape-factor (closed-form "
                        "estimate, median error ~20%%)")
    p.add_argument("--rtol", type=float, default=1e-3,
                   help="relative tolerance of the FE solve (default 1e-3)")
    p.add_argument("--workers", type=int, default=1, help="processes for FE (default 1)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    return p


def _compute(radii, sides, method, rtol, workers, progress):
    """Per-row results as a dict of (N,) arrays (open_area in input units²)."""
    t0 = time.perf_counter()
    if method == "fem":
        sol = solve_fem(radii, sides, rtol=rtol, workers=workers, progress=progress)
        rbar = radii.mean(axis=1)
        return dict(qstar=sol.qstar, open_area=sol.open_area * rbar**2,
                    contact_type=sol.contact_type, error_estimate=sol.error_estimate,
                    seconds=sol.seconds, status=sol.status, message=sol.message)
    ok, msg = validate_throats(radii, sides)
    q = np.full(radii.shape[0], np.nan)
    area = np.full(radii.shape[0], np.nan)
    ctype = np.full(radii.shape[0], "", dtype=object)
    if ok.any():
        q[ok] = shape_factor_qstar(radii[ok], sides[ok])
        area[ok] = open_area(radii[ok], sides[ok])
        ctype[ok] = contact_type(radii[ok], sides[ok])
    # no per-throat estimate exists: report the fit's 95th-percentile error
    est = np.where(ok, FIT["p95_rel_error"], np.nan)
    status = np.where(ok, np.where(area > 0, "ok", "closed"), "invalid")
    secs = np.full(radii.shape[0], (time.perf_counter() - t0) / max(radii.shape[0], 1))
    return dict(qstar=q, open_area=area, contact_type=ctype.astype(str), error_estimate=est,
                seconds=secs, status=status, message=msg.astype(str))


def _read_csv(path):
    """Rows of the CSV as float arrays; unparsable cells become NaN (flagged later)."""
    with open(path, newline="") as fh:
        reader = csv.DictReader(fh)
        missing = [c for c in COLUMNS if c not in (reader.fieldnames or [])]
        if missing:
            raise ValueError(f"{path}: missing columns {missing}; need {','.join(COLUMNS)}")
        rows = list(reader)
        fields = list(reader.fieldnames)
    vals = np.full((len(rows), 6), np.nan)
    parse_err = {}
    for k, row in enumerate(rows):
        for c, name in enumerate(COLUMNS):
            try:
                vals[k, c] = float(row[name])
            except (TypeError, ValueError):
                parse_err[k] = f"cannot parse {name}={row[name]!r}"
    return rows, fields, vals, parse_err


def main(argv=None) -> int:
    parser = _parser()
    args = parser.parse_args(argv)
    if not (0 < args.rtol < 1):
        parser.error(f"--rtol must be in (0, 1), got {args.rtol}")
    if args.workers < 1:
        parser.error(f"--workers must be >= 1, got {args.workers}")
    if args.radii is not None:
        if args.sides is None:
            parser.error("--radii needs --sides L12 L13 L23")
        res = _compute(np.array([args.radii]), np.array([args.sides]), args.method,
                       args.rtol, 1, False)
        out = {k: (v[0].item() if hasattr(v[0], "item") else v[0]) for k, v in res.items()}
        for k in ("qstar", "open_area", "error_estimate"):
            if isinstance(out[k], float) and not np.isfinite(out[k]):
                out[k] = None
        print(json.dumps({k: out[k] for k in ("qstar", "open_area", "contact_type",
                                               "error_estimate", "seconds", "status",
                                               "message")}))
        if out["status"] in ("invalid", "failed"):
            print(f"error: {out['message']}", file=sys.stderr)
            return 1
        return 0
    if not args.out:
        parser.error("--csv needs --out OUT.csv")
    try:
        rows, fields, vals, parse_err = _read_csv(args.csv)
    except (OSError, ValueError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    progress = (not args.no_progress) and len(rows) > 20
    res = _compute(vals[:, :3], vals[:, 3:], args.method, args.rtol, args.workers, progress)
    for k, m in parse_err.items():
        res["message"][k] = m
    bad = 0
    for k in range(len(rows)):
        if res["status"][k] in ("invalid", "failed"):
            bad += 1
            print(f"row {k + 1} (line {k + 2}): {res['status'][k]}: {res['message'][k]}",
                  file=sys.stderr)
    extra = ["qstar", "open_area", "contact_type", "error_estimate", "status", "message"]
    with open(args.out, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=[f for f in fields if f not in extra] + extra)
        w.writeheader()
        for k, row in enumerate(rows):
            row = {f: row[f] for f in fields if f not in extra}
            for key in extra:
                v = res[key][k]
                if isinstance(v, (float, np.floating)):
                    v = "" if not np.isfinite(v) else repr(float(v))
                row[key] = str(v)
            w.writerow(row)
    n_ok = len(rows) - bad
    print(f"wrote {args.out}: {n_ok} of {len(rows)} rows solved ({args.method})",
          file=sys.stderr)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
