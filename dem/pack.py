"""CLI: make a settled sphere packing.

    python -m dem.pack --scene rect-bin --out rect.csv --seed 1     # procedure 'sediment'
    python -m dem.pack --scene rect-bin --procedure lid --out rect_lid.csv
    python -m dem.pack --scene cyl-bin --out cyl.csv
    python -m dem.pack --scene box --size 0.1 0.05 --height 0.1 --out box.csv
    python -m dem.pack --scene cylinder --size 0.08 --height 0.1 --out cyl_small.csv
    python -m dem.pack --scene box --grain soybean --out bed.csv     # multi-sphere grains, rain-filled
    python -m dem.pack --scene box --grain wheat --fill spout --spout-diameter 0.02 --out pile.csv
    python -m dem.pack --scene box --grain wheat --depth 3.4 --bin-diameter 6 --out deep.csv  # overburden
    python -m dem.pack --scene box --grain wheat --stress 0 20000 40000 --out set.csv  # set_0kPa.csv ...
    python -m dem.pack --scene box --grain wheat --fill grow --porosity 0.402 --out bed.csv   # search
    python -m dem.pack --scene box --grain my_kernel.csv --template-units mm --out bed.csv

With ``--grain`` (a library name or a template CSV x,y,z,r) the grains are rigid multi-sphere
clumps (:mod:`dem.clumps`): the CSV gains ``grain_id`` and a second file ``<stem>.grains.csv`` has
one row per grain; ``--scene box`` alone means 0.04 x 0.04 x 0.04 m. Grains are poured
(``--fill rain``, the default, or ``spout``; :mod:`dem._pour`) with their real masses and the
library's friction, restitution and rolling friction (``--no-rolling``: none), or grown in place (``--fill grow``, :mod:`dem._clump_pack`; ``--porosity``: :mod:`dem._grain_search`).
``--depth Z --bin-diameter D`` (or ``--stress PA``) then loads the poured bed through a lid
servo-controlled to Janssen's vertical stress at that depth (:mod:`dem._load`). Several
``--stress`` values make a bed set: one pour, each stress loaded from a copy of the same poured
state and written to ``<stem>_<kPa>kPa.csv`` (``set.csv`` with ``--stress 0 20000``:
``set_0kPa.csv``, ``set_20kPa.csv``).

Writes the packing CSV (``x,y,z,r``, m) and its JSON summary (same stem). Exit status 0
on success, 2 on bad arguments (nothing written), 1 when the simulation went unstable (nothing
written) or stopped at the step limit before equilibrium (written, marked ``"converged": false``).
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np
from network.core import check_physical_porosity, recorded_reach

from ._cli import (EXIT_FAILED, OneLineParser, check_counts, check_output, check_seed, progress_printer,
                   resolve_container, run_main)
from ._container import SCENE_DEFAULTS, SCENES, default_measure_spheres
from ._io import summary_path, write_packing
from ._clump_pack import grains_path, pack_grains, write_grain_packing
from ._grain_search import grain_count, pack_grains_to_porosity
from ._load import MAX_STRESS_PA
from ._pack_inputs import Progress, fmt_num, grain_material, grain_porosity, material_from_args
from ._pack_pour import fill_options, pour_and_load, stress_outputs
from ._pour import FILL_METHODS
from ._procedures import PROCEDURES, PackOptions, RunOptions, pack_bed
from .grains import grain
from .templates import resolve_template

#: default step limit of each stage: sphere beds; multi-sphere grain beds (a grain step costs
#: 6-11 sphere steps; corn's 0.08 m cube settles in ~100 000, give --max-steps)
SPHERE_MAX_STEPS, GRAIN_MAX_STEPS = 200_000, 60_000


def _parser():
    p = OneLineParser(prog="python -m dem.pack", description=__doc__.split("\n")[1])
    p.add_argument("--scene", required=True, choices=sorted(SCENES) + ["box", "cylinder"],
                   help="container: the thesis's rect-bin or cyl-bin, or a box/cylinder sized by --size and --height")
    p.add_argument("--out", required=True, help="packing CSV path (JSON summary written beside it)")
    p.add_argument("--seed", type=int, default=1, help="random seed of the insertion (same seed, same packing; default 1)")
    p.add_argument("--size", type=float, nargs="+", help="box: length_x width_y; cylinder: diameter (m)")
    p.add_argument("--height", type=float, help="fill height (m) for box/cylinder")
    p.add_argument("--porosity", type=float, default=None,
                   help="target porosity (spheres: default 0.408, Table 3.1). With --grain: reached within "
                        "--porosity-tol in network's sample region by searching the procedure's lever "
                        "(closed-box growth .. deposition friction) with the grain's own count (from its "
                        "measured loose-fill porosity), or exit 2 with the reachable range: the beds at "
                        "levers -1, 0, +1, packed once per grain, container and seed and kept in "
                        "$GRAINFLOW_REACH_CACHE or ~/.cache/grainflow/reach (the bundled boxes': recorded); "
                        "without it one packing at --deposition-friction")
    p.add_argument("--porosity-tol", type=float, default=0.005, help="--grain --porosity: tolerance (default 0.005)")
    p.add_argument("--max-packings", type=int, default=6,
                   help="--grain --porosity: packings the search may spend inside the reachable range, the "
                        "range's own beds not counted (default 6)")
    p.add_argument("--workers", type=int, default=1, choices=[1, 2],
                   help="--grain --porosity: processes for the range's packings (default 1)")
    p.add_argument("--size-cv", type=float, default=None,
                   help="--grain: size spread, the coefficient of variation of the kernels' axes (grains scaled "
                        "by 1 + cv z, z normal cut at 2.5; default: the library's axes_sd_mm / axes_mm when "
                        "sourced, else 0, no spread, said in the summary)")
    p.add_argument("--deposition-friction", type=float, default=None,
                   help="--grain: grain-grain friction while the grains grow and fall (default 0: the densest "
                        "bed; friction then loosens it); the material's friction holds afterwards")
    p.add_argument("--n-particles", type=int, help="default: thesis Eq. 3.10")
    p.add_argument("--mass-scale", type=float, default=None,
                   help="density scaling S >= 1 during packing (1 = real masses; default 100, poured grain fills 1)")
    p.add_argument("--packing-friction", type=float, default=None,
                   help="particle friction during expansion/closed stage (default: the material's)")
    p.add_argument("--procedure", choices=list(PROCEDURES), default=None,
                   help="'lid': expand under a lid, then settle (Appendix B style; Appendix A closed box with "
                        "--lid-headroom 0 --keep-lid); 'sediment': frictionless sedimentation and taps, then friction "
                        "restored and settled (default for rect-bin, see dem.SCENE_DEFAULTS)")
    p.add_argument("--lid-headroom", type=float, default=None,
                   help="lid height above the fill height during expansion, as a fraction (0: Appendix A closed box; "
                        "default 0.2 for 'lid', 0.3 for 'sediment')")
    p.add_argument("--sediment-steps", type=int, default=None, help="'sediment': frictionless settling steps")
    p.add_argument("--tap-freq", type=float, default=None, help="'sediment': tap frequency, Hz")
    p.add_argument("--tap-amplitude", type=float, default=None, help="'sediment': tap amplitude, m")
    p.add_argument("--tap-duration", type=float, default=None, help="'sediment': tapping time, s (whole periods)")
    p.add_argument("--tap-decay", action=argparse.BooleanOptionalAction, default=None,
                   help="'sediment': amplitude falls linearly to 0 over the taps (annealed)")
    p.add_argument("--keep-lid", action="store_true", help="do not remove the lid before the last settling")
    p.add_argument("--tol", type=float, default=2e-3, help="mean unbalanced-force ratio at equilibrium")
    p.add_argument("--max-steps", type=int, default=None, help="step limit of each stage (default 200000 for spheres, "
                   f"{GRAIN_MAX_STEPS} for grown grain beds, 0.5 s of simulated time and at least {GRAIN_MAX_STEPS} "
                   "for a poured bed's rest and its load); a bed not at equilibrium by then is written with "
                   "\"converged\": false and exit 1")
    p.add_argument("--dt-safety", type=float, default=0.25, help="time step as this fraction of sqrt(mass_scale m_min / "
                   "max(k_n, k_s)), the critical step of the lightest sphere (default 0.25)")
    for name, default, what in [("density", 1285.0, "particle density, kg/m^3"),
                                ("kn", 4.0e6, "particle normal stiffness, N/m"),
                                ("ks", 2.0e6, "particle shear stiffness, N/m"),
                                ("friction", 0.47, "particle friction coefficient"),
                                ("wall-kn", 1.8e7, "wall normal stiffness, N/m"),
                                ("wall-ks", 0.9e7, "wall shear stiffness, N/m"),
                                ("wall-friction", 0.3, "wall friction coefficient"),
                                ("damping", 0.1, "viscous damping ratio"),
                                ("r-min", 0.00275, "smallest sphere radius, m"),
                                ("r-max", 0.00375, "largest sphere radius, m")]:
        p.add_argument(f"--{name}", type=float, default=default,
                       help=f"{what} (default {default:g}, thesis Table 3.1)")
    p.add_argument("--measure", type=float, nargs=3, action="append", metavar=("X", "Y", "Z"),
                   help="centre of a measurement sphere (m); repeat for several (default: thesis B1-B5)")
    p.add_argument("--measure-radius", type=float, default=None, help="m (default: width/14 as in Appendix C)")
    p.add_argument("--grain", default=None, help="multi-sphere grains: a library name (soybean, wheat, shelled_corn, "
                   "barley, canola) or a template CSV x,y,z,r; material from the grain library where it has values")
    p.add_argument("--template-units", choices=["mm", "m"], default="mm", help="units of a template CSV (default mm)")
    p.add_argument("--n-grains", type=int, default=None, help="--grain: number of grains (default from --porosity)")
    p.add_argument("--fill", choices=FILL_METHODS, default=None,
                   help="--grain: 'rain' (default: a spreader, grains over the whole cross-section), 'spout' (a "
                        "centre spout; the pile forms at its angle of repose), 'grow' (grown in place and settled; "
                        "the default with --porosity, --deposition-friction or --size-cv)")
    p.add_argument("--drop-height", type=float, default=None,
                   help="rain/spout: height the grains fall from onto the surface, m (default 0.3, at most 10)")
    p.add_argument("--rate", type=float, default=None,
                   help="rain/spout: mass flow, kg/s, > 0 (default: the surface rises one grain diameter per "
                        "rebound flight 2 e v0/g of a landed grain, so it is at rest before it is covered)")
    p.add_argument("--spout-diameter", type=float, default=None,
                   help="spout: diameter, m, between a grain's width and the container's narrowest width "
                        "(default three kernel lengths)")
    p.add_argument("--no-freeze", action="store_const", const=True, default=None,
                   help="poured fill: step every grain to the end (default: grains settled more than four kernel "
                        "lengths below the surface are frozen while the pour goes on, and released before the "
                        "bed's rest is judged and before a load; docs/dem-fill.md, Speed)")
    p.add_argument("--no-rolling", action="store_const", const=True, default=None,
                   help="poured fill: no rolling friction (default: the grain library's coefficients of rolling "
                        "friction, grain-grain and grain-wall, where it has them; 0 where not; docs/dem-fill.md, "
                        "Rolling friction)")
    p.add_argument("--depth", type=float, default=None,
                   help="rain/spout: load the bed to Janssen's vertical stress at this depth of a bin, m, >= 0 "
                        "(needs --bin-diameter; default: no load)")
    p.add_argument("--bin-diameter", type=float, default=None, help="--depth: the bin's diameter, m, > 0")
    p.add_argument("--bin-height", type=float, default=None,
                   help="--depth: the bin's wall height, m, > 0: a deeper --depth is refused (default: "
                        "no wall height, any depth)")
    p.add_argument("--stress", type=float, nargs="+", default=None,
                   help=f"rain/spout: load the bed through a lid to this vertical stress, Pa, 0 to "
                        f"{MAX_STRESS_PA:g} (not with --depth; default: no load); several: one pour, each stress loaded from a copy of the poured state and written to "
                        "<stem>_<kPa>kPa.csv")
    p.add_argument("--quiet", action="store_true", help="no progress lines on stderr")
    return p


def _pack_grains(args, fill) -> int:
    template = resolve_template(args.grain, units=args.template_units)
    size, height = args.size, args.height
    if args.scene == "box" and size is None and height is None:
        size, height = [0.04, 0.04], 0.04
    container = resolve_container(args.scene, size_m=size, height_m=height)
    if fill.method != "grow":
        return pour_and_load(args, fill, template, container)
    material, used = grain_material(args, template.name)
    pr = progress_printer(quiet=args.quiet)
    size_cv, size_cv_source = _size_cv(args, template.name)
    kw = dict(material=material, n_grains=args.n_grains, rng=args.seed,
              mass_scale=100.0 if args.mass_scale is None else args.mass_scale, size_cv=size_cv,
              tol=args.tol, max_steps=GRAIN_MAX_STEPS if args.max_steps is None else args.max_steps,
              progress=lambda sim, f: pr("grains", Progress(sim), None))
    if args.porosity is not None and args.deposition_friction is None:
        n, _, _ = grain_count(container, template, size_cv=size_cv, n_grains=args.n_grains)
        rec = recorded_reach(template.name, container.to_dict(), args.seed)
        if rec is not None and (rec["n_grains"] != n or not rec["beds"]):
            rec = None                     # the record's beds have another grain count
        try:
            xs, r, gid, grains, s = pack_grains_to_porosity(container, template, porosity=args.porosity,
                                                            porosity_tol=args.porosity_tol,
                                                            on_packing=_packing_line, workers=args.workers,
                                                            max_packings=args.max_packings, reach=rec,
                                                            **kw)
        except RuntimeError as e:
            print(f"error: {e}", file=sys.stderr)
            return EXIT_FAILED
    else:
        xs, r, gid, grains, s = pack_grains(container, template, porosity=grain_porosity(args, template.name),
                                            deposition_friction=args.deposition_friction or 0.0, **kw)
    s.update(scene=args.scene, seed=args.seed, container=container.to_dict(), material_from_library=used,
             size_cv_source=size_cv_source, fill={"method": "grow"})
    settle = s["stages"]["settle"]
    s["converged"] = bool(settle["converged"])
    write_grain_packing(args.out, xs, r, gid, grains, s)
    print(f"{s['n_grains']} grains of {template.n} spheres ({s['n_spheres']} spheres) -> {args.out} "
          f"(+ {grains_path(args.out).name}, {summary_path(args.out).name})")
    print(f"porosity (union of spheres): network's sample region {s['porosity_network_region']:.4f} +- "
          f"{s['porosity_network_region_error']:.4f}, interior box {s['porosity_interior_union']:.4f} "
          f"+- {s['porosity_interior_error']:.4f}; deposition friction {s['deposition_friction']:.3f}; "
          f"{s['steps']} steps, wall {s['wall_time_s']:.1f} s")
    if "porosity_search" in s:
        ps = s["porosity_search"]
        print(f"porosity search: reachable {ps['reachable_text']}; tried "
              + ", ".join(f"lever {t['lever']:+.3f} -> {t['porosity']:.4f}" for t in ps["tried"]))
    if not s["converged"]:
        print(f"error: not at equilibrium: the grains' settle stage stopped at the step limit (unbalanced force "
              f"ratio {settle['ratio']:.3g} > tol {args.tol:.3g}); written with \"converged\": false",
              file=sys.stderr)
        return EXIT_FAILED
    return 0


def _packing_line(t):
    """One stderr line per bed of a porosity search: the range's (packed now or read from the
    cache) and the search's own."""
    if t.get("cached"):
        print(f"[range] lever {t['lever']:+.3f}: porosity {t['porosity']:.4f} (cached)", file=sys.stderr,
              flush=True)
        return
    print(f"[{t.get('stage', 'search')}] lever {t['lever']:+.3f} (lid headroom {t['lid_headroom']:.3f}, deposition friction "
          f"{t['deposition_friction']:.3f}): porosity {t['porosity']:.4f} +- {t['porosity_error']:.4f}, "
          f"{t['wall_time_s']:.0f} s", file=sys.stderr, flush=True)


def _size_cv(args, name):
    """(size spread, where it came from): --size-cv, else the library's mean axis standard
    deviation over the mean axis (axes_sd_mm / axes_mm), else 0 (no sourced spread)."""
    if args.size_cv is not None:
        return args.size_cv, "--size-cv"
    try:
        lib = grain(name)
    except ValueError:
        return 0.0, "template file: no library spread"
    sd, ax = lib.axes_sd_mm.value, lib.axes_mm.value
    if sd is None or ax is None:
        return 0.0, f"none: the library has no axis standard deviations for {name} ({lib.axes_sd_mm.note})"
    return float(np.mean(np.asarray(sd) / np.asarray(ax))), f"library axes_sd_mm / axes_mm ({lib.axes_sd_mm.source})"


def _procedure_options(args):
    """The scene's default procedure options, overridden by the ones given on the command line."""
    opts = dict(SCENE_DEFAULTS.get(args.scene, {}))
    if args.procedure is not None and args.procedure != opts.get("procedure", "lid"):
        opts = {"procedure": args.procedure}
    for key, val in [("lid_headroom", args.lid_headroom), ("sediment_steps", args.sediment_steps),
                     ("tap_freq_hz", args.tap_freq), ("tap_amplitude_m", args.tap_amplitude),
                     ("tap_duration_s", args.tap_duration), ("tap_decay", args.tap_decay)]:
        if val is not None:
            opts[key] = val
    if opts.get("procedure", "lid") == "lid" and "lid_headroom" not in opts:
        opts["lid_headroom"] = 0.2
    return opts


def _check_outputs(args):
    """ValueError naming --out when the packing, its JSON summary or (--grain) its grain table
    cannot be written or is the --grain template file, before any work."""
    inputs = [("--grain", Path(args.grain))] if args.grain is not None and Path(
        str(args.grain)).is_file() else []
    outs = stress_outputs(args)
    for k, (s, out) in enumerate(outs):
        clash = next((t for t, o in outs[:k] if o.name == out.name), None)
        if clash is not None:
            raise ValueError(f"--stress {clash:.12g} and {s:.12g} Pa both write {out.name} (the names keep six "
                             "significant digits of kPa): give stresses that differ there")
        check_output(out, inputs=inputs)
        files = [summary_path(out)] + ([grains_path(out)] if args.grain is not None else [])
        for f in files:
            if f.resolve() == Path(out).resolve():
                raise ValueError(f"--out {args.out}: the packing would overwrite its own {f.name}; "
                                 "give a .csv name")
            check_output(f, f"--out {args.out}: companion", inputs=inputs)


def _pack(args) -> int:
    check_seed(args.seed)
    if args.max_steps is not None and args.max_steps < 1:
        raise ValueError(f"--max-steps must be >= 1, got {args.max_steps}")
    check_counts(args)
    ms = args.mass_scale
    if ms is not None and not (math.isfinite(ms) and ms >= 1):
        raise ValueError(f"--mass-scale {ms:g}: must be finite and >= 1 (1: real masses)")
    fill = fill_options(args)
    _check_outputs(args)
    if args.porosity is not None:       # a porosity no bed has: refused before any packing
        check_physical_porosity(args.porosity)
    if args.grain is not None:
        return _pack_grains(args, fill)
    if args.mass_scale is None:
        args.mass_scale = 100.0
    material = material_from_args(args)
    container = resolve_container(args.scene, size_m=args.size, height_m=args.height)
    measure = None
    if args.measure:
        r = args.measure_radius or default_measure_spheres(container)[1]
        measure = (np.array(args.measure, dtype=float), r)
    opts = _procedure_options(args)
    porosity = 0.408 if args.porosity is None else args.porosity
    options = PackOptions(packing_friction=args.packing_friction, open_top=not args.keep_lid, **opts)
    run = RunOptions(mass_scale=args.mass_scale, tol=args.tol, dt_safety=args.dt_safety,
                     max_steps=SPHERE_MAX_STEPS if args.max_steps is None else args.max_steps)
    res = pack_bed(container, material=material, porosity=porosity, n_particles=args.n_particles,
                   rng=args.seed, options=options, run=run, measure_spheres=measure,
                   progress=progress_printer(quiet=args.quiet))
    s = res.summary
    s["scene"] = args.scene
    s["procedure_options"] = opts
    s["seed"] = args.seed
    stuck = [name for name, st in s.get("stages", {}).items()
             if name != "expand" and not st.get("converged", True)]
    s["converged"] = not stuck
    write_packing(args.out, res.centers, res.radii, s)
    print(f"{s['n_spheres']} spheres -> {args.out} (+ {summary_path(args.out).name})")
    print(f"porosity: interior {s['porosity_interior']:.4f}, global (surface {s['bed_height_surface_m']:.4f} m) "
          f"{s['porosity_global_surface']:.4f}, measurement spheres {s['measure_spheres']['mean']:.4f}")
    c = s["coordination"]
    print("coordination: 1.05 d_max cutoff " + fmt_num(c["cutoff_mean"]) + ", true contacts "
          + fmt_num(c["contact_mean"]) + ("" if c["cutoff_mean"] is not None
                                       else " (no interior sphere to count)"))
    print(f"{s['steps']} steps, simulated {s['simulated_time_s']:.3f} s (mass scale {s['mass_scale']:g}), "
          f"wall {s['wall_time_s']:.1f} s, {s['particle_steps_per_s']:.3e} particle-steps/s")
    if stuck:
        st = s["stages"][stuck[0]]
        print(f"error: not at equilibrium: stage {stuck[0]} stopped at the step limit (unbalanced "
              f"force ratio {st['ratio']:.3g} > tol {s['tol_unbalanced_ratio']:.3g}); written with "
              f"\"converged\": false (give --max-steps or --tol)", file=sys.stderr)
        return EXIT_FAILED
    return 0


def main(argv=None) -> int:
    return run_main(_parser(), _pack, argv)


if __name__ == "__main__":
    raise SystemExit(main())
