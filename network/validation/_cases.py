"""Validation cases run through the one pipeline: lattice arrays and random packings.

:func:`lattice_sample_permeability` and :func:`random_sample_permeability` build a packing whose
exact permeability is known (``_references``), run :func:`network.solve_network` on an interior
sample with viscosity 1 and 1 Pa across, and return k in units of the lattice constant (or
sphere diameter) squared. Measured accuracy: ``docs/conduit-model.md``.
"""

from __future__ import annotations

import math

import numpy as np

from ..flow import ConductanceOptions, FlowOptions, SampleOptions, solve_network
from ..packing import Packing, lattice_packing, periodic_copies, random_packing
from ..pores import Region, tessellate

__all__ = ["ESTIMATORS", "lattice_sample_permeability", "random_sample_permeability"]


#: How :func:`lattice_sample_permeability` turns a solved sample into k.
ESTIMATORS = ("core", "box")


def lattice_sample_permeability(kind: str, solid_fraction: float, *, model: str = "conduit",
                                policy: str = "fe-only", qstar_fn=None, n_cells: int = 7,
                                axis: int = 0, n_sections: int = 6, jitter: float = 0.0,
                                rng=None, offset: float = 0.137, estimator: str = "core",
                                db=None, rtol: float = 1e-3, workers: int = 1):
    r"""Permeability of a lattice sample through the network pipeline (validation helper).

    Builds an ``n_cells``³ array of lattice constant 1 (:func:`lattice_packing`), tessellates
    it, keeps the box :math:`[1 + o, n - 2 + o]^3` (``offset`` o keeps the box faces off the
    planes of pore centres), merges pore bodies (:func:`network.merge_pores`; for the thesis model
    only exact ties, ``network.tie_groups``), computes conductances with viscosity 1, solves
    with 1 Pa across and returns k in units of the lattice constant squared, with the sphere
    radius, to compare with :func:`lattice_permeability`. k is taken in
    the core of the sample, one lattice constant in from every face
    (:func:`core_permeability`, ``estimator='core'``, default), or over the whole box,
    :math:`k = Q H / (A \cdot 1)` (``'box'``; biased low by the boundary layer by a term
    falling as 1/H: BCC phi = 0.5 0.860 of exact at 7 cells, 0.890 at 10, core 0.933 at both).

    Parameters
    ----------
    kind, solid_fraction
        As :func:`lattice_packing`.
    model : {'conduit', 'thesis'}, keyword-only
    policy : str, keyword-only
        Q* policy (``network.throat_qstar``) when ``qstar_fn`` is None.
    qstar_fn : callable, keyword-only
        ``qstar_fn(radii, sides) -> Q*`` (r̄ units) instead of the policy.
    n_cells, axis, n_sections, jitter, rng, offset : keyword-only
        Box size (>= 7 for the core estimator on SC: its core must hold two pore planes),
        flow axis, conduit section intervals, centre jitter (units of the lattice constant)
        and its seed, region offset.
    estimator : {'core', 'box'}, keyword-only
        How k is read off the solved sample (see above).
    db, rtol, workers : keyword-only
        Q* table (default ``cache.default_db_path()``), FE tolerance and processes, as
        ``network.throat_qstar``.

    Returns
    -------
    k : float
        Permeability, (lattice constant)².
    radius : float
        Sphere radius, lattice constants.
    """
    _check_model_estimator(model, estimator)
    c, r = lattice_packing(kind, solid_fraction, n_cells=n_cells, lattice_constant_m=1.0,
                           jitter=jitter, rng=rng)
    tess = tessellate(Packing(c, r))
    region = Region(np.full(3, 1.0 + offset), np.full(3, n_cells - 2 + offset))
    k = _network_permeability(tess, region, model=model, policy=policy, qstar_fn=qstar_fn,
                              n_sections=n_sections, axis=axis, estimator=estimator,
                              margin=1.0, db=db, rtol=rtol, workers=workers)
    return k, float(r[0])


def _check_model_estimator(model, estimator):
    if model not in ("conduit", "thesis"):
        raise ValueError(f"model must be 'conduit' or 'thesis', got {model!r}")
    if estimator not in ESTIMATORS:
        raise ValueError(f"estimator must be one of {ESTIMATORS}, got {estimator!r}")


def _network_permeability(tess, region, *, model, policy, qstar_fn, n_sections, axis,
                          estimator, margin, db=None, rtol=1e-3, workers=1):
    """k of the sample ``region`` of ``tess`` with viscosity 1 and 1 Pa across (units²).

    The one pipeline (:func:`network.solve_network`) with viscosity 1, no porosity estimate,
    and the core read ``margin`` in from every face (``estimator='core'``).
    """
    sample = SampleOptions(region=region, porosity_points=0,
                           core_margin_m=float(margin) if estimator == "core" else None)
    conductance = ConductanceOptions(
        model=model, policy=policy, qstar_fn=qstar_fn, db=db, rtol=rtol, workers=workers,
        model_options={"n_sections": n_sections} if model == "conduit" else None)
    res = solve_network(tess.packing, tessellation=tess, axis=axis, sample=sample,
                        conductance=conductance, flow=FlowOptions(viscosity_pa_s=1.0))
    return res.permeability_core_m2 if estimator == "core" else res.permeability_whole_m2


#: Periodic copies per axis of the random validation packings (the sample is the middle
#: two periods, so every pore of it is away from the copies' outer faces).
_RANDOM_COPIES = 3


def random_sample_permeability(porosity: float, *, n_spheres: int = 800, rng=1,
                               model: str = "conduit", policy: str = "table-only",
                               qstar_fn=None, axis: int = 0, n_sections: int = 6,
                               estimator: str = "core", margin_diameters: float = 2.0,
                               db=None, rtol: float = 1e-3, workers: int = 1):
    r"""Permeability of a random monodisperse sphere packing through the network pipeline.

    The validation case for the LBM drag law of random packings
    (:func:`beetstra_permeability`): ``n_spheres`` spheres of diameter 1
    packed at random in a periodic cube (:func:`network.random_packing` with
    ``periodic=True``, overlaps relaxed below 0.2 % of the contact distance; at porosity 0.36,
    close to random close packing, 0.8 % is left), the cube copied 3 x 3 x 3, tessellated,
    and the middle two periods along every axis taken as the sample; k is read in its core
    ``margin_diameters`` in from every face (:func:`core_permeability`) or over the whole
    sample box. Measured spread between seeds at porosity 0.40, conduit model, table Q*:
    400 spheres 0.96-1.06 of the LBM law, 800 spheres 1.01-1.02, 2000 spheres 1.02-1.05
    (core); below about 800 spheres the period is short enough (< 9 diameters) to matter.

    Parameters
    ----------
    porosity : float
        Void fraction of the periodic cube, 0.36 <= porosity < 1.
    n_spheres : int, keyword-only
        Spheres in the periodic cube (default 800).
    rng : int or numpy.random.Generator, keyword-only
        Seed of the packing (default 1).
    model, policy, qstar_fn, axis, n_sections, estimator, db, rtol, workers : keyword-only
        As :func:`lattice_sample_permeability`.
    margin_diameters : float, keyword-only
        Core margin for ``estimator='core'`` (default 2 diameters).

    Returns
    -------
    k : float
        Permeability in units of the sphere diameter squared.
    """
    _check_model_estimator(model, estimator)
    eps = float(porosity)
    if not 0.36 <= eps < 1.0:
        raise ValueError(f"porosity must lie in [0.36, 1), got {porosity!r}")
    base = random_packing(int(n_spheres), diameter_range_m=(1.0, 1.0), solid_fraction=1 - eps,
                          periodic=True, rng=rng)
    side = (math.pi / 6.0 * int(n_spheres) / (1.0 - eps)) ** (1.0 / 3.0)
    n = _RANDOM_COPIES
    tess = tessellate(periodic_copies(base, side, n))
    region = Region(np.full(3, 0.5 * side), np.full(3, (n - 0.5) * side))
    return _network_permeability(tess, region, model=model, policy=policy, qstar_fn=qstar_fn,
                                 n_sections=n_sections, axis=axis, estimator=estimator,
                                 margin=float(margin_diameters), db=db, rtol=rtol,
                                 workers=workers)
