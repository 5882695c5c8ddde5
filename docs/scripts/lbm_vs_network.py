"""Tables of ``docs/inertial-lbm.md``: LBM runs (JSON of ``lbm_periodic.py``) beside the laws
and the network model on the same packings.

For each LBM JSON: the packing (phi, n, seed) is rebuilt by ``random_inertial_case`` (copied
3 x 3 x 3, the middle two periods as the sample) and the network's k/k_app is solved at the
Reynolds numbers the LBM obtained, with the laws ``onset`` (the CLI's until session 7),
``DERIVED_LAW`` and ``PORE_LAW`` (the CLI's since). Printed per row: LBM, Beetstra, HKL, the
three network laws, and the relative differences in % of the pressure gradient. ``--json``
writes the rows.

    python docs/scripts/lbm_vs_network.py /tmp/lbm/ens_*.json --json rows.json
"""

from __future__ import annotations

import argparse
import json
import sys

import numpy as np


def compare(path):
    from network.flow import INERTIAL_LAWS
    from network.validation import DERIVED_LAW, random_inertial_case

    res = json.load(open(path))["result"]
    rows = [r for r in res["rows"] if r["re"] > 0.5]
    re = np.array([r["re"] for r in rows])
    net = {}
    laws = {"onset": INERTIAL_LAWS["onset"], "derived": DERIVED_LAW, "pore": INERTIAL_LAWS["pore"]}
    for name, law in laws.items():
        case = random_inertial_case(res["phi"], re, n_spheres=res["n"], rng=res["seed"], **law)
        net[name] = case.k_ratio
    out = []
    for i, r in enumerate(rows):
        out.append({"phi": res["phi"], "seed": res["seed"], "resolution": res["resolution"],
                    "re": r["re"], "converged": r["converged"], "lbm": r["k_ratio"],
                    "beetstra": r["beetstra"], "hill_koch_ladd": r["hill_koch_ladd"],
                    "onset": float(net["onset"][i]), "derived": float(net["derived"][i]),
                    "pore": float(net["pore"][i]),
                    "k_lbm_d2": res["k_stokes_d2"]})
    return out


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("files", nargs="+")
    p.add_argument("--json", default=None)
    a = p.parse_args(argv)
    rows = []
    for f in a.files:
        rows += compare(f)
    print(f"{'phi':>5} {'seed':>4} {'D':>3} {'Re':>6} {'LBM':>7} {'Beet':>7} {'HKL':>7} "
          f"{'onset':>7} {'deriv':>7} {'pore':>7} {'L/B %':>6} {'L/H %':>6} {'on/L %':>7} "
          f"{'de/L %':>7} {'po/L %':>7} {'po/B %':>7}")
    for r in rows:
        pc = lambda a, b: 100 * (a / b - 1)        # noqa: E731
        flag = "" if r["converged"] else " *"
        print(f"{r['phi']:5.2f} {r['seed']:4d} {r['resolution']:3.0f} {r['re']:6.2f} "
              f"{r['lbm']:7.4f} {r['beetstra']:7.4f} {r['hill_koch_ladd']:7.4f} "
              f"{r['onset']:7.4f} {r['derived']:7.4f} {r['pore']:7.4f} "
              f"{pc(r['lbm'], r['beetstra']):+6.1f} {pc(r['lbm'], r['hill_koch_ladd']):+6.1f} "
              f"{pc(r['onset'], r['lbm']):+7.1f} {pc(r['derived'], r['lbm']):+7.1f} "
              f"{pc(r['pore'], r['lbm']):+7.1f} {pc(r['pore'], r['beetstra']):+7.1f}{flag}")
    if a.json:
        with open(a.json, "w") as fh:
            json.dump(rows, fh, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
