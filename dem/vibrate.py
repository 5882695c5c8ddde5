"""CLI: vibrate a settled packing vertically (thesis 3.2, Appendix C) and record porosity.

    python -m dem.vibrate rect.csv --freq 15 --amplitude 0.002 --duration 1.0
    python -m dem.vibrate rect.csv --freq 15 --series --duration 1.0      # 0.5, 1, 2, 3, 4 mm
    python -m dem.vibrate --study thesis --out study/                   # cyl-bin, 16 s x 5 (dem.study)
    python -m dem.vibrate --study thesis --scene cylinder --size 0.075 --height 0.1 --duration 4

The container comes from the packing's JSON summary (written by ``dem.pack``) or from
``--scene``. A frequency or amplitude <= 0, an intensity above 10 g, a packing without a
container and no ``--scene``, or a packing not at rest (``--rest-tol``) is refused. Writes ``<out>/vib_<A>mm.json`` (histories and summary), the final packing
``<out>/vib_<A>mm.csv`` and snapshots ``<out>/vib_<A>mm_t<T>.csv``; with several
amplitudes also ``<out>/series.json`` (porosity change against intensity).
Exit status 0 on success, 2 on bad arguments, 1 when the run went unstable or was interrupted.
"""

from __future__ import annotations

import json
import time
from pathlib import Path

import numpy as np

from ._cli import (OneLineParser, check_counts, check_output_list, check_seed, progress_printer,
                   resolve_container, run_main)
from ._container import SCENES
from ._integrate import DemInstabilityError
from ._material import Material
from ._io import read_packing, summary_path, write_packing
from ._procedures import RunOptions
from ._vibrate import SETTLE_RUN, VibrationOptions, intensity_g, vibrate_bed
from .study import run_study

THESIS_AMPLITUDES_M = (0.0005, 0.001, 0.002, 0.003, 0.004)
#: the largest intensity accepted, g
MAX_INTENSITY_G = 10.0


def _parser():
    p = OneLineParser(prog="python -m dem.vibrate", description=__doc__.split("\n")[0])
    p.add_argument("packing", nargs="?", help="packing CSV (x,y,z,r) with its JSON summary beside it (not with "
                   "--study, which packs or reuses its own bed)")
    p.add_argument("--study", choices=["thesis"], help="the thesis's vibration study, resumable (dem.study): "
                   "five intensities, network resistance before/after, study.json and plots in --out")
    p.add_argument("--freq", type=float, default=15.0, help="Hz (thesis: 15)")
    p.add_argument("--amplitude", type=float, nargs="+", help="m, one or more")
    p.add_argument("--intensity", type=float, nargs="+", help="in g, alternative to --amplitude")
    p.add_argument("--series", action="store_true", help="the thesis's 0.5, 1, 2, 3, 4 mm")
    p.add_argument("--duration", type=float, default=None, help="s of vibration (default 1; --study: 16 as the "
                   "thesis)")
    p.add_argument("--mass-scale", type=float, default=100.0,
                   help="density scaling of the time step (1 = none; default 100, docs/dem-packing.md)")
    p.add_argument("--record-every", type=float, default=None, help="s (default a quarter period)")
    p.add_argument("--snapshots", type=float, nargs="*", default=(), help="times (s) to save packings")
    p.add_argument("--settle-steps", type=int, default=100000, help="step limit of the settling after vibration")
    p.add_argument("--scene", choices=sorted(SCENES) + ["box", "cylinder"],
                   help="container if the packing has no JSON; with --study the bed's scene (default cyl-bin)")
    p.add_argument("--size", type=float, nargs="+", help="--scene box: length_x width_y; cylinder: diameter (m)")
    p.add_argument("--height", type=float, help="--scene box/cylinder: fill height (m)")
    p.add_argument("--rest-tol", type=float, default=0.01,
                   help="refuse a packing whose spheres move more than this many mean radii on average in 0.02 s "
                        "with the walls still (not at rest); 0 or less: no check")
    p.add_argument("--steady-window", type=float, default=None,
                   help="stop once the global porosity changed less than 0.001 over this many s (default: off; "
                        "--study: 2 s; 0: off)")
    p.add_argument("--seed", type=int, default=1, help="--study: seed of the bed's packing")
    p.add_argument("--checkpoint-every", type=float, default=0.25, help="--study: s of simulated time between "
                   "checkpoints")
    p.add_argument("--no-network", action="store_true", help="--study: skip network.solve/paths on the beds")
    p.add_argument("--threads", type=int, default=None, help="threads of the step (default: chosen by timing)")
    p.add_argument("--out", default=None, help="output folder (default vibration_out; --study: vibration_study)")
    p.add_argument("--quiet", action="store_true", help="no progress lines on stderr")
    return p


def _amplitudes(args):
    """Amplitudes (m) asked for: the thesis series, --amplitude, or --intensity in g at --freq;
    refused (ValueError) when the frequency or an amplitude is <= 0 or an intensity above 10 g."""
    if not args.freq > 0:
        raise ValueError(f"--freq must be > 0, got {args.freq}")
    if args.series or (args.study and not (args.amplitude or args.intensity)):
        amps = list(THESIS_AMPLITUDES_M)
    elif args.amplitude:
        amps = list(args.amplitude)
    elif args.intensity:
        amps = [g * 9.81 / (2 * np.pi * args.freq) ** 2 for g in args.intensity]
    else:
        raise ValueError("give --amplitude, --intensity or --series")
    for a in amps:
        if not a > 0:
            raise ValueError(f"amplitudes must be > 0, got {a} m")
        if intensity_g(args.freq, a) > MAX_INTENSITY_G:
            raise ValueError(f"intensity {intensity_g(args.freq, a):.2f} g (A = {a} m at {args.freq} Hz) is above "
                             f"{MAX_INTENSITY_G:g} g")
    return amps


def _check_files(args, out, amps) -> None:
    """ValueError naming --out when a file the run writes in ``out`` (each amplitude's packing,
    summary and snapshots, the series) cannot be written or is the input packing or its JSON
    summary (:func:`network.core.check_output_list`), before any work."""
    names = []
    for amp in amps:
        tag = f"vib_{amp * 1e3:g}mm"
        names += [f"{tag}.csv", f"{tag}.json"] + [f"{tag}_t{t:g}.csv" for t in args.snapshots]
    names += ["series.json"] if len(amps) > 1 else []
    inputs = [("the packing", Path(args.packing)),
              ("the packing's JSON summary", summary_path(args.packing))]
    check_output_list([("--out", out / n) for n in names], inputs, make_folders=True)


def _check_run_options(args) -> None:
    """The run's numbers, each named by its option (ValueError), before any work."""
    for name, value in (("--duration", args.duration), ("--record-every", args.record_every)):
        if value is not None and not (np.isfinite(value) and value > 0):
            raise ValueError(f"{name} must be finite and > 0, got {value}")
    if args.steady_window is not None and not (np.isfinite(args.steady_window)
                                               and args.steady_window >= 0):
        raise ValueError(f"--steady-window must be finite and >= 0 (0: off), got {args.steady_window}")
    if not (np.isfinite(args.mass_scale) and args.mass_scale >= 1):
        raise ValueError(f"--mass-scale must be >= 1 (1: physical masses), got {args.mass_scale}")
    bad = [t for t in args.snapshots if not (np.isfinite(t) and t >= 0)]
    if bad:
        raise ValueError(f"--snapshots must be times >= 0 s, got {bad[0]}")


def _vibrate(args) -> int:
    check_seed(args.seed)
    check_counts(args)
    _check_run_options(args)
    amps = _amplitudes(args)
    if args.study:
        if args.packing:
            raise ValueError("--study packs or reuses its own bed (in --out); give no packing")
        args.scene = args.scene or "cyl-bin"
        args.out = args.out or "vibration_study"
        return run_study(args, resolve_container(args.scene, size_m=args.size, height_m=args.height), amps)
    if not args.packing:
        raise ValueError("give a packing CSV (or --study thesis)")
    centers, radii, summary = read_packing(args.packing)
    container = resolve_container(args.scene, size_m=args.size, height_m=args.height, summary=summary)
    material = Material(**summary["material"]) if summary and "material" in summary else Material()
    duration = 1.0 if args.duration is None else args.duration
    run = RunOptions(mass_scale=args.mass_scale, tol=SETTLE_RUN.tol, max_steps=args.settle_steps)
    vibrations = [VibrationOptions(freq_hz=args.freq, amplitude_m=amp, duration_s=duration,
                                   record_every_s=args.record_every, snapshot_times_s=args.snapshots,
                                   steady_window_s=args.steady_window or None,
                                   rest_tol=args.rest_tol if args.rest_tol > 0 and amp == amps[0] else None)
                  for amp in amps]                      # every option checked before any work
    out = Path(args.out or "vibration_out")
    _check_files(args, out, amps)
    out.mkdir(parents=True, exist_ok=True)
    rows = []
    for amp, vibration in zip(amps, vibrations):
        t0 = time.perf_counter()
        try:
            res = vibrate_bed(centers, radii, container, vibration=vibration, run=run, material=material,
                              threads=args.threads, progress=progress_printer(f"A={amp * 1e3:.1f} mm ", quiet=args.quiet))
        except DemInstabilityError as e:
            raise DemInstabilityError(f"A = {amp} m: {e}") from e
        tag = f"vib_{amp * 1e3:g}mm"
        s = res.summary
        s["wall_time_s"] = time.perf_counter() - t0
        s["history"] = {"times_s": res.times_s.tolist(), "porosity_spheres": res.porosity_spheres.tolist(),
                        "porosity_interior": res.porosity_interior.tolist(),
                        "porosity_global": res.porosity_global.tolist()}
        write_packing(out / f"{tag}.csv", res.centers, res.radii, s)
        for t, x in res.snapshots.items():
            write_packing(out / f"{tag}_t{t:g}.csv", x, res.radii)
        i0, i1 = s["initial"]["porosity_interior"], s["final"]["porosity_interior"]
        rows.append({"amplitude_m": amp, "intensity_g": intensity_g(args.freq, amp), "porosity_interior_before": i0,
                     "porosity_interior_after": i1, "relative_change_interior": (i1 - i0) / i0,
                     "porosity_spheres_before": s["initial"]["porosity_spheres_mean"],
                     "porosity_spheres_after": s["final"]["porosity_spheres_mean"],
                     "porosity_global_before": s["initial"]["porosity_global"],
                     "porosity_global_after": s["final"]["porosity_global"],
                     "wall_time_s": s["wall_time_s"], "vibration_steps": s["vibration_steps"]})
        print(f"A = {amp * 1e3:4.1f} mm ({rows[-1]['intensity_g']:.2f} g): interior porosity {i0:.4f} -> {i1:.4f} "
              f"({100 * (i1 - i0) / i0:+.2f} %), spheres {rows[-1]['porosity_spheres_before']:.4f} -> "
              f"{rows[-1]['porosity_spheres_after']:.4f}, wall {s['wall_time_s']:.0f} s")
    if len(rows) > 1:
        (out / "series.json").write_text(json.dumps({"freq_hz": args.freq, "duration_s": duration,
                                                     "mass_scale": args.mass_scale, "n_spheres": len(radii),
                                                     "rows": rows}, indent=1))
        best = min(rows, key=lambda r: r["porosity_interior_after"])
        print(f"lowest porosity at {best['intensity_g']:.2f} g ({100 * best['relative_change_interior']:+.2f} %)")
    return 0


def main(argv=None) -> int:
    return run_main(_parser(), _vibrate, argv)


if __name__ == "__main__":
    raise SystemExit(main())
