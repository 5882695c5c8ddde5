"""Command line: fill a throat table by batch precomputation.

Examples
--------
Every throat of a packing (as exported by ``python -m network.throatlist``)::

    python -m cache.precompute --db throats.sqlite --csv THROATS.csv --workers 2

The interpolation grid over the signature space (named grids: ``cache.GRIDS``)::

    python -m cache.precompute --db throats.sqlite --grid coarse --workers 1

On a Dask cluster (optional extra ``pip install 'grainflow[dask]'``): ``--dask local`` starts a
LocalCluster of ``--workers`` processes, ``--dask tcp://host:8786`` uses a running scheduler;
batches of ``--batch-size`` shapes are Dask tasks and only this process writes the table::

    python -m cache.precompute --db throats.sqlite --grid g1 --dask local --workers 2

Rerunning the same command resumes (solved shapes are reused); ``--retry-failed`` solves the
recorded failures again; Ctrl-C finishes and stores the running batches and says how many;
pool workers exit when the parent is killed (``kill -9``); two runs on one ``--db`` split the
shapes between them through claims in the table (``docs/cache-precompute.md``).  A summary
(solved, reused, failed, seconds) is printed as JSON.  Exit status: 0 done, 1 interrupted,
2 bad input or an unreachable scheduler (nothing written).
"""

from __future__ import annotations

import contextlib
import json
import logging
import os
import sqlite3
import sys

import throats
from network.core import MAX_WORKERS, check_count
from throats.solve import OneLineParser, check_output, run_interruptible

from ._build import precompute_grid, precompute_throats, resolve_solver
from ._csvio import read_throat_csv, row_problems
from ._dask import DaskConnectError, dask_executor
from ._grids import GRIDS
from ._gridio import export_grid
from ._store import CacheFileError, open_store


def build_parser():
    p = OneLineParser(prog="python -m cache.precompute", description=__doc__.split("\n")[0])
    p.add_argument("--db", required=True, metavar="DB.sqlite",
                   help="SQLite throat table; created if missing, its folder must exist "
                        "(required)")
    src = p.add_mutually_exclusive_group(required=True)
    src.add_argument("--csv", metavar="IN.csv",
                     help="throat shapes, columns r1,r2,r3,l12,l13,l23 in any one length unit "
                          "(as written by python -m network.throatlist); a bad row is refused "
                          "before anything is written")
    src.add_argument("--grid", choices=sorted(GRIDS), help="named interpolation grid to fill")
    p.add_argument("--rtol", type=float, default=1e-3,
                   help="relative FE tolerance, in (0, 1) (default 1e-3)")
    p.add_argument("--workers", type=int, default=1,
                   help="local processes, or the LocalCluster's with --dask local, >= 1 "
                        "(default 1: this process)")
    p.add_argument("--dask", metavar="ADDRESS",
                   help="run the FE batches on Dask: 'local' (a LocalCluster of --workers "
                        "processes) or a scheduler address such as tcp://host:8786 "
                        "(default: no Dask, multiprocessing)")
    p.add_argument("--batch-size", type=int, default=16,
                   help="shapes per task and per transaction, >= 1 (default 16)")
    p.add_argument("--retry-failed", action="store_true",
                   help="solve recorded failures again (default: skip them)")
    p.add_argument("--max-hours", type=float, default=None,
                   help="stop submitting batches after this many hours, > 0 (default: no limit)")
    p.add_argument("--export", metavar="NPZ",
                   help="after a complete --grid run, write the grid as .npz; its folder must "
                        "exist (default: not written)")
    p.add_argument("--orbits", action="store_true",
                   help="with --export: one value per vertex-permutation orbit of the nodes, "
                        "about a sixth of the file (default: every node)")
    p.add_argument("--quiet", action="store_true", help="no progress bar (default: a bar)")
    return p


def main(argv=None) -> int:
    """Run the command; exit 0 done, 1 interrupted, 2 bad input (one ``error:`` line)."""
    # Ctrl-C before or after the solve loop (that one reports itself)
    return run_interruptible(_main, argv, "interrupted: no shape was being solved; what "
                             "earlier batches stored is kept")


def _check(args):
    """Every option and the CSV, before anything is written: ValueError/OSError."""
    if not 0 < args.rtol < 1:
        raise ValueError(f"--rtol must be in (0, 1), got {args.rtol}")
    if args.workers < 1 or args.batch_size < 1:
        raise ValueError(f"--workers and --batch-size must be >= 1, got {args.workers} and "
                         f"{args.batch_size}")
    check_count("--workers", args.workers, MAX_WORKERS)
    check_count("--batch-size", args.batch_size, 1_000_000)
    if args.max_hours is not None and not args.max_hours > 0:
        raise ValueError(f"--max-hours must be > 0, got {args.max_hours}")
    csv_in = [("--csv", args.csv)] if args.csv else []
    check_output(args.db, "--db", inputs=csv_in)
    if args.export:
        if not args.grid:
            raise ValueError("--export needs --grid")
        check_output(args.export, "--export", inputs=csv_in + [("--db", args.db)])
    elif args.orbits:
        raise ValueError("--orbits needs --export")
    if args.orbits and getattr(GRIDS[args.grid], "kind", None) == "pair":
        raise ValueError(f"--orbits: grid {args.grid} (deep pairs) has no vertex-permutation "
                         "orbits; export it without --orbits")
    if not args.csv:
        return None, None
    errors = {}
    _, _, radii, sides = read_throat_csv(args.csv, errors)
    if len(radii) == 0:
        raise ValueError(f"{args.csv}: no throat rows after the header")
    ok, msg = throats.validate_throats(radii, sides)
    bad = row_problems(args.csv, ok, msg, errors)
    if bad:
        more = f" (and {len(bad) - 1} more bad rows)" if len(bad) > 1 else ""
        raise ValueError(f"{bad[0]}{more}; nothing written")
    return radii, sides


def _main(argv):
    args = build_parser().parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(levelname)s %(name)s: %(message)s")
    os.environ.setdefault("DASK_LOGGING__DISTRIBUTED", "warning")   # Dask's cluster chatter
    try:
        radii, sides = _check(args)
        solver, version = resolve_solver(None, None)
    except (ImportError, OSError, ValueError) as e:
        msg = f"{e.strerror}: {e.filename}" if isinstance(e, OSError) and e.filename else e
        print(f"error: {msg}", file=sys.stderr)
        return 2
    with contextlib.ExitStack() as stack:
        executor, slots = None, args.workers
        if args.dask:
            try:   # before the table is opened: an unreachable scheduler writes nothing
                executor, slots = stack.enter_context(dask_executor(args.dask,
                                                                    workers=args.workers))
            except DaskConnectError as e:
                print(f"error: {e}", file=sys.stderr)
                return 2
        try:
            store = stack.enter_context(open_store(args.db))
        except (CacheFileError, OSError, sqlite3.OperationalError) as e:
            print(f"error: {e}", file=sys.stderr)
            return 2
        kw = dict(rtol=args.rtol, solver=solver, solver_version=version, workers=slots,
                  batch_size=args.batch_size, retry_failed=args.retry_failed,
                  progress=not args.quiet, executor=executor,
                  max_seconds=None if args.max_hours is None else 3600 * args.max_hours)
        if args.csv:
            summary = precompute_throats(store, radii, sides, **kw)
        else:
            summary = precompute_grid(store, GRIDS[args.grid], **kw)
        out = summary.as_dict()
        out.update(db=str(args.db), solver_version=version, rtol=args.rtol, rows=store.count(),
                   dask=args.dask)
        if args.grid and args.export and not out.get("interrupted"):
            export_grid(store, args.grid, args.export, solver_version=version,
                        orbits=args.orbits)
            out["exported"] = args.export
    print(json.dumps(out, indent=1))
    if out.get("interrupted"):
        print(f"interrupted: {summary.solved + summary.failed} shapes solved and stored in "
              f"this run ({out['rows']} rows in {args.db}); rerun the same command to resume",
              file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
