"""Part 4 of ``python -m network.bench`` (``--inertial``): the inertial curve, speed and error.

:func:`inertial_speed` times a 12-point curve (Re_p of soybean air at 0.005-0.3 m/s) on the
periodic random benchmark packing (``random_packing(n, rng=seed, periodic=True,
solid_fraction=0.60)``, as the scaling part makes it; the sample is the default region):
tessellation, conductances, the Stokes solve and the Newton curve each timed, with Newton
iterations per velocity and the 1-minute load average. :func:`inertial_validation` runs the
drag-law cases of :mod:`network.validation` (Finney's packing, periodic random packings and,
given a work folder, settled beds of our DEM packer, :data:`DEM_BEDS`, flow vertical and
horizontal) for the conduit window law, and :func:`inertial_lines` prints both. Measurements: ``docs/inertial-flow.md``.
"""

from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from .._cli import available_cores
from ..packing import random_packing
from ..pores import default_region
from ..flow import INERTIAL_LAW
from ..validation import (bed_inertial_case, finney_inertial_case, random_inertial_case,
                          solve_sample_curve)

__all__ = ["DEM_BEDS", "INERTIAL_REYNOLDS", "dem_bed_file", "inertial_lines",
           "inertial_speed", "inertial_validation"]

#: Reynolds numbers of the validation table.
INERTIAL_REYNOLDS = (1.0, 2.0, 5.0, 10.0, 20.0, 50.0, 100.0, 200.0)


#: Settled beds of equal 6 mm spheres from the project's DEM packer: name -> ``python -m dem.pack`` options beside :data:`DEM_BED_BOX`.
#: 'dense': frictionless sedimentation and taps (solid fraction 0.635 in the sample box);
#: 'lid': grown under a lid with friction 0.47, then settled (0.593); 'loose': friction 1.0
#: throughout, more headroom (0.575; friction 2.0 and headroom 1.0 gave 0.584, no looser).
DEM_BEDS = {"dense": ("--procedure", "sediment", "--porosity", "0.40"),
            "lid": ("--procedure", "lid", "--porosity", "0.42"),
            "loose": ("--procedure", "lid", "--porosity", "0.47", "--packing-friction", "1.0",
                      "--friction", "1.0", "--lid-headroom", "0.5")}
#: The bin of every :data:`DEM_BEDS` bed: 90 x 90 mm, filled 90 mm, sphere radius 3 mm, seed 1.
DEM_BED_BOX = ("--scene", "box", "--size", "0.09", "0.09", "--height", "0.09", "--r-min",
               "0.003", "--r-max", "0.003", "--seed", "1")


def dem_bed_file(name: str, workdir) -> Path:
    """CSV of the :data:`DEM_BEDS` bed ``name`` in ``workdir``, packed by ``python -m dem.pack``
    on first use (3 400-3 900 spheres, 23-47 s here)."""
    path = Path(workdir) / f"dem_bed_{name}.csv"
    if not path.exists():
        t0 = time.perf_counter()
        cmd = [sys.executable, "-m", "dem.pack", *DEM_BED_BOX, *DEM_BEDS[name], "--quiet",
               "--out", str(path)]
        done = subprocess.run(cmd, capture_output=True, text=True)
        if done.returncode != 0 or not path.exists():
            last = (done.stderr.strip().splitlines() or ["no message"])[-1]
            raise RuntimeError(f"dem.pack for the {name!r} bed failed (exit {done.returncode}): "
                               f"{last}")
        print(f"  packed the DEM bed {name!r} in {time.perf_counter() - t0:.0f} s -> {path}",
              flush=True)
    return path


def _load() -> float:
    return float(os.getloadavg()[0])


def _cpu_s() -> float:
    """CPU seconds of this process and its finished children (the forked chains)."""
    t = os.times()
    return t.user + t.system + t.children_user + t.children_system


def inertial_speed(n_spheres: int = 20_000, *, seed: int = 1, n_points: int = 12,
                   policy: str = "table-only", db=None, workers: int | None = None) -> dict:
    """Stage times (s) of a ``n_points`` curve 0.005-0.3 m/s on the benchmark packing, its
    Newton solves in ``workers`` continuation chains (default: the usable cores); the
    process CPU time of the whole curve beside the wall times."""
    if workers is None:
        workers = available_cores()
    t0 = time.perf_counter()
    pk = random_packing(int(n_spheres), rng=seed, periodic=True, solid_fraction=0.60)
    gen = time.perf_counter() - t0
    region = default_region(pk, axis="z")
    us = np.geomspace(0.005, 0.3, int(n_points))
    load0 = _load()
    cpu0 = _cpu_s()
    k, _, pts, t = solve_sample_curve(pk, region, us, axis=2, policy=policy, db=db,
                                      viscosity_pa_s=1.932e-5, density_kg_m3=1.2,
                                      workers=workers)
    cpu = _cpu_s() - cpu0
    stokes = t["tessellate"] + t["conductance"] + t["stokes"]
    return {"n_spheres": int(n_spheres), "law": INERTIAL_LAW, "workers": int(workers),
            "cpu_s": cpu, "generate_s": gen,
            **{f"{k2}_s": v for k2, v in t.items()},
            "stokes_pipeline_s": stokes, "curve_total_s": stokes + t["inertial"],
            "curve_over_stokes": (stokes + t["inertial"]) / stokes,
            "newton_iterations": [p.iterations for p in pts],
            "cg_iterations": [p.cg_iterations for p in pts],
            "converged": all(p.converged for p in pts), "permeability_m2": k,
            "load_before": load0, "load_after": _load()}


def inertial_validation(*, reynolds=INERTIAL_REYNOLDS, solid_fractions=(0.55, 0.60, 0.64),
                        n_spheres: int = 800, seed: int = 1, policy: str = "table-only",
                        db=None, workdir=None, beds=tuple(DEM_BEDS)) -> list[dict]:
    """Rows (law, case, Re, network k/k_app, each drag law's ratio and error) for Finney's
    packing, the random packings and (``workdir`` given) the DEM ``beds`` with vertical and
    horizontal flow."""
    paths = [dem_bed_file(name, workdir) for name in beds] if workdir is not None else []
    kw = dict(policy=policy, db=db)
    cases = [finney_inertial_case(reynolds, **kw)]
    cases += [random_inertial_case(phi, reynolds, n_spheres=n_spheres, rng=seed, **kw)
              for phi in solid_fractions]
    cases += [bed_inertial_case(path, reynolds, axis=axis, **kw)
              for path in paths for axis in (2, 0)]
    return [{"law": INERTIAL_LAW} | r for c in cases for r in c.rows()]


def inertial_lines(speed: dict | None, rows: list[dict]) -> list[str]:
    """The printed table of part 4."""
    out = []
    if speed:
        law = speed.get("law", INERTIAL_LAW)
        out.append(f"inertial curve ({law} law), {speed['n_spheres']} "
                   f"spheres: tessellate {speed['tessellate_s']:.2f} s, conductance "
                   f"{speed['conductance_s']:.2f} s, "
                   f"Stokes solve {speed['stokes_s']:.2f} s, Newton {speed['inertial_s']:.2f} s: "
                   f"curve {speed['curve_over_stokes']:.2f}x the Stokes pipeline; Newton "
                   f"iterations {speed['newton_iterations']}, CG {speed['cg_iterations']}, "
                   f"{speed.get('workers', 1)} chain(s), CPU {speed.get('cpu_s', float('nan')):.2f}"
                   f" s, load {speed['load_before']:.1f}"
                   f"-{speed['load_after']:.1f}")
    if rows:
        out.append(f"{'law':<9} {'case':<34} {'Re_p':>6} {'k/k_app':>8} {'Beetstra':>9} "
                   f"{'err %':>7} {'HKL':>7} {'err %':>7}")
        for r in rows:
            out.append(f"{r['law']:<9} {r['case']:<34} {r['reynolds_particle']:6g} "
                       f"{r['k_over_k_app']:8.4f} {r['beetstra_ratio']:9.4f} "
                       f"{100 * r['beetstra_error']:+7.2f} "
                       f"{r.get('hill_koch_ladd_ratio', float('nan')):7.4f} "
                       f"{100 * r.get('hill_koch_ladd_error', float('nan')):+7.2f}")
    return out
