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
``--db`` before interpolating.  Invalid rows are reported on stderr with their row number
(header = row 1) and written with empty values.
"""

from __future__ import annotations

import argparse
import json
import logging
import sys

import numpy as np

import throats

from ._csvio import read_throat_csv, write_csv
from ._lookup import POLICIES, lookup_qstar
from ._store import CacheFileError


def build_parser():
    p = argparse.ArgumentParser(prog="python -m cache.lookup", description=__doc__.split("\n")[0])
    p.add_argument("--db", default=None, help="throat table (default: cache.default_db_path())")
    p.add_argument("--csv", required=True, help="input, columns r1,r2,r3,l12,l13,l23")
    p.add_argument("--out", required=True, help="output CSV")
    p.add_argument("--policy", choices=POLICIES, default="table+fe",
                   help="where Q* comes from (default table+fe): table+fe = stored value, else "
                        "the grid table, else FE where the table's error estimate exceeds "
                        "--rtol (FE results stored in --db); table-only = stored value, else the "
                        "grid table, else the shape factor (never FE); fe-only = stored value, "
                        "else FE; shape-factor = closed-form estimate (median error ~20%%)")
    p.add_argument("--rtol", type=float, default=1e-3,
                   help="relative tolerance of table+fe and of FE solves (default 1e-3)")
    p.add_argument("--workers", type=int, default=1, help="processes for FE (default 1)")
    p.add_argument("--grid", default=None, help="grid name (default: newest in --db, else shipped)")
    p.add_argument("--quiet", action="store_true")
    return p


def main(argv=None) -> int:
    args = build_parser().parse_args(argv)
    logging.basicConfig(level=logging.WARNING, format="%(levelname)s %(name)s: %(message)s")
    try:
        header, rows, radii, sides = read_throat_csv(args.csv)
        res = lookup_qstar(radii, sides, db=args.db, policy=args.policy, rtol=args.rtol,
                           workers=args.workers, progress=not args.quiet, grid=args.grid)
    except (OSError, ValueError, CacheFileError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    ok = res.source != "failed"
    area = np.full(len(rows), np.nan)
    ctype = np.full(len(rows), "", dtype=object)
    if ok.any():
        area[ok] = throats.open_area(radii[ok], sides[ok])        # input units squared
        ctype[ok] = throats.contact_type(radii[ok], sides[ok])
    for i in np.flatnonzero(~ok):
        print(f"row {i + 2}: {res.message[i]}", file=sys.stderr)  # +2: header, 1-based
    write_csv(args.out, header, rows, {"qstar": res.qstar, "open_area": area,
                                      "contact_type": ctype, "error_estimate": res.error_estimate,
                                      "source": res.source, "message": res.message})
    if not args.quiet:
        print(json.dumps(res.stats, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
