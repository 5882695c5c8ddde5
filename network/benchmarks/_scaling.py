"""Part 2 of ``python -m network.bench``: time and memory per stage against packing size.

Packings of ``n`` spheres (``random_packing``, periodic box, solid fraction 0.60; above
``DIRECT_MAX`` spheres a crop of periodic copies of the ``DIRECT_MAX`` packing) are generated
once and kept in a work directory; each size runs in its own subprocess
(``python -m network.bench --one CSV``, which calls :func:`run_one`), so ``ru_maxrss`` is the
peak of that size alone. Method and measurements: ``docs/network-bench.md``.
"""

from __future__ import annotations

import json
import os
import resource
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from ..flow import ConductanceOptions, solve_network
from ..packing import periodic_copies, random_packing, read_packing, write_packing_csv
from .._cli import available_cores
from ._common import qstar_sources

__all__ = ["DIRECT_MAX", "packing_file", "run_one", "scaling", "scaling_exponent"]

#: Largest packing generated directly; bigger ones tile it periodically (see packing_file).
DIRECT_MAX = 100_000


def _tiled(base_n: int, n: int, workdir: Path, seed: int):
    """A packing of about ``n`` spheres cut from periodic copies of the ``base_n`` packing.

    The base packing is periodic (box side L = (4/3 π Σr³ / 0.60)^(1/3)), so its periodic
    images tile space without overlaps; a cube of k³ copies is cropped to the sub-cube holding
    about n spheres. The structure repeats every L, which does not matter for timing.
    """
    base = read_packing(packing_file(base_n, workdir, seed))
    box = (4.0 / 3.0 * np.pi * np.sum(base.radii**3) / 0.60) ** (1.0 / 3.0)
    k = int(np.ceil((n / base.n) ** (1.0 / 3.0)))
    big = periodic_copies(base, box, k)
    side = k * box * (n / big.n) ** (1.0 / 3.0)
    keep = np.all(big.centers < side, axis=1)
    return big.subset(keep, source=f"{k}^3 tiling of {base_n} periodic spheres")


def packing_file(n: int, workdir: Path, seed: int) -> Path:
    """CSV of the ``n``-sphere bench packing in ``workdir``, generated on first use."""
    path = workdir / f"bench_{n}_s{seed}.csv"
    if not path.exists():
        t0 = time.perf_counter()
        if n <= DIRECT_MAX:
            pk = random_packing(n, rng=seed, periodic=True, solid_fraction=0.60)
        else:
            pk = _tiled(DIRECT_MAX, n, workdir, seed)
        write_packing_csv(pk, path, digits=7)
        print(f"  generated {n} spheres in {time.perf_counter() - t0:.1f} s -> {path}",
              flush=True)
    return path


def run_one(path: Path, policy: str, db, repeats: int, trace: bool = True,
            model: str = "conduit") -> dict:
    """One scaling case in this process: stage times, iterations, memory."""
    best = None
    for _ in range(repeats):
        t0 = time.perf_counter()
        pk = read_packing(path)
        t_read = time.perf_counter() - t0
        res = solve_network(pk, axis="z", threads=available_cores(), trace_memory=False,
                            conductance=ConductanceOptions(model=model, policy=policy, db=db))
        wall = time.perf_counter() - t0
        if best is None or wall < best["wall_s"]:
            best = {"wall_s": wall, "read_s": t_read, "stages_s": dict(res.timings_s),
                    "iterations": res.solver["iterations"], "n_unknowns": res.solver["n_unknowns"],
                    "solver_setup_s": res.solver["setup_s"], "solver_solve_s": res.solver["solve_s"],
                    "n_pores": res.n_pores, "n_throats": res.n_throats,
                    "permeability_m2": res.permeability_m2, "mass_balance_ok": res.check["ok"],
                    "qstar_sources": qstar_sources(res.qstar_stats)}
    walls_rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    # one more pass with tracemalloc for per-stage traced peaks (slower; not timed)
    if trace:
        pk = read_packing(path)
        res = solve_network(pk, axis="z", threads=available_cores(), trace_memory=True,
                            conductance=ConductanceOptions(model=model, policy=policy, db=db))
        best["traced_peak_mb"] = res.timings_s.get("peak_memory_mb", {})
    best["max_rss_mb"] = max(walls_rss, resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0)
    best["n_spheres"] = pk.n
    best["policy"] = policy
    best["conductance_model"] = model
    best["repeats"] = repeats
    best["threads"] = available_cores()
    return best


def scaling(sizes, workdir, policy, db, seed, repeats, timeout, model="conduit") -> list[dict]:
    """Every size in its own subprocess; a row per size (``error`` on failure or timeout)."""
    rows = []
    for n in sizes:
        path = packing_file(n, workdir, seed)
        cmd = [sys.executable, "-m", "network.bench", "--one", str(path), "--policy", policy,
               "--model", model, "--repeats", str(repeats if n <= DIRECT_MAX else 1)]
        if n > DIRECT_MAX:
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
        row["us_per_sphere"] = 1e6 * row["wall_s"] / row["n_spheres"]
        row["kb_per_sphere"] = 1024.0 * row["max_rss_mb"] / row["n_spheres"]
        print(f"  {n:>7d} spheres: wall {row['wall_s']:7.2f} s (read {row['read_s']:.2f}, "
              f"tess {st['tessellate']:.2f}, sample {st['sample']:.2f}, cond "
              f"{st['conductance']:.2f}, asm {st['assemble']:.2f}, AMG setup "
              f"{row['solver_setup_s']:.2f}, solve {st['solve']:.2f}, porosity "
              f"{st.get('porosity', 0.0):.2f}); {row['iterations']} it; {row['n_unknowns']} "
              f"unknowns; max RSS {row['max_rss_mb']:.0f} MB; {row['us_per_sphere']:.0f} us and "
              f"{row['kb_per_sphere']:.1f} kB per sphere", flush=True)
    return rows


def scaling_exponent(rows) -> tuple[float, int, int] | None:
    """(slope of log wall time over log N, smallest N, largest N); None below two sizes run."""
    ok = [r for r in rows if "wall_s" in r]
    if len(ok) < 2:
        return None
    n = np.array([r["n_spheres"] for r in ok], dtype=float)
    w = np.array([r["wall_s"] for r in ok])
    return float(np.polyfit(np.log(n), np.log(w), 1)[0]), int(n.min()), int(n.max())
