"""``python -m network.throatlist``: the throats of a packing's flow sample, as CSV for the cache.

Writes every distinct throat of the sample (faces joining two sample pores; faces inside a
tied pore body are left out, as ``network.solve`` does) with columns
``r1,r2,r3,l12,l13,l23,throat,pore1,pore2`` — the first six are the input of
``python -m cache.precompute``; ``throat`` and ``pore1``/``pore2`` are tessellation indices.

Examples
--------
    python -m network.throatlist bed.csv --out throats.csv
    python -m network.throatlist --out default_throats.csv          # the bundled scene
    python -m network.throatlist bed_mm.csv --units mm --out throats.csv

The packing is read in ``--units`` (``--sample``, ``--margin`` too); the CSV is in metres, with
17 significant digits so that the values read back are the tessellation's bit for bit and the
cache's shape keys (``cache.shape_keys``, quantum 1e-9 r̄) match those ``network.solve`` looks
up (9 digits would move keys and send every throat to FE). Exit 0
done, 1 failed, 2 bad input: one ``error:`` line (docs/cli.md). ``python -m network.throats`` is
the same command under the name the throat-export contract gives it.
"""

from __future__ import annotations

import os
import sys
import time

import numpy as np

from ._cli import (CliParser, add_packing, add_sample, bad_input, check_common, check_outputs,
                   computing, load_packing, packing_inputs, progress_log, run,
                   sample_box_m)
from .packing import read_container
from .pores import sample_region, select_sample, tessellate, tie_groups

HEADER = "r1,r2,r3,l12,l13,l23,throat,pore1,pore2"


def build_parser(prog: str = "python -m network.throatlist") -> CliParser:
    ap = CliParser(
        prog=prog,
        description="Export the distinct throats (r1,r2,r3,l12,l13,l23 in m + ids) of a "
                    "packing's flow sample: the input of cache.precompute. Exit status 0 done, "
                    "1 failed, 2 bad input (docs/cli.md).")
    add_packing(ap)
    ap.add_argument("--out", required=True, metavar="OUT.csv",
                    help=f"output CSV, columns {HEADER} (lengths in m, 17 significant digits; "
                         "its folder must exist; required)")
    add_sample(ap, cylinder=False)
    ap.add_argument("--all", dest="everything", action="store_true",
                    help="every interior face of the whole tessellation (default: only the "
                         "faces of the flow sample, as network.solve uses)")
    ap.add_argument("--quiet", "-q", action="store_true",
                    help="no progress on stderr (default: progress shown)")
    return ap


def main(argv=None, prog: str = "python -m network.throatlist") -> int:
    """Run the command; exit status 0 done, 1 the computation failed, 2 bad input."""
    return run(_main, build_parser(prog), argv)


def _main(args) -> int:
    progress_log(args, "%(message)s")
    t0 = time.perf_counter()
    with bad_input():
        check_common(args)
        check_outputs(out=args.out, inputs=packing_inputs(args))
        path, packing = load_packing(args, tables=False)   # geometry only: no Q* table
        box, margin = sample_box_m(args)
        region = None if args.everything else sample_region(
            packing, box=box, margin=margin, container=None if box else read_container(path))
    with computing():
        tess = tessellate(packing)
        if args.everything:
            idx = tess.interior_throats
        else:
            labels, n_groups = tie_groups(tess)
            sample = select_sample(tess, region, axis="z",
                                   groups=None if n_groups == tess.n_pores else labels)
            idx = sample.throats
        data = np.column_stack([tess.throat_radii[idx], tess.throat_sides[idx], idx,
                                tess.throat_pores[idx]])
        part = f"{args.out}.part"            # complete file or none (Ctrl-C, full disk)
        np.savetxt(part, data, delimiter=",", fmt=["%.17g"] * 6 + ["%d"] * 3, comments="",
                   header=HEADER)
        os.replace(part, args.out)
    print(f"wrote {args.out}: {idx.size} throats of {tess.n_throats} "
          f"({packing.n} spheres, {path}, read in {args.units}) in "
          f"{time.perf_counter() - t0:.2f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
