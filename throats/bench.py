"""Benchmark: time per throat against relative error, FE at several tolerances and the
shape-factor estimate.

    python -m throats.bench [--n 200] [--seed 1] [--rtols 1e-2 3e-3 1e-3 1e-4]
                            [--json throats_bench.json] [--fit]

Exit status: 0 done, 1 interrupted (Ctrl-C: nothing written), 2 bad options (one ``error:``
line, checked before any work).

Throats: ``--n`` interior Delaunay faces of random 5.5–7.5 mm packings
(``network.sample_throats``, the project's one sampler) plus hand-made hard cases (tangent
and overlapping disks, gaps of 1e-4 r̄, a disk across the opposite side, slivers, large
radius ratios).  The reference
is the finest solve: ``solve_fem(rtol=1e-6, delta=0.002)`` (five times narrower closing
width, so the closing-rule error is part of the measured error).  Each FE tolerance is run
twice and the per-throat minimum time is kept (the machine is shared); the process is pinned
to one CPU; wall and CPU (process) time per throat are both reported.
Prints a table and writes JSON with load average, platform, CPU count and a timestamp.

``--fit`` refits the shape-factor constants on 1600 throats (seed 2026) and prints them.
"""

from __future__ import annotations

import json
import math
import os
import platform
import sys
import time

import numpy as np

import network

from ._area import open_area_perimeter
from ._geometry import canonical_form, contact_type
from ._shape_factor import shape_factor_qstar
from ._solve import SOLVER_VERSION, solve_fem
from .solve import OneLineParser, check_output, run_interruptible

HARD_CASES = {
    # name: (radii, sides)
    "type d, touching equal disks": ([1, 1, 1], [2, 2, 2]),
    "type b, touching pair": ([1, 1, 1], [2, 2.4, 2.4]),
    "type a, gap 1e-4": ([1, 1, 1], [2.0001, 2.3, 2.3]),
    "type d, gaps -1e-4 (overlap)": ([1, 1, 1], [1.9999, 1.9999, 1.9999]),
    "type c, overlaps 5 %": ([1, 1.1, 0.9], [2.0, 1.8, 2.1]),
    "disk across opposite side": ([0.6, 0.6, 1.3], [3.2, 2.0, 2.0]),
    "disk 1e-3 from opposite side": ([1.2, 0.7, 1.0], [3.0, 1.6, 3.3]),
    "sliver (obtuse 150 deg)": ([0.9, 0.9, 0.8], [3.9, 2.0, 2.0]),
    "radius ratio 1.4, wide": ([1.4, 0.8, 0.8], [3.0, 3.0, 2.5]),
    "type a, wide open": ([1, 1, 1], [3.0, 3.0, 3.0]),
}


def _stats(x):
    x = np.asarray(x, dtype=float)
    x = x[np.isfinite(x)]
    if x.size == 0:
        return dict(median=None, p95=None, max=None)
    return dict(median=float(np.median(x)), p95=float(np.percentile(x, 95)),
                max=float(x.max()))


def run(n=200, seed=1, rtols=(1e-2, 3e-3, 1e-3, 1e-4), repeats=2):
    """Measure on one core (the process is pinned to one CPU); returns the JSON dict."""
    pinned = None
    if hasattr(os, "sched_setaffinity"):
        pinned = os.sched_getaffinity(0)
        os.sched_setaffinity(0, {min(pinned)})
    try:
        out = _run(n, seed, rtols, repeats)
        out["pinned_to_cpu"] = None if pinned is None else int(min(pinned))
        return out
    finally:
        if pinned is not None:
            os.sched_setaffinity(0, pinned)


def _run(n, seed, rtols, repeats):
    load_start = list(os.getloadavg())
    r_pack, s_pack = network.sample_throats(n, rng=seed)
    rbar = r_pack.mean(axis=1, keepdims=True)
    r_pack, s_pack = r_pack / rbar, s_pack / rbar          # any unit: report in rbar
    names = list(HARD_CASES)
    r_hard = np.array([HARD_CASES[k][0] for k in names], dtype=float)
    s_hard = np.array([HARD_CASES[k][1] for k in names], dtype=float)
    r_all = np.concatenate([r_pack, r_hard])
    s_all = np.concatenate([s_pack, s_hard])
    groups = {"packing": np.arange(n), "hard": np.arange(n, n + len(names))}

    solve_fem(r_all[:1], s_all[:1])  # warm up gmsh/skfem
    t0 = time.perf_counter()
    ref = solve_fem(r_all, s_all, rtol=1e-6, delta=0.002)
    t_ref = time.perf_counter() - t0
    q_ref = ref.qstar
    ctype = contact_type(r_all, s_all)
    methods = {}
    for rtol in rtols:
        runs = [solve_fem(r_all, s_all, rtol=rtol) for _ in range(repeats)]
        secs = np.min([s.seconds for s in runs], axis=0)
        cpu = np.min([s.cpu_seconds for s in runs], axis=0)
        sol = runs[0]
        with np.errstate(invalid="ignore", divide="ignore"):
            err = np.abs(sol.qstar / q_ref - 1)
        methods[f"fem rtol={rtol:g}"] = dict(
            kind="fem", rtol=rtol, qstar=sol.qstar, err=err, seconds=secs, cpu=cpu,
            estimate=sol.error_estimate, n_elements=sol.n_elements, status=sol.status)
    # shape factor: batched time per throat (min over repeats of a 1e5-row batch)
    big = np.tile(np.arange(r_all.shape[0]), int(np.ceil(1e5 / r_all.shape[0])))
    times = []
    for _ in range(5):
        t0 = time.perf_counter()
        shape_factor_qstar(r_all[big], s_all[big])
        times.append((time.perf_counter() - t0) / big.size)
    q_sf = shape_factor_qstar(r_all, s_all)
    with np.errstate(invalid="ignore", divide="ignore"):
        err_sf = np.abs(q_sf / q_ref - 1)
    err_sf[(q_ref == 0) & (q_sf == 0)] = 0.0
    methods["shape-factor"] = dict(kind="shape-factor", qstar=q_sf, err=err_sf,
                                   seconds=np.full(r_all.shape[0], min(times)),
                                   throughput_per_s=dict(best=1 / min(times),
                                                         median=1 / float(np.median(times))))

    out = dict(
        benchmark="throats", solver_version=SOLVER_VERSION,
        timestamp=time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
        platform=platform.platform(), python=sys.version.split()[0],
        cpu_count=os.cpu_count(), loadavg_start=load_start,
        throats=dict(n_packing=n, seed=seed, hard_cases=names,
                     contact_types={t: int(np.sum(ctype[:n] == t)) for t in "abcd"}),
        reference=dict(method="solve_fem(rtol=1e-6, delta=0.002)", seconds_total=t_ref,
                       status=dict(zip(*[x.tolist() for x in np.unique(ref.status,
                                                                        return_counts=True)]))),
        results={}, hard_cases={})
    for name, m in methods.items():
        res = {}
        for g, idx in groups.items():
            e = m["err"][idx]
            row = dict(error=_stats(e), ms_per_throat=_stats(1e3 * m["seconds"][idx]))
            if "cpu" in m:
                row["cpu_ms_per_throat"] = _stats(1e3 * m["cpu"][idx])
            if m["kind"] == "fem":
                est = m["estimate"][idx]
                row["estimate_covers_error"] = float(np.mean(est >= e))
                row["n_elements_median"] = float(np.median(m["n_elements"][idx]))
                row["status"] = dict(zip(*[x.tolist() for x in np.unique(m["status"][idx],
                                                                         return_counts=True)]))
                row["fraction_error_le_rtol"] = float(np.mean(e <= m["rtol"]))
            else:
                row["throughput_per_s"] = m["throughput_per_s"]
            res[g] = row
        out["results"][name] = res
    for k, name in enumerate(names):
        i = n + k
        out["hard_cases"][name] = dict(
            qstar_ref=float(q_ref[i]), contact_type=str(ctype[i]),
            **{m: dict(err=float(methods[m]["err"][i]),
                       ms=float(1e3 * methods[m]["seconds"][i])) for m in methods})
    out["loadavg_end"] = list(os.getloadavg())
    return out


def fit(n=1600, seed=2026, rtol=1e-4):
    """Refit the shape-factor constants c_t = exp(median(log(Q_FE/(A^3/P^2)))) per type.

    Throats from ``network.sample_throats(n, rng=seed)``; the shipped constants come from the
    throat sampler of commit 1404360 (``docs/throats-shape-factor.md``).
    """
    r, s = network.sample_throats(n, rng=seed)
    sol = solve_fem(r, s, rtol=rtol, progress=True)
    rs, ss = canonical_form(r, s)
    a, p = open_area_perimeter(rs, ss)
    ct = contact_type(r, s)
    ok = sol.status == "ok"
    base = a**3 / p**2
    c = {t: float(np.exp(np.median(np.log(sol.qstar[ok & (ct == t)] / base[ok & (ct == t)]))))
         for t in "abcd" if np.any(ok & (ct == t))}
    err = np.abs(np.array([c.get(t, np.nan) for t in ct]) * base / sol.qstar - 1)[ok]
    return dict(c=c, n=int(ok.sum()), median_rel_error=float(np.median(err)),
                p95_rel_error=float(np.percentile(err, 95)),
                per_type={t: (int(np.sum(ct[ok] == t)), float(np.median(err[ct[ok] == t])),
                              float(np.percentile(err[ct[ok] == t], 95))) for t in c})


def _f(v, spec):
    """``v`` formatted with ``spec``; '-' for a statistic of an empty set (None)."""
    return "-" if v is None else format(v, spec)


def _table(out):
    lines = [f"throats bench  (solver {out['solver_version']}, load "
             f"{out['loadavg_start'][0]:.2f}, {out['cpu_count']} CPUs, {out['timestamp']})",
             f"{'method':<18} {'set':<8} {'ms/throat med':>13} {'p95':>8} {'cpu ms med':>10} "
             f"{'rel.err med':>11} {'p95':>9} {'max':>9} {'est>=err':>8}"]
    for name, res in out["results"].items():
        for g, row in res.items():
            ms, e = row["ms_per_throat"], row["error"]
            cover = row.get("estimate_covers_error")
            cpu = row.get("cpu_ms_per_throat", {}).get("median")
            lines.append(f"{name:<18} {g:<8} {_f(ms['median'], '.4g'):>13} "
                         f"{_f(ms['p95'], '.4g'):>8} {'' if cpu is None else f'{cpu:.4g}':>10} "
                         f"{_f(e['median'], '.2e'):>11} {_f(e['p95'], '.2e'):>9} "
                         f"{_f(e['max'], '.2e'):>9} "
                         f"{'' if cover is None else f'{cover:.2f}':>8}")
    sf = out["results"]["shape-factor"]["packing"]["throughput_per_s"]
    lines.append(f"shape-factor throughput: best {sf['best']:.3g}/s, median {sf['median']:.3g}/s")
    lines.append("hard cases (rel. error / ms):")
    for name, row in out["hard_cases"].items():
        cells = "  ".join(f"{m.replace('fem rtol=', 'fe')}: {v['err']:.1e}/{v['ms']:.3g}"
                          for m, v in row.items() if isinstance(v, dict))
        lines.append(f"  {name:<30} {row['contact_type']} Q*={row['qstar_ref']:.5g}  {cells}")
    return "\n".join(lines)


def _parser():
    p = OneLineParser(prog="python -m throats.bench", description=__doc__.split("\n")[0])
    p.add_argument("--n", type=int, default=200, help="packing throats, >= 1 (default 200)")
    p.add_argument("--seed", type=int, default=1, help="packing seed, >= 0 (default 1)")
    p.add_argument("--rtols", type=float, nargs="+", default=[1e-2, 3e-3, 1e-3, 1e-4],
                   help="FE tolerances compared, each in (0, 1) (default 1e-2 3e-3 1e-3 1e-4)")
    p.add_argument("--json", default="throats_bench.json", metavar="OUT.json",
                   help="output JSON path, its folder must exist (default throats_bench.json, "
                        "written in the current folder)")
    p.add_argument("--fit", action="store_true",
                   help="refit the shape-factor constants and print them (writes nothing)")
    return p


def main(argv=None) -> int:
    """Run the benchmark; exit 0 done, 1 interrupted (Ctrl-C), 2 bad options."""
    return run_interruptible(_main, argv, "interrupted: nothing written (--json is written at "
                             "the end)")


def _main(argv):
    args = _parser().parse_args(argv)
    try:
        network.core.check_count("--n", args.n, network.core.MAX_SPHERES)
        if args.seed < 0:
            raise ValueError(f"--seed must be >= 0, got {args.seed}")
        for rt in args.rtols:
            if not (math.isfinite(rt) and 0 < rt < 1):
                raise ValueError(f"--rtols must each be in (0, 1), got {rt:g}")
        if not args.fit:
            check_output(args.json, "--json")
    except ValueError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    if args.fit:
        print(json.dumps(fit(), indent=1))
        return 0
    out = run(args.n, args.seed, tuple(args.rtols))
    print(_table(out))
    with open(args.json, "w") as fh:
        json.dump(out, fh, indent=1)
    print(f"wrote {args.json}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
