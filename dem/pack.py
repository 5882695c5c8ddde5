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
library's friction and restitution, or grown in place (``--fill grow``, :mod:`dem._clump_pack`; ``--porosity``: :mod:`dem._grain_search`).
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
import contextlib
import copy
import math
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
from network.core import check_physical_porosity, recorded_reach

from ._cli import (EXIT_FAILED, OneLineParser, check_counts, check_output, check_seed, progress_printer,
                   resolve_container, run_main)
from ._container import SCENE_DEFAULTS, SCENES, default_measure_spheres
from ._material import Material
from ._io import summary_path, write_packing
from ._clump_pack import grains_path, pack_grains, write_grain_packing
from ._grain_search import grain_count, pack_grains_to_porosity
from ._contacts import damping_ratio_for_restitution
from ._load import MAX_STRESS_PA, janssen_stress, load_bed
from ._reach import count_porosity
from ._pile import poured_bed_summary
from ._pour import FILL_METHODS, FillOptions, check_fill_options, pour_grains, rest_steps
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


def _pack_grains(args, fill) -> int:
    template = resolve_template(args.grain, units=args.template_units)
    size, height = args.size, args.height
    if args.scene == "box" and size is None and height is None:
        size, height = [0.04, 0.04], 0.04
    container = resolve_container(args.scene, size_m=size, height_m=height)
    if fill.method != "grow":
        return _pour(args, fill, template, container)
    material, used = _grain_material(args, template.name)
    pr = progress_printer(quiet=args.quiet)
    size_cv, size_cv_source = _size_cv(args, template.name)
    kw = dict(material=material, n_grains=args.n_grains, rng=args.seed,
              mass_scale=100.0 if args.mass_scale is None else args.mass_scale, size_cv=size_cv,
              tol=args.tol, max_steps=GRAIN_MAX_STEPS if args.max_steps is None else args.max_steps,
              progress=lambda sim, f: pr("grains", _Progress(sim), None))
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
        xs, r, gid, grains, s = pack_grains(container, template, porosity=_grain_porosity(args, template.name),
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


def _grain_porosity(args, name):
    """The porosity that sets the grain count of one packing: --porosity, else the middle of the
    grain's measured loose-fill range, else 0.408 (thesis Table 3.1): dem._reach.count_porosity."""
    return args.porosity if args.porosity is not None else count_porosity(name)[0]


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


def _stress_outputs(args):
    """[(stress Pa or None, packing path)]: ``--out`` itself, or with several ``--stress`` values
    one ``<stem>_<kPa>kPa<suffix>`` per stress."""
    if args.stress is None or len(args.stress) == 1:
        return [(None if args.stress is None else args.stress[0], Path(args.out))]
    out = Path(args.out)
    return [(s, out.with_name(f"{out.stem}_{s / 1000:g}kPa{out.suffix}")) for s in args.stress]


def _check_outputs(args):
    """ValueError naming --out when the packing, its JSON summary or (--grain) its grain table
    cannot be written or is the --grain template file, before any work."""
    inputs = [("--grain", Path(args.grain))] if args.grain is not None and Path(
        str(args.grain)).is_file() else []
    outs = _stress_outputs(args)
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


_POUR_ONLY = (("--drop-height", "drop_height"), ("--rate", "rate"), ("--spout-diameter", "spout_diameter"),
              ("--depth", "depth"), ("--bin-diameter", "bin_diameter"), ("--bin-height", "bin_height"),
              ("--stress", "stress"), ("--no-freeze", "no_freeze"))


def _fill_options(args):
    """The fill of a grain bed from the command line (None for spheres); ValueError naming the
    option and its value for every combination or value the fill and the load refuse."""
    given = [opt for opt, key in _POUR_ONLY if getattr(args, key) is not None]
    if args.grain is None:
        if given or args.fill is not None:
            raise ValueError(f"{(given or ['--fill'])[0]} needs --grain (poured fills and loads are grain beds)")
        return None
    grow_only = args.porosity is not None or args.deposition_friction is not None or args.size_cv is not None
    method = args.fill or ("grow" if grow_only else "rain")
    if method == "grow":
        if given:
            raise ValueError(f"{given[0]} needs a poured fill (--fill rain or spout), not --fill grow")
        return FillOptions(method="grow")
    if args.porosity is not None:
        raise ValueError(f"--porosity {args.porosity:g} with --fill {method}: a poured bed makes its own porosity; "
                         "the porosity search grows the bed (--fill grow)")
    if args.deposition_friction is not None:
        raise ValueError("--deposition-friction belongs to --fill grow (a poured bed keeps the library's friction)")
    if args.size_cv is not None:
        raise ValueError(f"--size-cv {args.size_cv:g} with --fill {method}: poured fills take one kernel size")
    if args.spout_diameter is not None and method != "spout":
        raise ValueError(f"--spout-diameter {args.spout_diameter:g} needs --fill spout")
    for opt, key in (("--depth", "depth"), ("--bin-diameter", "bin_diameter"), ("--bin-height", "bin_height")):
        v = getattr(args, key)
        if v is not None and not (math.isfinite(v) and (v >= 0 if key == "depth" else v > 0)):
            raise ValueError(f"{opt} {v:g} m: must be a finite length, {'>= 0' if key == 'depth' else '> 0'}")
    if args.stress is not None:
        for v in args.stress:
            if not (math.isfinite(v) and 0 <= v <= MAX_STRESS_PA):
                raise ValueError(f"--stress {v:g} Pa: must be finite, >= 0 and <= {MAX_STRESS_PA:g} Pa")
        if len(set(args.stress)) != len(args.stress):
            raise ValueError(f"--stress {' '.join(f'{v:g}' for v in args.stress)}: a stress is given twice")
        if args.depth is not None:
            raise ValueError(f"--stress {args.stress[0]:g} together with --depth {args.depth:g}: give one")
    if args.depth is not None and args.bin_diameter is None:
        raise ValueError(f"--depth {args.depth:g} needs --bin-diameter (Janssen's stress depends on it)")
    if args.depth is None and (args.bin_diameter is not None or args.bin_height is not None):
        raise ValueError("--bin-diameter and --bin-height go with --depth")
    if args.depth is not None and args.bin_height is not None and args.depth > args.bin_height:
        raise ValueError(f"--depth {args.depth:g} m is beyond the bin's wall height (--bin-height {args.bin_height:g} m)")
    with _fill_options_named():
        return FillOptions(method=method, drop_height_m=0.3 if args.drop_height is None else args.drop_height,
                           rate_kg_s=args.rate, spout_diameter_m=args.spout_diameter,
                           mass_scale=1.0 if args.mass_scale is None else args.mass_scale,
                           freeze=not args.no_freeze)


@contextlib.contextmanager
def _fill_options_named():
    """A fill's ValueError (:class:`FillOptions`, :func:`check_fill_options`: "drop height 11 m:
    ...") re-raised naming the command-line option ("--drop-height 11 m: ...")."""
    try:
        yield
    except ValueError as e:
        opt = {"drop height": "--drop-height", "rate": "--rate", "spout diameter": "--spout-diameter",
               "mass scale": "--mass-scale"}
        raise ValueError(next((f"{o} " + str(e).split(" ", len(k.split()))[-1] for k, o in opt.items()
                               if str(e).startswith(k)), str(e))) from None


def _janssen_inputs(name):
    """(wall friction mu_w, lateral pressure ratio K, what they are) of a library grain for Janssen's
    stress: the bulk's friction on a smooth steel wall (``wall_friction_steel``, not the DEM walls'
    contact friction) and K (measured, or Jaky's 1 - sin(phi) as the library notes); ValueError
    when the library lacks them."""
    try:
        g = grain(name)
    except ValueError:
        raise ValueError(f"--depth needs a library grain (wall friction and K); {name!r} is a template file: "
                         "give --stress") from None
    mu = g.wall_friction_steel.value
    if mu is None:
        raise ValueError(f"--depth: the grain library has no wall friction against steel for {g.name}: give --stress")
    if g.lateral_pressure_ratio.value is not None:
        k, k_src = g.lateral_pressure_ratio.value, g.lateral_pressure_ratio.source
    elif g.internal_friction_deg.value is not None:
        phi = g.internal_friction_deg.value
        k, k_src = 1 - math.sin(math.radians(phi)), f"Jaky 1 - sin({phi:g} deg): {g.internal_friction_deg.source}"
    else:
        raise ValueError(f"--depth: the grain library has no lateral pressure ratio K nor angle of internal friction "
                         f"for {g.name} (Janssen's stress needs one): give --stress")
    return float(mu), float(k), {"wall_friction": mu, "wall_friction_source": g.wall_friction_steel.source,
                                 "lateral_pressure_ratio": k, "lateral_pressure_ratio_source": k_src}


def _pour_material(args, name):
    """The grow fill's library material plus the damping of the library's restitution
    (grain-grain, and grain-wall where sourced; else the grain-grain value)."""
    mat, used = _grain_material(args, name)
    try:
        g = grain(name)
    except ValueError:
        return mat, used, None
    e_pp, e_pw = g.restitution_pp.value, g.restitution_pw.value
    if e_pp is None:
        return mat, used, None
    used["restitution_pp"] = {"value": e_pp, "source": g.restitution_pp.source}
    if e_pw is not None:
        used["restitution_pw"] = {"value": e_pw, "source": g.restitution_pw.source}
    mat = replace(mat, damping_ratio=float(damping_ratio_for_restitution(e_pp)),
                  wall_damping_ratio=float(damping_ratio_for_restitution(e_pw if e_pw is not None else e_pp)))
    return mat, used, float(e_pp)


def _pour(args, fill, template, container) -> int:
    """--fill rain|spout, then the load of --depth or --stress (several stresses: each from a copy
    of the same poured state)."""
    t0, c0 = time.perf_counter(), time.process_time()
    with _fill_options_named():
        check_fill_options(fill, container, template)
    janssen = _janssen_inputs(template.name) if args.depth is not None else None
    material, used, e_pp = _pour_material(args, template.name)
    phi_count = _grain_porosity(args, template.name)
    if janssen is not None:
        est = janssen_stress(args.depth, bulk_density_kg_m3=material.density_kg_m3 * (1 - phi_count),
                             diameter_m=args.bin_diameter, wall_friction=janssen[0], lateral_ratio=janssen[1])
        if est > MAX_STRESS_PA:
            raise ValueError(f"--depth {args.depth:g} m of a {args.bin_diameter:g} m bin: Janssen's stress there, "
                             f"about {est / 1e3:.0f} kPa at the grain's loose-fill porosity {phi_count:.3f}, is "
                             f"beyond the {MAX_STRESS_PA / 1e3:g} kPa a load takes")
    n = args.n_grains if args.n_grains is not None else int((1 - phi_count) * container.volume_m3 / template.volume_m3)
    if n < 1:
        raise ValueError(f"no grain of {template.volume_m3:.3g} m^3 fits the container")
    pr = progress_printer(quiet=args.quiet)
    max_steps = args.max_steps                       # None: the pour's own rest budget (0.5 s)
    cb = lambda sim, f: pr(fill.method, _Progress(sim), None)
    sim, record = pour_grains(container, template, material=material, fill=fill, n_grains=n, rng=args.seed,
                              tol=args.tol, max_steps=max_steps, progress=cb, restitution=e_pp, porosity=phi_count)
    outs = _stress_outputs(args)
    poured = copy.deepcopy(sim) if len(outs) > 1 else None
    rc = 0
    for k, (stress, out) in enumerate(outs):
        bed = sim if poured is None else (poured if k == len(outs) - 1 else copy.deepcopy(poured))
        rc = max(rc, _load_and_write(args, out, bed, stress, janssen=janssen, fill=fill, template=template,
                                     container=container, material=material, used=used, record=record, n=n,
                                     max_steps=max_steps, pr=pr, t0=t0, c0=c0))
    return rc


def _load_and_write(args, out, sim, stress, *, janssen, fill, template, container, material, used, record, n,
                    max_steps, pr, t0, c0) -> int:
    """Load one poured bed to ``stress`` (or Janssen's at --depth), write it to ``out``, print its
    lines; the exit status."""
    s = {"n_grains": n, "n_spheres": sim.n, "template": template.name, "template_source": template.source,
         "spheres_per_grain": template.n, "grain_volume_m3": template.volume_m3, "fill": record}
    converged = record["converged"]
    if janssen is not None or (stress is not None and stress > 0):
        before = poured_bed_summary(sim, template, container, record)
        load = {"porosity_before_load": before["porosity_network_region"]}
        if janssen is not None:
            mu, k, load_src = janssen
            rho_b = material.density_kg_m3 * (1 - before["porosity_network_region"])
            stress = janssen_stress(args.depth, bulk_density_kg_m3=rho_b, diameter_m=args.bin_diameter,
                                    wall_friction=mu, lateral_ratio=k)
            load.update(depth_m=args.depth, bin_diameter_m=args.bin_diameter, bin_height_m=args.bin_height,
                        bulk_density_kg_m3=rho_b, janssen=load_src)
        if stress > 0:
            tl, cl = time.perf_counter(), time.process_time()
            load.update(load_bed(sim, container, stress, tol=args.tol,
                                 max_steps=rest_steps(sim.dt) if max_steps is None else max_steps,
                                 callback=lambda sim, f: pr("load", _Progress(sim), None)))
            load.update(wall_time_s=time.perf_counter() - tl, cpu_time_s=time.process_time() - cl)
            converged = converged and load["converged"]
        else:
            load.update(target_pa=0.0, converged=True)
        s["load"] = load
    elif stress is not None:
        s["load"] = {"target_pa": 0.0, "converged": True}
    s.update(poured_bed_summary(sim, template, container, record))
    s.update(steps=sim.steps, simulated_time_s=sim.time_s, dt_s=sim.dt, mass_scale=fill.mass_scale,
             wall_time_s=time.perf_counter() - t0, cpu_time_s=time.process_time() - c0,
             particle_steps=record["particle_steps"] + s.get("load", {}).get("steps", 0) * sim.n,
             material={k: getattr(material, k) for k in material.__dataclass_fields__},
             engine="dem.clumps (numba: the sphere step's kernels and a rigid-body update)",
             scene=args.scene, seed=args.seed, container=container.to_dict(), material_from_library=used,
             converged=bool(converged))
    if args.stress is not None and len(args.stress) > 1:
        s["bed_set"] = {"stresses_pa": [float(v) for v in args.stress],
                        "note": "one pour; each stress loaded from a copy of the same poured state; "
                                "wall and CPU times count the pour and every load before this one"}
    s["particle_steps_per_cpu_s"] = s["particle_steps"] / max(s["cpu_time_s"], 1e-9)
    write_grain_packing(out, sim.sphere_centers(), sim.radii.copy(), sim.gid.copy(),
                        {"centers": sim.X.copy(), "quaternions": sim.q.copy(), "volume_m3": sim.volume_m3.copy(),
                         "template": [template.name] * sim.n_grains}, s)
    print(f"{n} grains of {template.n} spheres ({sim.n} spheres), {fill.method} from {fill.drop_height_m:g} m at "
          f"{record['rate_kg_s']:.3g} kg/s -> {out} (+ {grains_path(out).name}, {summary_path(out).name})")
    print(f"porosity (union of spheres): network's sample region {s['porosity_network_region']:.4f} +- "
          f"{s['porosity_network_region_error']:.4f}; orientation order S {_num(s['orientation_order_S'], 3)}"
          + (f"; angle of repose {_num(s['angle_of_repose']['angle_deg'], 1)} deg" if "angle_of_repose" in s else "")
          + f"; {sim.steps} steps, wall {s['wall_time_s']:.1f} s")
    if "load" in s and s["load"].get("target_pa"):
        ld = s["load"]
        print(f"load: lid stress {ld['lid_stress_pa']:.4g} Pa (target {ld['target_pa']:.4g} Pa), porosity "
              f"{ld['porosity_before_load']:.4f} -> {s['porosity_network_region']:.4f}")
    if not converged:
        what = "fill" if not record["converged"] else "load"
        st = record["rest"] if what == "fill" else s["load"]
        print(f"error: not at rest: the {what} stopped at its step limit ({st['steps']} steps, unbalanced force "
              f"ratio {st['ratio']:.3g} > tol {args.tol:.3g}); written with \"converged\": false (give --max-steps)",
              file=sys.stderr)
        return EXIT_FAILED
    return 0


def _pack(args) -> int:
    check_seed(args.seed)
    if args.max_steps is not None and args.max_steps < 1:
        raise ValueError(f"--max-steps must be >= 1, got {args.max_steps}")
    check_counts(args)
    ms = args.mass_scale
    if ms is not None and not (math.isfinite(ms) and ms >= 1):
        raise ValueError(f"--mass-scale {ms:g}: must be finite and >= 1 (1: real masses)")
    fill = _fill_options(args)
    _check_outputs(args)
    if args.porosity is not None:       # a porosity no bed has: refused before any packing
        check_physical_porosity(args.porosity)
    if args.grain is not None:
        return _pack_grains(args, fill)
    if args.mass_scale is None:
        args.mass_scale = 100.0
    material = _material(args)
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


def _num(v, digits=2) -> str:
    return "n/a" if v is None else f"{v:.{digits}f}"


def main(argv=None) -> int:
    return run_main(_parser(), _pack, argv)


if __name__ == "__main__":
    raise SystemExit(main())
