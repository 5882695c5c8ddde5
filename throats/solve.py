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

Default method ``fem``.  Every triangle of disks gets an answer (``status`` 'ok' or 'closed',
Q* possibly 0).  A bad row (unparsable, NaN, non-positive radius, impossible or collinear
triangle) is reported on stderr as ``error: FILE row N: ...`` with N counted as a spreadsheet does
(header = row 1); the other rows are still written.  Exit status: 0 when every row has an
answer, 1 when some row is invalid or failed (or Ctrl-C), 2 for bad options or files (one
``error:`` line, checked before anything is computed or written).
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import sys
import tempfile
import time

import numpy as np

from network.core import MAX_WORKERS, check_output_list, read_table

from ._area import open_area
from ._geometry import contact_type, mean_radius, validate_throats
from ._shape_factor import FIT, shape_factor_qstar
from ._solve import solve_fem

__all__ = ["OneLineParser", "check_output", "main", "run_interruptible"]

COLUMNS = ["r1", "r2", "r3", "l12", "l13", "l23"]
METHODS = ("fem", "shape-factor")


class OneLineParser(argparse.ArgumentParser):
    """``ArgumentParser`` whose usage errors are one ``error:`` line and exit 2."""

    def error(self, message):
        print(f"error: {message} (see {self.prog} --help)", file=sys.stderr)
        raise SystemExit(2)


def check_output(path, option="--out", inputs=()):
    """ValueError naming ``option`` if ``path`` cannot be written (a folder, a missing folder, a
    folder that takes no new file, an existing file not writable) or is one of ``inputs``
    (``(option, path)`` pairs): :func:`network.core.check_output_list`."""
    check_output_list([(option, path)], inputs)


def _parser():
    p = OneLineParser(
        prog="python -m throats.solve",
        description="Dimensionless throat flow Q* (units of the mean radius) by finite "
                    "elements or the shape-factor estimate.")
    src = p.add_mutually_exclusive_group(required=True)
    src.add_argument("--radii", nargs=3, type=float, metavar=("R1", "R2", "R3"),
                     help="radii of the three spheres, any length unit, the same as --sides "
                          "(one throat, printed as JSON)")
    src.add_argument("--csv", metavar="IN.csv",
                     help="CSV with columns r1,r2,r3,l12,l13,l23 (any one length unit; other "
                          "columns are copied)")
    p.add_argument("--sides", nargs=3, type=float, metavar=("L12", "L13", "L23"),
                   help="side lengths between the sphere centres, the unit of --radii")
    p.add_argument("--out", metavar="OUT.csv",
                   help="output CSV (required with --csv): the input columns plus qstar "
                        "(r-bar units), open_area (input unit squared), contact_type, "
                        "error_estimate (relative), status, message")
    p.add_argument("--method", choices=METHODS, default="fem",
                   help="fem (default: finite elements to --rtol) or shape-factor (closed-form "
                        "estimate, median error ~20%%)")
    p.add_argument("--rtol", type=float, default=1e-3,
                   help="relative tolerance of the FE solve, in (0, 1) (default 1e-3)")
    p.add_argument("--workers", type=int, default=1,
                   help="processes for FE, >= 1 (default 1)")
    p.add_argument("--no-progress", action="store_true",
                   help="no progress bar on stderr (default: a bar for more than 20 rows)")
    return p


def _compute(radii, sides, method, rtol, workers, progress):
    """Per-row results as a dict of (N,) arrays (open_area in input units²).

    Q* and the open area are computed in units of the mean radius r̄ (``solve_fem`` does so
    itself; the shape-factor rows here), the area scaled back by r̄², so any finite positive
    length unit gives the same Q*; an area beyond the float range (unit ~1e155 and up) is
    written empty.
    """
    t0 = time.perf_counter()
    ok, msg = validate_throats(radii, sides)
    rbar = np.ones(radii.shape[0])
    rbar[ok] = mean_radius(radii[ok])
    r_star, s_star = radii / rbar[:, None], sides / rbar[:, None]
    if method == "fem":
        sol = solve_fem(radii, sides, rtol=rtol, workers=workers, progress=progress)
        with np.errstate(over="ignore", under="ignore", invalid="ignore"):
            area = sol.open_area * rbar**2
        return dict(qstar=sol.qstar, open_area=area,
                    contact_type=sol.contact_type, error_estimate=sol.error_estimate,
                    seconds=sol.seconds, status=sol.status, message=sol.message)
    q = np.full(radii.shape[0], np.nan)
    area_star = np.full(radii.shape[0], np.nan)
    ctype = np.full(radii.shape[0], "", dtype=object)
    if ok.any():
        q[ok] = shape_factor_qstar(r_star[ok], s_star[ok])
        area_star[ok] = open_area(r_star[ok], s_star[ok])
        ctype[ok] = contact_type(r_star[ok], s_star[ok])
    with np.errstate(over="ignore", under="ignore", invalid="ignore"):
        area = area_star * rbar**2
    # no per-throat estimate exists: report the fit's 95th-percentile error
    est = np.where(ok, FIT["p95_rel_error"], np.nan)
    status = np.where(ok, np.where(area_star > 0, "ok", "closed"), "invalid")
    secs = np.full(radii.shape[0], (time.perf_counter() - t0) / max(radii.shape[0], 1))
    return dict(qstar=q, open_area=area, contact_type=ctype.astype(str), error_estimate=est,
                seconds=secs, status=status, message=msg.astype(str))


def _read_csv(path):
    """Rows of the CSV (dicts; a short row's missing fields None) as float arrays; unparsable
    cells become NaN (flagged later). Read as spreadsheets write it
    (:func:`network.core.read_table`); errors name ``--csv`` and the file."""
    fields, table = read_table(path, "--csv", what="a throat list")
    missing = [c for c in COLUMNS if c not in fields]
    if missing:
        raise ValueError(f"--csv {path}: missing columns {missing}; need {','.join(COLUMNS)}")
    rows = [dict(zip(fields, vals + [None] * (len(fields) - len(vals)))) for _, vals in table]
    vals = np.full((len(rows), 6), np.nan)
    parse_err = {}
    for k, row in enumerate(rows):
        for c, name in enumerate(COLUMNS):
            try:
                vals[k, c] = float(row[name])
            except (TypeError, ValueError):
                parse_err[k] = f"cannot parse {name}={row[name]!r}"
        if any(row[f] is None for f in fields):         # DictReader's filler of a short row
            given = sum(row[f] is not None for f in fields)
            parse_err[k] = f"the row has {given} of {len(fields)} values"
    return rows, fields, vals, parse_err


def run_interruptible(body, argv, message: str) -> int:
    """``body(argv)``'s exit status; Ctrl-C prints ``message`` (one line) and gives 1."""
    try:
        return body(argv)
    except KeyboardInterrupt:
        print(message, file=sys.stderr)
        return 1


def main(argv=None) -> int:
    """Run the command; exit 0 every row answered, 1 some row not (or Ctrl-C), 2 bad input."""
    return run_interruptible(_main, argv, "interrupted: nothing written")


def _main(argv):
    parser = _parser()
    args = parser.parse_args(argv)
    if not (0 < args.rtol < 1):
        parser.error(f"--rtol must be in (0, 1), got {args.rtol}")
    if not 1 <= args.workers <= MAX_WORKERS:
        parser.error(f"--workers must be 1 to {MAX_WORKERS}, got {args.workers}")
    if args.radii is not None:
        if args.sides is None:
            parser.error("--radii needs --sides L12 L13 L23")
        ok, why = validate_throats([args.radii], [args.sides])
        if not ok[0]:           # bad options, not a bad CSV row: exit 2 before any work
            parser.error(f"--radii {' '.join(f'{v:g}' for v in args.radii)} --sides "
                         f"{' '.join(f'{v:g}' for v in args.sides)}: {why[0]}")
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
        check_output(args.out, inputs=[("--csv", args.csv)])
        rows, fields, vals, parse_err = _read_csv(args.csv)
    except (OSError, ValueError) as exc:
        msg = f"{exc.strerror}: {exc.filename}" if isinstance(exc, OSError) else exc
        print(f"error: {msg}", file=sys.stderr)
        return 2
    progress = (not args.no_progress) and len(rows) > 20
    res = _compute(vals[:, :3], vals[:, 3:], args.method, args.rtol, args.workers, progress)
    for k, m in parse_err.items():
        res["message"][k] = m
    bad = 0
    for k in range(len(rows)):
        if res["status"][k] in ("invalid", "failed"):
            bad += 1
            print(f"error: {args.csv} row {k + 2}: {res['status'][k]}: {res['message'][k]}",
                  file=sys.stderr)   # header = row 1, as in a spreadsheet
    extra = ["qstar", "open_area", "contact_type", "error_estimate", "status", "message"]
    with open(f"{args.out}.part", "w", newline="") as fh:   # renamed once complete
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
    os.replace(f"{args.out}.part", args.out)
    n_ok = len(rows) - bad
    print(f"wrote {args.out}: {n_ok} of {len(rows)} rows solved ({args.method})",
          file=sys.stderr)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
