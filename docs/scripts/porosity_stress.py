r"""Porosity against vertical stress of the bundled bin bed sets (``docs/dem-fill.md``,
"Porosity against stress"; ``docs/grain-library.md``).

Reads ``network/data/<grain>_rain_<kPa>kPa.json`` (``dem.pack``'s summaries: the lid's measured
stress, the porosity in network's sample region and in the interior box, each with its Monte
Carlo standard error), prints the table and draws porosity against stress for each grain, with
Janssen's stress at 10 m of a 6 m bin marked (the grain library's K and mu_w, network.bin's
copies, and the bulk density of the poured bed).

    python docs/scripts/porosity_stress.py --plot docs/img/porosity_stress.png
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from network._grains import BED  # noqa: E402
from network.bin._material import JANSSEN, janssen_stress  # noqa: E402
from network.report.binbeds import bed_set_files  # noqa: E402

GRAINS = ("soybean", "wheat", "shelled_corn")


def rows(grain: str) -> list[dict]:
    """One row per bed of the grain's set: stress (lid, Pa), porosities and their errors, S."""
    out = []
    for s, p in bed_set_files(grain):
        m = json.loads(p.with_suffix(".json").read_text())
        out.append({"stress_pa": s, "region": m["porosity_network_region"],
                    "region_err": m["porosity_network_region_error"],
                    "interior": m["porosity_interior_union"],
                    "interior_err": m["porosity_interior_error"],
                    "S": m["orientation_order_S"], "n_grains": m["n_grains"],
                    "box_m": m["container"]["size_m"] + [m["container"]["fill_height_m"]]})
    return out


def janssen_10m_6m(grain: str, porosity: float) -> float:
    k, mu = JANSSEN[grain]
    rho_b = BED[grain].particle_density_kg_m3 * (1 - porosity)
    return float(janssen_stress(10.0, bulk_density_kg_m3=rho_b, diameter_m=6.0, wall_friction=mu,
                                lateral_ratio=k))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--plot", default=None, help="PNG of porosity against stress")
    args = ap.parse_args(argv)
    data = {g: rows(g) for g in GRAINS}
    for g, rs in data.items():
        if not rs:
            print(f"{g}: no bundled bed set")
            continue
        sj = janssen_10m_6m(g, rs[0]["region"])
        print(f"{g}: {rs[0]['n_grains']} grains, box {rs[0]['box_m']} m; Janssen at 10 m of a "
              f"6 m bin {sj / 1000:.1f} kPa")
        for r in rs:
            print(f"  {r['stress_pa'] / 1000:6.2f} kPa  region {r['region']:.4f} +- "
                  f"{r['region_err']:.4f}  interior {r['interior']:.4f} +- "
                  f"{r['interior_err']:.4f}  S {r['S']:+.3f}")
    if args.plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(6.4, 4.2))
        for (g, rs), c in zip(data.items(), ("C0", "C1", "C2")):
            if not rs:
                continue
            s = [r["stress_pa"] / 1000 for r in rs]
            ax.errorbar(s, [r["region"] for r in rs], yerr=[r["region_err"] for r in rs],
                        color=c, marker="o", label=f"{g.replace('_', ' ')}, network region")
            ax.errorbar(s, [r["interior"] for r in rs], yerr=[r["interior_err"] for r in rs],
                        color=c, marker="s", ls="--", mfc="none", label=f"{g.replace('_', ' ')}, interior")
            ax.axvline(janssen_10m_6m(g, rs[0]["region"]) / 1000, color=c, ls=":", lw=1)
        ax.set_xlabel("vertical stress, kPa (dotted: Janssen at 10 m of a 6 m bin)")
        ax.set_ylabel("porosity")
        ax.set_title("rain-filled beds loaded through a lid (mass scale 100)")
        ax.legend(fontsize=7, ncol=2)
        fig.tight_layout()
        fig.savefig(args.plot, dpi=110)
        print(f"wrote {args.plot}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
