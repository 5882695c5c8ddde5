"""Dimensionless throat flow rates Q* by policy: the network's only door to ``cache``.

``throats``/``cache`` return the dimensionless flow rate :math:`Q^*` of a throat cross-section in
mean-radius units (geometry apart from fluid, STYLE item 5); the conductance models turn it into
conductances. Policies (the cache's names): ``'shape-factor'`` fast closed-form estimate;
``'table-only'`` table lookup/interpolation only (the default); ``'table+fe'`` table, finite
elements for misses; ``'fe-only'`` finite elements for every distinct throat.
"""

from __future__ import annotations

import dataclasses
import logging
import time

import numpy as np

import throats
from cache import POLICIES, SOURCES, lookup_qstar

__all__ = ["POLICIES", "SOURCES", "QstarResult", "check_policy", "throat_qstar",
           "qstar_from_function"]

log = logging.getLogger(__name__)

# POLICIES: the Q* policies, as ``cache`` names and defines them (one definition).


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


def check_policy(policy: str) -> str:
    """``policy`` if it is one of :data:`POLICIES`, else ValueError listing them."""
    if policy not in POLICIES:
        raise ValueError(f"unknown Q* policy {policy!r}; choose one of {', '.join(POLICIES)}")
    return policy


def throat_qstar(radii, sides, *, policy: str = "table-only", rtol: float = 1e-3, db=None,
                 workers: int = 1, progress: bool = False,
                 on_failed: str = "shape-factor", estimate: bool = True) -> QstarResult:
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
    estimate : bool
        False: no error estimate for interpolated rows of 'table-only' (NaN; the table's
        per-cell estimate is not built), for callers that use Q* only (default True).

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
    check_policy(policy)
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
                       progress=progress, estimate=estimate)
    q = np.asarray(res.qstar, dtype=float)
    src = np.asarray(res.source, dtype=str)
    err = np.asarray(res.error_estimate, dtype=float)
    stats = dict(res.stats or {})
    backend = "cache.lookup_qstar"
    # rows per source from the lookup's counts (sorting N strings cost 0.1 s per 1e6 rows)
    sources = {k: stats.get(f"n_{k.replace('-', '_')}", 0) for k in SOURCES}
    bad = ~np.isfinite(q) | (q < 0)
    n_fallback = 0
    if bad.any() and on_failed == "shape-factor":
        for k, c in zip(*np.unique(src[bad], return_counts=True)):
            sources[str(k)] -= int(c)
        sources["shape-factor-fallback"] = int(bad.sum())
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
    stats.update({"policy": policy, "backend": backend, "seconds": seconds, "rtol": rtol,
                  "n_shape_factor_fallback": n_fallback,
                  "n_throats": int(n),
                  "sources": {k: int(c) for k, c in sorted(sources.items()) if c > 0}})
    log.info("Q* of %d throats by %s (%s) in %.2f s: %s", n, policy, backend, seconds,
             stats["sources"])
    return QstarResult(q, src, err, stats)


def qstar_from_function(qstar_fn, radii, sides) -> QstarResult:
    """Q* of N throats from a caller's function ``qstar_fn(radii (N,3), sides (N,3)) -> (N,)``.

    For tests and validation cases with their own Q* source (exact FE of a lattice section, a
    closed form); the result has the same type as :func:`throat_qstar`'s.
    """
    q = np.asarray(qstar_fn(np.asarray(radii, float), np.asarray(sides, float)), dtype=float)
    return QstarResult(q, np.full(q.size, "qstar_fn"), np.full(q.size, np.nan),
                       {"policy": "qstar_fn", "n_throats": int(q.size),
                        "sources": {"qstar_fn": int(q.size)} if q.size else {}})
