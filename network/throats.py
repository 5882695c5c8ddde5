"""``python -m network.throats``: the throats of a packing's flow sample, as CSV for the cache.

Writes every distinct throat of the sample (faces joining two sample pores; faces inside a
tied pore body are left out, as ``network.solve`` does) with columns
``r1,r2,r3,l12,l13,l23,throat,pore1,pore2`` — the first six are the input of
``python -m cache.precompute``; ``throat`` and ``pore1``/``pore2`` are tessellation indices.

Examples
--------
    python -m network.throats bed.csv --out throats.csv
    python -m network.throats --out default_throats.csv          # the bundled scene
"""

from __future__ import annotations

import argparse
import logging
import sys
import time
from pathlib import Path

import numpy as np

from .packing import default_packing_path, read_packing
from .pores import sample_region, select_sample, tessellate, tie_groups


def build_parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(
        prog="python -m network.throats",
        description="Export the distinct throats (r1,r2,r3,l12,l13,l23 + ids) of a packing's "
                    "flow sample: the input of cache.precompute.")
    ap.add_argument("packing", nargs="?", default=None,
                    help="CSV x,y,z,r / .npz / LIGGGHTS dump (default: the bundled scene)")
    ap.add_argument("--out", required=True, help="output CSV")
    ap.add_argument("--sample", nargs=6, type=float,
                    metavar=("XMIN", "XMAX", "YMIN", "YMAX", "ZMIN", "ZMAX"),
                    help="sample box (packing units); default: the interior box")
    ap.add_argument("--margin", type=float, default=None,
                    help="wall margin of the default box (default 1.5 mean diameters)")
    ap.add_argument("--all", dest="everything", action="store_true",
                    help="every interior face of the whole tessellation, not only the sample")
    ap.add_argument("--quiet", "-q", action="store_true")
    return ap


def main(argv=None) -> int:
    args = build_parser().parse_args(argv)
    if not args.quiet:
        logging.basicConfig(level=logging.INFO, format="%(message)s", stream=sys.stderr)
    t0 = time.perf_counter()
    path = Path(args.packing) if args.packing else default_packing_path()
    try:
        packing = read_packing(path)
        tess = tessellate(packing)
        if args.everything:
            idx = tess.interior_throats
        else:
            region = sample_region(packing, box=args.sample, margin=args.margin)
            labels, n_groups = tie_groups(tess)
            sample = select_sample(tess, region, axis="z",
                                   groups=None if n_groups == tess.n_pores else labels)
            idx = sample.throats
    except (OSError, ValueError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    data = np.column_stack([tess.throat_radii[idx], tess.throat_sides[idx], idx,
                            tess.throat_pores[idx]])
    fmt = ["%.9g"] * 6 + ["%d"] * 3
    np.savetxt(args.out, data, delimiter=",", fmt=fmt, comments="",
               header="r1,r2,r3,l12,l13,l23,throat,pore1,pore2")
    print(f"wrote {args.out}: {idx.size} throats of {tess.n_throats} "
          f"({packing.n} spheres, {path}) in {time.perf_counter() - t0:.2f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
