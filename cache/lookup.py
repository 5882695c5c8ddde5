"""Command line: Q* of every throat in a CSV file, from the cache (and FE where needed).

Example::

    python -m cache.lookup --db throats.sqlite --csv IN.csv --out OUT.csv --policy table+fe --rtol 1e-3

Writes the input columns plus ``qstar, open_area, contact_type, error_estimate`` (the columns
of ``python -m throats.solve --csv``, with the same meanings) and ``source, message``:

* ``qstar``: dimensionless Q*, in units of the mean radius (g = Q* r̄⁴/(μL));
* ``open_area``: open (fluid) area of the cross-section in the input's length unit squared
  (m² for a CSV in metres), not scaled by r̄;
* ``error_estimate``: relative error estimate of ``qstar`` (empty for the shape factor);
* ``source``: exact (stored FE value), interp (grid table), fe, shape-factor, closed, failed.

Default policy ``table+fe``; ``table-only`` and ``table+fe`` use values already stored in
``--db`` before interpolating.  Invalid rows are reported on stderr as ``error: FILE row N: ...``
(header = row 1, as a spreadsheet counts) and written with empty values.  Exit status: 0 every
row answered, 1 some row not (or Ctrl-C: no output written), 2 bad options or files (one
``error:`` line, checked before anything is computed or written).
"""

from __future__ import annotations

import json
import logging
import os
import sqlite3
import sys

import numpy as np

import throats
from network.core import MAX_WORKERS, check_count
from throats.solve import OneLineParser, check_output, run_interruptible

from ._csvio import read_throat_csv, row_problems, write_csv
from ._grids import GRIDS
from ._lookup import POLICIES, default_db_path, lookup_qstar
from ._store import CacheFileError


def build_parser():
    p = OneLineParser(prog="python -m cache.lookup", description=__doc__.split("\n")[0])
    p.add_argument("--db", default=None, metavar="DB.sqlite",
                   help="throat table, SQLite: stored values are used first, FE results are "
                        "stored in it (default: cache.default_db_path(), $GRAINFLOW_CACHE_DB or "
                        "~/.cache/grainflow/throats.sqlite); a file given here is created if "
                        "missing, its folder must exist")
    p.add_argument("--csv", required=True, metavar="IN.csv",
                   help="input, columns r1,r2,r3,l12,l13,l23 in any one length unit (other "
                        "columns are copied; required)")
    p.add_argument("--out", required=True, metavar="OUT.csv",
                   help="output CSV, the input columns plus qstar (r-bar units), open_area "
                        "(input unit squared), contact_type, error_estimate (relative), source, "
                        "message; its folder must exist (required)")
    p.add_argument("--policy", choices=POLICIES, default="table+fe",
                   help="where Q* comes from (default table+fe): table+fe = stored value, else "
                        "the grid table, else FE where the table's error estimate exceeds "
                        "--rtol (FE results stored in --db); table-only = stored value, else the "
                        "grid table, else the shape factor (never FE); fe-only = stored value, "
                        "else FE; shape-factor = closed-form estimate (median error ~20%%)")
    p.add_argument("--rtol", type=float, default=1e-3,
                   help="relative tolerance of table+fe and of FE solves, in (0, 1) "
                        "(default 1e-3)")
    p.add_argument("--workers", type=int, default=1, help="processes for FE, >= 1 (default 1)")
    p.add_argument("--grid", default=None,
                   help="grid name (default: the newest in --db, else the shipped g1)")
    p.add_argument("--quiet", action="store_true",
                   help="no progress bar and no statistics on stdout (default: both)")
    return p


def main(argv=None) -> int:
    """Run the command; exit 0 every row answered, 1 some row not (or Ctrl-C), 2 bad input."""
    return run_interruptible(_main, argv, "interrupted: nothing written to the output (FE "
                             "results already stored in the table are kept)")


def _main(argv):
    args = build_parser().parse_args(argv)
    logging.basicConfig(level=logging.WARNING, format="%(levelname)s %(name)s: %(message)s")
    errors = {}
    try:
        if not 0 < args.rtol < 1:
            raise ValueError(f"--rtol must be in (0, 1), got {args.rtol}")
        if args.workers < 1:
            raise ValueError(f"--workers must be >= 1, got {args.workers}")
        check_count("--workers", args.workers, MAX_WORKERS)
        if args.grid is not None and args.grid not in GRIDS:
            raise ValueError(f"--grid {args.grid}: no such grid; the grids are "
                             f"{', '.join(GRIDS)}")
        check_output(args.out, inputs=[("--csv", args.csv),
                                       ("--db", args.db or default_db_path())])
        if args.db is not None and not os.path.isfile(args.db):
            check_output(args.db, "--db", inputs=[("--csv", args.csv)])   # to be created
        header, rows, radii, sides = read_throat_csv(args.csv, errors)
        res = lookup_qstar(radii, sides, db=args.db, policy=args.policy, rtol=args.rtol,
                           workers=args.workers, progress=not args.quiet, grid=args.grid)
    except (OSError, ValueError, CacheFileError, sqlite3.OperationalError) as e:
        msg = f"{e.strerror}: {e.filename}" if isinstance(e, OSError) and e.filename else e
        print(f"error: {msg}", file=sys.stderr)
        return 2
    ok = res.source != "failed"
    area = np.full(len(rows), np.nan)
    ctype = np.full(len(rows), "", dtype=object)
    if ok.any():
        area[ok] = throats.open_area(radii[ok], sides[ok])        # input units squared
        ctype[ok] = throats.contact_type(radii[ok], sides[ok])
    for line in row_problems(args.csv, ok, res.message, errors):
        print(f"error: {line}", file=sys.stderr)
    write_csv(args.out, header, rows, {"qstar": res.qstar, "open_area": area,
                                      "contact_type": ctype, "error_estimate": res.error_estimate,
                                      "source": res.source, "message": res.message})
    if not args.quiet:
        print(json.dumps(res.stats, indent=1))
    return 0 if ok.all() else 1


if __name__ == "__main__":
    sys.exit(main())
