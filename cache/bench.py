"""Benchmark: speed against error of every way to get Q* (shape factor … tables … FE).

    python -m cache.bench [--db throats.sqlite] [--n-fe 300] [--seed 2024] [--out cache_bench.json]

1. Held-out throats: ``--n-fe`` Delaunay faces of random 5.5–7.5 mm packings
   (``network.sample_throats``, seed ``--seed``); reference Q* by FE at ``rtol=1e-4``
   (``throats.solve_fem``).  No grid is built from packings, so these are never table nodes.
2. For every grid table in ``--db`` (and the shipped one): interpolation error (median, p90,
   p99, max) against the reference, coverage (rows with a finite error estimate), and how
   often the estimate bounds the true error.
3. Policies: 'shape-factor', 'table-only', 'table+fe' at several ``rtol`` (on a scratch copy
   of the table, so the solves do not pollute it), 'fe-only' (FE at rtol 1e-3): error and
   time per throat.
4. Throughput: ``lookup_qstar(policy='table-only')`` and 'shape-factor' on one batch of
   ``--n-batch`` throats (the held-out set tiled and shuffled), wall and CPU seconds, repeated.
5. Table size on disk and the precompute time recorded in the table.
6. Each extension grid (``cache.EXTENSION_GRIDS``) on ``--n-extension`` held-out random shapes
   in its box that g1 and the grids before it cannot serve (FE at ``rtol=1e-4``): its error and
   the shape-factor estimate's.

Prints a table and writes JSON (with load average, platform, CPU count, timestamp).  Exit
status: 0 done, 1 failed or interrupted (Ctrl-C: nothing written), 2 bad options or files (one
``error:`` line, checked before any work).
"""

from __future__ import annotations

import datetime as _dt
import json
import math
import os
import platform
import shutil
import sqlite3
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import network
import throats

from ._gridio import grid_from_store, read_grid_file
from ._interp import GridTable, grid_coordinates
from ._lookup import default_db_path, load_grid_table, lookup_qstar, shipped_grid_path
from ._orbits import EXTENSION_GRIDS
from ._routes import table_routes
from ._signature import shape_keys, signature
from ._store import CacheFileError, open_store
from .lookup import OneLineParser, check_output

#: the arrays of a ``--reference`` file
REFERENCE_KEYS = ("radii", "sides", "q_ref", "q_fe", "t_fe", "c_fe")


def _pct(err):
    err = np.asarray(err, float)
    err = err[np.isfinite(err)]
    if not len(err):
        return {"n": 0, "median": None, "p90": None, "p99": None, "max": None}
    p = np.percentile(err, [50, 90, 99, 100])
    return {"n": int(len(err)), "median": float(p[0]), "p90": float(p[1]), "p99": float(p[2]),
            "max": float(p[3])}


def _f(v, spec):
    """``v`` formatted with ``spec``; '-' for a statistic of an empty set (None)."""
    return "-" if v is None else format(v, spec)


def _timed(fn, repeat):
    walls, cpus, out = [], [], None
    for _ in range(repeat):
        c0, t0 = time.process_time(), time.perf_counter()
        out = fn()
        walls.append(time.perf_counter() - t0)
        cpus.append(time.process_time() - c0)
    return out, walls, cpus


def build_parser():
    p = OneLineParser(prog="python -m cache.bench", description=__doc__.split("\n")[0])
    p.add_argument("--db", default=None,
                   help="table with grid(s), read only (default: cache.default_db_path()); a "
                        "missing file in an existing folder: the shipped grids only")
    p.add_argument("--n-fe", type=int, default=300,
                   help="held-out throats solved by FE, >= 1 (default 300)")
    p.add_argument("--seed", type=int, default=2024,
                   help="seed of the held-out throats, >= 0 (default 2024)")
    p.add_argument("--n-batch", type=int, default=1_000_000,
                   help="rows in the throughput batch, >= 1 (default 1000000)")
    p.add_argument("--repeat", type=int, default=3,
                   help="timing repeats, >= 1, best reported (default 3)")
    p.add_argument("--rtols", default="3e-2,1e-2,3e-3,1e-3",
                   help="comma-separated rtol values for table+fe, each in (0, 1) "
                        "(default 3e-2,1e-2,3e-3,1e-3)")
    p.add_argument("--reference", default=None,
                   help="npz to cache the held-out FE reference in (reused when it exists; "
                        "else written, its folder must exist)")
    p.add_argument("--n-extension", type=int, default=200,
                   help="held-out shapes for the extension grid, >= 0, 0: none (default 200)")
    p.add_argument("--out", default="cache_bench.json",
                   help="output JSON path, its folder must exist (default cache_bench.json)")
    return p


def _check(args):
    """(db path, rtols, reference arrays or None), every option checked before any work;
    ValueError naming the option and value."""
    for opt, v, lo in (("--n-fe", args.n_fe, 1), ("--n-batch", args.n_batch, 1),
                       ("--repeat", args.repeat, 1), ("--n-extension", args.n_extension, 0),
                       ("--seed", args.seed, 0)):
        if v < lo:
            raise ValueError(f"{opt} must be >= {lo}, got {v}")
    core = network.core
    core.check_count("--n-fe", args.n_fe, 1_000_000)
    core.check_count("--n-extension", args.n_extension, 1_000_000, 0)
    core.check_count("--n-batch", args.n_batch, 100_000_000)
    core.check_count("--repeat", args.repeat, core.MAX_REPEATS)
    try:
        rtols = [float(v) for v in args.rtols.split(",") if v.strip()]
    except ValueError:
        rtols = []
    if not rtols or not all(math.isfinite(v) and 0 < v < 1 for v in rtols):
        raise ValueError(f"--rtols {args.rtols}: give comma-separated numbers, each in (0, 1)")
    db = Path(args.db) if args.db else default_db_path()
    check_output(args.out, "--out", inputs=[("--db", db)] + (
        [("--reference", args.reference)] if args.reference else []))
    if db.is_dir():
        raise ValueError(f"--db {db}: is a folder, give a table file")
    if db.exists():
        try:
            with open_store(db, create=False) as st:
                st.grid_names()
        except (CacheFileError, OSError, sqlite3.Error) as e:
            raise ValueError(f"--db {db}: not a readable throat table ({e})") from None
    elif args.db is not None:
        if not db.parent.is_dir():
            raise ValueError(f"--db {db}: no such file, and no folder {db.parent}")
        print(f"note: --db {db} does not exist: the shipped grids only", file=sys.stderr)
    ref = None
    if args.reference:
        rp = Path(args.reference)
        if rp.is_dir():
            raise ValueError(f"--reference {rp}: is a folder, give an .npz file")
        if not rp.exists():
            check_output(rp, "--reference", inputs=[("--db", db)])   # written after its FE
            return db, rtols, None
        try:
            z = np.load(rp)
            ref = {k: np.asarray(z[k], float) for k in REFERENCE_KEYS}
        except Exception as e:      # junk: not an npz, pickled, or missing arrays
            raise ValueError(f"--reference {rp}: not a reference written by cache.bench "
                             f"({type(e).__name__}: {e})") from None
        n = len(ref["radii"])
        if ref["radii"].shape != (n, 3) or ref["sides"].shape != (n, 3) or n == 0 or \
                ref["q_ref"].shape != (n,) or ref["q_fe"].shape != (n,):
            raise ValueError(f"--reference {rp}: arrays of inconsistent shapes")
    return db, rtols, ref


def main(argv=None) -> int:
    """Run the benchmark; exit 0 done, 1 failed or interrupted (Ctrl-C), 2 bad options."""
    try:
        args = build_parser().parse_args(argv)
        try:
            db, rtols, ref = _check(args)
        except ValueError as e:
            print(f"error: {e}", file=sys.stderr)
            return 2
        return _bench(args, db, rtols, ref)
    except (RuntimeError, CacheFileError, sqlite3.Error) as e:
        print(f"failed, nothing written: {e}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print("interrupted: nothing written to --out (a new --reference is written only once "
              "its FE solves finish)", file=sys.stderr)
        return 1


def _bench(args, db, rtols, loaded):
    version = throats.SOLVER_VERSION
    res = {"timestamp": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
           "platform": platform.platform(), "python": sys.version.split()[0],
           "cpu_count": os.cpu_count(), "loadavg_start": os.getloadavg(), "db": str(db),
           "solver_version": version, "seed": args.seed}

    # 1. held-out throats and their FE reference -------------------------------------------
    ref_path = Path(args.reference) if args.reference else None
    if loaded is not None:
        r, s, q_ref, q_fe = (loaded[k] for k in ("radii", "sides", "q_ref", "q_fe"))
        t_fe, c_fe = float(loaded["t_fe"]), float(loaded["c_fe"])
    else:
        r, s = network.sample_throats(args.n_fe, rng=args.seed)
        ref = throats.solve_fem(r, s, rtol=1e-4)
        c0, t0 = time.process_time(), time.perf_counter()
        fe = throats.solve_fem(r, s, rtol=1e-3)
        t_fe = (time.perf_counter() - t0) / len(r)
        c_fe = (time.process_time() - c0) / len(r)
        q_ref, q_fe = ref.qstar, fe.qstar
        if ref_path:
            np.savez(ref_path, radii=r, sides=s, q_ref=q_ref, q_fe=q_fe, t_fe=t_fe, c_fe=c_fe)
    good = np.isfinite(q_ref) & (q_ref > 0)
    r, s, q_ref, q_fe = r[good], s[good], q_ref[good], q_fe[good]
    n = len(r)
    if n == 0:
        raise RuntimeError("no held-out throat has a finite positive reference Q*")
    res["n_heldout"] = n
    rows = []

    def rel(q):
        return np.abs(np.asarray(q) / q_ref - 1)

    # 2. grid tables ------------------------------------------------------------------------
    tables = {}
    if db.exists():
        with open_store(db, create=False) as st:
            for name in st.grid_names():
                t = grid_from_store(st, name, version)
                if t is not None:
                    tables[f"{name} (db)"] = t
            res["table_rows"] = st.count()
            res["table_ok_rows"] = st.count(status="ok")
            solve_s = st.conn.execute("SELECT sum(seconds) FROM throats").fetchone()[0]
            res["precompute_solve_seconds"] = solve_s
        res["db_bytes"] = db.stat().st_size
    for name in ("g1", "g2"):
        sp = shipped_grid_path(name)
        if sp.exists():
            spec, built, values = read_grid_file(sp)
            if built == version:
                tables[f"{name} (shipped)"] = GridTable(spec, *values())
                res[f"shipped_{name}_bytes"] = sp.stat().st_size
    x = grid_coordinates(r, s)
    res["tables"] = {}
    for name, t in tables.items():
        for curv in (False, True):
            tt = t if curv else GridTable(t.spec, t.qstar, t.fe_error, curvature=False)
            q, e = tt(x)
            err = rel(q)
            fin = np.isfinite(e)
            key = f"{name} {'curvature' if curv else 'multilinear'}"
            res["tables"][key] = {
                "nodes": int(t.qstar.size), "error_all": _pct(err), "error_covered": _pct(err[fin]),
                "coverage": float(fin.mean()),
                "estimate_bounds_error": float(np.mean(err[fin] <= e[fin])) if fin.any() else None,
                "estimate_median": float(np.median(e[fin])) if fin.any() else None}
    # 3. policies ---------------------------------------------------------------------------
    sf, w, c = _timed(lambda: throats.shape_factor_qstar(r, s), 1)
    rows.append(("shape-factor", _pct(rel(sf)), w[0] / n, c[0] / n, 0.0))
    best = None
    for name in tables:
        if name.startswith("g1"):
            best = name
            break
    if best is None and tables:
        best = next(iter(tables))
    if best is not None:
        t = tables[best]
        lk, w, c = _timed(lambda: lookup_qstar(r, s, db=db, policy="table-only", table=t), 1)
        rows.append((f"table-only [{best}]", _pct(rel(lk.qstar)), w[0] / n, c[0] / n,
                     float(np.mean(lk.source == "shape-factor"))))
        for rt in rtols:
            with tempfile.TemporaryDirectory() as tmp:
                scratch = Path(tmp) / "scratch.sqlite"
                if db.exists():
                    with open_store(db, create=False) as st:  # consistent copy (WAL)
                        st.conn.execute("PRAGMA wal_checkpoint(FULL)")
                    shutil.copy(db, scratch)
                lk, w, c = _timed(lambda: lookup_qstar(r, s, db=scratch, policy="table+fe",
                                                             rtol=rt, table=t), 1)
            rows.append((f"table+fe rtol={rt:g} [{best}]", _pct(rel(lk.qstar)), w[0] / n,
                         c[0] / n, lk.stats["n_fe"] / n))
    rows.append(("fe-only (FE rtol=1e-3)", _pct(rel(q_fe)), t_fe, c_fe, 1.0))
    res["policies"] = [{"method": m, "error": e, "wall_seconds_per_throat": sec,
                        "cpu_seconds_per_throat": cpu, "fraction_fe_or_sf": f}
                       for m, e, sec, cpu, f in rows]

    # 4. throughput --------------------------------------------------------------------------
    if best is not None:
        rng = np.random.default_rng(args.seed)
        idx = rng.integers(0, n, args.n_batch)
        rb, sb = r[idx] * rng.uniform(0.5, 2.0, (args.n_batch, 1)), None
        sb = s[idx] * (rb[:, :1] / r[idx][:, :1])
        t = tables[best]
        _, walls, cpus = _timed(lambda: lookup_qstar(rb, sb, db=db, policy="table-only",
                                                           table=t), args.repeat)
        res["throughput_table_only"] = {"n": args.n_batch, "wall_s": walls, "cpu_s": cpus,
                                        "rows_per_s_wall_best": args.n_batch / min(walls),
                                        "rows_per_s_cpu_best": args.n_batch / min(cpus)}
        # the same batch with no throat store, and with a small default store of other
        # shapes (what any cache.lookup run without --db leaves: 28 rows, none in the batch):
        # a small store costs nothing; every row it holds costs one lookup (a hit)
        with tempfile.TemporaryDirectory() as tmp:
            for key, k in (("throughput_no_store", 0), ("throughput_small_store", 28)):
                path = Path(tmp) / f"{key}.sqlite"
                if k:
                    other = np.resize(np.arange(n), k)
                    _small_store(path, r[other], s[other] * 1.01, q_fe[other], version)
                _, walls, cpus = _timed(lambda: lookup_qstar(rb, sb, db=path,
                                                             policy="table-only", table=t),
                                        args.repeat)
                res[key] = {"n": args.n_batch, "store_rows": k, "wall_s": walls, "cpu_s": cpus,
                            "rows_per_s_cpu_best": args.n_batch / min(cpus)}
        xb = grid_coordinates(rb, sb)
        _, walls, cpus = _timed(lambda: t(xb), args.repeat)
        res["throughput_interp_kernel"] = {"n": args.n_batch, "wall_s": walls, "cpu_s": cpus,
                                           "rows_per_s_cpu_best": args.n_batch / min(cpus)}
        _, walls, cpus = _timed(lambda: throats.shape_factor_qstar(rb, sb), args.repeat)
        res["throughput_shape_factor"] = {"n": args.n_batch, "wall_s": walls, "cpu_s": cpus,
                                          "rows_per_s_cpu_best": args.n_batch / min(cpus)}
    if args.n_extension > 0:
        res["extension"] = _extension(args.n_extension, args.seed, version)
    res["loadavg_end"] = os.getloadavg()

    # report ---------------------------------------------------------------------------------
    print(f"held-out throats: {n} (random 5.5-7.5 mm packing, seed {args.seed}); reference FE rtol=1e-4")
    print(f"load average {res['loadavg_start']} -> {res['loadavg_end']}, {os.cpu_count()} CPUs")
    print(f"\n{'table':34s} {'nodes':>7s} {'cover':>6s} {'med':>8s} {'p90':>8s} {'p99':>8s} "
          f"{'max':>8s} {'est>=err':>8s}")
    for k, v in res["tables"].items():
        e = v["error_all"]
        print(f"{k:34s} {v['nodes']:7d} {v['coverage']:6.3f} {_f(e['median'], '.2e'):>8} "
              f"{_f(e['p90'], '.2e'):>8} {_f(e['p99'], '.2e'):>8} {_f(e['max'], '.2e'):>8} "
              f"{_f(v['estimate_bounds_error'], '.3f'):>8}")
    print(f"\n{'method':40s} {'wall s/th':>9s} {'cpu s/th':>9s} {'med err':>9s} {'p99 err':>9s} "
          f"{'max err':>9s} {'FE/SF':>6s}")
    for m, e, sec, cpu, f in rows:
        print(f"{m:40s} {sec:9.2e} {cpu:9.2e} {_f(e['median'], '.2e'):>9} "
              f"{_f(e['p99'], '.2e'):>9} {_f(e['max'], '.2e'):>9} {f:6.3f}")
    for key in ("throughput_table_only", "throughput_no_store", "throughput_small_store",
                "throughput_interp_kernel", "throughput_shape_factor"):
        if key in res:
            v = res[key]
            print(f"{key}: {v['n']} rows, wall {min(v['wall_s']):.3f} s (median "
                  f"{np.median(v['wall_s']):.3f}), cpu {min(v['cpu_s']):.3f} s -> "
                  f"{v['n'] / min(v['cpu_s']):.3g} rows/s per core (cpu)")
    for name, ext in (res.get("extension") or {}).items():
        print(f"\nextension grid {name} ({ext['bytes']} bytes) on {ext['n']} held-out shapes in its box "
              f"that the tables before it do not serve (FE rtol=1e-4): served {ext['served']}")
        for k in ("table", "shape_factor"):
            e = ext[k]
            print(f"  {k:14s} median {_f(e['median'], '.2e')}  p90 {_f(e['p90'], '.2e')}  "
                  f"p99 {_f(e['p99'], '.2e')}  max {_f(e['max'], '.2e')}")
    for k in ("db_bytes", "shipped_g1_bytes", "shipped_g2_bytes", "table_rows",
              "precompute_solve_seconds"):
        if k in res:
            print(f"{k}: {res[k]}")
    with open(args.out, "w") as fh:
        json.dump(res, fh, indent=1, default=float)
    print(f"wrote {args.out}")
    return 0


def _small_store(path, radii, sides, qstar, version):
    """A throat store at ``path`` holding ``qstar`` for the given throats (status ok)."""
    k = len(radii)
    cr, cs = throats.canonical_form(radii, sides)
    with open_store(path) as st:
        st.put(shape_keys(signature(radii, sides)), cr, cs, solver_version=version, rtol=1e-3,
               qstar=qstar, open_area=np.full(k, np.nan), contact_type=np.full(k, "", object),
               error_estimate=np.zeros(k), n_elements=np.full(k, -1), seconds=np.zeros(k),
               status=np.full(k, "ok", object), message=np.full(k, "", object))


def _extension(n, seed, version):
    """Each extension grid and the shape-factor estimate against FE (rtol 1e-4) on ``n`` random
    shapes in the grid's box that g1 and the grids before it do not serve (:func:`table_routes`):
    radii r̄(1 + ρ) with ρ1, ρ2 uniform over the grid's radius axis (all three > 0.2 r̄), gaps
    uniform over its gap axis (a deep-pair grid: ln l12, δ13 and τ uniform over its axes),
    vertices in a random order."""
    rng = np.random.default_rng(seed + 1)
    out, pair = {}, {(0, 1): 0, (0, 2): 1, (1, 2): 2}
    for name in EXTENSION_GRIDS:
        ext = load_grid_table(grid=name, solver_version=version)
        if ext is None:
            continue
        rho_max, (g_lo, g_hi) = ext.spec.rho_nodes[-1], ext.spec.gap_nodes[[0, -1]]
        r, s, sv = np.empty((0, 3)), np.empty((0, 3)), np.empty(0, dtype=bool)
        while len(r) < n:
            rho = rng.uniform(-rho_max, rho_max, (8 * n, 2))
            rr = np.column_stack([1 + rho, 1 - rho.sum(axis=1)])
            g = rng.uniform(g_lo, g_hi, (8 * n, 3))
            ss = np.column_stack([rr[:, 0] + rr[:, 1] + g[:, 0], rr[:, 0] + rr[:, 2] + g[:, 1],
                                  rr[:, 1] + rr[:, 2] + g[:, 2]])
            if hasattr(ext.spec, "log_side_nodes"):    # a deep-pair grid: its own coordinates
                ls, tau = ext.spec.log_side_nodes, ext.spec.tau_nodes
                l12 = np.exp(rng.uniform(ls[0], ls[-1], 8 * n))
                l13 = rr[:, 0] + rr[:, 2] + g[:, 1]
                ss = np.column_stack([l12, l13, l13 - rng.uniform(tau[0], tau[-1], 8 * n) * l12])
            p = rng.permutation(3)                 # any vertex order: the lookup reorders
            cols = [pair[tuple(sorted((p[a], p[b])))] for a, b in ((0, 1), (0, 2), (1, 2))]
            rr, ss = rr[:, p], ss[:, cols]
            ok = throats.validate_throats(rr, ss)[0] & (rr.min(axis=1) > 0.2)
            for route, _, rn, sn, served in table_routes(rr[ok], ss[ok], solver_version=version):
                if route == name:                  # the rows that reach it, as it is asked
                    r, s, sv = np.vstack([r, rn]), np.vstack([s, sn]), np.append(sv, served)
        r, s, sv = r[:n], s[:n], sv[:n]
        ref = throats.solve_fem(r, s, rtol=1e-4).qstar
        q = ext.at_throats(r, s, errors=False)[0]
        good = np.isfinite(ref) & (ref > 0)
        served = good & sv
        out[name] = {"n": int(good.sum()), "served": int(served.sum()),
                     "table": _pct(np.abs(q[served] / ref[served] - 1)),
                     "shape_factor": _pct(np.abs(throats.shape_factor_qstar(r[served], s[served])
                                                 / ref[served] - 1)),
                     "bytes": shipped_grid_path(name).stat().st_size}
    return out


if __name__ == "__main__":
    sys.exit(main())
