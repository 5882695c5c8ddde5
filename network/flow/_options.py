"""The options of :func:`network.solve_network`, in three groups: the sample, the conductances,
the flow.

Each group is a frozen, keyword-only dataclass whose defaults are the command's; its values are
checked when it is made (``ValueError`` naming the field), so a bad option is refused before any
work. A changed copy comes from :func:`dataclasses.replace`.

>>> FlowOptions(velocity_m_s=0.1, inertia=True).curve_velocities_m_s
()
>>> ConductanceOptions(policy="exact")
Traceback (most recent call last):
...
ValueError: unknown Q* policy 'exact'; choose one of table-only, table+fe, fe-only, shape-factor
"""

from __future__ import annotations

import dataclasses
from typing import Callable

from .._air import MU_AIR_PA_S, RHO_AIR_KG_M3, check_density, check_positive, check_viscosity
from ..conductance import check_model, check_policy
from ..pores import Region

__all__ = ["ConductanceOptions", "FlowOptions", "SampleOptions", "DEFAULT_DEPTH_M",
           "DEFAULT_VELOCITY_M_S"]

#: Superficial air velocity of the thesis's low-flow case, m/s (m³ s⁻¹ m⁻²).
DEFAULT_VELOCITY_M_S = 0.013
#: Bed depth of the thesis's comparison, m.
DEFAULT_DEPTH_M = 0.25


def _count(name: str, value, least: int) -> int:
    """``value`` as an int >= ``least`` (a bool is not a count)."""
    if isinstance(value, bool) or int(value) != value or value < least:
        raise ValueError(f"{name} must be an integer >= {least}, got {value!r}")
    return int(value)


@dataclasses.dataclass(frozen=True, kw_only=True)
class SampleOptions:
    """Which part of the packing is the sample, and its porosity.

    Parameters
    ----------
    region : Region, optional
        Sample box or cylinder; default :func:`network.default_region` with ``margin_m``.
    margin_m : float, optional, m
        Wall margin of the default region (default 1.5 mean diameters), > 0.
    cylinder : bool
        Use the inscribed cylinder of the default box (default False).
    container : dict, optional
        The packing's container (:func:`network.read_container`), for the default region.
    core_margin_m : float, optional, m
        Margin of the core permeability: default 2 mean diameters, reported only when the
        core is 5 diameters wide; given (> 0), the core estimate is always made (and its
        failure raised), as the lattice validation cases need.
    porosity_points : int
        Monte-Carlo points for the porosity (default 200 000; 0 skips it: NaN, or ``porosity``
        as given). The porosity reported is that of the region ``permeability_m2`` is measured
        in: the inset window (:func:`network.flow.inset_window`) when the sample is wide enough
        for one, else the sample; the sample's is ``porosity_sample``.
    porosity : (float, float), optional
        Precomputed (porosity, standard error) of the sample region (e.g. from another axis).
    """

    region: Region | None = None
    margin_m: float | None = None
    cylinder: bool = False
    container: dict | None = None
    core_margin_m: float | None = None
    porosity_points: int = 200_000
    porosity: tuple | None = None

    def __post_init__(self):
        if self.margin_m is not None:
            object.__setattr__(self, "margin_m", check_positive("margin_m", self.margin_m))
        if self.core_margin_m is not None:
            object.__setattr__(self, "core_margin_m",
                               check_positive("core_margin_m", self.core_margin_m))
        object.__setattr__(self, "porosity_points",
                           _count("porosity_points", self.porosity_points, 0))
        if self.porosity is not None:
            eps, err = (float(v) for v in self.porosity)
            object.__setattr__(self, "porosity", (eps, err))


@dataclasses.dataclass(frozen=True, kw_only=True)
class ConductanceOptions:
    """How the throat conductances are obtained (:mod:`network.conductance`).

    Parameters
    ----------
    model : {'conduit', 'thesis'}
        Throat conductance model (default 'conduit'; 'thesis' is Eq. 3.41 with L = 2r̄, kept
        to reproduce the thesis).
    policy : {'shape-factor', 'table-only', 'table+fe', 'fe-only'}
        Q* source; default 'table-only' (the table, the shape-factor estimate where it cannot
        answer, never FE).
    rtol : float
        Q* relative tolerance of the FE policies (default 1e-3), > 0.
    db : path, optional
        Throat table (default: the cache's default database).
    workers : int
        Processes for FE solves (default 1), >= 1.
    progress : bool
        Progress bar for FE solves (default False).
    merge_ties : bool
        Join exactly co-spherical tetrahedra (and slivers) into one pore body
        (:func:`network.tie_groups`) so lattices do not depend on Qhull's tie-breaking
        (default True; random packings have no exact ties and are unchanged).
    model_options : dict, optional
        Options of the conduit model (e.g. ``{"n_sections": 8}``).
    qstar_fn : callable, optional
        ``qstar_fn(radii (N,3), sides (N,3)) -> (N,)`` Q* instead of the policy (validation
        cases with exact FE of lattice sections).
    function : callable, optional
        ``function(tessellation, throat_ids) -> g`` (m³ Pa⁻¹ s⁻¹) overriding model and policy
        (tests).
    """

    model: str = "conduit"
    policy: str = "table-only"
    rtol: float = 1e-3
    db: object = None
    workers: int = 1
    progress: bool = False
    merge_ties: bool = True
    model_options: dict | None = None
    qstar_fn: Callable | None = None
    function: Callable | None = None

    def __post_init__(self):
        if self.function is None:
            check_model(self.model)
            check_policy(self.policy)
        object.__setattr__(self, "rtol", check_positive("rtol", self.rtol))
        object.__setattr__(self, "workers", _count("workers", self.workers, 1))


@dataclasses.dataclass(frozen=True, kw_only=True)
class FlowOptions:
    """The air and the flow: viscosity, velocity, bed depth and the inertial solve.

    Parameters
    ----------
    viscosity_pa_s : float
        μ (default 1.932e-5 Pa s, the thesis's air), > 0.
    velocity_m_s : float
        Superficial velocity (default 0.013 m/s), > 0.
    depth_m : float
        Bed depth of the reported pressure drop (default 0.25 m), > 0.
    inertia : bool
        Also solve the nonlinear network with the conduit window law
        (:mod:`network.flow._inertial`, conduit model only) at ``velocity_m_s`` and at
        ``curve_velocities_m_s``; the result's ``inertial`` holds the points (default False:
        Stokes only).
    density_kg_m3 : float
        ρ of the inertial loss (default 1.20 kg/m³), > 0.
    curve_velocities_m_s : sequence of float
        More superficial velocities (m/s, > 0) for the resistance curve (default none).
    inertial_workers : int
        Processes for the nonlinear solves (``workers`` of :func:`network.flow.solve_inertial`:
        parallel continuation chains of at least 4 velocities each; default 1), >= 1.
    """

    viscosity_pa_s: float = MU_AIR_PA_S
    velocity_m_s: float = DEFAULT_VELOCITY_M_S
    depth_m: float = DEFAULT_DEPTH_M
    inertia: bool = False
    density_kg_m3: float = RHO_AIR_KG_M3
    curve_velocities_m_s: tuple = ()
    inertial_workers: int = 1

    def __post_init__(self):
        object.__setattr__(self, "viscosity_pa_s", check_viscosity(self.viscosity_pa_s))
        object.__setattr__(self, "velocity_m_s", check_positive("velocity_m_s",
                                                                 self.velocity_m_s))
        object.__setattr__(self, "depth_m", check_positive("depth_m", self.depth_m))
        object.__setattr__(self, "density_kg_m3", check_density(self.density_kg_m3))
        object.__setattr__(self, "curve_velocities_m_s", tuple(
            check_positive("velocity_m_s", u) for u in (self.curve_velocities_m_s or ())))
        object.__setattr__(self, "inertial_workers",
                           _count("inertial_workers", self.inertial_workers, 1))
