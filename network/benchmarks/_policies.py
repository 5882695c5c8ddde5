"""Part 1 of ``python -m network.bench``: every conductance model × Q* policy on one packing.

Each policy runs against its own fresh copy of the table, so FE cost is really paid and no
policy profits from FE solves stored by another; each model is compared with its own fe-only
answer. Method and measurements: ``docs/network-bench.md``.
"""

from __future__ import annotations

import shutil
import tempfile
import time
from pathlib import Path

from ..flow import ConductanceOptions, SampleOptions, solve_network
from ..packing import random_packing
from ._common import qstar_sources
from ._table import copy_table, default_table

__all__ = ["policies", "policy_lines"]


def policies(n, policy_list, db, seed, workers, models=("conduit", "thesis")) -> dict:
    """Every model × policy on one periodic ``n``-sphere packing (solid fraction 0.60)."""
    pk = random_packing(n, rng=seed, periodic=True, solid_fraction=0.60)
    base = Path(db) if db else default_table()
    tmp = Path(tempfile.mkdtemp(prefix="grainflow-bench-"))
    rows = []
    for model, pol in [(m, p) for m in models for p in policy_list]:
        db_used = tmp / f"{model}-{pol}.sqlite"
        copy_table(base, db_used)
        t0 = time.perf_counter()
        try:
            res = solve_network(pk, axis="z", sample=SampleOptions(porosity_points=0),
                                conductance=ConductanceOptions(model=model, policy=pol,
                                                               db=db_used, workers=workers))
            rows.append({"conductance_model": model, "policy": pol,
                         "permeability_m2": res.permeability_m2,
                         "seconds": time.perf_counter() - t0,
                         "conductance_s": res.timings_s["conductance"],
                         "sources": qstar_sources(res.qstar_stats),
                         "n_throats": res.n_throats})
        except Exception as e:  # noqa: BLE001 - report every policy
            rows.append({"conductance_model": model, "policy": pol,
                         "error": f"{type(e).__name__}: {e}",
                         "seconds": time.perf_counter() - t0})
    ref = {r["conductance_model"]: r["permeability_m2"] for r in rows
           if r["policy"] == "fe-only" and "permeability_m2" in r}
    for r in rows:   # each model against its own FE answer
        if ref.get(r["conductance_model"]) and "permeability_m2" in r:
            r["rel_diff_vs_fe_only"] = r["permeability_m2"] / ref[r["conductance_model"]] - 1.0
    shutil.rmtree(tmp, ignore_errors=True)
    return {"n_spheres": n, "seed": seed, "table": str(base) if base else None, "rows": rows}


def policy_lines(pol: dict) -> list[str]:
    """The printed rows of part 1: k, its difference from fe-only, wall and Q* seconds."""
    lines = []
    for r in pol["rows"]:
        if "error" in r:
            lines.append(f"  {r['conductance_model']:>8s} {r['policy']:>13s}: {r['error']}")
        else:
            d = r.get("rel_diff_vs_fe_only")
            lines.append(f"  {r['conductance_model']:>8s} {r['policy']:>13s}: "
                         f"k = {r['permeability_m2']:.4e} m²"
                         + (f" ({d:+.2%} vs fe-only)" if d is not None else "")
                         + f", {r['seconds']:.2f} s (Q* {r['conductance_s']:.2f} s) {r['sources']}")
    return lines
