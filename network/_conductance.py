r"""Throat conductances: Q* from the cache (or throats/) and g = Q* r̄⁴/(μ L).

Geometry apart from fluid (STYLE item 5): ``throats``/``cache`` return the dimensionless flow
rate :math:`Q^*` in mean-radius units; :func:`thesis_conductance` alone turns it into a
hydraulic conductance with the viscosity and the pore length of thesis Eq. 3.41,

.. math:: g = \frac{Q}{\Delta P} = \frac{Q^* \bar r^4}{\mu L}, \qquad L = 2 \bar r,
          \qquad \bar r = (r_1 + r_2 + r_3)/3 .

Conductance models
------------------
``'thesis'``
    Eq. 3.41 as above: the window's narrowest cross-section taken to run the whole pore
    length :math:`2\bar r`.
``'conduit'``
    Delegated to ``network._conduit.conduit_conductance`` (resistance integrated over
    cross-sections between the pore centres; derivation in that module).

Q* policies (the cache's names)
-------------------------------
``'shape-factor'`` fast closed-form estimate; ``'table-only'`` table lookup/interpolation
only; ``'table+fe'`` table, finite elements for misses; ``'fe-only'`` finite elements for every
distinct throat. With ``cache.lookup_qstar`` available every policy goes through it; without it,
``'shape-factor'`` and ``'fe-only'`` call ``throats.shape_factor_qstar`` / ``throats.solve_fem``.
"""

from __future__ import annotations

import dataclasses
import logging
import time

import numpy as np

from cache import lookup_qstar

__all__ = [
    "MU_AIR_PA_S",
    "RHO_AIR_KG_M3",
    "POLICIES",
    "MODELS",
    "QstarResult",
    "thesis_conductance",
    "throat_qstar",
    "throat_conductance",
]

log = logging.getLogger(__name__)

#: Air viscosity used by the thesis (Appendix G), Pa·s.
MU_AIR_PA_S = 1.932e-5
#: Air density used by the thesis, kg/m³.
RHO_AIR_KG_M3 = 1.20
#: Q* policies, as named by ``cache.lookup_qstar``.
POLICIES = ("shape-factor", "table-only", "table+fe", "fe-only")
#: Conductance models.
MODELS = ("thesis", "conduit")


def thesis_conductance(qstar, radii_m, *, viscosity_pa_s: float = MU_AIR_PA_S):
    r"""Throat conductance of thesis Eq. 3.41, m³ Pa⁻¹ s⁻¹, shape (N,).

    .. math:: g = \frac{Q^* \bar r^4}{\mu L}, \quad L = 2\bar r
              \;\Longrightarrow\; g = \frac{Q^* \bar r^3}{2 \mu}

    Parameters
    ----------
    qstar : (N,) array_like
        Dimensionless flow rate in mean-radius units (0 for a closed throat).
    radii_m : (N, 3) array_like, m
        Radii of the three spheres of each throat.
    viscosity_pa_s : float, optional
        Dynamic viscosity μ (default 1.932e-5 Pa·s, air, as in the thesis).

    Returns
    -------
    (N,) ndarray, m³ Pa⁻¹ s⁻¹

    Examples
    --------
    A circular tube of radius r̄ = 1 mm (Q* = π/8) over L = 2 mm is Hagen–Poiseuille,
    g = π r⁴/(8 μ L):

    >>> import numpy as np
    >>> g = thesis_conductance([np.pi / 8], [[1e-3, 1e-3, 1e-3]], viscosity_pa_s=1e-3)
    >>> bool(np.isclose(g[0], np.pi * 1e-12 / (8 * 1e-3 * 2e-3)))
    True
    """
    q = np.asarray(qstar, dtype=float)
    r = np.asarray(radii_m, dtype=float)
    if r.ndim != 2 or r.shape[1] != 3 or q.shape != (r.shape[0],):
        raise ValueError(f"qstar (N,) and radii (N, 3) expected, got {q.shape} and {r.shape}")
    if not viscosity_pa_s > 0:
        raise ValueError(f"viscosity must be > 0, got {viscosity_pa_s!r}")
    if np.any(q < 0):
        raise ValueError("qstar must be >= 0 (NaN marks a failed throat: resolve it first)")
    rbar = r.mean(axis=1)
    return q * rbar**4 / (viscosity_pa_s * 2.0 * rbar)


@dataclasses.dataclass(frozen=True)
class QstarResult:
    """Q* per throat with where it came from.

    ``qstar`` (N,) r̄ units; ``source`` (N,) str; ``error_estimate`` (N,) relative (NaN unknown);
    ``stats`` dict (policy, backend, seconds, counts per source, ...).
    """

    qstar: np.ndarray
    source: np.ndarray
    error_estimate: np.ndarray
    stats: dict


def _check_policy(policy):
    if policy not in POLICIES:
        raise ValueError(f"unknown Q* policy {policy!r}; choose one of {', '.join(POLICIES)}")


def throat_qstar(radii, sides, *, policy: str = "table-only", rtol: float = 1e-3, db=None,
                 workers: int = 1, progress: bool = False,
                 on_failed: str = "shape-factor") -> QstarResult:
    """Dimensionless flow rate Q* (r̄ units) of N throats under a policy.

    Parameters
    ----------
    radii, sides : (N, 3) array_like, any consistent length unit
        [r1, r2, r3] and [l12, l13, l23].
    policy : {'shape-factor', 'table-only', 'table+fe', 'fe-only'}
    rtol : float
        Requested relative accuracy of table interpolation / FE (default 1e-3).
    db : path or None
        Throat table (None: ``cache.default_db_path()``).
    workers : int
        Processes for finite-element solves.
    progress : bool
        Progress bar on long FE batches.
    on_failed : {'shape-factor', 'raise'}
        What to do with throats the policy could not answer (FE failure, ``'failed'`` source):
        use their shape-factor estimate (default; counted in ``stats`` and logged as a
        warning), or raise.

    Returns
    -------
    QstarResult

    Raises
    ------
    ValueError
        Unknown policy, or a policy needing the table while ``cache`` is unavailable.
    RuntimeError
        Some throats have no valid Q* (``on_failed='raise'``, or the fallback failed too).
    """
    _check_policy(policy)
    if on_failed not in ("shape-factor", "raise"):
        raise ValueError(f"on_failed must be 'shape-factor' or 'raise', got {on_failed!r}")
    radii = np.asarray(radii, dtype=float)
    sides = np.asarray(sides, dtype=float)
    n = radii.shape[0]
    t0 = time.perf_counter()
    if n == 0:
        return QstarResult(np.zeros(0), np.zeros(0, dtype="<U12"), np.zeros(0),
                           {"policy": policy, "backend": "none", "seconds": 0.0})
    res = lookup_qstar(radii, sides, db=db, policy=policy, rtol=rtol, workers=workers,
                       progress=progress)
    q = np.asarray(res.qstar, dtype=float)
    src = np.asarray(res.source).astype(str)
    err = np.asarray(res.error_estimate, dtype=float)
    stats = dict(res.stats or {})
    backend = "cache.lookup_qstar"
    bad = ~np.isfinite(q) | (q < 0)
    n_fallback = 0
    if bad.any() and on_failed == "shape-factor":
        import throats

        q = q.copy()
        src = src.astype("<U24")
        q[bad] = np.asarray(throats.shape_factor_qstar(radii[bad], sides[bad]), dtype=float)
        src[bad] = "shape-factor-fallback"
        err = err.copy()
        err[bad] = np.nan
        n_fallback = int(bad.sum())
        log.warning("%d of %d throats had no valid Q* from %s (FE failure or table miss): "
                    "their shape-factor estimate is used instead", n_fallback, n, policy)
        bad = ~np.isfinite(q) | (q < 0)
    if bad.any():
        k = int(np.flatnonzero(bad)[0])
        raise RuntimeError(f"{int(bad.sum())} of {n} throats have no valid Q* (first: radii "
                           f"{radii[k].tolist()}, sides {sides[k].tolist()}, source {src[k]!r})")
    seconds = time.perf_counter() - t0
    kinds, counts = np.unique(src, return_counts=True)
    stats.update({"policy": policy, "backend": backend, "seconds": seconds, "rtol": rtol,
                  "n_shape_factor_fallback": n_fallback,
                  "n_throats": int(n),
                  "sources": {str(k): int(c) for k, c in zip(kinds, counts)}})
    log.info("Q* of %d throats by %s (%s) in %.2f s: %s", n, policy, backend, seconds,
             stats["sources"])
    return QstarResult(q, src, err, stats)


def throat_conductance(tessellation, throats_idx, *, model: str = "thesis",
                       policy: str = "table-only", viscosity_pa_s: float = MU_AIR_PA_S,
                       rtol: float = 1e-3, db=None, workers: int = 1, progress: bool = False,
                       **model_options):
    """Conductance g (m³ Pa⁻¹ s⁻¹) of selected throats of a tessellation under a model.

    Parameters
    ----------
    tessellation : Tessellation
    throats_idx : (M,) array_like of int
        Throats to evaluate (only those the scene needs).
    model : {'thesis', 'conduit'}
        See the module docstring.
    policy, rtol, db, workers, progress
        Passed to :func:`throat_qstar` (and to the conduit model).
    viscosity_pa_s : float
        μ, Pa·s (default 1.932e-5).
    **model_options
        Passed to the conduit model only (e.g. ``merge``, the pore bodies already used to
        contract the network).

    Returns
    -------
    g : (M,) ndarray, m³ Pa⁻¹ s⁻¹
    qres : QstarResult or None
        Q* details for the thesis model; whatever the conduit model reports otherwise.
    """
    if model not in MODELS:
        raise ValueError(f"unknown conductance model {model!r}; choose one of {', '.join(MODELS)}")
    _check_policy(policy)
    idx = np.asarray(throats_idx, dtype=np.int64)
    if model == "conduit":
        from ._conduit import conduit_conductance   # here: _conduit imports this module

        g, info = conduit_conductance(tessellation, idx, viscosity_pa_s=viscosity_pa_s,
                                      policy=policy, rtol=rtol, db=db, workers=workers,
                                      progress=progress, **model_options)
        return np.asarray(g, dtype=float), info
    if model_options:
        raise TypeError(f"options {sorted(model_options)} apply to the conduit model only")
    radii = tessellation.throat_radii[idx]
    sides = tessellation.throat_sides[idx]
    qres = throat_qstar(radii, sides, policy=policy, rtol=rtol, db=db, workers=workers,
                        progress=progress)
    return thesis_conductance(qres.qstar, radii, viscosity_pa_s=viscosity_pa_s), qres
