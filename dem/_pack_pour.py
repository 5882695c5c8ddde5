"""The poured grain bed of ``python -m dem.pack``: ``--fill rain|spout`` and its load.

The fill's options checked against each other and named in every refusal (:func:`fill_options`),
the load's inputs (``--stress``, or ``--depth`` with ``--bin-diameter``: Janssen's stress from the
grain library's wall friction and lateral pressure ratio), the pour (:mod:`dem._pour`), each load
(:mod:`dem._load`) and the files written with their summary lines; several ``--stress`` values
make a bed set, each stress loaded from a copy of the same poured state and written to
``<stem>_<kPa>kPa.csv`` (:func:`stress_outputs`).
"""

from __future__ import annotations

import contextlib
import copy
import math
import sys
import time
from dataclasses import replace
from pathlib import Path

from ._cli import EXIT_FAILED, progress_printer
from ._io import summary_path
from ._clump_pack import grains_path, write_grain_packing
from ._contacts import damping_ratio_for_restitution
from ._load import MAX_STRESS_PA, janssen_stress, load_bed
from ._pack_inputs import Progress, fmt_num, grain_material, grain_porosity
from ._pile import poured_bed_summary
from ._pour import FillOptions, check_fill_options, pour_grains, rest_steps
from .grains import grain


def stress_outputs(args):
    """[(stress Pa or None, packing path)]: ``--out`` itself, or with several ``--stress`` values
    one ``<stem>_<kPa>kPa<suffix>`` per stress."""
    if args.stress is None or len(args.stress) == 1:
        return [(None if args.stress is None else args.stress[0], Path(args.out))]
    out = Path(args.out)
    return [(s, out.with_name(f"{out.stem}_{s / 1000:g}kPa{out.suffix}")) for s in args.stress]


_POUR_ONLY = (("--drop-height", "drop_height"), ("--rate", "rate"), ("--spout-diameter", "spout_diameter"),
              ("--depth", "depth"), ("--bin-diameter", "bin_diameter"), ("--bin-height", "bin_height"),
              ("--stress", "stress"), ("--no-freeze", "no_freeze"), ("--no-rolling", "no_rolling"))


def fill_options(args):
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
    mat, used = grain_material(args, name)
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


#: the rolling-friction model of the poured fills, as the companion JSON names it
ROLLING_MODEL = ("EDEM standard rolling friction (Ai et al. 2011 type A, directional constant torque): "
                 "T = -mu_r F_n R omega/|omega| per contact, R the touching sphere's radius, omega the grain's "
                 "spin; limited to the torque that stops the spin in a step (dem._contacts.rolling_torque)")


def _rolling_friction(args, name, material):
    """The material with the library's coefficients of rolling friction of grain ``name``
    (grain-grain, grain-wall; 0 where the library has none, and with ``--no-rolling``) and the
    companion JSON's record of them."""
    try:
        g = grain(name)
    except ValueError:
        g = None
    rec = {"on": False, "model": ROLLING_MODEL}
    vals = {}
    for key, field, attr in (("particle", "rolling_friction_pp", "rolling_friction"),
                             ("wall", "rolling_friction_pw", "wall_rolling_friction")):
        v = getattr(g, field) if g is not None else None
        if v is None:
            rec[key] = {"value": 0.0, "source": "none: a template file, not a library grain"}
        elif v.value is None:
            rec[key] = {"value": 0.0, "source": "none: the library has no value", "note": v.note}
        else:
            rec[key] = {"value": 0.0 if args.no_rolling else float(v.value), "library_value": float(v.value),
                        "source": v.source, "note": v.note}
        vals[attr] = rec[key]["value"]
    rec["on"] = any(x > 0 for x in vals.values())
    if args.no_rolling:
        rec["off_by"] = "--no-rolling"
    return replace(material, **vals), rec


def pour_and_load(args, fill, template, container) -> int:
    """--fill rain|spout, then the load of --depth or --stress (several stresses: each from a copy
    of the same poured state)."""
    t0, c0 = time.perf_counter(), time.process_time()
    with _fill_options_named():
        check_fill_options(fill, container, template)
    janssen = _janssen_inputs(template.name) if args.depth is not None else None
    material, used, e_pp = _pour_material(args, template.name)
    material, rolling = _rolling_friction(args, template.name, material)
    phi_count = grain_porosity(args, template.name)
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
    cb = lambda sim, f: pr(fill.method, Progress(sim), None)
    sim, record = pour_grains(container, template, material=material, fill=fill, n_grains=n, rng=args.seed,
                              tol=args.tol, max_steps=max_steps, progress=cb, restitution=e_pp, porosity=phi_count)
    outs = stress_outputs(args)
    poured = copy.deepcopy(sim) if len(outs) > 1 else None
    rc = 0
    for k, (stress, out) in enumerate(outs):
        bed = sim if poured is None else (poured if k == len(outs) - 1 else copy.deepcopy(poured))
        rc = max(rc, _load_and_write(args, out, bed, stress, janssen=janssen, fill=fill, template=template,
                                     container=container, material=material, used=used, record=record, n=n,
                                     max_steps=max_steps, pr=pr, t0=t0, c0=c0, rolling=rolling))
    return rc


def _load_and_write(args, out, sim, stress, *, janssen, fill, template, container, material, used, record, n,
                    max_steps, pr, t0, c0, rolling) -> int:
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
                                 callback=lambda sim, f: pr("load", Progress(sim), None)))
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
             rolling_friction=rolling, converged=bool(converged))
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
          f"{s['porosity_network_region_error']:.4f}; orientation order S {fmt_num(s['orientation_order_S'], 3)}"
          + (f"; angle of repose {fmt_num(s['angle_of_repose']['angle_deg'], 1)} deg" if "angle_of_repose" in s else "")
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
