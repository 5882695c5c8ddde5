"""Benchmark: particle-steps per second against N, and the cost/effect of density scaling.

    python -m dem.bench                       # N = 1000 ... 50000, writes dem_bench.json
    python -m dem.bench --n 20000 --repeat 3
    python -m dem.bench --mass-scale-study    # small packing made with S = 1, 10, 100
    python -m dem.bench --grains 500 2000 5000   # the grain engine (soybean templates)
    python -m dem.bench --grain-pack 5000        # + wall time of dem.pack for 5000 soybeans
    python -m dem.bench --study DIR              # the thesis vibration study (about 1 h): its row
    python -m dem.bench --pour 3000 --pour-stress 20000   # rain-filled wheat bed, then its load

Scene for the rate: N spheres of radius 3.25 mm on a simple cubic lattice 6.5 mm apart
(overlap 1e-4 r, six contacts each, close to the 4–6 true contacts of a settled bed),
with gravity, box walls and the Verlet list, density scaling 100: the inner loop of
``dem.pack``. Grain rows (``--grains G``): G soybean templates (6 spheres) aligned on a
lattice of their length, width and thickness (overlap 1e-4 of each), the same walls, gravity and
scaling, timed in sphere-steps/s of :class:`dem.ClumpSimulation`. ``--grain-pack G`` times
``python -m dem.pack --scene box --grain soybean`` for G grains in a cube (as a subprocess,
numba compilation excluded by a warm-up run). ``--pour G`` times the rain fill of G wheat kernels
into a 0.06 x 0.06 m box (``python -m dem.pack --scene box --size 0.06 0.06 --height 0.05 --grain
wheat --n-grains G --mass-scale 100``, plus ``--stress PA`` with ``--pour-stress``; the speed target
of a poured bed, ``docs/dem-fill.md`` section Speed) as a subprocess after a warm-up of 20 grains,
with the pour's and the load's CPU and wall seconds, its particle-steps (all spheres, and the
active ones stepped) and the frozen share; ``--pour-no-freeze`` adds the same pour without
freezing. The JSON records the load average, platform, CPU count and a timestamp.
"""

from __future__ import annotations

import json
import math
import os
import platform
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from ._cli import (EXIT_FAILED, MAX_REPEATS, MAX_SPHERES, MAX_STEPS, MAX_WORKERS, OneLineParser,
                   check_count, check_output_list, run_main)
from ._container import Container, make_simulation
from ._load import MAX_STRESS_PA
from ._procedures import PackOptions, RunOptions, pack_bed
from .clumps import ClumpSimulation
from .templates import library_template
from .vibrate import main as vibrate_main


def lattice_simulation(n, *, rng=0, mass_scale=100.0, threads=None):
    """N spheres (r = 3.25 mm) on a simple cubic lattice in a closed box (benchmark scene)."""
    rng = np.random.default_rng(rng)
    a = 0.0065
    nx = max(2, int(round((n / 2) ** (1 / 3))))
    ny = nx
    nz = int(np.ceil(n / (nx * ny)))
    g = np.stack(np.meshgrid(np.arange(nx), np.arange(ny), np.arange(nz), indexing="ij"), -1).reshape(-1, 3)[:n]
    x = (g + 0.5) * a + rng.normal(0, 1e-7, (len(g), 3))
    x[:, 0] -= nx * a / 2
    x[:, 1] -= ny * a / 2
    c = Container("box", (nx * a, ny * a), nz * a)
    return make_simulation(c, x, np.full(len(x), a / 2 * (1 + 1e-4)), lid=True, mass_scale=mass_scale,
                           threads=threads)


def _time_steps(sim, steps, repeat):
    """(wall seconds array, CPU seconds list) of ``repeat`` runs of ``steps`` steps, after 5 warm-up
    steps (compilation, first neighbour list)."""
    for _ in range(5):
        sim.step()
    times, cpu = [], []
    for _ in range(repeat):
        t, c = time.perf_counter(), time.process_time()
        for _ in range(steps):
            sim.step()
        times.append(time.perf_counter() - t)
        cpu.append(time.process_time() - c)
    return np.array(times), cpu


def rate(n, *, steps=None, repeat=3, threads=None):
    """Particle-steps per second for N (min/median over ``repeat`` timings); ``threads`` None
    lets the simulation choose (the steps each thread count ran are in ``steps_by_threads``)."""
    sim = lattice_simulation(n, threads=threads)
    steps = steps or max(20, int(2e6 / n))
    times, cpu = _time_steps(sim, steps, repeat)
    return {
        "n": int(sim.n), "steps": steps, "pairs": int(len(sim.verlet.pairs)), "contacts": int(len(sim.contact_fn)),
        "rebuilds": int(sim.stats["rebuilds"]), "seconds": times.tolist(),
        "rate_best": float(n * steps / times.min()), "rate_median": float(n * steps / np.median(times)),
        "ms_per_step_best": float(1e3 * times.min() / steps),
        # per second of this process's CPU time: what an idle core would give (shared machine)
        "rate_per_cpu_s_best": float(n * steps / min(cpu)), "cpu_seconds": cpu,
        "steps_by_threads": {str(k): v for k, v in sim.threads.steps_by_threads.items()},
    }


def grain_lattice_simulation(n_grains, *, grain="soybean", mass_scale=100.0, threads=None):
    """G library grains, all aligned with the axes, on a lattice of their extent (L, W, T) shrunk by
    1e-4 (neighbours along x, y, z touch) in a closed box that fits it: the grain rate scene."""
    t = library_template(grain)
    ext = t.extent_m * (1 - 1e-4)
    nx = max(2, int(round((n_grains / 2) ** (1 / 3))))
    nz = int(np.ceil(n_grains / (nx * nx)))
    g = np.stack(np.meshgrid(np.arange(nx), np.arange(nx), np.arange(nz), indexing="ij"), -1).reshape(-1, 3)
    x = (g[:n_grains] + 0.5) * ext
    x[:, :2] -= nx * ext[:2] / 2
    c = Container("box", (nx * t.extent_m[0], nx * t.extent_m[1]), nz * t.extent_m[2])
    q = np.tile([1.0, 0.0, 0.0, 0.0], (len(x), 1))
    return ClumpSimulation([t], np.zeros(len(x), int), x, q, np.ones(len(x)), c.walls(lid=True),
                           mass_scale=mass_scale, threads=threads)


def grain_rate(n_grains, *, steps=None, repeat=3, threads=None):
    """Sphere-steps per second of the grain engine on :func:`grain_lattice_simulation` (``threads``
    as :func:`rate`)."""
    sim = grain_lattice_simulation(n_grains, threads=threads)
    n = len(sim.radii)
    steps = steps or max(10, int(1e6 / n))
    times, cpu = _time_steps(sim, steps, repeat)
    return {"grains": int(sim.n_grains), "n": int(n), "steps": steps, "contacts": int(len(sim.contact_fn)),
            "wall_contacts": int(len(sim.last_wall_fn)), "seconds": times.tolist(), "cpu_seconds": cpu,
            "rate_best": float(n * steps / times.min()), "rate_median": float(n * steps / np.median(times)),
            "rate_per_cpu_s_best": float(n * steps / min(cpu)), "ms_per_step_best": float(1e3 * times.min() / steps),
            "loadavg": os.getloadavg(),
            "steps_by_threads": {str(k): v for k, v in sim.threads.steps_by_threads.items()}}


def grain_pack_time(n_grains, *, seed=1, porosity=0.40985, out_dir=None, warm_up=True):
    """Wall time of ``python -m dem.pack --scene box --grain soybean --n-grains G`` in a cube holding
    G soybeans at ``porosity`` (side (G V_g / (1 - porosity))^(1/3)), run as a subprocess after a
    warm-up of min(20, G) grains that fills numba's cache (``warm_up``). Returns the command, its wall
    and CPU seconds (s), the load averages, and the packing summary's steps, spheres and porosity."""
    import tempfile
    side = float((n_grains * library_template("soybean").volume_m3 / (1 - porosity)) ** (1 / 3))
    out_dir = out_dir or tempfile.mkdtemp(prefix="grain_pack_")
    cmd = [sys.executable, "-m", "dem.pack", "--scene", "box", "--grain", "soybean", "--size", f"{side:.4f}",
           f"{side:.4f}", "--height", f"{side:.4f}", "--n-grains", str(n_grains), "--seed", str(seed),
           "--quiet", "--out", os.path.join(out_dir, "bed.csv")]
    warm = cmd[:cmd.index("--n-grains") + 1] + [str(min(20, n_grains))] + cmd[cmd.index("--n-grains") + 2:-1] + \
        [os.path.join(out_dir, "warm.csv")]
    if warm_up:
        subprocess.run(warm, check=True, capture_output=True)
    load0, t0, c0 = os.getloadavg(), time.perf_counter(), os.times()
    done = subprocess.run(cmd, check=True, capture_output=True, text=True)
    wall, c1 = time.perf_counter() - t0, os.times()
    with open(os.path.join(out_dir, "bed.json")) as f:
        summary = json.load(f)
    return {"grains": n_grains, "side_m": side, "command": " ".join(cmd[1:]), "wall_s": wall,
            "cpu_s": (c1.children_user - c0.children_user) + (c1.children_system - c0.children_system),
            "loadavg_before": load0, "loadavg_after": os.getloadavg(), "steps": summary["steps"],
            "n_spheres": summary["n_spheres"], "pack_wall_time_s": summary["wall_time_s"],
            "porosity_network_region": summary.get("porosity_network_region"), "stdout": done.stdout[-2000:]}


#: the poured benchmark bed: wheat rained into a 0.06 x 0.06 m box (0.05 m fill height), mass scale 100
POUR_ARGS = ["--scene", "box", "--size", "0.06", "0.06", "--height", "0.05", "--grain", "wheat", "--mass-scale", "100"]
#: targets of a 3000-kernel poured bed and of its load on two cores, s
POUR_TARGET_S, LOAD_TARGET_S = 600.0, 300.0


def pour_time(n_grains, *, stress_pa=None, freeze=True, seed=1, out_dir=None, warm_up=True):
    """CPU and wall seconds of ``python -m dem.pack`` with :data:`POUR_ARGS` for ``n_grains`` wheat
    kernels (then ``--stress stress_pa``; ``freeze`` False adds ``--no-freeze``), as a subprocess
    after a warm-up of 20 kernels that fills numba's cache. Returns the command, the pour's and the
    load's CPU and wall seconds (from the companion JSON), the particle-steps of every sphere and
    of the active ones, the grains frozen at the fill's end, the porosity and the load averages."""
    import tempfile
    out_dir = out_dir or tempfile.mkdtemp(prefix="pour_")
    cmd = [sys.executable, "-m", "dem.pack", *POUR_ARGS, "--n-grains", str(n_grains), "--seed", str(seed),
           "--quiet", "--out", os.path.join(out_dir, "bed.csv")]
    if stress_pa:
        cmd[-3:-3] = ["--stress", f"{stress_pa:g}"]
    if not freeze:
        cmd[-3:-3] = ["--no-freeze"]
    if warm_up:
        warm = [*cmd[:cmd.index("--n-grains") + 1], "20", "--max-steps", "400", "--quiet", "--out",
                os.path.join(out_dir, "warm.csv")]
        subprocess.run(warm, capture_output=True)          # a warm-up not at rest exits 1: only the cache counts
    load0, t0, c0 = os.getloadavg(), time.perf_counter(), os.times()
    done = subprocess.run(cmd, capture_output=True, text=True)
    wall, c1 = time.perf_counter() - t0, os.times()
    if done.returncode not in (0, EXIT_FAILED):
        raise RuntimeError(f"{' '.join(cmd[1:])} exited {done.returncode}: {done.stderr.strip()[-300:]}")
    with open(os.path.join(out_dir, "bed.json")) as f:
        s = json.load(f)
    fill, load = s["fill"], s.get("load", {})
    fz = fill.get("freeze", {})
    return {"grains": n_grains, "n_spheres": s["n_spheres"], "freeze": freeze, "stress_pa": stress_pa,
            "command": "python " + " ".join(cmd[1:]), "converged": s["converged"], "wall_s": wall,
            "cpu_s": (c1.children_user - c0.children_user) + (c1.children_system - c0.children_system),
            "pour_cpu_s": fill.get("cpu_time_s"), "pour_wall_s": fill.get("wall_time_s"),
            "load_cpu_s": load.get("cpu_time_s"), "load_wall_s": load.get("wall_time_s"),
            "steps": s["steps"], "fill_steps": fill["fill_steps"], "rest_steps": fill["rest"]["steps"],
            "load_steps": load.get("steps"), "particle_steps": fill["particle_steps"],
            "active_particle_steps": fz.get("active_particle_steps"), "frozen_at_fill_end": fz.get("frozen_at_fill_end"),
            "pour_particle_steps_per_cpu_s": fill["particle_steps"] / fill["cpu_time_s"],
            "porosity_network_region": s.get("porosity_network_region"),
            "pour_target_s": POUR_TARGET_S, "load_target_s": LOAD_TARGET_S,
            "loadavg_before": load0, "loadavg_after": os.getloadavg()}


def mass_scale_study(scales=(1.0, 10.0, 100.0), *, seed=1, settle_time_s=0.3, grow_time_s=0.04):
    """Pack the same small box (0.05 x 0.02 x 0.05 m, ~200 spheres) with several density
    scalings S, with the same physical expansion and settling times (S = 1 is the reference)."""
    c = Container("box", (0.05, 0.02), 0.05)
    out = []
    for s in scales:
        dt = 0.25 * np.sqrt(s * 1285 * 4 / 3 * np.pi * (0.00275 / 1.4) ** 3 / 4e6)  # first-step dt
        res = pack_bed(c, rng=seed, options=PackOptions(grow_steps=int(grow_time_s / dt), lid_headroom=0.5),
                       run=RunOptions(mass_scale=s, settle_time_s=settle_time_s))
        m = res.summary
        out.append({"mass_scale": s, "n": m["n_spheres"], "porosity_interior": m["porosity_interior"],
                    "porosity_global_surface": m["porosity_global_surface"],
                    "coordination_cutoff": m["coordination"]["cutoff_mean"],
                    "coordination_contacts": m["coordination"]["contact_mean"],
                    "max_overlap_fraction": m["max_overlap_fraction"], "steps": m["steps"],
                    "wall_time_s": m["wall_time_s"]})
        print(f"S = {s:6g}: interior porosity {m['porosity_interior']:.4f}, global {m['porosity_global_surface']:.4f}, "
              f"Z(1.05 dmax) {m['coordination']['cutoff_mean']:.2f}, Z(contact) {m['coordination']['contact_mean']:.2f}, "
              f"{m['steps']} steps, {m['wall_time_s']:.1f} s", flush=True)
    return out


#: The vibration study's representative scene (docs/dem-vibration.md: a cylinder 0.10 m across at
#: the thesis's 0.25 m fill height; it compacts as the full 0.15 m bin within 0.0024 porosity).
STUDY_ARGS = ["--study", "thesis", "--scene", "cylinder", "--size", "0.1", "--height", "0.25", "--seed", "1"]
#: Target for the five-intensity study on two cores (one hour), s.
STUDY_TARGET_S = 3600.0


def study_row(out_dir, *, threads=None) -> dict:
    """Run (or resume, or reuse) ``python -m dem.vibrate`` with :data:`STUDY_ARGS` in ``out_dir``
    and return its bench row: scene, spheres, per intensity the simulated seconds, steps and
    wall seconds, the bed's packing and the timed network steps, the total against
    :data:`STUDY_TARGET_S`, and particle-steps/s of the vibration."""
    argv = [*STUDY_ARGS, "--out", str(out_dir)] + ([] if threads is None else ["--threads", str(threads)])
    code = vibrate_main(argv)
    if code != 0:
        raise RuntimeError(f"dem.vibrate {' '.join(argv)} exited {code}")
    with open(os.path.join(out_dir, "study.json")) as f:
        st = json.load(f)
    rows, w = st["rows"], st["wall_time_s"]
    steps = [int(r["vibration_steps"]) for r in rows]
    vib_wall = float(sum(w["vibration"]))
    return {"command": "python -m dem.vibrate " + " ".join(argv), "scene": st["scene"],
            "container": st["container"], "n_spheres": st["n_spheres"], "dt_s": st["dt_s"],
            "intensities_g": [r["intensity_g"] for r in rows], "vibrated_s": [r["vibrated_s"] for r in rows],
            "stopped_by": [r["stopped_by"] for r in rows], "steps": steps, "wall_s": w,
            "total_wall_s": w["total"], "target_s": STUDY_TARGET_S, "met": w["total"] <= STUDY_TARGET_S,
            "particle_steps_per_s": st["n_spheres"] * sum(steps) / vib_wall if vib_wall > 0 else None}


def _parser():
    p = OneLineParser(prog="python -m dem.bench", description=__doc__.split("\n")[0])
    p.add_argument("--n", type=int, nargs="+", default=None,
                   help="sphere counts timed, each >= 1 (default 1000 2000 5000 10000 20000 50000)")
    p.add_argument("--repeat", type=int, default=3,
                   help="timing repeats, >= 1, best and median reported (default 3)")
    p.add_argument("--steps", type=int, default=None,
                   help="steps per timing, >= 1 (default max(20, 2e6 / N))")
    p.add_argument("--threads", type=int, default=None,
                   help="threads of the step kernels, >= 1 (default: chosen by timing, see dem._threads)")
    p.add_argument("--mass-scale-study", action="store_true",
                   help="instead of the rates: pack one bed at each --scales mass scale and compare")
    p.add_argument("--scales", type=float, nargs="+", default=None,
                   help="--mass-scale-study only: density scalings, finite and > 0 (default 1 10 100)")
    p.add_argument("--grains", type=int, nargs="+", default=None,
                   help="instead of the sphere rates: grain-engine rates for these soybean grain counts")
    p.add_argument("--grain-pack", type=int, default=None, metavar="G",
                   help="also time python -m dem.pack --grain soybean for G grains in a cube (e.g. 5000)")
    p.add_argument("--pour", type=int, default=None, metavar="G",
                   help="instead of the rates: time the rain fill of G wheat kernels into a 0.06 x 0.06 m box "
                        "(mass scale 100; the speed target of a poured bed: 3000 kernels in 10 min)")
    p.add_argument("--pour-stress", type=float, default=None, metavar="PA",
                   help="--pour only: then load the bed to PA through the lid (dem.pack --stress; target 5 min)")
    p.add_argument("--pour-no-freeze", action="store_true",
                   help="--pour only: also time the same pour with every grain stepped (dem.pack --no-freeze)")
    p.add_argument("--study", metavar="DIR", default=None,
                   help="instead of the rates: run (or resume, or reuse) the thesis vibration study on the "
                        "representative 0.10 x 0.25 m cylinder in DIR (about an hour on two cores) and print "
                        "its row against the one-hour target")
    p.add_argument("--json", default="dem_bench.json",
                   help="output JSON path, its folder must exist (default dem_bench.json, in the current folder)")
    return p


def _check_args(args) -> None:
    """ValueError naming the option for any bad value or combination, before any work."""
    def positive(opt, vals, high=MAX_SPHERES):
        for v in vals:
            if v is not None and v < 1:
                raise ValueError(f"{opt} must be >= 1, got {v}")
            check_count(opt, v, high)

    positive("--n", args.n or [])
    positive("--repeat", [args.repeat], MAX_REPEATS)
    positive("--steps", [args.steps], MAX_STEPS)
    positive("--threads", [args.threads], MAX_WORKERS)
    positive("--grains", args.grains or [])
    positive("--grain-pack", [args.grain_pack])
    positive("--pour", [args.pour])
    if args.pour_stress is not None and not (math.isfinite(args.pour_stress)
                                             and 0 < args.pour_stress <= MAX_STRESS_PA):
        raise ValueError(f"--pour-stress must be finite, > 0 and <= {MAX_STRESS_PA:g} Pa (dem.pack --stress), "
                         f"got {args.pour_stress:g}")
    if (args.pour_stress is not None or args.pour_no_freeze) and not args.pour:
        raise ValueError(f"{'--pour-stress' if args.pour_stress is not None else '--pour-no-freeze'}: only with --pour")
    for v in args.scales or []:
        if not (math.isfinite(v) and v > 0):
            raise ValueError(f"--scales must be finite and > 0, got {v:g}")
    modes = [opt for opt, on in (("--study", args.study), ("--mass-scale-study", args.mass_scale_study),
                                 ("--grains", args.grains), ("--grain-pack", args.grain_pack),
                                 ("--pour", args.pour)) if on]
    if len(modes) > 1 and set(modes) != {"--grains", "--grain-pack"}:
        raise ValueError(f"{' and '.join(modes)}: one kind of run at a time (--grains goes with "
                         "--grain-pack only)")
    if args.n and modes:
        raise ValueError(f"--n: the sphere rates only, not with {modes[0]}")
    if args.scales and not args.mass_scale_study:
        raise ValueError("--scales: only with --mass-scale-study")
    outputs = [("--study", Path(args.study) / "study.json")] if args.study else []
    check_output_list(outputs + [("--json", args.json)], make_folders=True)
    folder = Path(args.json).parent
    if not folder.is_dir():
        raise ValueError(f"--json {args.json}: folder {folder} does not exist")


def main(argv=None) -> int:
    """Run the benchmark; exit 0 done, 1 failed or interrupted (Ctrl-C), 2 bad input."""
    return run_main(_parser(), _bench, argv,
                    interrupted="nothing written (--json is written at the end)")


def _bench(args) -> int:
    _check_args(args)
    try:
        return _run(args)
    except (RuntimeError, subprocess.CalledProcessError) as e:
        print(f"failed, nothing written: {e}", file=sys.stderr)
        return EXIT_FAILED


def _run(args) -> int:
    meta = {"loadavg_before": os.getloadavg(), "platform": platform.platform(), "cpu_count": os.cpu_count(),
            "python": sys.version.split()[0], "numpy": np.__version__,
            "timestamp": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime())}
    result = {"meta": meta}
    if args.study:
        r = result["study"] = study_row(args.study, threads=args.threads)
        print(f"{'scene':>9} {'spheres':>8} {'intensities g':>30} {'vibrated s':>30} {'steps':>9} {'bed s':>6} "
              f"{'vibration s':>12} {'network s':>10} {'total s':>8} {'p-steps/s':>10}  target 3600 s")
        print(f"{r['scene']:>9} {r['n_spheres']:8d} {' '.join(f'{g:.2f}' for g in r['intensities_g']):>30} "
              f"{' '.join(f'{v:.1f}' for v in r['vibrated_s']):>30} {sum(r['steps']):9d} "
              f"{r['wall_s']['bed'] or 0:6.0f} {sum(r['wall_s']['vibration']):12.0f} "
              f"{r['wall_s']['network_timed']:10.0f} {r['total_wall_s']:8.0f} {r['particle_steps_per_s'] or 0:10.3e}  "
              f"{'met' if r['met'] else 'missed'}", flush=True)
        if r["wall_s"]["incomplete"] or r["wall_s"]["network_steps_untimed"]:
            print(f"  not in the total: the wall time of earlier runs of amplitudes {r['wall_s']['incomplete']} "
                  f"(checkpoints without it) and {r['wall_s']['network_steps_untimed']} network steps done before",
                  flush=True)
    elif args.pour:
        print(f"{'grains':>7} {'spheres':>8} {'freeze':>6} {'pour CPU s':>11} {'wall s':>7} {'load CPU s':>11} "
              f"{'wall s':>7} {'p-steps/CPU-s':>14} {'active':>7} {'porosity':>9} {'load':>5}")
        rows = []
        for freeze in (True, False) if args.pour_no_freeze else (True,):
            r = pour_time(args.pour, stress_pa=args.pour_stress, freeze=freeze)
            rows.append(r)
            act = r["active_particle_steps"] / r["particle_steps"] if r["active_particle_steps"] else 1.0
            print(f"{r['grains']:7d} {r['n_spheres']:8d} {'on' if freeze else 'off':>6} {r['pour_cpu_s']:11.0f} "
                  f"{r['pour_wall_s']:7.0f} {r['load_cpu_s'] or 0:11.0f} {r['load_wall_s'] or 0:7.0f} "
                  f"{r['pour_particle_steps_per_cpu_s']:14.3e} {act:7.2f} {r['porosity_network_region'] if r['porosity_network_region'] is not None else float('nan'):9.4f} "
                  f"{r['loadavg_after'][0]:5.2f}", flush=True)
        print(f"targets: pour {POUR_TARGET_S:.0f} s, load {LOAD_TARGET_S:.0f} s (3000 kernels, two cores)")
        result["pour"] = rows
    elif args.mass_scale_study:
        result["mass_scale_study"] = mass_scale_study(tuple(args.scales or (1.0, 10.0, 100.0)))
    elif args.grains or args.grain_pack:
        print(f"{'grains':>7} {'spheres':>8} {'contacts':>9} {'ms/step':>8} {'s-steps/s best':>15} {'median':>12} "
              f"{'per CPU-s':>12} {'threads':>8} {'load':>5}")
        rows = []
        for g in args.grains or []:
            r = grain_rate(g, steps=args.steps, repeat=args.repeat, threads=args.threads)
            rows.append(r)
            print(f"{r['grains']:7d} {r['n']:8d} {r['contacts']:9d} {r['ms_per_step_best']:8.2f} "
                  f"{r['rate_best']:15.3e} {r['rate_median']:12.3e} {r['rate_per_cpu_s_best']:12.3e} "
                  f"{max(r['steps_by_threads'], key=r['steps_by_threads'].get):>8} {r['loadavg'][0]:5.2f}", flush=True)
        result["grain_rates"] = rows
        if args.grain_pack:
            r = grain_pack_time(args.grain_pack)
            result["grain_pack"] = r
            print(f"dem.pack {r['grains']} soybeans ({r['n_spheres']} spheres, {r['side_m']:.3f} m cube): "
                  f"{r['wall_s']:.1f} s wall, {r['cpu_s']:.1f} s CPU, {r['steps']} steps, load "
                  f"{r['loadavg_before'][0]:.2f} -> {r['loadavg_after'][0]:.2f}", flush=True)
    else:
        print(f"{'N':>7} {'pairs':>8} {'contacts':>9} {'ms/step':>8} {'p-steps/s best':>15} {'median':>12} "
              f"{'per CPU-s':>12} {'threads':>8}")
        rows = []
        for n in args.n or [1000, 2000, 5000, 10000, 20000, 50000]:
            r = rate(n, steps=args.steps, repeat=args.repeat, threads=args.threads)
            rows.append(r)
            print(f"{r['n']:7d} {r['pairs']:8d} {r['contacts']:9d} {r['ms_per_step_best']:8.2f} "
                  f"{r['rate_best']:15.3e} {r['rate_median']:12.3e} {r['rate_per_cpu_s_best']:12.3e} "
                  f"{max(r['steps_by_threads'], key=r['steps_by_threads'].get):>8}", flush=True)
        result["rates"] = rows
    meta["loadavg_after"] = os.getloadavg()
    print(f"load average before {meta['loadavg_before']}, after {meta['loadavg_after']}; {meta['cpu_count']} CPUs")
    with open(args.json, "w") as f:
        json.dump(result, f, indent=1)
    print(f"-> {args.json}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
