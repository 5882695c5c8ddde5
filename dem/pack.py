"""CLI: make a settled sphere packing.

    python -m dem.pack --scene rect-bin --out rect.csv --seed 1     # procedure 'sediment'
    python -m dem.pack --scene rect-bin --procedure lid --out rect_lid.csv
    python -m dem.pack --scene cyl-bin --out cyl.csv
    python -m dem.pack --scene box --size 0.1 0.05 --height 0.1 --out box.csv
    python -m dem.pack --scene cylinder --size 0.08 --height 0.1 --out cyl_small.csv
    python -m dem.pack --scene box --grain soybean --out bed.csv     # multi-sphere grains
    python -m dem.pack --scene box --grain wheat --porosity 0.402 --out bed.csv   # search, 3-6 packings
    python -m dem.pack --scene box --grain my_kernel.csv --template-units mm --out bed.csv

With ``--grain`` (a library name or a template CSV x,y,z,r) the grains are rigid multi-sphere
clumps (:mod:`dem.clumps`, :mod:`dem._clump_pack`): the CSV gains ``grain_id`` and a second file
``<stem>.grains.csv`` has one row per grain; ``--scene box`` alone means 0.04 x 0.04 x 0.04 m.

Writes the packing CSV (``x,y,z,r``, m) and its JSON summary (same stem). Exit status 0
on success, 2 on bad arguments, 1 when the simulation went unstable (nothing written) or
stopped at the step limit before equilibrium (written, marked ``"converged": false``).
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np

from ._cli import (EXIT_FAILED, check_output, check_seed, progress_printer, resolve_container,
                   run_main)
from ._container import SCENE_DEFAULTS, SCENES, default_measure_spheres
from ._material import Material
from ._io import summary_path, write_packing
from ._clump_pack import grains_path, pack_grains, pack_grains_to_porosity, write_grain_packing
from ._procedures import PROCEDURES, pack_bed
from .grains import grain
from .templates import resolve_template

#: default step limit of each stage: sphere beds; multi-sphere grain beds (a grain step costs
#: 6-11 sphere steps; corn's 0.08 m cube settles in ~100 000, give --max-steps)
SPHERE_MAX_STEPS, GRAIN_MAX_STEPS = 200_000, 60_000


def _parser():
    p = argparse.ArgumentParser(prog="python -m dem.pack", description=__doc__.split("\n")[1])
    p.add_argument("--scene", required=True, choices=sorted(SCENES) + ["box", "cylinder"],
                   help="container: the thesis's rect-bin or cyl-bin, or a box/cylinder sized by --size and --height")
    p.add_argument("--out", required=True, help="packing CSV path (JSON summary written beside it)")
    p.add_argument("--seed", type=int, default=1, help="random seed of the insertion (same seed, same packing; default 1)")
    p.add_argument("--size", type=float, nargs="+", help="box: length_x width_y; cylinder: diameter (m)")
    p.add_argument("--height", type=float, help="fill height (m) for box/cylinder")
    p.add_argument("--porosity", type=float, default=None,
                   help="target porosity (spheres: default 0.408, Table 3.1). With --grain: reached within "
                        "--porosity-tol in network's sample region by searching the procedure's lever "
                        "(closed-box growth .. deposition friction, 3-6 packings), or exit 2 with the "
                        "reachable range; without it one packing at --deposition-friction, grain count "
                        "from the grain's measured loose-fill porosity")
    p.add_argument("--porosity-tol", type=float, default=0.005, help="--grain --porosity: tolerance (default 0.005)")
    p.add_argument("--max-packings", type=int, default=6,
                   help="--grain --porosity: packings the search may spend, the two ends included (default 6)")
    p.add_argument("--workers", type=int, default=1, choices=[1, 2],
                   help="--grain --porosity: processes for the search's two end packings (default 1)")
    p.add_argument("--size-cv", type=float, default=None,
                   help="--grain: size spread, the coefficient of variation of the kernels' axes (grains scaled "
                        "by 1 + cv z, z normal cut at 2.5; default: the library's axes_sd_mm / axes_mm when "
                        "sourced, else 0, no spread, said in the summary)")
    p.add_argument("--deposition-friction", type=float, default=None,
                   help="--grain: grain-grain friction while the grains grow and fall (default 0: the densest "
                        "bed; friction then loosens it); the material's friction holds afterwards")
    p.add_argument("--n-particles", type=int, help="default: thesis Eq. 3.10")
    p.add_argument("--mass-scale", type=float, default=100.0, help="density scaling during packing (1 = none)")
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
                   f"{GRAIN_MAX_STEPS} for --grain beds); a bed not at equilibrium by then is written with "
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
    p.add_argument("--quiet", action="store_true", help="no progress lines on stderr")
    return p


def _grain_material(args, name):
    """Library density and friction of a grain (thesis values for soybean); the rest from the options."""
    mat = _material(args)
    try:
        g = grain(name)
    except ValueError:
        return mat, {}
    used = {}
    for field, attr in [("particle_density_kg_m3", "density_kg_m3"), ("friction_pp", "friction"),
                        ("friction_pw", "wall_friction")]:
        v = getattr(g, field)
        if v.value is not None:
            used[attr] = {"value": v.value, "source": v.source}
    vals = {k: v["value"] for k, v in used.items()}
    return replace(mat, **vals), used


def _pack_grains(args) -> int:
    template = resolve_template(args.grain, units=args.template_units)
    size, height = args.size, args.height
    if args.scene == "box" and size is None and height is None:
        size, height = [0.04, 0.04], 0.04
    container = resolve_container(args.scene, size_m=size, height_m=height)
    material, used = _grain_material(args, template.name)
    pr = progress_printer(quiet=args.quiet)
    size_cv, size_cv_source = _size_cv(args, template.name)
    kw = dict(material=material, n_grains=args.n_grains, rng=args.seed, mass_scale=args.mass_scale, size_cv=size_cv,
              tol=args.tol, max_steps=GRAIN_MAX_STEPS if args.max_steps is None else args.max_steps,
              progress=lambda sim, f: pr("grains", _Progress(sim), None))
    if args.porosity is not None and args.deposition_friction is None:
        try:
            xs, r, gid, grains, s = pack_grains_to_porosity(container, template, porosity=args.porosity,
                                                            porosity_tol=args.porosity_tol,
                                                            on_packing=_packing_line, workers=args.workers,
                                                            max_packings=args.max_packings,
                                                            **kw)
        except RuntimeError as e:
            print(f"error: {e}", file=sys.stderr)
            return EXIT_FAILED
    else:
        xs, r, gid, grains, s = pack_grains(container, template, porosity=_grain_porosity(args, template.name),
                                            deposition_friction=args.deposition_friction or 0.0, **kw)
    s.update(scene=args.scene, seed=args.seed, container=container.to_dict(), material_from_library=used,
             size_cv_source=size_cv_source)
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
        print(f"porosity search: reachable {ps['reachable'][0]:.4f}-{ps['reachable'][1]:.4f}; tried "
              + ", ".join(f"lever {t['lever']:+.3f} -> {t['porosity']:.4f}" for t in ps["tried"]))
    if not s["converged"]:
        print(f"error: not at equilibrium: the grains' settle stage stopped at the step limit (unbalanced force "
              f"ratio {settle['ratio']:.3g} > tol {args.tol:.3g}); written with \"converged\": false",
              file=sys.stderr)
        return EXIT_FAILED
    return 0


def _packing_line(t):
    """One stderr line per packing of a porosity search."""
    print(f"[search] lever {t['lever']:+.3f} (lid headroom {t['lid_headroom']:.3f}, deposition friction "
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


def _grain_porosity(args, name):
    """The porosity that sets the grain count of one packing: --porosity, else the middle of the
    grain's measured loose-fill range, else 0.408 (thesis Table 3.1)."""
    if args.porosity is not None:
        return args.porosity
    try:
        rng = grain(name).bulk_porosity.value
    except ValueError:
        rng = None
    return 0.408 if rng is None else 0.5 * (rng[0] + rng[1])


class _Progress:
    """The few attributes progress_printer reads, from a ClumpSimulation."""

    def __init__(self, sim):
        self.steps, self.n, self.time_s = sim.steps, sim.n_grains, sim.time_s
        self.kinetic_energy = sim.kinetic_energy


def _material(args):
    return Material(
        density_kg_m3=args.density, kn_n_m=args.kn, ks_n_m=args.ks, friction=args.friction,
        wall_kn_n_m=args.wall_kn, wall_ks_n_m=args.wall_ks, wall_friction=args.wall_friction,
        damping_ratio=args.damping, radius_min_m=args.r_min, radius_max_m=args.r_max,
    )


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
    cannot be written, before any work."""
    check_output(args.out)
    files = [summary_path(args.out)] + ([grains_path(args.out)] if args.grain is not None else [])
    for f in files:
        if f.resolve() == Path(args.out).resolve():
            raise ValueError(f"--out {args.out}: the packing would overwrite its own {f.name}; "
                             "give a .csv name")
        check_output(f, f"--out {args.out}: companion")


def _pack(args) -> int:
    check_seed(args.seed)
    if args.max_steps is not None and args.max_steps < 1:
        raise ValueError(f"--max-steps must be >= 1, got {args.max_steps}")
    _check_outputs(args)
    if args.grain is not None:
        return _pack_grains(args)
    material = _material(args)
    container = resolve_container(args.scene, size_m=args.size, height_m=args.height)
    measure = None
    if args.measure:
        r = args.measure_radius or default_measure_spheres(container)[1]
        measure = (np.array(args.measure, dtype=float), r)
    opts = _procedure_options(args)
    porosity = 0.408 if args.porosity is None else args.porosity
    res = pack_bed(container, material=material, porosity=porosity, n_particles=args.n_particles,
                   rng=args.seed, mass_scale=args.mass_scale, packing_friction=args.packing_friction,
                   open_top=not args.keep_lid, tol=args.tol,
                   max_steps=SPHERE_MAX_STEPS if args.max_steps is None else args.max_steps,
                   dt_safety=args.dt_safety, measure_spheres=measure,
                   progress=progress_printer(quiet=args.quiet), **opts)
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
    print("coordination: 1.05 d_max cutoff " + _num(c["cutoff_mean"]) + ", true contacts "
          + _num(c["contact_mean"]) + ("" if c["cutoff_mean"] is not None
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


def _num(v) -> str:
    return "n/a" if v is None else f"{v:.2f}"


def main(argv=None) -> int:
    return run_main(_parser(), _pack, argv)


if __name__ == "__main__":
    raise SystemExit(main())
