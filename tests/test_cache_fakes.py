"""Analytic stand-in solvers for the cache tests (protocol of ``throats.solve_fem``).

The cache must work with any solver; these are cheap, deterministic functions of the throat
*shape* (invariant under vertex permutation and scaling, like Q*), so the store, resume,
concurrency and interpolation machinery can be tested exactly without meshing.
"""

import os
import time
import numpy as np

from throats import ThroatSolution


# the injected solvers return the real result type
FakeSolution = ThroatSolution


def smooth_q(radii, sides):
    """A smooth, positive, permutation/scale-invariant stand-in for Q* (r̄ units).

    .. math:: Q = 0.02 \\exp(1.5 S_1 - 0.4 S_2 + 0.8 P), \\quad
              S_1 = \\sum \\delta_{ij},\\ S_2 = \\sum \\delta_{ij}^2,\\ P = \\sum \\rho_i^2
    """
    r = np.asarray(radii, float)
    s = np.asarray(sides, float)
    rb = r.mean(axis=1, keepdims=True)
    r, s = r / rb, s / rb
    d = np.stack([s[:, 0] - r[:, 0] - r[:, 1], s[:, 1] - r[:, 0] - r[:, 2],
                  s[:, 2] - r[:, 1] - r[:, 2]], axis=1)
    p = r - 1
    return 0.02 * np.exp(1.5 * d.sum(1) - 0.4 * (d**2).sum(1) + 0.8 * (p**2).sum(1))


def _solution(q, status=None, message=None, seconds=1e-4):
    n = len(q)
    status = np.full(n, "ok", dtype=object) if status is None else status
    message = np.full(n, "", dtype=object) if message is None else message
    return FakeSolution(q, np.ones(n), np.full(n, "a", dtype=object), np.full(n, 1e-4),
                        np.full(n, 100), np.full(n, seconds), status, message)


def fake_solve(radii, sides, *, rtol=1e-3, workers=1, progress=False):
    """Fast analytic solver."""
    return _solution(smooth_q(radii, sides))


fake_solve.SOLVER_VERSION = "fake-1"


def slow_fake_solve(radii, sides, *, rtol=1e-3, workers=1, progress=False):
    """Analytic solver that takes ``$CACHE_FAKE_DELAY`` seconds per throat (default 5 ms)."""
    delay = float(os.environ.get("CACHE_FAKE_DELAY", "0.005"))
    time.sleep(delay * len(radii))
    return _solution(smooth_q(radii, sides), seconds=delay)


slow_fake_solve.SOLVER_VERSION = "fake-1"


def flaky_solve(radii, sides, *, rtol=1e-3, workers=1, progress=False):
    """Fails (status 'failed', with a reason) on throats whose largest scaled side exceeds 2.5."""
    q = smooth_q(radii, sides)
    s = np.asarray(sides, float) / np.asarray(radii, float).mean(1, keepdims=True)
    bad = s.max(1) > 2.5
    status = np.where(bad, "failed", "ok").astype(object)
    message = np.where(bad, "mesh lost a gap (fake)", "").astype(object)
    return _solution(np.where(bad, np.nan, q), status, message)


flaky_solve.SOLVER_VERSION = "fake-1"


def raising_solve(radii, sides, *, rtol=1e-3, workers=1, progress=False):
    raise RuntimeError("gmsh crashed (fake)")


raising_solve.SOLVER_VERSION = "fake-1"


def test_smooth_q_is_shape_invariant():
    # source: construction — permuting vertices (1<->3) and scaling by 7 must not change Q
    r = np.array([[1.0, 1.2, 0.9]])
    s = np.array([[2.3, 2.0, 2.25]])
    r2 = r[:, [2, 1, 0]] * 7
    s2 = s[:, [2, 1, 0]] * 7  # l32, l31, l21 -> [l23, l13, l12]
    np.testing.assert_allclose(smooth_q(r, s), smooth_q(r2, s2), rtol=1e-14)
