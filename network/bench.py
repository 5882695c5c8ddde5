"""``python -m network.bench``: speed against error of the network model.

Two parts (issue 4, item 10):

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

Prints a table and writes JSON with the load average, platform, CPU count and a timestamp.

Examples
--------
    python -m network.bench --sizes 5000 20000 --policy-spheres 600
    python -m network.bench --sizes 5000 20000 100000 500000 --skip-policies --json bench.json
"""

from __future__ import annotations

import argparse
import json
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

from ._conductance import MODELS, POLICIES
from ._generate import random_packing
from ._io import read_packing, write_packing_csv
from ._pipeline import solve_network


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
    from ._io import Packing

    base = read_packing(_packing_file(base_n, workdir, seed))
    box = (4.0 / 3.0 * np.pi * np.sum(base.radii**3) / 0.60) ** (1.0 / 3.0)
    k = int(np.ceil((n / base.n) ** (1.0 / 3.0)))
    shifts = np.stack(np.meshgrid(*[np.arange(k)] * 3, indexing="ij"), -1).reshape(-1, 3) * box
    c = (base.centers[None, :, :] + shifts[:, None, :]).reshape(-1, 3)
    r = np.tile(base.radii, len(shifts))
    side = k * box * (n / c.shape[0]) ** (1.0 / 3.0)
    keep = np.all(c < side, axis=1)
    return Packing(c[keep], r[keep], source=f"{k}^3 tiling of {base_n} periodic spheres")


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
    report["machine_end"] = _machine()
    with open(args.json_out, "w") as f:
        json.dump(report, f, indent=2, default=str)
    print(f"load average {report['machine_end']['loadavg']}; wrote {args.json_out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
