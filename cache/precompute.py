"""Command line: fill a throat table by batch precomputation.

Examples
--------
Every throat of a packing (as exported by ``python -m network.throats``)::

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

import argparse
import contextlib
import json
import logging
import os
import sys

from ._build import precompute_grid, precompute_throats, resolve_solver
from ._csvio import read_throat_csv
from ._dask import DaskConnectError, dask_executor
from ._interp import GRIDS
from ._lookup import export_grid
from ._store import CacheFileError, open_store


def build_parser():
    p = argparse.ArgumentParser(prog="python -m cache.precompute", description=__doc__.split("\n")[0])
    p.add_argument("--db", required=True, help="SQLite throat table (created if missing)")
    src = p.add_mutually_exclusive_group(required=True)
    src.add_argument("--csv", help="throat shapes, columns r1,r2,r3,l12,l13,l23")
    src.add_argument("--grid", choices=sorted(GRIDS), help="named interpolation grid to fill")
    p.add_argument("--rtol", type=float, default=1e-3, help="FE tolerance (default 1e-3)")
    p.add_argument("--workers", type=int, default=1,
                   help="local processes, or the LocalCluster's with --dask local (default 1)")
    p.add_argument("--dask", metavar="ADDRESS",
                   help="run the FE batches on Dask: 'local' (a LocalCluster of --workers "
                        "processes) or a scheduler address such as tcp://host:8786 "
                        "(default: no Dask, multiprocessing)")
    p.add_argument("--batch-size", type=int, default=16, help="solves per transaction (default 16)")
    p.add_argument("--retry-failed", action="store_true", help="solve recorded failures again")
    p.add_argument("--max-hours", type=float, default=None, help="stop submitting after this long")
    p.add_argument("--export", metavar="NPZ", help="after a --grid run, write the grid as .npz")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    return p


def main(argv=None) -> int:
    """Run the command; exit 0 done, 1 interrupted, 2 bad input (one ``error:`` line)."""
    try:
        return _main(argv)
    except KeyboardInterrupt:   # before or after the solve loop (that one reports itself)
        print("interrupted: no shape was being solved; what earlier batches stored is kept",
              file=sys.stderr)
        return 1


def _main(argv):
    args = build_parser().parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(levelname)s %(name)s: %(message)s")
    os.environ.setdefault("DASK_LOGGING__DISTRIBUTED", "warning")   # Dask's cluster chatter
    if args.workers < 1 or args.batch_size < 1:
        print("error: --workers and --batch-size must be >= 1", file=sys.stderr)
        return 2
    try:
        solver, version = resolve_solver(None, None)
        if args.csv:
            _, _, radii, sides = read_throat_csv(args.csv)
    except (ImportError, OSError, ValueError) as e:
        print(f"error: {e}", file=sys.stderr)
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
        except CacheFileError as e:
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
            export_grid(store, args.grid, args.export, solver_version=version)
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
