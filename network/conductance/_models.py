"""Throat conductances of a tessellation under a conductance model: the stage's one entry point.

``'conduit'`` (default of the pipeline): the resistance of each pore → window → pore conduit
integrated over cross-sections (:func:`conduit_conductance`, ``docs/conduit-model.md``).
``'thesis'``: thesis Eq. 3.41, the window's Q* over L = 2r̄ (:func:`thesis_conductance`).
Both return a :class:`ConductanceResult`.
"""

from __future__ import annotations

import numpy as np

from .._air import MU_AIR_PA_S, check_viscosity
from .._json import jsonable
from ._conduit import conduit_conductance
from ._qstar import check_policy, qstar_from_function, throat_qstar
from ._result import ConductanceResult
from ._thesis import thesis_conductance

__all__ = ["MODELS", "check_model", "throat_conductance"]

#: Conductance models.
MODELS = ("thesis", "conduit")


def check_model(model: str) -> str:
    """``model`` if it is one of :data:`MODELS`, else ValueError listing them."""
    if model not in MODELS:
        raise ValueError(f"unknown conductance model {model!r}; choose one of {', '.join(MODELS)}")
    return model


def throat_conductance(tessellation, throats_idx, *, model: str = "thesis",
                       policy: str = "table-only", viscosity_pa_s: float = MU_AIR_PA_S,
                       rtol: float = 1e-3, db=None, workers: int = 1, progress: bool = False,
                       qstar_fn=None, **model_options) -> ConductanceResult:
    """Conductance g (m³ Pa⁻¹ s⁻¹) of selected throats of a tessellation under a model.

    Parameters
    ----------
    tessellation : Tessellation
    throats_idx : (M,) array_like of int
        Throats to evaluate (only those the scene needs).
    model : {'thesis', 'conduit'}
    policy, rtol, db, workers, progress
        Q* policy and its options (:func:`throat_qstar`).
    viscosity_pa_s : float
        μ, Pa·s (default 1.932e-5).
    qstar_fn : callable, optional
        ``qstar_fn(radii (N,3), sides (N,3)) -> (N,)`` Q* in r̄ units instead of the policy
        (validation cases with exact FE of lattice sections, tests).
    **model_options
        Conduit model only: ``merge`` (the pore bodies already used to contract the network),
        ``n_sections``, ``sections``, ...

    Returns
    -------
    ConductanceResult
    """
    check_model(model)
    check_policy(policy)
    mu = check_viscosity(viscosity_pa_s)
    idx = np.asarray(throats_idx, dtype=np.int64)
    if model == "conduit":
        return conduit_conductance(tessellation, idx, viscosity_pa_s=mu, policy=policy,
                                   rtol=rtol, db=db, workers=workers, progress=progress,
                                   qstar_fn=qstar_fn, **model_options)
    if model_options:
        raise TypeError(f"options {sorted(model_options)} apply to the conduit model only")
    radii = tessellation.throat_radii[idx]
    sides = tessellation.throat_sides[idx]
    qres = (throat_qstar(radii, sides, policy=policy, rtol=rtol, db=db, workers=workers,
                         progress=progress)
            if qstar_fn is None else qstar_from_function(qstar_fn, radii, sides))
    g = thesis_conductance(qres.qstar, radii, viscosity_pa_s=mu)
    return ConductanceResult(g, "thesis", qres.qstar, jsonable(qres.stats))
