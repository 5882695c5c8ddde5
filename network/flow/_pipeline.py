r"""From a packing to permeability and pressure drop: the network model end to end.

Stages (each timed): tessellate → select the sample (region, inlet, outlet) → Q* and
conductances of the sample's throats only → prune pores not joining inlet and outlet →
assemble, condense, solve (pyamg SA-PCG), verify → Darcy permeability and comparisons.

The thesis imposes the total inlet flow :math:`Q = v A` (Appendix G). The network is linear, so
we solve once with :math:`\Delta P = 1` Pa between inlet and outlet pores, obtaining
:math:`Q_1`, and scale: the pressures of the flow-imposed problem are :math:`p\,vA/Q_1`. Then

.. math:: k = \frac{\mu Q_1 H}{A \cdot 1\,\mathrm{Pa}}, \qquad
          \frac{\Delta P}{L} = \frac{\mu v}{k}, \qquad \Delta P_\mathrm{bed} = \frac{\mu v}{k} D .
"""

from __future__ import annotations

import dataclasses
import logging
import time
import tracemalloc
from typing import Callable

import numpy as np

from .._deferred import beside
from ..conductance import (KERNEL_MIN_THROATS, conduit_law, has_grid,
                           load_conduit_kernel, throat_conductance)
from ..packing import Packing
from ..pores import (Region, Tessellation, axis_index, default_region, merge_pores,
                     prune_disconnected, region_porosity, select_sample, tessellate, tie_groups)
from ._darcy import core_permeability, darcy_permeability
from ._amg import import_pyamg
from ._inertial import solve_inertial
from ._linear import solve_fixed_pressure
from ._options import (DEFAULT_DEPTH_M, DEFAULT_VELOCITY_M_S, ConductanceOptions, FlowOptions,
                       SampleOptions)
from ._result import FlowResult

__all__ = ["solve_network", "solve_axes", "DEFAULT_VELOCITY_M_S", "DEFAULT_DEPTH_M",
           "CORE_MARGIN_DIAMETERS", "CORE_MIN_DIAMETERS", "INERTIAL_LAW", "INSET_DIAMETERS",
           "INSET_MIN_DIAMETERS"]

log = logging.getLogger(__name__)


#: Name of the per-conduit inertial law in the JSON (``inertial_law``): the conduit window law
#: of :func:`network.conductance.conduit_law` (``docs/inertial-flow.md``).
INERTIAL_LAW = "window"


def solve_network(packing: Packing, *, axis="z", sample: SampleOptions | None = None,
                  conductance: ConductanceOptions | None = None, flow: FlowOptions | None = None,
                  tessellation: Tessellation | None = None, solver: Callable | None = None,
                  threads: int = 1, trace_memory: bool = False) -> FlowResult:
    """Permeability and pressure drop of a packing by the Delaunay network model.

    Parameters
    ----------
    packing : Packing
        Centres and radii, m.
    axis : {'x', 'y', 'z'}
        Flow direction (default 'z').
    sample : SampleOptions, optional
        Region, margins and porosity (default :class:`SampleOptions()`: the interior box 1.5
        mean diameters in from the packing's extent, 200 000 Monte-Carlo points).
    conductance : ConductanceOptions, optional
        Model, Q* policy and table (default: the conduit model, table-only).
    flow : FlowOptions, optional
        Air, velocity, bed depth and the inertial solve (default: the thesis's air at
        0.013 m/s over 0.25 m, Stokes only).
    tessellation : Tessellation, optional
        Reuse a tessellation of ``packing`` (e.g. for the three axes).
    solver : callable, optional
        ``solver(A, b) -> x`` instead of pyamg (tests pass ``spsolve``).
    threads : int
        Threads (default 1): the porosity runs beside the tessellation (Qhull releases the
        GIL) and the conduit conductances in blocks on ``threads`` threads; the result does
        not depend on it.
    trace_memory : bool
        Record the peak traced memory of each stage (slower; used by the benchmark).

    Returns
    -------
    FlowResult
    """
    # every option is checked before any work: the option groups check their own values when
    # made (a bad policy is refused before the tessellation), the rest here
    s_opt = SampleOptions() if sample is None else sample
    c_opt = ConductanceOptions() if conductance is None else conductance
    f_opt = FlowOptions() if flow is None else flow
    for name, value, kind in (("sample", s_opt, SampleOptions),
                              ("conductance", c_opt, ConductanceOptions),
                              ("flow", f_opt, FlowOptions)):
        if not isinstance(value, kind):
            raise TypeError(f"{name} must be a {kind.__name__}, got {type(value).__name__}")
    region, margin, cylinder = s_opt.region, s_opt.margin_m, s_opt.cylinder
    container, core_margin_m = s_opt.container, s_opt.core_margin_m
    porosity_points, porosity = s_opt.porosity_points, s_opt.porosity
    conductance_model, policy, rtol, db = c_opt.model, c_opt.policy, c_opt.rtol, c_opt.db
    workers, progress, merge_ties = c_opt.workers, c_opt.progress, c_opt.merge_ties
    model_options, qstar_fn, conductance = c_opt.model_options, c_opt.qstar_fn, c_opt.function
    viscosity_pa_s, velocity_m_s, depth_m = f_opt.viscosity_pa_s, f_opt.velocity_m_s, f_opt.depth_m
    inertia, density_kg_m3 = f_opt.inertia, f_opt.density_kg_m3
    curve_u, inertial_workers = list(f_opt.curve_velocities_m_s), f_opt.inertial_workers
    ax = axis_index(axis)
    axis = "xyz"[ax]
    if inertia and (conductance is not None or conductance_model != "conduit"):
        raise ValueError("inertia needs the conduit model (its window and body areas); "
                         f"got {conductance_model if conductance is None else 'custom'}")
    times, peaks = {}, {}

    def stage(name):
        return _Stage(name, times, peaks, trace_memory)

    threads = int(threads)
    if threads < 1:
        raise ValueError(f"threads must be >= 1, got {threads}")
    reg = (default_region(packing, margin=margin, cylinder=cylinder, container=container,
                          axis=axis) if region is None else region)
    eps_job = None
    if threads > 1:
        # work that needs no tessellation, on a second core while gmsh or Qhull (which release
        # the GIL) runs: the Q* table's load (and the compiled conduit loop's for a large
        # packing), pyamg's import, the porosity; the thread ends with its job
        own = conductance is None
        eps_job = beside(_beside_tessellation, packing, reg, ax,
                         porosity_points if porosity is None else 0,
                         db if own and policy != "shape-factor" else False,
                         own and conductance_model == "conduit" and policy == "table-only"
                         and qstar_fn is None and 10 * packing.n >= KERNEL_MIN_THROATS)
    with stage("tessellate"):
        tess = tessellate(packing, threads=threads) if tessellation is None else tessellation
    with stage("sample"):
        labels, model_opts = None, dict(model_options or {})
        if conductance is None and conductance_model == "conduit":
            model_opts.setdefault("threads", threads)
        if conductance is None and conductance_model == "conduit" and merge_ties:
            # the conduit model's pore bodies (near-co-spherical groups, slivers) are
            # contracted here, so its near-infinite internal conductances never reach the solver
            merge = merge_pores(tess)
            labels = np.asarray(merge.labels)
            model_opts["merge"] = merge
        if labels is None and merge_ties:
            labels, n_groups = tie_groups(tess)
            if n_groups == tess.n_pores:
                labels = None
        sample = select_sample(tess, reg, axis=axis, groups=labels)
    with stage("conductance"):
        qstats: dict = {}
        window_qstar = None                  # (Nt,) window Q* of the tessellation's throats
        if conductance is not None:
            g = np.asarray(conductance(tess, sample.throats), dtype=float)
        else:
            cres = throat_conductance(tess, sample.throats, model=conductance_model,
                                      policy=policy, viscosity_pa_s=viscosity_pa_s, rtol=rtol,
                                      db=db, workers=workers, progress=progress,
                                      qstar_fn=qstar_fn, **model_opts)
            g, qstats = cres.g, cres.stats
            window_qstar = np.full(tess.n_throats, np.nan)
            window_qstar[sample.throats] = cres.qstar
    throats_before = sample.throats
    with stage("prune"):
        sample, g = prune_disconnected(sample, tess, g)
    with stage("solve"):
        # one Gauss-Seidel sweep forward before and one backward after the coarse correction
        # (pyamg's default sweeps both ways twice): 38 CG iterations instead of 31 at 20 000
        # spheres but 0.22 instead of 0.26 s; with inertia the hierarchy then preconditions
        # the Newton steps too (one AMG setup instead of two)
        p, info, check = solve_fixed_pressure(sample.n_pores, sample.conns, g, sample.inlet,
                                              sample.outlet, p_in=1.0, p_out=0.0, solver=solver,
                                              smoother="forward-backward")
    inertial = None
    if inertia:
        with stage("inertial"):
            keep = np.searchsorted(throats_before, sample.throats)
            K, c_on = conduit_law(
                tess, sample.throats, cres.h_m[keep], internal=np.asarray(cres.internal)[keep],
                pore_xyz_m=sample.pore_xyz, conns=sample.conns,
                stokes_flow_m3_s=check["throat_flow"], axis=ax, density_kg_m3=density_kg_m3,
                viscosity_pa_s=viscosity_pa_s, threads=threads)
            us = [velocity_m_s] + curve_u
            pts = solve_inertial(sample.n_pores, sample.conns, g, K, sample.inlet,
                                 sample.outlet, np.asarray(us) * sample.area_m2,
                                 onset_scale=c_on, amg=info.amg,
                                 workers=inertial_workers, stokes=(p, check["q_in"]))
            inertial = {"density_kg_m3": density_kg_m3, "velocities_m_s": us, "points": pts,
                        "law": INERTIAL_LAW}
    times["assemble"] = info.assemble_s
    times["solve"] -= info.assemble_s
    if not check["ok"]:
        log.warning("mass balance check failed: %s", {k: v for k, v in check.items()
                                                       if k != "throat_flow"})
    with stage("porosity"):
        if porosity is not None:
            eps, eps_err = map(float, porosity)
        elif eps_job is not None and porosity_points:
            eps, eps_err = eps_job.result()
        elif porosity_points:
            eps, eps_err = region_porosity(packing, reg, ax, n_points=porosity_points)
        else:
            eps, eps_err = float("nan"), float("nan")
    q1 = check["q_in"]
    with stage("permeability"):
        k_whole = darcy_permeability(q1, 1.0, sample.length_m, sample.area_m2,
                                     viscosity_pa_s=viscosity_pa_s)
        k_inset = _inset_estimate(sample, g, p, reg, packing.grain_diameter, viscosity_pa_s,
                                  tess)
        k = k_whole if k_inset is None else k_inset
    eps_sample, eps_sample_err = eps, eps_err
    if k_inset is not None and porosity_points:   # k of the inset window: its porosity
        with stage("porosity"):
            eps, eps_err = region_porosity(packing, inset_window(reg, ax, packing.grain_diameter),
                                           ax, n_points=porosity_points)
    # pressures and flows of the flow-imposed problem (thesis BC): Q = v A
    scale = velocity_m_s * sample.area_m2 / q1
    d32 = packing.sauter_diameter
    times["total"] = float(sum(v for kk, v in times.items()))
    if trace_memory:
        times["peak_memory_mb"] = peaks
    solver_info = {"method": info.method, "iterations": info.iterations, "n_unknowns":
                   int(sample.n_pores - sample.inlet.size - sample.outlet.size),
                   "converged": info.converged, "residual": info.residual,
                   "setup_s": info.setup_s, "solve_s": info.solve_s}
    chk = {k2: v for k2, v in check.items() if k2 != "throat_flow"}
    if core_margin_m is None:
        k_core, core_margin = _core_estimate(sample, g, p, reg, packing.grain_diameter,
                                             viscosity_pa_s)
    else:
        core_margin = core_margin_m
        k_core = core_permeability(sample, g, p, margin_m=core_margin_m,
                                   viscosity_pa_s=viscosity_pa_s)
    return FlowResult(
        axis=axis, conductance_model=conductance_model if conductance is None else "custom",
        policy=policy if conductance is None else "custom", viscosity_pa_s=viscosity_pa_s,
        velocity_m_s=velocity_m_s, depth_m=depth_m, region_lo=tuple(map(float, reg.lo)),
        region_hi=tuple(map(float, reg.hi)), region_radius=reg.radius,
        n_pores=sample.n_pores, n_throats=sample.n_throats, n_inlet=int(sample.inlet.size),
        n_outlet=int(sample.outlet.size), n_dropped=sample.n_dropped, length_m=sample.length_m,
        area_m2=sample.area_m2, flow_m3_s=q1, permeability_m2=k,
        permeability_whole_m2=k_whole, sample_estimator="whole" if k_inset is None else "inset",
        mean_diameter_m=packing.mean_diameter, sauter_diameter_m=d32, porosity=eps,
        porosity_std=eps_err, porosity_sample=eps_sample, porosity_sample_std=eps_sample_err,
        solver=solver_info, check=chk, qstar_stats=qstats,
        timings_s=times, pressure_pa=p * scale, throat_flow_m3_s=check["throat_flow"] * scale,
        throat_conductance=g, pore_ids=sample.pores, throat_ids=sample.throats,
        conns=sample.conns, pore_xyz=sample.pore_xyz, pore_groups=sample.groups,
        permeability_core_m2=k_core, core_margin_m=core_margin, inertial=inertial,
        throat_qstar=None if window_qstar is None else window_qstar[sample.throats])


def _beside_tessellation(packing, reg, ax, porosity_points, db, kernel=False):
    """The Q* table loaded (``db``; False: none needed), the compiled conduit loop loaded
    (``kernel``), pyamg's modules imported, and the region's (porosity, standard error) when
    ``porosity_points`` (else None): what :func:`solve_network` runs beside the tessellation."""
    if db is not False and has_grid(db) and kernel:
        load_conduit_kernel(db)
    import_pyamg()
    return region_porosity(packing, reg, ax, n_points=porosity_points) if porosity_points else None


#: Core margin of :func:`_core_estimate`, in mean sphere diameters.
CORE_MARGIN_DIAMETERS = 2.0
#: Narrowest core (mean diameters, every axis) for which it is reported.
CORE_MIN_DIAMETERS = 5.0


#: Lateral and axial inset (grain diameters) of the boundary-free sample estimate, and the
#: narrowest inset window (diameters, both lateral directions) for which it is used.
INSET_DIAMETERS = (1.5, 1.0)
INSET_MIN_DIAMETERS = 4.0


def inset_window(region, axis: int, grain_diameter_m: float):
    """The inset window of a box sample, :data:`INSET_DIAMETERS` grain diameters in from its
    lateral faces and ends (the region whose permeability is ``permeability_m2`` when
    ``sample_estimator`` is 'inset'), or None: a cylinder, or a sample too narrow for it."""
    if region.radius is not None:
        return None
    d = float(grain_diameter_m)
    lat, end = INSET_DIAMETERS
    lo, hi = np.asarray(region.lo, float).copy(), np.asarray(region.hi, float).copy()
    width = hi - lo
    axis = int(axis)
    if np.any(np.delete(width, axis) - 2 * lat * d < INSET_MIN_DIAMETERS * d) \
            or width[axis] - 2 * end * d < INSET_MIN_DIAMETERS * d:
        return None
    inset = np.full(3, lat * d)
    inset[axis] = end * d
    return Region(lo + inset, hi - inset)


def _inset_estimate(sample, g, p, region, grain_diameter_m, viscosity_pa_s, tessellation):
    """k of the sample without its lateral boundary layer, or None (cylinder, too narrow).

    The conduits cut by the lateral faces leave a layer 1-2 grains thick that carries less
    flow, so mu Q H / (A dP) is low by about 1/width (random packing: -12 % at 6 grain
    diameters, -7 % at 8.2, -5.6 % at 10, -2.4 % at 17.7 against the same network made
    periodic, ``docs/sample-boundary.md``). Darcy's law in the window 1.5 diameters in from
    the lateral faces and 1 from the ends (:func:`core_permeability`) is unbiased there
    (1.00 +- 0.04 at 8.2 diameters, +- 0.01 at 10).
    """
    d = float(grain_diameter_m)
    lat, end = INSET_DIAMETERS
    width = np.asarray(region.hi, float) - np.asarray(region.lo, float)
    axis = int(sample.axis)
    lateral = np.delete(width, axis) - 2 * lat * d
    if region.radius is not None:
        log.info("cylindrical sample: permeability_m2 is the whole-sample value (no inset "
                 "window for cylinders)")
        return None
    if np.any(lateral < INSET_MIN_DIAMETERS * d) \
            or width[axis] - 2 * end * d < INSET_MIN_DIAMETERS * d:
        log.warning("sample %s grain diameters wide: too narrow for the boundary-free estimate "
                    "(needs %.0f); permeability_m2 is the whole-sample value, low by the cut "
                    "lateral conduits (random packing: -12 %% at 6, -7 %% at 8 diameters)",
                    np.round(np.delete(width, axis) / d, 1).tolist(),
                    INSET_MIN_DIAMETERS + 2 * lat)
        return None
    try:
        k = core_permeability(  # faces gathered only for the throats crossing a plane
            sample, g, p, margin_m=lat * d, axial_margin_m=end * d, viscosity_pa_s=viscosity_pa_s,
            faces=lambda rows: tessellation.packing.centers[
                tessellation.throat_vertices[sample.throats[rows]]])
    except ValueError as exc:
        log.warning("no boundary-free estimate (%s): permeability_m2 is the whole-sample value",
                    exc)
        return None
    return float(k) if np.isfinite(k) and k > 0 else None


def _core_estimate(sample, g, p, region, mean_diameter_m, viscosity_pa_s):
    """(k of the core, margin) of a box sample, or (None, None) when there is no such core."""
    if region.radius is not None:
        return None, None
    margin = CORE_MARGIN_DIAMETERS * float(mean_diameter_m)
    width = np.asarray(region.hi, float) - np.asarray(region.lo, float) - 2 * margin
    if np.any(width < CORE_MIN_DIAMETERS * float(mean_diameter_m)):
        # a small core averages over too few pores (on a BCC array 3 diameters wide: 11 %
        # low; from 5.7 diameters on within 1 %)
        return None, None
    try:
        k = core_permeability(sample, g, p, margin_m=margin, viscosity_pa_s=viscosity_pa_s)
    except ValueError as exc:
        log.info("no core permeability: %s", exc)
        return None, None
    return (float(k), margin) if np.isfinite(k) and k > 0 else (None, None)


class _Stage:
    """Context manager timing one stage (and its traced peak memory when asked)."""

    def __init__(self, name, times, peaks, trace):
        self.name, self.times, self.peaks, self.trace = name, times, peaks, trace

    def __enter__(self):
        log.info("stage %s ...", self.name)
        if self.trace:
            tracemalloc.start()
            tracemalloc.reset_peak()
        self.t0 = time.perf_counter()
        return self

    def __exit__(self, *exc):
        dt = time.perf_counter() - self.t0
        self.times[self.name] = self.times.get(self.name, 0.0) + dt
        if self.trace:
            self.peaks[self.name] = tracemalloc.get_traced_memory()[1] / 2**20
            tracemalloc.stop()
        log.info("stage %s done in %.2f s", self.name, dt)
        return False


def solve_axes(packing: Packing, regions: dict, *, sample: SampleOptions | None = None,
               tessellation: Tessellation | None = None, **options) -> list[FlowResult]:
    """:func:`solve_network` along several axes, sharing one tessellation and the porosity.

    Parameters
    ----------
    packing : Packing
    regions : dict
        ``{axis: Region}`` in solve order (e.g. from :func:`network.pores.sample_region`).
    sample : SampleOptions, optional
        Its ``region`` and ``porosity`` are set per axis.
    tessellation : Tessellation, optional
        Reused for every axis (made here once where several axes are solved).
    **options
        ``conductance``, ``flow``, ``solver``, ``threads``, ``trace_memory`` of
        :func:`solve_network`.

    Returns
    -------
    list of FlowResult
        One per axis; the porosity is measured once per distinct region.
    """
    sample = SampleOptions() if sample is None else sample
    if not regions:
        raise ValueError("no axis to solve")
    if len(regions) > 1 and tessellation is None:
        tessellation = tessellate(packing)      # one tessellation for every axis
    results, porosity_of = [], {}
    for axis, reg in regions.items():
        key = (tuple(reg.lo), tuple(reg.hi), reg.radius)
        res = solve_network(packing, axis=axis, sample=dataclasses.replace(
            sample, region=reg, porosity=porosity_of.get(key)), tessellation=tessellation,
            **options)
        porosity_of.setdefault(key, (res.porosity_sample, res.porosity_sample_std))
        results.append(res)
    return results
