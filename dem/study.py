"""The thesis's vibration study as one resumable command: ``python -m dem.vibrate --study thesis``.

Thesis 3.2 and 4.1.3: a cylinder bed vibrated at 15 Hz with 0.5, 1, 2, 3 and 4 mm (0.45–3.62 g)
for 16 s each. In ``--out`` (default ``vibration_study``) the command

1. packs the bed (``bed.csv``, procedure of the scene's ``dem.SCENE_DEFAULTS``) or reuses it;
2. vibrates a copy at each intensity for ``--duration`` s or until the global porosity has been
   steady for ``--steady-window`` s, recording global porosity and the local porosity in the
   measurement spheres B1–B5 every period (``vib_<A>mm/after.csv`` + ``.json``), with a
   checkpoint every ``--checkpoint-every`` s of simulated time: an interrupted study started
   again goes on from the checkpoints and ends with the same numbers;
3. runs ``python -m network.solve`` (pressure drop, permeability), ``python -m network.curve`` (the
   resistance curve with inertia, 0.005-0.3 m/s, and its fits) and ``python -m network.paths``
   (tortuosity, widths) on the bed before and after each vibration, as subprocesses: dem imports
   no other project package; a failed or missing network step is recorded and retried on the
   next run;
4. writes ``study.json`` (one row per intensity, coordination distributions, dt, stiffnesses)
   and the plots ``porosity_time.png`` (thesis Figs. 4.11, 4.13), ``porosity_intensity.png``
   (Fig. 4.14), ``pressure_drop_intensity.png`` and ``resistance_curves.png``.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from ._container import SCENE_DEFAULTS, default_measure_spheres
from ._integrate import DemInstabilityError
from ._io import read_packing, write_packing, write_summary
from ._material import SOYBEAN, Material
from ._plots import plot_study
from ._procedures import PackOptions, RunOptions, pack_bed
from ._vibrate import SETTLE_RUN, VibrationOptions, intensity_g, vibrate_bed

__all__ = ["run_study", "NETWORK_STEPS"]

#: network CLIs run on every bed: name -> (module, extra arguments)
NETWORK_STEPS = {"solve": ("network.solve", ["--quiet"]), "paths": ("network.paths", ["--no-branched"]),
                 "curve": ("network.curve", ["--quiet"])}
#: steps that sample the container's cylinder (the others trace paths in the box)
_CYLINDER_STEPS = ("solve", "curve")


def _log(msg, quiet):
    if not quiet:
        print(msg, file=sys.stderr, flush=True)


def _bed(out, container, scene, seed, mass_scale, quiet):
    """The study's bed: reused from ``out/bed.csv`` when its container matches, else packed."""
    path = out / "bed.csv"
    if path.exists():
        centers, radii, summary = read_packing(path)
        if summary and summary.get("container") == container.to_dict():
            _log(f"reusing {path} ({len(radii)} spheres)", quiet)
            return path, centers, radii, summary
        raise ValueError(f"{path} holds a packing of another container; remove it or choose another --out")
    _log(f"packing the {scene} bed (seed {seed}) -> {path}", quiet)
    opts = dict(SCENE_DEFAULTS.get(scene, {"procedure": "lid", "lid_headroom": 0.2}))
    res = pack_bed(container, rng=seed, options=PackOptions(**opts), run=RunOptions(mass_scale=mass_scale))
    summary = dict(res.summary, scene=scene, seed=seed, procedure_options=opts)
    write_packing(path, res.centers, res.radii, summary)
    _log(f"packed {len(res.radii)} spheres in {summary['wall_time_s']:.0f} s, interior porosity "
         f"{summary['porosity_interior']:.4f}", quiet)
    # the stages vibrate the bed as written (9 digits), as a resumed study reads it back: the
    # in-memory bed differed by 1e-11, which a vibration grew to 0.004 in porosity
    centers, radii, _ = read_packing(path)
    return path, centers, radii, summary


def _network(csv, container, out_json, quiet, timeout_s=1800):
    """Run the network CLIs on one packing (subprocesses); returns their JSON or the error."""
    result = {}
    for name, (module, extra) in NETWORK_STEPS.items():
        target = out_json.with_name(f"{out_json.stem}_{name}.json")
        t0 = None                    # a step done by an earlier run: its time is not known here
        if not target.exists():
            cmd = [sys.executable, "-m", module, str(csv), "--json", str(target), *extra]
            if name in _CYLINDER_STEPS and container.kind == "cylinder":
                cmd.append("--cylinder")
            _log(f"  {' '.join(cmd[1:])}", quiet)
            t0 = time.perf_counter()
            try:
                run = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout_s)
                err = None if run.returncode == 0 else (run.stderr.strip().splitlines() or ["?"])[-1]
            except subprocess.TimeoutExpired:
                err = f"timed out after {timeout_s} s"
            if err is not None or not target.exists():
                result[name] = {"error": f"{module} failed: {err}"}
                _log(f"  {module} failed: {err}", quiet)
                continue
        result[name] = _network_numbers(name, json.loads(target.read_text()))
        if t0 is not None:
            result[name]["seconds"] = time.perf_counter() - t0
    return result


def _network_numbers(name, data):
    if name == "curve":     # the resistance curve with inertia: its fits and points
        keys = ("permeability_m2", "forchheimer_beta_per_m", "d272_a", "d272_b", "ergun_A", "ergun_B")
        return {**{k: data.get(k) for k in keys},
                "velocity_m_s": [p["velocity_m_s"] for p in data.get("points", [])],
                "pressure_gradient_pa_per_m": [p["pressure_gradient_pa_per_m"] for p in data.get("points", [])]}
    if name == "solve":
        keys = ("pressure_drop_pa", "pressure_gradient_pa_per_m", "permeability_m2", "pressure_drop_stokes_pa",
                "porosity", "velocity_m_s", "depth_m", "n_pores", "n_throats")
        return {k: data.get(k) for k in keys}
    # network.paths: per path kind (widest, narrowest, ...), the mean over its traced paths
    by_kind = {}
    for path in data.get("paths", []):
        if path.get("tortuosity") is not None and path.get("duplicate_of") is None:
            by_kind.setdefault(path["kind"], []).append(path)
    return {kind: {"n_paths": len(ps), **{k: float(np.mean([p[k] for p in ps])) for k in (
        "tortuosity", "mean_width_m", "bottleneck_width_m")}} for kind, ps in by_kind.items()}


def _row(amp, freq, s, coord_before):
    i0, i1 = s["initial"]["porosity_interior"], s["final"]["porosity_interior"]
    g0, g1 = s["initial"]["porosity_global"], s["final"]["porosity_global"]
    return {"amplitude_m": amp, "intensity_g": intensity_g(freq, amp),
            "porosity_global_before": g0, "porosity_global_after": g1, "relative_change_global": (g1 - g0) / g0,
            "porosity_interior_before": i0, "porosity_interior_after": i1, "relative_change_interior": (i1 - i0) / i0,
            "porosity_spheres_before": s["history"]["porosity_spheres"][0],
            "porosity_spheres_after": s["history"]["porosity_spheres"][-1],
            "min_local_porosity_during": s["minimum_during"]["porosity_spheres_min"],
            "vibrated_s": s["vibrated_s"], "stopped_by": s["stopped_by"], "vibration_steps": s["vibration_steps"],
            "wall_time_s": s["wall_time_s"], "wall_time_note": s.get("wall_time_note"),
            "coordination_before": coord_before, "coordination_after": s["coordination"]}


def _checkpointer(path, wall_before_s=0.0, t0=None):
    """Checkpoint writer; it also keeps the wall time of the vibration so far (``wall_s``:
    ``wall_before_s`` of earlier runs plus this run's since ``t0``), so a resumed intensity
    reports its whole cost."""
    t0 = time.perf_counter() if t0 is None else t0

    def save(ck):
        arrays = {f"state__{k}": np.asarray(v) for k, v in ck["state"].items()}
        arrays.update({f"snap__{t!r}": x for t, x in ck["snapshots"].items()})
        meta = {"history": {k: np.asarray(v).tolist() for k, v in ck["history"].items()},
                "next_record_s": ck["next_record_s"], "next_checkpoint_s": ck["next_checkpoint_s"],
                "wall_s": wall_before_s + time.perf_counter() - t0}
        tmp = path.with_name(path.stem + ".tmp.npz")
        np.savez(tmp, meta=np.array(json.dumps(meta)), **arrays)
        os.replace(tmp, path)
    return save


def _load_checkpoint(path):
    with np.load(path) as f:
        meta = json.loads(str(f["meta"]))
        state = {k[len("state__"):]: f[k] for k in f.files if k.startswith("state__")}
        snaps = {float(k[len("snap__"):]): f[k] for k in f.files if k.startswith("snap__")}
    hist = {k: (list(map(np.asarray, v)) if k == "porosity_spheres" else v) for k, v in meta["history"].items()}
    return {"state": state, "history": hist, "snapshots": snaps, "next_record_s": meta["next_record_s"],
            "next_checkpoint_s": meta["next_checkpoint_s"], "wall_s": meta.get("wall_s")}


def _progress(label, duration_s, quiet):
    """tqdm bar over simulated seconds (stderr), fed by vibrate_bed's progress callback."""
    from tqdm import tqdm  # optional pretty display; the study runs without it

    bar = tqdm(total=round(duration_s, 3), desc=label, unit="s sim", disable=quiet, file=sys.stderr, mininterval=1.0,
               bar_format="{desc}: {percentage:3.0f}%|{bar}| {n:.2f}/{total:.2f} s [{elapsed}<{remaining}{postfix}]")
    t0 = time.perf_counter()

    def progress(stage, sim, force):
        if stage == "vibrate":
            bar.update(max(0.0, round(min(sim.time_s, bar.total) - bar.n, 3)))
        rate = (sim.steps - progress.steps0) * sim.n / max(time.perf_counter() - t0, 1e-9)
        bar.set_postfix_str(f"{stage}, {rate:.2e} particle-steps/s", refresh=False)

    progress.steps0 = 0
    return bar, progress


def run_study(args, container, amplitudes) -> int:
    """Body of ``--study thesis`` (see the module notes); returns the exit code."""
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    quiet = args.quiet
    duration = 16.0 if args.duration is None else args.duration
    steady = 2.0 if args.steady_window is None else args.steady_window
    # every option checked before the bed is packed
    run = RunOptions(mass_scale=args.mass_scale, tol=SETTLE_RUN.tol, max_steps=args.settle_steps)
    base = VibrationOptions(freq_hz=args.freq, duration_s=duration, record_every_s=1.0 / args.freq,
                            steady_window_s=steady or None,
                            rest_tol=args.rest_tol if args.rest_tol > 0 else None)
    vibrations = [replace(base, amplitude_m=amp) for amp in amplitudes]
    bed_csv, centers, radii, bed_summary = _bed(out, container, args.scene, args.seed, args.mass_scale, quiet)
    measure = default_measure_spheres(container)
    network_before = None if args.no_network else _network(bed_csv, container, out / "network_before.json", quiet)
    rows, series = [], {}
    t_study = time.perf_counter()
    for k, amp in enumerate(amplitudes):
        tag = f"vib_{amp * 1e3:g}mm"
        d = out / tag
        d.mkdir(exist_ok=True)
        done = d / "after.json"
        if done.exists():
            s = json.loads(done.read_text())
            _log(f"[{k + 1}/{len(amplitudes)}] {tag}: done before, reused", quiet)
        else:
            ck_path = d / "checkpoint.npz"
            resume = _load_checkpoint(ck_path) if ck_path.exists() else None
            label = f"[{k + 1}/{len(amplitudes)}] A = {amp * 1e3:g} mm ({intensity_g(args.freq, amp):.2f} g)"
            if resume is not None:
                label += f" resumed at {float(resume['state']['time_s']):.2f} s"
            bar, progress = _progress(label, duration, quiet)
            if resume is not None:
                bar.update(round(float(resume["state"]["time_s"]), 3))
                progress.steps0 = int(resume["state"]["steps"])
            t0 = time.perf_counter()
            wall_before = float((resume or {}).get("wall_s") or 0.0)
            try:
                # a resumed run was at rest when it started
                vibration = vibrations[k] if resume is None else replace(vibrations[k], rest_tol=None)
                res = vibrate_bed(centers, radii, container, vibration=vibration, run=run,
                                  material=_material(bed_summary), measure_spheres=measure, progress=progress,
                                  checkpoint=_checkpointer(ck_path, wall_before, t0), checkpoint_every_s=args.checkpoint_every,
                                  resume=resume, threads=args.threads)
            except DemInstabilityError as e:
                raise DemInstabilityError(f"A = {amp} m: {e}; what was saved stays in {out}") from e
            finally:
                bar.close()
            s = res.summary
            s["wall_time_s"] = wall_before + time.perf_counter() - t0  # earlier runs' from the checkpoint
            s["resumed_at_s"] = None if resume is None else float(resume["state"]["time_s"])
            if resume is not None and resume.get("wall_s") is None:
                s["wall_time_note"] = (f"since the restart at {s['resumed_at_s']:.2f} s simulated: the checkpoint "
                                       "kept no wall time of the earlier run")
            s["history"] = {"times_s": res.times_s.tolist(), "porosity_spheres": res.porosity_spheres.tolist(),
                            "porosity_interior": res.porosity_interior.tolist(),
                            "porosity_global": res.porosity_global.tolist(),
                            "floor_z_m": res.motion["floor_z_m"].tolist(), "bed_z_m": res.motion["bed_z_m"].tolist()}
            write_packing(d / "after.csv", res.centers, res.radii, s)
            ck_path.unlink(missing_ok=True)
        if not args.no_network and (set(NETWORK_STEPS) - set(s.get("network") or {})
                                    or any("error" in v for v in s["network"].values())):
            s["network"] = _network(d / "after.csv", container, d / "network.json", quiet)
            write_summary(d / "after.csv", s)
        row = _row(amp, args.freq, s, bed_summary["coordination"])
        row["network_after"] = s.get("network")
        rows.append(row)
        series[tag] = {"intensity_g": row["intensity_g"], **{k2: s["history"][k2] for k2 in (
            "times_s", "porosity_global", "porosity_spheres")}}
        _log(f"{tag} ({row['intensity_g']:.2f} g): global porosity {row['porosity_global_before']:.4f} -> "
             f"{row['porosity_global_after']:.4f} ({100 * row['relative_change_global']:+.2f} %), min local "
             f"{row['min_local_porosity_during']:.4f}, {row['vibrated_s']:.2f} s vibrated ({row['stopped_by']})", quiet)
    mat = _material(bed_summary)
    dt = rows and json.loads((out / f"vib_{amplitudes[0] * 1e3:g}mm" / "after.json").read_text())["dt_s"]
    study = {
        "study": "thesis", "scene": args.scene, "container": container.to_dict(), "n_spheres": int(len(radii)),
        "freq_hz": args.freq, "duration_s": duration, "steady_window_s": steady, "steady_tol": 1e-3,
        "mass_scale": args.mass_scale, "dt_s": dt,
        "stiffness_n_m": {"particle_normal": mat.kn_pp, "particle_shear": mat.ks_pp, "wall_normal": mat.kn_pw,
                          "wall_shear": mat.ks_pw, "note": "contact (series) values; with mass scale S the step "
                          "sees stiffness / S: dt = 0.25 sqrt(S m_min / k_particle)"},
        "bed": {"csv": str(bed_csv), "porosity_interior": bed_summary["porosity_interior"],
                "porosity_global_surface": bed_summary["porosity_global_surface"],
                "coordination": bed_summary["coordination"], "network": network_before},
        "rows": rows, "series": series, "wall_time_s_this_run": time.perf_counter() - t_study,
        "wall_time_s": _wall_times(bed_summary, network_before, rows),
    }
    (out / "study.json").write_text(json.dumps(study, indent=1))
    plots = plot_study(study, out)
    _print_table(study)
    made = f", {', '.join(p.name for p in plots)}" if plots else " (no matplotlib: no plots; pip install '.[plot]')"
    print(f"-> {out / 'study.json'}{made}")
    return 0


def _wall_times(bed_summary, network_before, rows):
    """Wall seconds of the study's parts as recorded (earlier runs included where the files kept
    them): packing the bed, each intensity's vibration, the network steps timed; ``total``."""
    nets = [network_before] + [r.get("network_after") for r in rows]
    net = [v.get("seconds") for n in nets for v in (n or {}).values() if isinstance(v, dict)]
    out = {"bed": bed_summary.get("wall_time_s"), "vibration": [r["wall_time_s"] for r in rows],
           "network_timed": float(sum(x for x in net if x is not None)),
           "network_steps_untimed": sum(x is None for x in net),
           "incomplete": [r["amplitude_m"] for r in rows if r.get("wall_time_note")]}
    out["total"] = float((out["bed"] or 0.0) + sum(out["vibration"]) + out["network_timed"])
    return out


def _material(summary):
    return Material(**summary["material"]) if summary and "material" in summary else SOYBEAN


def _net(network, step, kind, key):
    """One number of a bed's network results, or None."""
    d = ((network or {}).get(step) or {})
    d = d.get(kind) if kind else d
    return (d or {}).get(key) if isinstance(d, dict) else None


def _print_table(study):
    """The summary table: porosity, pressure drop (network.solve) and the widest paths'
    tortuosity and mean width (network.paths) before and after each vibration."""
    print(f"{'A mm':>5} {'Γ g':>5} {'φ before':>9} {'φ after':>8} {'change':>7} {'min local':>9} {'Δp before':>10} "
          f"{'Δp after':>9} {'τ before':>8} {'τ after':>7} {'w before':>8} {'w after':>7} {'vibrated':>9}")
    fmt = lambda v, w, p: f"{v:{w}.{p}f}" if isinstance(v, (int, float)) else f"{'-':>{w}}"  # noqa: E731
    before = study["bed"]["network"]
    for r in study["rows"]:
        after = r["network_after"]
        dp = [_net(n, "solve", None, "pressure_drop_pa") for n in (before, after)]
        tau = [_net(n, "paths", "widest", "tortuosity") for n in (before, after)]
        w = [_net(n, "paths", "widest", "mean_width_m") for n in (before, after)]
        w = [None if v is None else 1e3 * v for v in w]
        print(f"{r['amplitude_m'] * 1e3:5.1f} {r['intensity_g']:5.2f} {r['porosity_global_before']:9.4f} "
              f"{r['porosity_global_after']:8.4f} {100 * r['relative_change_global']:+6.2f}% "
              f"{r['min_local_porosity_during']:9.4f} {fmt(dp[0], 10, 3)} {fmt(dp[1], 9, 3)} {fmt(tau[0], 8, 3)} "
              f"{fmt(tau[1], 7, 3)} {fmt(w[0], 8, 2)} {fmt(w[1], 7, 2)} {r['vibrated_s']:8.2f}s")
    print("(φ: global porosity; Δp: network.solve pressure drop, Pa; τ, w: tortuosity and mean width (mm) of "
          "the widest paths, network.paths)")
