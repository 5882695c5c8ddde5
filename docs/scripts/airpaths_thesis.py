r"""The thesis's airflow-path tables (4.1-4.3) and turning angles (Fig. 4.6) on a packing.

Validation script of ``docs/airpaths.md``. On the rect-bin scene
(``python -m dem.pack --scene rect-bin --seed 1 --out rb.csv``) it builds widest and narrowest
paths (``network.paths.build_paths``, the default :class:`~network.paths.BuildRules`) from the
thesis's three air entry points (4.1.2: (0.02, 0), (-0.07, 0), (0.09, 0) m in x, y; the
thesis's frame is the DEM's, Appendix A: x in -0.125..0.125, y in -0.01..0.01, floor z = 0)
and from 20 random entry points (``random_entry_points``, seed 0), vertically (z) and, for
Table 4.3, horizontally (x, entries in the y-z plane: (0, 0.0625), (0, 0.125), (0, 0.1875) m
and 20 random). Each other reading of :class:`~network.paths.BuildRules` and the Appendix D
angle rule are measured on the same 20 entries. Prints Markdown tables; ``--json`` keeps
every number and ``--plot`` draws the turning-angle distribution.

    python docs/scripts/airpaths_thesis.py rb.csv --json airpaths.json \
        --plot docs/img/airpaths_turning_angles.png
"""

from __future__ import annotations

import argparse
import json

import numpy as np

from network.packing import read_packing
from network.paths import (BuildRules, build_paths, interior_angles, random_entry_points,
                           smoothed_length)

THESIS_AEP_XY_M = np.array([[0.02, 0.0], [-0.07, 0.0], [0.09, 0.0]])
#: Horizontal entries (y, z), m: the thesis does not give its AEP4-6.
HORIZONTAL_AEP_M = np.array([[0.0, 0.0625], [0.0, 0.125], [0.0, 0.1875]])
#: Table 4.1 (length m, width mm, tetrahedra), Table 4.2 (tortuosity), Table 4.3 (horizontal).
THESIS = {
    "widest": {"length_m": [0.365, 0.365, 0.385], "width_mm": [2.91, 2.83, 2.73],
               "tetrahedra": [152, 160, 162], "tortuosity": [1.33, 1.39, 1.45]},
    "narrowest": {"length_m": [0.390, 0.376, 0.401], "width_mm": [1.99, 1.85, 2.00],
                  "tetrahedra": [148, 142, 154], "tortuosity": [1.40, 1.34, 1.47]},
    "horizontal": {"length_m": [0.355, 0.363, 0.390], "width_mm": [2.86, 2.63, 2.81],
                   "tetrahedra": [153, 154, 159], "tortuosity": [1.34, 1.40, 1.40]},
}
READINGS = {
    "chosen": BuildRules(),
    "exits all": BuildRules(exits="all"),
    "rule 1 ball": BuildRules(overlap="ball"),
    "rule 1 none": BuildRules(overlap="none"),
    "rule 2 second": BuildRules(closed="second"),
    "area exact": BuildRules(area="exact"),
    "no insphere": BuildRules(insphere=False),
    "start lowest centre": BuildRules(start="lowest-centre"),
}


def appendix_d_turn(points):
    """What Appendix D's script computes as the angle, as a turn: 180 - ww, degrees (its
    ``ww`` is (180/3.14) cos(omega), plus 180 when negative; no arccos)."""
    return 180.0 - interior_angles(points, rule="appendix-d")


def measures(paths, angle_rule="eq3.25"):
    """Per path: length, width, tetrahedra, tortuosity (smoothed), raw tortuosity, status."""
    out = []
    for p in paths:
        if angle_rule == "appendix-d":
            t = smoothed_length(p.points, rule="appendix-d") / p.depth_m
        else:
            t = p.tortuosity
        out.append({"length_m": p.length_m, "width_mm": p.mean_width_m * 1e3,
                    "tetrahedra": p.n_tetrahedra, "tortuosity": t,
                    "tortuosity_raw": p.tortuosity_raw, "status": p.status,
                    "backtracks": p.n_backtracks, "relaxed": p.n_relaxed})
    return out


def stats(rows, key):
    v = np.array([r[key] for r in rows if r["status"] == "ok"], dtype=float)
    if not v.size:
        return {"mean": float("nan"), "sd": float("nan"), "min": float("nan"),
                "max": float("nan"), "n": 0}
    return {"mean": float(v.mean()), "sd": float(v.std(ddof=1)) if v.size > 1 else 0.0,
            "min": float(v.min()), "max": float(v.max()), "n": int(v.size)}


def xz_turn(points):
    """Turning angles of the path drawn in the x-z plane (Fig. 4.5's view across the 20 mm
    slab), degrees; segments normal to the plane are skipped."""
    q = np.diff(np.asarray(points)[:, [0, 2]], axis=0)
    q = q[np.linalg.norm(q, axis=1) > 0]
    cos = np.einsum("ij,ij->i", q[:-1], q[1:]) / (np.linalg.norm(q[:-1], axis=1)
                                                  * np.linalg.norm(q[1:], axis=1))
    return np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))


def turning(paths):
    ok = [p for p in paths if p.status == "ok"]
    return {"eq3.25": np.concatenate([p.turning_angles_deg for p in ok]),
            "appendix-d": np.concatenate([appendix_d_turn(p.points) for p in ok]),
            "x-z view": np.concatenate([xz_turn(p.points) for p in ok])}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("packing")
    ap.add_argument("--entries", type=int, default=20)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--json")
    ap.add_argument("--plot")
    ap.add_argument("--no-readings", action="store_true", help="skip the other readings")
    args = ap.parse_args(argv)
    pk = read_packing(args.packing)
    x, r = np.asarray(pk.centers), np.asarray(pk.radii)
    res = {"n_spheres": int(len(r)), "readings": {}, "paths": {}}
    rnd = {"z": random_entry_points(x, r, args.entries, axis="z", rng=args.seed),
           "x": random_entry_points(x, r, args.entries, axis="x", rng=args.seed)}
    angles = {}
    for kind in ("widest", "narrowest"):
        three = build_paths(x, r, THESIS_AEP_XY_M, kind=kind)
        many = build_paths(x, r, rnd["z"], kind=kind)
        res["paths"][kind] = {"aep": measures(three), "random": measures(many),
                              "aep_appendix_d": measures(three, "appendix-d"),
                              "random_appendix_d": measures(many, "appendix-d")}
        angles[kind] = {"aep": turning(three), "random": turning(many)}
        res["paths"][kind]["turning"] = {
            w: {k: {"below_30": float(np.mean(v < 30)), "0_10": float(np.mean(v < 10)),
                    "80_90": float(np.mean((v >= 80) & (v < 90))),
                    "over_90": float(np.mean(v >= 90)),
                    "hist_10deg": np.histogram(v, bins=np.arange(0, 190, 10))[0].tolist()}
                for k, v in a.items()} for w, a in angles[kind].items()}
    hz3 = build_paths(x, r, HORIZONTAL_AEP_M, kind="widest", axis="x")
    hzn = build_paths(x, r, rnd["x"], kind="widest", axis="x")
    res["paths"]["horizontal"] = {"aep": measures(hz3), "random": measures(hzn),
                                  "aep_appendix_d": measures(hz3, "appendix-d"),
                                  "random_appendix_d": measures(hzn, "appendix-d")}
    if not args.no_readings:
        for name, rules in READINGS.items():
            res["readings"][name] = {}
            for kind in ("widest", "narrowest"):
                rows = measures(build_paths(x, r, rnd["z"], kind=kind, rules=rules))
                res["readings"][name][kind] = {k: stats(rows, k) for k in
                                               ("tortuosity", "width_mm", "tetrahedra",
                                                "length_m")}
                res["readings"][name][kind]["ok"] = sum(q["status"] == "ok" for q in rows)
    _print(res)
    if args.json:
        with open(args.json, "w") as f:
            json.dump(res, f, indent=1)
    if args.plot:
        _plot(angles, args.plot)
    return 0


def _print(res):
    keys = (("length_m", "L_e (m)", 3), ("width_mm", "W (mm)", 2), ("tetrahedra", "tetrahedra", 0),
            ("tortuosity", "T (Eq. 3.25)", 2))
    for kind in ("widest", "narrowest", "horizontal"):
        d = res["paths"][kind]
        print(f"\n{kind}: | quantity | thesis AEP1-3 (mean) | ours AEP1-3 (mean) | ours 20: "
              "mean ± sd (min-max) |")
        for key, label, nd in keys:
            th = THESIS[kind][key]
            ours = [q[key] for q in d["aep"]]
            s = stats(d["random"], key)
            print(f"| {label} | {' / '.join(f'{v:.{nd}f}' for v in th)} ({np.mean(th):.{nd}f}) | "
                  f"{' / '.join(f'{v:.{nd}f}' for v in ours)} ({np.mean(ours):.{nd}f}) | "
                  f"{s['mean']:.{nd}f} ± {s['sd']:.{nd}f} ({s['min']:.{nd}f}-{s['max']:.{nd}f}) |")
        ours = [q["tortuosity"] for q in d["aep_appendix_d"]]
        s = stats(d["random_appendix_d"], "tortuosity")
        print(f"| T (Appendix D angle) | | {' / '.join(f'{v:.2f}' for v in ours)} "
              f"({np.mean(ours):.2f}) | {s['mean']:.2f} ± {s['sd']:.2f} "
              f"({s['min']:.2f}-{s['max']:.2f}) |")
        print("status:", [q["status"] for q in d["aep"]], "random ok:",
              sum(q["status"] == "ok" for q in d["random"]))
        if "turning" in d:
            for w in ("aep", "random"):
                print(f"turning ({w}):", {k: round(v["below_30"], 3)
                                          for k, v in d["turning"][w].items()})
    if res["readings"]:
        print("\n| reading | widest T | widest W (mm) | widest tetra | narrowest T | "
              "narrowest W (mm) | narrowest tetra |")
        for name, d in res["readings"].items():
            cells = []
            for kind in ("widest", "narrowest"):
                t, w = d[kind]["tortuosity"], d[kind]["width_mm"]
                cells += [f"{t['mean']:.2f} ± {t['sd']:.2f}", f"{w['mean']:.2f} ± {w['sd']:.2f}",
                          f"{d[kind]['tetrahedra']['mean']:.0f}"]
            print(f"| {name} | " + " | ".join(cells) + " |")


def _plot(angles, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axs = plt.subplots(1, 2, figsize=(9, 3.6), sharey=True)
    bins = np.arange(0, 190, 10)
    for axp, kind, tag in zip(axs, ("widest", "narrowest"), ("(a)", "(b)")):
        for key, label, style in (("eq3.25", "180° - ω, Eq. 3.25 in 3-D", "C0"),
                                  ("x-z view", "the same in the x-z view (Fig. 4.5)", "C2"),
                                  ("appendix-d", "Appendix D's 180° - ww (no arccos)", "C3")):
            v = angles[kind]["random"][key]
            axp.hist(v, bins=bins, weights=np.full(v.size, 100.0 / v.size), histtype="step",
                     lw=1.8, color=style, label=f"{label}: {np.mean(v < 30) * 100:.0f} % < 30°")
        axp.axvline(30, color="k", lw=0.8, ls=":")
        axp.set_title(f"{tag} {kind} paths, 20 entries")
        axp.set_xlabel("local turning angle (degrees)")
        axp.set_xticks(np.arange(0, 181, 30))
        axp.legend(fontsize=7, loc="upper right")
    axs[0].set_ylabel("frequency (%)")
    fig.suptitle("Local turning angles on the rect-bin "
                 "(thesis Fig. 4.6: more than 50 % below 30°)", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


if __name__ == "__main__":
    raise SystemExit(main())
