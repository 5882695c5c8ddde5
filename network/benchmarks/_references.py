"""Part 3 of ``python -m network.bench``: k against published / computed Stokes k.

Every conductance model × Q* policy on lattices (SC against Zick & Homsy 1982, BCC/FCC against
this project's Stokes FE of the unit cell) and on random monodisperse packings (against the LBM
drag law of van der Hoef et al. 2005), each cell from a fresh copy of the table (``db``, or an
empty one: interpolation in the grid shipped in ``cache/data``), so FE cost is paid every time.
One table: a row per case with k/k_ref and the wall seconds per column, summary rows per
column. Cases, timing rules and measurements: ``docs/network-bench.md``.
"""

from __future__ import annotations

import argparse
import math
import shutil
import tempfile
import time
from pathlib import Path

from ..packing import LATTICES, TOUCHING_FRACTION, random_packing
from ..validation import (beetstra_permeability, computed_lattice_permeability,
                          lattice_permeability, lattice_sample_permeability,
                          random_sample_permeability)
from ._table import copy_table, drop_table, table_totals

__all__ = ["FE_POLICIES", "REF_LATTICE_CASES", "REF_RANDOM_POROSITIES", "lattice_case",
           "references", "references_table"]

#: Lattice cases: (lattice, solid fraction); pi/6 is touching simple cubic.
REF_LATTICE_CASES = (("sc", 0.3), ("sc", 0.45), ("sc", math.pi / 6),
                     ("bcc", 0.3), ("bcc", 0.4), ("bcc", 0.5), ("bcc", 0.6), ("bcc", 0.66),
                     ("fcc", 0.3), ("fcc", 0.45), ("fcc", 0.55), ("fcc", 0.65), ("fcc", 0.72))
#: Porosities of the random-packing cases.
REF_RANDOM_POROSITIES = (0.36, 0.40, 0.45)
#: Policies that run FE solves (opt-in per porosity on random packings, see --fe-random).
FE_POLICIES = ("table+fe", "fe-only")


def lattice_case(text: str):
    """``kind:phi`` (``phi`` a number or ``touch``) -> (kind, phi), for argparse."""
    kind, sep, phi = text.partition(":")
    kind = kind.lower()
    if not sep or kind not in LATTICES:
        raise argparse.ArgumentTypeError(f"expected KIND:PHI with KIND in {LATTICES}, got {text!r}")
    if phi.lower() == "touch":
        return kind, TOUCHING_FRACTION[kind]
    try:
        value = float(phi)
    except ValueError:
        raise argparse.ArgumentTypeError(f"solid fraction of {text!r} is not a number") from None
    if not 0.0 < value <= TOUCHING_FRACTION[kind] * (1 + 1e-4):
        raise argparse.ArgumentTypeError(
            f"solid fraction of {text!r} outside (0, {TOUCHING_FRACTION[kind]:.6f}]")
    return kind, value


def _lattice_reference(kind: str, phi: float, radius: float) -> float:
    """Exact Stokes k of the array, lattice constant²: Zick & Homsy (SC), own FE (BCC/FCC)."""
    if kind == "sc":
        return float(lattice_permeability("sc", phi, radius))
    return float(computed_lattice_permeability(kind, phi))


def _ref_cell(case: dict, model: str, policy: str, base: Path | None, tmp: Path,
              repeats: int) -> dict:
    """One case × model × policy: k, k/k_ref, minimum wall time over fresh-table repeats."""
    cell = {"conductance_model": model, "policy": policy, "repeats": repeats,
            "seconds_all": [], "fe_solves": [], "fe_seconds": []}
    for rep in range(repeats):
        db = tmp / f"{case['name']}-{model}-{policy}-{rep}.sqlite".replace(":", "_")
        copy_table(base, db)
        n0, s0 = table_totals(db)
        t0 = time.perf_counter()
        try:
            if case["kind"] == "random":
                k = random_sample_permeability(case["porosity"], n_spheres=case["n_spheres"],
                                               rng=case["seed"], model=model, policy=policy,
                                               db=db)
            else:
                k, r = lattice_sample_permeability(case["kind"], case["solid_fraction"],
                                                   model=model, policy=policy, db=db)
                case.setdefault("radius", r)
        except Exception as e:  # noqa: BLE001 - report every cell
            cell["error"] = f"{type(e).__name__}: {e}"
            cell["seconds_all"].append(time.perf_counter() - t0)
            break
        cell["seconds_all"].append(time.perf_counter() - t0)
        n1, s1 = table_totals(db)
        cell["fe_solves"].append(n1 - n0)
        cell["fe_seconds"].append(s1 - s0)
        drop_table(db)
        cell.setdefault("k_all", []).append(float(k))
        cell["k"] = cell["k_all"][0]
    cell["seconds"] = min(cell["seconds_all"])
    if "k" in cell:
        if case["kind"] != "random" and "k_ref" not in case:
            case["k_ref"] = _lattice_reference(case["kind"], case["solid_fraction"],
                                               case["radius"])
        cell["ratio"] = cell["k"] / case["k_ref"]
    return cell


def _warm_up(base: Path | None, tmp: Path) -> float:
    """Import the pipeline and load the interpolation grid (not timed in the cells)."""
    db = tmp / "warm-up.sqlite"
    copy_table(base, db)
    t0 = time.perf_counter()
    lattice_sample_permeability("sc", 0.45, model="conduit", policy="table-only", db=db)
    return time.perf_counter() - t0


def _cases(lattice_cases, random_porosities, n_spheres, seed) -> list[dict]:
    """The rows of the table, with their references (lattice k_ref once its radius is known)."""
    cases = []
    for kind, phi in lattice_cases:
        cases.append({"name": f"{kind}:{phi:.4f}", "kind": kind, "solid_fraction": float(phi),
                      "reference": ("Zick & Homsy (1982) Table 2" if kind == "sc" else
                                    "network._references.computed_lattice_permeability "
                                    "(own Stokes FE)"),
                      "k_unit": "lattice constant^2"})
    for eps in random_porosities:
        t0 = time.perf_counter()   # the generation every random cell repeats, timed alone
        random_packing(int(n_spheres), diameter_range_m=(1.0, 1.0), solid_fraction=1 - eps,
                       periodic=True, rng=seed)
        cases.append({"name": f"random:{eps:.2f}", "kind": "random", "porosity": float(eps),
                      "n_spheres": int(n_spheres), "seed": seed,
                      "packing_s": time.perf_counter() - t0,
                      "k_ref": float(beetstra_permeability(1.0 - eps, 1.0)),
                      "reference": "van der Hoef et al. (2005) LBM drag law (beetstra_permeability)",
                      "k_unit": "diameter^2"})
    return cases


def _summary(cases, key) -> dict:
    """Column ``key``: total seconds, FE solves, max |k/k_ref - 1| over lattices and random."""
    cells = [c["cells"][key] for c in cases]
    run = [c for c in cells if "seconds" in c]
    entry = {"total_seconds": float(sum(c["seconds"] for c in run)),
             "fe_solves": int(sum(c["fe_solves"][0] for c in run if c["fe_solves"])),
             "n_cases_run": len(run), "n_cases": len(cells),
             "n_errors": sum("error" in c for c in cells)}
    for name, random in (("lattices", False), ("random", True)):
        group = [c["cells"][key] for c in cases if (c["kind"] == "random") == random]
        err = [abs(c["ratio"] - 1.0) for c in group if "ratio" in c]
        entry[f"max_abs_error_{name}"] = max(err) if err else None
        entry[f"n_{name}"] = len(err)
        entry[f"n_{name}_cases"] = len(group)
    return entry


def references(lattice_cases, random_porosities, models, policies, db, *, fe_random=(0.40,),
               repeats=2, n_spheres=800, seed=1) -> dict:
    """Part 3: every case × model × policy, with summaries per model × policy column."""
    base = Path(db) if db else None   # None: every cell starts from an empty table
    if base is not None and not base.exists():
        raise FileNotFoundError(f"throat table {base} does not exist")
    tmp = Path(tempfile.mkdtemp(prefix="grainflow-bench-ref-"))
    fe_set = {round(float(e), 6) for e in fe_random}
    cases = _cases(lattice_cases, random_porosities, n_spheres, seed)
    warm = _warm_up(base, tmp)
    columns = [(m, p) for m in models for p in policies]
    for case in cases:
        case["cells"] = {}
        for model, pol in columns:
            key = f"{model}/{pol}"
            rnd = case["kind"] == "random"
            if rnd and pol in FE_POLICIES and round(case["porosity"], 6) not in fe_set:
                case["cells"][key] = {"conductance_model": model, "policy": pol,
                                      "skipped": "FE policy on a random packing not requested "
                                                 "(--fe-random)"}
                continue
            reps = 1 if (rnd and pol in FE_POLICIES) else repeats
            cell = _ref_cell(case, model, pol, base, tmp, reps)
            case["cells"][key] = cell
            print(f"  {case['name']:>12s} {key:>22s}: "
                  + (f"k/k_ref = {cell['ratio']:.4f}" if "ratio" in cell else cell.get("error"))
                  + f", {cell['seconds']:.2f} s"
                  + (f", {cell['fe_solves'][0]} FE solves" if cell["fe_solves"] else ""),
                  flush=True)
    summary = {f"{m}/{p}": _summary(cases, f"{m}/{p}") for m, p in columns}
    shutil.rmtree(tmp, ignore_errors=True)
    return {"models": list(models), "policies": list(policies), "columns":
            [f"{m}/{p}" for m, p in columns], "repeats": repeats, "fe_random": sorted(fe_set),
            "fe_rtol": 1e-3,
            "table": str(base) if base else "empty (interpolation in the shipped grid)", "warm_up_s": warm,
            "cases": cases, "summary": summary}


def references_table(ref: dict) -> list[str]:
    """The printed table of part 3 (cells: k/k_ref and wall seconds; '-' not run)."""
    cols = ref["columns"]
    w = 15
    abbrev = {"shape-factor": "shape-f", "table-only": "table", "table+fe": "table+fe",
              "fe-only": "fe-only"}
    head1 = f"{'case':<13s}{'k_ref':>10s} |" + "".join(f"{c.split('/')[0]:>{w}s}" for c in cols)
    head2 = f"{'':<13s}{'':>10s} |" + "".join(
        f"{abbrev.get(c.split('/')[1], c.split('/')[1]):>{w}s}" for c in cols)
    lines = [head1, head2, "-" * len(head1)]
    for case in ref["cases"]:
        label = (f"{case['kind'].upper()} {case['solid_fraction']:.3f}" if case["kind"] != "random"
                 else f"rand e={case['porosity']:.2f}")
        k_ref = case.get("k_ref")
        row = f"{label:<13s}{(f'{k_ref:.4g}' if k_ref else '?'):>10s} |"
        for c in cols:
            cell = case["cells"][c]
            if "ratio" in cell:
                row += f"{cell['ratio']:7.3f}{cell['seconds']:7.2f}s"
            elif "error" in cell:
                row += f"{'error':>{w}s}"
            else:
                row += f"{'-':>{w}s}"
        lines.append(row)
    lines.append("-" * len(head1))
    summ = ref["summary"]

    def srow(label, fmt):
        return f"{label:<24s}|" + "".join(fmt(summ[c]) for c in cols)

    def err(name):
        def f(e):
            v = e[f"max_abs_error_{name}"]
            if v is None:
                return f"{'-':>{w}s}"
            part = "" if e[f"n_{name}"] == e[f"n_{name}_cases"] else f" ({e[f'n_{name}']})"
            return f"{f'{v:.3f}{part}':>{w}s}"
        return f
    lines.append(srow("max|k/kref-1| lattices", err("lattices")))
    lines.append(srow("max|k/kref-1| random", err("random")))
    lines.append(srow("total wall s", lambda e: f"{e['total_seconds']:{w}.1f}"))
    lines.append(srow("FE solves", lambda e: f"{e['fe_solves']:{w}d}"))
    lines.append("cells: k/k_ref and wall seconds (min of "
                 f"{ref['repeats']} repeats on fresh tables; FE cells on random packings once); "
                 "'-' not run (FE on random packings only at --fe-random "
                 f"{' '.join(f'{e:.2f}' for e in ref['fe_random']) or '(none)'}); "
                 "(n): cases the maximum is over.")
    return lines
