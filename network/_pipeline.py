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

from ._conductance import MU_AIR_PA_S, RHO_AIR_KG_M3, throat_conductance
from ._empirical import (asabe_d272_gradient, darcy_permeability, ergun_gradient,
                         kozeny_carman_gradient)
from ._flow import solve_fixed_pressure
from ._io import Packing
from ._merge import merge_pores
from ._porosity import region_porosity
from ._sample import (AXES, Region, core_permeability, default_region, prune_disconnected,
                      select_sample)
from ._tessellation import Tessellation, tessellate, tie_groups

__all__ = ["FlowResult", "solve_network", "DEFAULT_VELOCITY_M_S", "DEFAULT_DEPTH_M"]

log = logging.getLogger(__name__)

#: Superficial air velocity of the thesis's low-flow case, m/s (m³ s⁻¹ m⁻²).
DEFAULT_VELOCITY_M_S = 0.013
#: Bed depth of the thesis's comparison, m.
DEFAULT_DEPTH_M = 0.25


@dataclasses.dataclass(frozen=True)
class FlowResult:
    """Network-model result along one axis (all SI). See :meth:`summary` for the JSON keys.

    Per-pore arrays (``pressure_pa`` in Pa for the flow-imposed problem, ``pore_xyz`` in m) are
    indexed like ``pore_ids``; per-throat arrays (``throat_flow_m3_s``, ``throat_conductance``,
    ``conns`` in local pore indices) like ``throat_ids`` (tessellation throats). When
    tetrahedra were joined into pore bodies, ``pore_groups`` (Np,) gives every tetrahedron's
    body and ``pore_ids`` are body ids; otherwise it is None and ``pore_ids`` are tetrahedra.
    """

    axis: str
    conductance_model: str
    policy: str
    viscosity_pa_s: float
    velocity_m_s: float
    depth_m: float
    region_lo: tuple
    region_hi: tuple
    region_radius: float | None
    n_pores: int
    n_throats: int
    n_inlet: int
    n_outlet: int
    n_dropped: int
    length_m: float
    area_m2: float
    flow_m3_s: float
    permeability_m2: float
    mean_diameter_m: float
    sauter_diameter_m: float
    porosity: float
    porosity_std: float
    solver: dict
    check: dict
    qstar_stats: dict
    timings_s: dict
    pressure_pa: np.ndarray = dataclasses.field(repr=False)
    throat_flow_m3_s: np.ndarray = dataclasses.field(repr=False)
    throat_conductance: np.ndarray = dataclasses.field(repr=False)
    pore_ids: np.ndarray = dataclasses.field(repr=False)
    throat_ids: np.ndarray = dataclasses.field(repr=False)
    conns: np.ndarray = dataclasses.field(repr=False)
    pore_xyz: np.ndarray = dataclasses.field(repr=False)
    pore_groups: np.ndarray | None = dataclasses.field(default=None, repr=False)
    #: k of the sample's core, ``core_margin_m`` in from every face (None: cylinder sample
    #: or a core too small), m²; see :func:`network._sample.core_permeability`.
    permeability_core_m2: float | None = None
    core_margin_m: float | None = None

    @property
    def k_over_d2(self) -> float:
        """k / d32² (Sauter mean diameter), dimensionless."""
        return self.permeability_m2 / self.sauter_diameter_m**2

    @property
    def pressure_gradient_pa_per_m(self) -> float:
        return self.viscosity_pa_s * self.velocity_m_s / self.permeability_m2

    @property
    def pressure_drop_pa(self) -> float:
        return self.pressure_gradient_pa_per_m * self.depth_m

    def comparisons(self) -> dict:
        """Empirical pressure gradients (Pa/m) and drops over ``depth_m`` (Pa) at the same v."""
        v, e, d = self.velocity_m_s, self.porosity, self.sauter_diameter_m
        out = {}
        for name, grad in (
            ("ergun", ergun_gradient(v, porosity=e, diameter_m=d, viscosity_pa_s=self.viscosity_pa_s,
                                     density_kg_m3=RHO_AIR_KG_M3)),
            ("kozeny_carman", kozeny_carman_gradient(v, porosity=e, diameter_m=d,
                                                     viscosity_pa_s=self.viscosity_pa_s)),
            ("asabe_d272", asabe_d272_gradient(v)),
        ):
            out[name] = {"pressure_gradient_pa_per_m": float(grad),
                         "pressure_drop_pa": float(grad * self.depth_m)}
        return out

    def summary(self) -> dict:
        """Every scalar as a JSON-ready dict (keys named in issue 4, item 7)."""
        return {
            "axis": self.axis,
            "conductance_model": self.conductance_model,
            "policy": self.policy,
            "permeability_m2": self.permeability_m2,
            "permeability_core_m2": self.permeability_core_m2,
            "permeability_core_note": (
                "Darcy's law in the sample's core, core_margin_m in from every face, free of "
                "the sample's boundary layer (cut conduits on the lateral faces, inlet/outlet "
                "pores that are not a plane), which lowers permeability_m2 by a term falling "
                "as 1/H; null for cylindrical samples or a core narrower than 5 mean "
                "diameters"),
            "core_margin_m": self.core_margin_m,
            "k_over_d2": self.k_over_d2,
            "k_over_d2_note": "d = Sauter mean diameter d32 = 2 sum(r^3)/sum(r^2) (also used in "
                              "Ergun and Kozeny-Carman)",
            "pressure_gradient_pa_per_m": self.pressure_gradient_pa_per_m,
            "pressure_drop_pa": self.pressure_drop_pa,
            "velocity_m_s": self.velocity_m_s,
            "depth_m": self.depth_m,
            "viscosity_pa_s": self.viscosity_pa_s,
            "flow_m3_s": self.flow_m3_s,
            "flow_m3_s_note": "total flow for 1 Pa across the sample",
            "porosity": self.porosity,
            "porosity_std": self.porosity_std,
            "mean_diameter_m": self.mean_diameter_m,
            "sauter_diameter_m": self.sauter_diameter_m,
            "n_pores": self.n_pores,
            "n_throats": self.n_throats,
            "n_inlet_pores": self.n_inlet,
            "n_outlet_pores": self.n_outlet,
            "n_dropped_pores": self.n_dropped,
            "sample_length_m": self.length_m,
            "sample_area_m2": self.area_m2,
            "sample_lo_m": list(self.region_lo),
            "sample_hi_m": list(self.region_hi),
            "sample_radius_m": self.region_radius,
            "solver": self.solver,
            "mass_balance": self.check,
            "qstar": self.qstar_stats,
            "comparisons": self.comparisons(),
            "seconds": self.timings_s,
        }


def solve_network(packing: Packing, *, axis="z", region: Region | None = None,
                  margin: float | None = None, cylinder: bool = False,
                  conductance_model: str = "conduit", policy: str = "table-only",
                  viscosity_pa_s: float = MU_AIR_PA_S,
                  velocity_m_s: float = DEFAULT_VELOCITY_M_S, depth_m: float = DEFAULT_DEPTH_M,
                  rtol: float = 1e-3, db=None, workers: int = 1, progress: bool = False,
                  tessellation: Tessellation | None = None, solver: Callable | None = None,
                  porosity_points: int = 200_000, conductance: Callable | None = None,
                  trace_memory: bool = False, merge_ties: bool = True,
                  porosity: tuple | None = None, container: dict | None = None) -> FlowResult:
    """Permeability and pressure drop of a packing by the Delaunay network model.

    Parameters
    ----------
    packing : Packing
        Centres and radii, m.
    axis : {'x', 'y', 'z'}
        Flow direction (default 'z').
    region : Region, optional
        Sample box/cylinder; default :func:`network._sample.default_region` with ``margin``.
    margin : float, optional, m
        Wall margin of the default region (default 1.5 mean diameters).
    cylinder : bool
        Use the inscribed cylinder of the default box.
    container : dict, optional
        The packing's container (:func:`network.read_container`), for the default region.
    conductance_model : {'conduit', 'thesis'}
        Throat conductance model (default 'conduit', :mod:`network._conduit`; 'thesis' is
        Eq. 3.41 with L = 2r̄, kept to reproduce the thesis).
    policy : {'shape-factor', 'table-only', 'table+fe', 'fe-only'}
        Q* source (see :mod:`network._conductance`); default 'table-only' (the table, the
        shape-factor estimate where it cannot answer, never FE).
    viscosity_pa_s, velocity_m_s, depth_m : float
        μ (1.932e-5 Pa·s), superficial velocity (0.013 m/s), bed depth (0.25 m).
    rtol, db, workers, progress
        Passed to the Q* lookup.
    tessellation : Tessellation, optional
        Reuse a tessellation of ``packing`` (e.g. for the three axes).
    solver : callable, optional
        ``solver(A, b) -> x`` instead of pyamg (tests pass ``spsolve``).
    porosity_points : int
        Monte-Carlo points for the porosity (0 skips it: NaN).
    conductance : callable, optional
        ``conductance(tessellation, throat_ids) -> g`` overriding model and policy (tests).
    trace_memory : bool
        Record the peak traced memory of each stage (slower; used by the benchmark).
    porosity : (float, float), optional
        Precomputed (porosity, standard error) of the region (e.g. from another axis).
    merge_ties : bool
        Join exactly co-spherical tetrahedra (and slivers) into one pore body
        (:func:`network.tie_groups`) so lattices do not depend on Qhull's tie-breaking
        (default True; random packings have no exact ties and are unchanged).

    Returns
    -------
    FlowResult
    """
    if axis not in AXES:
        raise ValueError(f"axis must be one of 'x', 'y', 'z', got {axis!r}")
    for name, val in (("viscosity", viscosity_pa_s), ("velocity", velocity_m_s),
                      ("depth", depth_m)):
        if not (np.isfinite(val) and val > 0):
            raise ValueError(f"{name} must be > 0, got {val!r}")
    ax = AXES[axis]
    times: dict = {}
    peaks: dict = {}

    def stage(name):
        return _Stage(name, times, peaks, trace_memory)

    with stage("tessellate"):
        tess = tessellate(packing) if tessellation is None else tessellation
    with stage("sample"):
        reg = (default_region(packing, margin=margin, cylinder=cylinder, container=container,
                              axis=axis) if region is None else region)
        labels, model_opts = None, {}
        if conductance is None and conductance_model == "conduit" and merge_ties:
            # the conduit model's pore bodies (near-co-spherical groups, slivers) are
            # contracted here, so its near-infinite internal conductances never reach the solver
            merge = merge_pores(tess)
            labels = np.asarray(merge.labels)
            model_opts = {"merge": merge}
        if labels is None and merge_ties:
            labels, n_groups = tie_groups(tess)
            if n_groups == tess.n_pores:
                labels = None
        sample = select_sample(tess, reg, axis=axis, groups=labels)
    with stage("conductance"):
        qstats: dict = {}
        if conductance is not None:
            g = np.asarray(conductance(tess, sample.throats), dtype=float)
        else:
            g, qres = throat_conductance(tess, sample.throats, model=conductance_model,
                                         policy=policy, viscosity_pa_s=viscosity_pa_s, rtol=rtol,
                                         db=db, workers=workers, progress=progress,
                                         **model_opts)
            if qres is not None and hasattr(qres, "stats"):
                qstats = _jsonable(qres.stats)
            elif isinstance(qres, dict):
                qstats = _jsonable(qres)
    with stage("prune"):
        sample, g = prune_disconnected(sample, tess, g)
    with stage("solve"):
        p, info, check = solve_fixed_pressure(sample.n_pores, sample.conns, g, sample.inlet,
                                              sample.outlet, p_in=1.0, p_out=0.0, solver=solver)
    times["assemble"] = info.assemble_s
    times["solve"] -= info.assemble_s
    if not check["ok"]:
        log.warning("mass balance check failed: %s", {k: v for k, v in check.items()
                                                       if k != "throat_flow"})
    with stage("porosity"):
        if porosity is not None:
            eps, eps_err = map(float, porosity)
        elif porosity_points:
            eps, eps_err = region_porosity(packing, reg, ax, n_points=porosity_points)
        else:
            eps, eps_err = float("nan"), float("nan")
    q1 = check["q_in"]
    k = darcy_permeability(q1, 1.0, sample.length_m, sample.area_m2,
                           viscosity_pa_s=viscosity_pa_s)
    # pressures and flows of the flow-imposed problem (thesis BC): Q = v A
    scale = velocity_m_s * sample.area_m2 / q1
    r = packing.radii
    d32 = float(2 * np.sum(r**3) / np.sum(r**2))
    times["total"] = float(sum(v for kk, v in times.items()))
    if trace_memory:
        times["peak_memory_mb"] = peaks
    solver_info = {"method": info.method, "iterations": info.iterations, "n_unknowns":
                   int(sample.n_pores - sample.inlet.size - sample.outlet.size),
                   "converged": info.converged, "residual": info.residual,
                   "setup_s": info.setup_s, "solve_s": info.solve_s}
    chk = {k2: v for k2, v in check.items() if k2 != "throat_flow"}
    k_core, core_margin = _core_estimate(sample, g, p, reg, packing.mean_diameter,
                                         viscosity_pa_s)
    return FlowResult(
        axis=axis, conductance_model=conductance_model if conductance is None else "custom",
        policy=policy if conductance is None else "custom", viscosity_pa_s=viscosity_pa_s,
        velocity_m_s=velocity_m_s, depth_m=depth_m, region_lo=tuple(map(float, reg.lo)),
        region_hi=tuple(map(float, reg.hi)), region_radius=reg.radius,
        n_pores=sample.n_pores, n_throats=sample.n_throats, n_inlet=int(sample.inlet.size),
        n_outlet=int(sample.outlet.size), n_dropped=sample.n_dropped, length_m=sample.length_m,
        area_m2=sample.area_m2, flow_m3_s=q1, permeability_m2=k,
        mean_diameter_m=packing.mean_diameter, sauter_diameter_m=d32, porosity=eps,
        porosity_std=eps_err, solver=solver_info, check=chk, qstar_stats=qstats,
        timings_s=times, pressure_pa=p * scale, throat_flow_m3_s=check["throat_flow"] * scale,
        throat_conductance=g, pore_ids=sample.pores, throat_ids=sample.throats,
        conns=sample.conns, pore_xyz=sample.pore_xyz, pore_groups=sample.groups,
        permeability_core_m2=k_core, core_margin_m=core_margin)


#: Core margin of :func:`_core_estimate`, in mean sphere diameters.
CORE_MARGIN_DIAMETERS = 2.0
#: Narrowest core (mean diameters, every axis) for which it is reported.
CORE_MIN_DIAMETERS = 5.0


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


def _jsonable(d):
    """Copy of a stats dict with numpy scalars turned into Python numbers."""
    out = {}
    for k, v in dict(d).items():
        if isinstance(v, dict):
            out[str(k)] = _jsonable(v)
        elif isinstance(v, (np.integer,)):
            out[str(k)] = int(v)
        elif isinstance(v, (np.floating,)):
            out[str(k)] = float(v)
        elif isinstance(v, (str, int, float, bool)) or v is None:
            out[str(k)] = v
        elif isinstance(v, np.ndarray):
            if v.size <= 8:
                out[str(k)] = v.tolist()
            # long per-throat arrays are not summary material: left out
        elif isinstance(v, (list, tuple)):
            out[str(k)] = [x.item() if hasattr(x, "item") else x for x in v]
        elif dataclasses.is_dataclass(v):   # e.g. the conduit's PoreMerge: its scalar fields
            out[str(k)] = _jsonable({f.name: getattr(v, f.name) for f in dataclasses.fields(v)})
        else:
            out[str(k)] = str(v)
    return out
