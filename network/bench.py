"""``python -m network.bench``: speed against error of the network model.

Three parts (issue 4, item 10; issue 7, item 4):

1. **Policies** — the same packing solved with each conductance model (``--models``: conduit,
   thesis) and each Q* policy (shape-factor, table-only, table+fe, fe-only): permeability, its
   difference from the same model's fe-only answer (the reference) and the wall time. Each policy runs against its own fresh copy of the table (``--db``, default
   the cache's default table), so FE cost is really paid and no policy reuses another's solves.
2. **Scaling** — packings of 5 000, 20 000, 100 000 and 500 000 spheres (``random_packing``,
   periodic box, solid fraction 0.60, d = 5.5–7.5 mm; above 100 000 spheres a crop of periodic
   copies of the 100 000 packing; generated once and kept in ``--workdir``),
   each run in its own subprocess: time per stage (read CSV, tessellate, sample, conductance,
   prune, assemble, solve), solver iterations, peak resident memory (``ru_maxrss``) and the peak
   memory traced per stage (``tracemalloc``: numpy and Python allocations; Qhull's own C
   allocations are only in ``ru_maxrss``).
3. **References** — permeability error against published / computed Stokes values and wall
   time, for every conductance model (``--models``) × Q* policy (``--policies``), on the same
   packings: the issue-7 cases, SC at φ = 0.3, 0.45, π/6 against Zick & Homsy (1982)
   (``network._references.lattice_permeability``), BCC at φ = 0.3, 0.4, 0.5, 0.6, 0.66 and FCC
   at 0.3, 0.45, 0.55, 0.65, 0.72 against this project's Stokes FE of the unit cell
   (``computed_lattice_permeability``), each through
   ``network._lattices.lattice_sample_permeability`` (7³ cells, core estimate); random
   monodisperse packings of porosity 0.36, 0.40, 0.45 (``--ref-spheres`` 800 spheres, seed
   ``--ref-seed`` 1, periodic, copied 3×3×3, core estimate:
   ``random_sample_permeability``) against the LBM drag law of van der Hoef et al. (2005)
   (``beetstra_permeability``). One table: a row per case with its reference k (units of the
   lattice constant² or the diameter²), a column per model × policy with k/k_ref and the wall
   seconds (minimum of ``--ref-repeats``, each repeat against its own fresh copy of the table,
   so FE solves are paid every time; modules are imported and the interpolation grid loaded
   by an untimed warm-up first); summary rows with max |k/k_ref − 1| over the lattices and over
   the random packings, total seconds and FE solves (rows the run added to its copy of the
   table) per column. A random-packing cell includes generating the packing (its time is in the
   JSON as ``packing_s``). FE policies on random packings are expensive: at porosity 0.40,
   800 spheres, measured (2 shared cores) fe-only 69 000 distinct FE solves in 320 s with the
   conduit model, 10 000 in 65 s with the thesis model; table+fe (rtol 1e-3) 30 000 in 160 s
   and 9 900 in 60 s. All three porosities would take ~30 minutes, so the FE policies on random
   packings run only at the porosities given by ``--fe-random`` (default 0.40, ~11 minutes for
   the whole part; none with an empty list) and once, not ``--ref-repeats`` times; cells not
   run print as ``-``, and a summary over fewer cases than the column has shows their count.
   Unlike part 1, every cell starts from an empty table (interpolation in the grid shipped in
   ``cache/data``) unless ``--db`` names one to copy, so the numbers do not depend on what the
   user's default table happens to hold: table-only answers rows the grid does not cover with
   an exact hit when the table has one, else with the shape-factor estimate (on SC conduits the
   two differ by 3 %). Each cell passes its copy as ``db`` to the validation helpers of
   ``network._lattices``; FE solves run at their default tolerance, rtol = 1e-3.

Prints a table and writes JSON with the load average, platform, CPU count and a timestamp.
``--skip-references`` leaves part 3 out; ``--references-only`` runs part 3 alone.

Examples
--------
    python -m network.bench --sizes 5000 20000 --policy-spheres 600 --skip-references
    python -m network.bench --sizes 5000 20000 100000 500000 --skip-policies --skip-references \\
        --json bench.json
    python -m network.bench --references-only --json references.json
    python -m network.bench --references-only --fe-random 0.36 0.40 0.45   # ~30 min
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from .conductance import MODELS, POLICIES
from .flow import solve_network
from .packing import Packing, random_packing, read_packing, write_packing_csv


def _machine() -> dict:
    return {"platform": platform.platform(), "python": platform.python_version(),
            "cpu_count": os.cpu_count(), "loadavg": list(os.getloadavg()),
            "timestamp": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime())}


#: Largest packing generated directly; bigger ones tile it periodically (see _packing_file).
_DIRECT_MAX = 100_000


def _tiled(base_n: int, n: int, workdir: Path, seed: int):
    """A packing of about ``n`` spheres cut from periodic copies of the ``base_n`` packing.

    The base packing is periodic (box side L = (4/3 π Σr³ / 0.60)^(1/3)), so its periodic
    images tile space without overlaps; a cube of k³ copies is cropped to the sub-cube holding
    about n spheres. The structure repeats every L, which does not matter for timing.
    """
    from .packing import periodic_copies

    base = read_packing(_packing_file(base_n, workdir, seed))
    box = (4.0 / 3.0 * np.pi * np.sum(base.radii**3) / 0.60) ** (1.0 / 3.0)
    k = int(np.ceil((n / base.n) ** (1.0 / 3.0)))
    big = periodic_copies(base, box, k)
    side = k * box * (n / big.n) ** (1.0 / 3.0)
    keep = np.all(big.centers < side, axis=1)
    return Packing(big.centers[keep], big.radii[keep],
                   source=f"{k}^3 tiling of {base_n} periodic spheres")


def _packing_file(n: int, workdir: Path, seed: int) -> Path:
    path = workdir / f"bench_{n}_s{seed}.csv"
    if not path.exists():
        t0 = time.perf_counter()
        if n <= _DIRECT_MAX:
            pk = random_packing(n, rng=seed, periodic=True, solid_fraction=0.60)
        else:
            pk = _tiled(_DIRECT_MAX, n, workdir, seed)
        write_packing_csv(pk, path, digits=7)
        print(f"  generated {n} spheres in {time.perf_counter() - t0:.1f} s -> {path}",
              flush=True)
    return path


def _sources(stats: dict) -> dict:
    """Q* sources of a run (the conduit model nests the lookup statistics one level down)."""
    return stats.get("sources") or stats.get("qstar_stats", {}).get("sources", {})


def run_one(path: Path, policy: str, db, repeats: int, trace: bool = True,
            model: str = "conduit") -> dict:
    """One scaling case in this process: stage times, iterations, memory."""
    best = None
    for _ in range(repeats):
        t0 = time.perf_counter()
        pk = read_packing(path)
        t_read = time.perf_counter() - t0
        res = solve_network(pk, axis="z", policy=policy, db=db, porosity_points=0,
                            trace_memory=False, conductance_model=model)
        wall = time.perf_counter() - t0
        if best is None or wall < best["wall_s"]:
            best = {"wall_s": wall, "read_s": t_read, "stages_s": dict(res.timings_s),
                    "iterations": res.solver["iterations"], "n_unknowns": res.solver["n_unknowns"],
                    "solver_setup_s": res.solver["setup_s"], "solver_solve_s": res.solver["solve_s"],
                    "n_pores": res.n_pores, "n_throats": res.n_throats,
                    "permeability_m2": res.permeability_m2, "mass_balance_ok": res.check["ok"],
                    "qstar_sources": _sources(res.qstar_stats)}
    walls_rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    # one more pass with tracemalloc for per-stage traced peaks (slower; not timed)
    if trace:
        pk = read_packing(path)
        res = solve_network(pk, axis="z", policy=policy, db=db, porosity_points=0,
                            trace_memory=True, conductance_model=model)
        best["traced_peak_mb"] = res.timings_s.get("peak_memory_mb", {})
    best["max_rss_mb"] = max(walls_rss, resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0)
    best["n_spheres"] = pk.n
    best["policy"] = policy
    best["conductance_model"] = model
    best["repeats"] = repeats
    return best


def _scaling(sizes, workdir, policy, db, seed, repeats, timeout, model="conduit"):
    rows = []
    for n in sizes:
        path = _packing_file(n, workdir, seed)
        cmd = [sys.executable, "-m", "network.bench", "--one", str(path), "--policy", policy,
               "--model", model, "--repeats", str(repeats if n <= 100_000 else 1)]
        if n > 100_000:
            cmd.append("--no-trace")   # the tracemalloc pass would double a 500k run
        if db:
            cmd += ["--db", str(db)]
        load0 = os.getloadavg()[0]
        t0 = time.perf_counter()
        try:
            out = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, check=False)
        except subprocess.TimeoutExpired:
            rows.append({"n_spheres": n, "error": f"timeout after {timeout} s"})
            print(f"  {n}: timeout", flush=True)
            continue
        if out.returncode != 0:
            rows.append({"n_spheres": n, "error": out.stderr.strip().splitlines()[-1:]})
            print(f"  {n}: failed: {out.stderr.strip().splitlines()[-1:]}", flush=True)
            continue
        row = json.loads(out.stdout.strip().splitlines()[-1])
        row["subprocess_s"] = time.perf_counter() - t0
        row["loadavg_1min_before"] = load0
        rows.append(row)
        st = row["stages_s"]
        print(f"  {n:>7d} spheres: wall {row['wall_s']:7.2f} s (read {row['read_s']:.2f}, "
              f"tess {st['tessellate']:.2f}, cond {st['conductance']:.2f}, "
              f"asm {st['assemble']:.2f}, solve {st['solve']:.2f}); {row['iterations']} it; "
              f"{row['n_unknowns']} unknowns; max RSS {row['max_rss_mb']:.0f} MB", flush=True)
    return rows


def _has_table(db) -> bool:
    try:
        from cache import load_grid_table
        return load_grid_table(db) is not None
    except Exception:  # noqa: BLE001 - no cache, no grid, foreign file: no table
        return False


def _copy_db(src: Path | None, dst: Path) -> None:
    """Consistent copy of a (WAL-mode) SQLite table through the backup API."""
    import sqlite3

    if src is None or not Path(src).exists():
        return
    with sqlite3.connect(f"file:{src}?mode=ro", uri=True) as a, sqlite3.connect(dst) as b:
        a.backup(b)


def _policies(n, policy_list, db, seed, workers, models=("conduit", "thesis")):
    """Every policy on the same packing, each against its own fresh copy of the table, so that
    no policy profits from FE solves stored by another."""
    pk = random_packing(n, rng=seed, periodic=True, solid_fraction=0.60)
    base = Path(db) if db else None
    if base is None:
        try:
            from cache import default_db_path
            base = Path(default_db_path())
        except Exception:  # noqa: BLE001 - bench goes on without a table
            base = None
    tmp = Path(tempfile.mkdtemp(prefix="grainflow-bench-"))
    rows = []
    for model, pol in [(m, p) for m in models for p in policy_list]:
        db_used = tmp / f"{model}-{pol}.sqlite"
        _copy_db(base, db_used)
        t0 = time.perf_counter()
        try:
            res = solve_network(pk, axis="z", policy=pol, db=db_used, workers=workers,
                                porosity_points=0, conductance_model=model)
            rows.append({"conductance_model": model, "policy": pol,
                         "permeability_m2": res.permeability_m2,
                         "seconds": time.perf_counter() - t0,
                         "conductance_s": res.timings_s["conductance"],
                         "sources": _sources(res.qstar_stats),
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


# ---------------------------------------------------------------------------------------------
# part 3: references (issue 7, item 4)

#: Lattice cases of issue 7: (lattice, solid fraction); pi/6 is touching simple cubic.
REF_LATTICE_CASES = (("sc", 0.3), ("sc", 0.45), ("sc", math.pi / 6),
                     ("bcc", 0.3), ("bcc", 0.4), ("bcc", 0.5), ("bcc", 0.6), ("bcc", 0.66),
                     ("fcc", 0.3), ("fcc", 0.45), ("fcc", 0.55), ("fcc", 0.65), ("fcc", 0.72))
#: Porosities of the random-packing cases of issue 7.
REF_RANDOM_POROSITIES = (0.36, 0.40, 0.45)
#: Policies that run FE solves (opt-in per porosity on random packings, see --fe-random).
_FE_POLICIES = ("table+fe", "fe-only")


def _lattice_case(text: str):
    """``kind:phi`` (``phi`` a number or ``touch``) -> (kind, phi), for argparse."""
    from .packing import LATTICES, TOUCHING_FRACTION

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
    from .validation import computed_lattice_permeability, lattice_permeability

    if kind == "sc":
        return float(lattice_permeability("sc", phi, radius))
    return float(computed_lattice_permeability(kind, phi))


def _store_totals(path: Path) -> tuple[int, float]:
    """(rows, summed FE seconds) of a throat table; (0, 0.0) when it does not exist."""
    import sqlite3

    if not Path(path).exists() or Path(path).stat().st_size == 0:
        return 0, 0.0
    with sqlite3.connect(f"file:{path}?mode=ro", uri=True) as con:
        try:
            n, sec = con.execute("SELECT count(*), coalesce(sum(seconds), 0) FROM throats"
                                 ).fetchone()
        except sqlite3.OperationalError:   # no throats table yet
            return 0, 0.0
    return int(n), float(sec)


def _ref_cell(case: dict, model: str, policy: str, base: Path | None, tmp: Path,
              repeats: int) -> dict:
    """One case × model × policy: k, k/k_ref, minimum wall time over fresh-table repeats."""
    from .validation import lattice_sample_permeability, random_sample_permeability

    cell = {"conductance_model": model, "policy": policy, "repeats": repeats,
            "seconds_all": [], "fe_solves": [], "fe_seconds": []}
    for rep in range(repeats):
        db = tmp / f"{case['name']}-{model}-{policy}-{rep}.sqlite".replace(":", "_")
        _copy_db(base, db)
        n0, s0 = _store_totals(db)
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
        n1, s1 = _store_totals(db)
        cell["fe_solves"].append(n1 - n0)
        cell["fe_seconds"].append(s1 - s0)
        db.unlink(missing_ok=True)
        for extra in ("-wal", "-shm"):
            Path(f"{db}{extra}").unlink(missing_ok=True)
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
    from .validation import lattice_sample_permeability

    db = tmp / "warm-up.sqlite"
    _copy_db(base, db)
    t0 = time.perf_counter()
    lattice_sample_permeability("sc", 0.45, model="conduit", policy="table-only", db=db)
    return time.perf_counter() - t0


def _references(lattice_cases, random_porosities, models, policies, db, *, fe_random=(0.40,),
                repeats=2, n_spheres=800, seed=1) -> dict:
    """Part 3: every case × model × policy, with summaries per model × policy column."""
    from .packing import random_packing
    from .validation import beetstra_permeability

    base = Path(db) if db else None   # None: every cell starts from an empty table
    if base is not None and not base.exists():
        raise FileNotFoundError(f"throat table {base} does not exist")
    tmp = Path(tempfile.mkdtemp(prefix="grainflow-bench-ref-"))
    fe_set = {round(float(e), 6) for e in fe_random}
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
    warm = _warm_up(base, tmp)
    columns = [(m, p) for m in models for p in policies]
    for case in cases:
        case["cells"] = {}
        for model, pol in columns:
            key = f"{model}/{pol}"
            rnd = case["kind"] == "random"
            if rnd and pol in _FE_POLICIES and round(case["porosity"], 6) not in fe_set:
                case["cells"][key] = {"conductance_model": model, "policy": pol,
                                      "skipped": "FE policy on a random packing not requested "
                                                 "(--fe-random)"}
                continue
            reps = 1 if (rnd and pol in _FE_POLICIES) else repeats
            cell = _ref_cell(case, model, pol, base, tmp, reps)
            case["cells"][key] = cell
            print(f"  {case['name']:>12s} {key:>22s}: "
                  + (f"k/k_ref = {cell['ratio']:.4f}" if "ratio" in cell else cell.get("error"))
                  + f", {cell['seconds']:.2f} s"
                  + (f", {cell['fe_solves'][0]} FE solves" if cell["fe_solves"] else ""),
                  flush=True)
    summary = {}
    for model, pol in columns:
        key = f"{model}/{pol}"
        cells = [c["cells"][key] for c in cases]
        lat = [c["cells"][key] for c in cases if c["kind"] != "random"]
        rnd = [c["cells"][key] for c in cases if c["kind"] == "random"]
        run = [c for c in cells if "seconds" in c]
        entry = {"total_seconds": float(sum(c["seconds"] for c in run)),
                 "fe_solves": int(sum(c["fe_solves"][0] for c in run if c["fe_solves"])),
                 "n_cases_run": len(run), "n_cases": len(cells),
                 "n_errors": sum("error" in c for c in cells)}
        for name, group in (("lattices", lat), ("random", rnd)):
            err = [abs(c["ratio"] - 1.0) for c in group if "ratio" in c]
            entry[f"max_abs_error_{name}"] = max(err) if err else None
            entry[f"n_{name}"] = len(err)
            entry[f"n_{name}_cases"] = len(group)
        summary[key] = entry
    shutil.rmtree(tmp, ignore_errors=True)
    return {"models": list(models), "policies": list(policies), "columns":
            [f"{m}/{p}" for m, p in columns], "repeats": repeats, "fe_random": sorted(fe_set),
            "fe_rtol": 1e-3,
            "table": str(base) if base else "empty (interpolation in the shipped grid)", "warm_up_s": warm,
            "cases": cases, "summary": summary}


def _references_table(ref: dict) -> list[str]:
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


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m network.bench", description=__doc__.split("\n")[0])
    ap.add_argument("--sizes", type=int, nargs="*", default=[5000, 20000, 100000],
                    help="sphere counts of the scaling part (default 5000 20000 100000; add "
                         "500000 for the full run)")
    ap.add_argument("--policy", default="table-only", choices=POLICIES,
                    help="Q* policy of the scaling part (default table-only: a precomputed table)")
    ap.add_argument("--policies", nargs="*", default=list(POLICIES), choices=POLICIES)
    ap.add_argument("--models", nargs="*", default=["conduit", "thesis"], choices=MODELS,
                    help="conductance models of the policy comparison (default both)")
    ap.add_argument("--model", default="conduit", choices=MODELS,
                    help="conductance model of the scaling part (default conduit)")
    ap.add_argument("--policy-spheres", type=int, default=600,
                    help="packing size of the policy comparison (FE cost grows with it)")
    ap.add_argument("--skip-policies", action="store_true")
    ap.add_argument("--skip-references", action="store_true",
                    help="leave out part 3 (permeability error against the references)")
    ap.add_argument("--references-only", action="store_true",
                    help="run part 3 alone (no policy comparison, no scaling)")
    ap.add_argument("--ref-lattices", nargs="*", type=_lattice_case, default=None,
                    metavar="KIND:PHI",
                    help="lattice cases of part 3, e.g. sc:0.45 fcc:touch (default the 13 cases "
                         "of issue 7)")
    ap.add_argument("--ref-random", nargs="*", type=float, default=list(REF_RANDOM_POROSITIES),
                    metavar="POROSITY",
                    help="random-packing porosities of part 3 (default 0.36 0.40 0.45; none "
                         "with an empty list)")
    ap.add_argument("--fe-random", nargs="*", type=float, default=[0.40], metavar="POROSITY",
                    help="porosities at which the FE policies (table+fe, fe-only) run on random "
                         "packings (default 0.40: ~10 min of FE; all three: ~30 min)")
    ap.add_argument("--ref-spheres", type=int, default=800,
                    help="spheres in the periodic random packings of part 3 (default 800)")
    ap.add_argument("--ref-seed", type=int, default=1, help="seed of those packings (default 1)")
    ap.add_argument("--ref-repeats", type=int, default=2,
                    help="repeats per part-3 cell, minimum wall time reported (default 2; FE "
                         "cells on random packings run once)")
    ap.add_argument("--db", default=None,
                    help="throat table with the interpolation grid (default: the cache's default; "
                         "the policy part works on copies)")
    ap.add_argument("--workers", type=int, default=1, help="FE processes")
    ap.add_argument("--workdir", default=None,
                    help="where generated packings are kept (default ~/.cache/grainflow/bench)")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--repeats", type=int, default=2, help="repeats per size (minimum reported)")
    ap.add_argument("--timeout", type=float, default=1800.0, help="per-size limit, s")
    ap.add_argument("--json", dest="json_out", default="network_bench.json")
    ap.add_argument("--one", default=None, help=argparse.SUPPRESS)
    ap.add_argument("--no-trace", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.references_only and args.skip_references:
        ap.error("--references-only and --skip-references exclude each other")
    if args.ref_repeats < 1 or args.ref_spheres < 1:
        ap.error("--ref-repeats and --ref-spheres must be >= 1")
    for eps in args.ref_random:
        if not 0.36 <= eps < 1.0:
            ap.error(f"--ref-random porosity {eps} outside [0.36, 1)")
    if args.references_only:
        args.skip_policies = True
        args.sizes = []

    if args.one:  # child process of the scaling part
        row = run_one(Path(args.one), args.policy, args.db, args.repeats, trace=not args.no_trace,
                      model=args.model)
        print(json.dumps(row))
        return 0

    workdir = Path(args.workdir or Path.home() / ".cache" / "grainflow" / "bench")
    workdir.mkdir(parents=True, exist_ok=True)
    report = {"machine_start": _machine()}
    if not args.skip_policies:
        print(f"policies on a {args.policy_spheres}-sphere packing:", flush=True)
        pol = _policies(args.policy_spheres, args.policies, args.db, args.seed, args.workers,
                        models=args.models)
        report["policies"] = pol
        for r in pol["rows"]:
            if "error" in r:
                print(f"  {r['conductance_model']:>8s} {r['policy']:>13s}: {r['error']}")
            else:
                d = r.get("rel_diff_vs_fe_only")
                print(f"  {r['conductance_model']:>8s} {r['policy']:>13s}: "
                      f"k = {r['permeability_m2']:.4e} m²"
                      + (f" ({d:+.2%} vs fe-only)" if d is not None else "")
                      + f", {r['seconds']:.2f} s (Q* {r['conductance_s']:.2f} s) {r['sources']}")
    if args.sizes:
        policy = args.policy
        if policy in ("table-only", "table+fe") and not _has_table(args.db):
            report["scaling_policy_note"] = (f"no interpolation table for {args.db or 'the default db'}"
                                             f": {policy} replaced by shape-factor")
            print(f"  note: {report['scaling_policy_note']}")
            policy = "shape-factor"
        report["scaling_policy"] = policy
        report["scaling_model"] = args.model
        print(f"scaling ({args.model} model, {policy}):", flush=True)
        report["scaling"] = _scaling(args.sizes, workdir, policy, args.db, args.seed,
                                     args.repeats, args.timeout, model=args.model)
        ok = [r for r in report["scaling"] if "wall_s" in r]
        if len(ok) >= 2:
            n = np.array([r["n_spheres"] for r in ok], dtype=float)
            w = np.array([r["wall_s"] for r in ok])
            slope = np.polyfit(np.log(n), np.log(w), 1)[0]
            report["scaling_exponent"] = float(slope)
            print(f"  wall time ~ N^{slope:.2f} over {int(n.min())}..{int(n.max())} spheres")
    if not args.skip_references:
        lat = REF_LATTICE_CASES if args.ref_lattices is None else args.ref_lattices
        print(f"references ({len(lat)} lattices, {len(args.ref_random)} random packings; "
              f"models {' '.join(args.models)}; policies {' '.join(args.policies)}):", flush=True)
        ref = _references(lat, args.ref_random, args.models, args.policies, args.db,
                          fe_random=args.fe_random, repeats=args.ref_repeats,
                          n_spheres=args.ref_spheres, seed=args.ref_seed)
        report["references"] = ref
        print("\n".join(_references_table(ref)), flush=True)
    report["machine_end"] = _machine()
    with open(args.json_out, "w") as f:
        json.dump(report, f, indent=2, default=str)
    print(f"load average {report['machine_end']['loadavg']}; wrote {args.json_out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
