"""Tables of ``docs/inertial-lbm.md``: LBM runs (JSON of ``lbm_periodic.py``) beside the laws
and the network model on the same packings.

For each LBM JSON (a run of ``lbm_periodic.py``, or a stored table of rows such as
``docs/data/lbm_n800_reference.json`` and ``lbm_reference.json``, whose rows carry phi, seed, n
and re): the packing (phi, n, seed) is rebuilt by ``random_inertial_case`` (copied 3 x 3 x 3, the
middle two periods as the sample) and the network's k/k_app is solved at the Reynolds numbers the
LBM obtained, with the package's current constants, with the law ``window`` (the package's) and
the alternatives ``docs/inertial-flow.md`` compares it with (``--laws`` picks). Printed per row:
LBM, Beetstra, HKL, the network laws, and the relative differences in % of the pressure
gradient. ``--json`` writes
the rows. ``--packing NPZ ...`` (one per LBM file, in order; the NPZ that ``lbm_periodic.py
--packing`` ran, e.g. a Monte Carlo configuration of ``mc_ensemble.py --export``) takes the
network's packing from the file instead of rebuilding it (``periodic_inertial_case``, the same
sample).

    python docs/scripts/lbm_vs_network.py /tmp/lbm/ens_*.json --json rows.json
    python docs/scripts/lbm_vs_network.py mc.json --packing .lbm/mc800_0.55_s1.npz
    python docs/scripts/lbm_vs_network.py docs/data/lbm_n800_reference.json --laws pore chain

A stored table of ordered arrays (``docs/data/lbm_arrays_reference.json``: rows with ``kind``
'sc' or 'fcc') is compared through ``lattice_inertial_case`` (7 cells) instead; its rows print
kind, phi, Re, LBM and the laws.
"""

from __future__ import annotations

import argparse
import json
import sys

import numpy as np


#: Network laws of the table, each the window law's form with its own constants (a one-row
#: table holds one onset slope and recovered share for every conduit; docs/inertial-flow.md):
#: 'derived' the single-constriction Navier-Stokes slope without recovery, 'pore' the 3-D pore
#: body alone, 'chain' that body in a chain at its own window ratio, 'window' the package's
#: table (network.conductance.CHAIN_WINDOW_TABLE).
LAW_TABLES = {"derived": {"sigma": (0.5,), "onset_slope": (0.0235,), "recovery": (0.0,)},
              "pore": {"sigma": (0.5,), "onset_slope": (0.1250,), "recovery": (0.455,)},
              "chain": {"sigma": (0.5,), "onset_slope": (0.1089,), "recovery": (0.097,)},
              "window": None}
LAW_NAMES = tuple(LAW_TABLES)


def _runs(data):
    """(phi, n, seed, resolution, k_stokes_d2, rows) per packing of a loaded LBM JSON: one run
    of ``lbm_periodic.py`` ('result'), or a stored table ('rows' with phi, seed, n, re, lbm;
    a packing's rows may come from runs of several resolutions, each row keeps its own)."""
    if "result" in data:
        res = data["result"]
        rows = [{"re": r["re"], "converged": r["converged"], "lbm": r["k_ratio"],
                 "beetstra": r["beetstra"], "hill_koch_ladd": r["hill_koch_ladd"]}
                for r in res["rows"] if r["re"] > 0.5 and r["beetstra"] is not None]
        return [(res["phi"], res["n"], res["seed"], res["resolution"], res["k_stokes_d2"], rows)]
    groups = {}
    for r in data["rows"]:
        if r["re"] > 0.5:
            groups.setdefault((r["phi"], r["n"], r["seed"]), []).append(r)
    return [(phi, n, seed, rows[0]["resolution"], rows[0].get("k_lbm_d2"), rows)
            for (phi, n, seed), rows in groups.items()]


def _npz_packing(path, phi, n):
    """The unit-sphere packing of an NPZ of ``lbm_periodic.py --packing`` (checked against the
    LBM run's phi and n)."""
    from lbm_periodic import load_packing
    from network.packing import Packing

    centers, radii, _, phi_z, n_z, _ = load_packing(path)
    if n_z != n or not np.isclose(phi_z, phi):
        raise SystemExit(f"{path}: phi {phi_z} n {n_z}, the LBM run has phi {phi} n {n}")
    return Packing(centers, radii, source=str(path))


def compare(data, laws=LAW_NAMES, packing=None):
    """Rows of a loaded LBM JSON of random packings beside the network's k/k_app; ``packing``:
    the NPZ the LBM ran, else the packing is rebuilt from (phi, n, seed)."""
    from network.validation import periodic_inertial_case, random_inertial_case

    out = []
    for phi, n, seed, resolution, k_d2, rows in _runs(data):
        re = np.array([r["re"] for r in rows])
        if packing is None:
            net = {name: random_inertial_case(phi, re, n_spheres=n, rng=seed,
                                              table=LAW_TABLES[name]).k_ratio for name in laws}
        else:
            base = _npz_packing(packing, phi, n)
            net = {name: periodic_inertial_case(base, phi, re, table=LAW_TABLES[name]).k_ratio
                   for name in laws}
        for i, r in enumerate(rows):
            out.append({"phi": phi, "seed": seed, "resolution": r.get("resolution", resolution),
                        "n": n,
                        "re": r["re"], "converged": r["converged"], "lbm": r["lbm"],
                        "beetstra": r["beetstra"], "hill_koch_ladd": r["hill_koch_ladd"],
                        **{name: float(net[name][i]) for name in laws}, "k_lbm_d2": k_d2})
    return out


def compare_arrays(data, laws=LAW_NAMES):
    """Rows of a loaded ordered-array table (``kind``, phi, re, lbm) beside the network's
    k/k_app of the same array (``lattice_inertial_case``, flow along a cube axis)."""
    from network.validation import lattice_inertial_case

    groups = {}
    for r in data["rows"]:
        groups.setdefault((r["kind"], r["phi"]), []).append(r)
    out = []
    for (kind, phi), rows in groups.items():
        re = np.array([r["re"] for r in rows])
        net = {name: lattice_inertial_case(kind, phi, re, table=LAW_TABLES[name]).k_ratio
               for name in laws}
        out += [{"kind": kind, "phi": phi, "re": r["re"], "converged": r["converged"],
                 "lbm": r["lbm"], **{name: float(net[name][i]) for name in laws}}
                for i, r in enumerate(rows)]
    return out


def _pc(x, y):
    """x over y - 1, in %."""
    return 100 * (x / y - 1)


def _print_arrays(rows, laws):
    print(f"{'array':>5} {'phi':>5} {'Re':>6} {'LBM':>7} " + "".join(f"{n:>8}" for n in laws)
          + "".join(f"{n[:5] + '/L%':>9}" for n in laws))
    for r in rows:
        print(f"{r['kind']:>5} {r['phi']:5.2f} {r['re']:6.1f} {r['lbm']:7.4f} "
              + "".join(f"{r[n]:8.4f}" for n in laws)
              + "".join(f"{_pc(r[n], r['lbm']):+9.1f}" for n in laws)
              + ("" if r["converged"] else " *"))


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("files", nargs="+")
    p.add_argument("--laws", nargs="+", default=list(LAW_NAMES), choices=LAW_NAMES)
    p.add_argument("--json", default=None)
    p.add_argument("--packing", nargs="+", default=None, metavar="NPZ",
                   help="the packing each LBM file ran (one per file, in order)")
    a = p.parse_args(argv)
    if a.packing is not None and len(a.packing) != len(a.files):
        p.error(f"{len(a.packing)} --packing files for {len(a.files)} LBM files")
    rows, arrays = [], []
    for i, f in enumerate(a.files):
        with open(f) as fh:
            data = json.load(fh)
        if "rows" in data and data["rows"] and "kind" in data["rows"][0]:
            arrays += compare_arrays(data, a.laws)
        else:
            rows += compare(data, a.laws, a.packing[i] if a.packing else None)
    if arrays:
        _print_arrays(arrays, a.laws)
    if rows:
        print(f"{'phi':>5} {'seed':>4} {'D':>3} {'Re':>6} {'LBM':>7} {'Beet':>7} {'HKL':>7} "
              + "".join(f"{n:>8}" for n in a.laws) + f" {'L/B %':>6} {'L/H %':>6} "
              + "".join(f"{n[:5] + '/L%':>9}" for n in a.laws) + f" {a.laws[-1][:5] + '/B%':>9}")
        for r in rows:
            flag = "" if r["converged"] else " *"
            print(f"{r['phi']:5.2f} {r['seed']:4d} {r['resolution']:3.0f} {r['re']:6.2f} "
                  f"{r['lbm']:7.4f} {r['beetstra']:7.4f} {r['hill_koch_ladd']:7.4f} "
                  + "".join(f"{r[n]:8.4f}" for n in a.laws)
                  + f" {_pc(r['lbm'], r['beetstra']):+6.1f}"
                  + f" {_pc(r['lbm'], r['hill_koch_ladd']):+6.1f} "
                  + "".join(f"{_pc(r[n], r['lbm']):+9.1f}" for n in a.laws)
                  + f" {_pc(r[a.laws[-1]], r['beetstra']):+9.1f}{flag}")
    if a.json:
        with open(a.json, "w") as fh:
            json.dump(rows + arrays, fh, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
