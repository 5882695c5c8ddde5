"""Steady Navier-Stokes by Newton's method on an assembled Stokes system (scikit-fem), shared by
``inertial_constriction_ns.py`` and ``inertial_pore_ns.py``: one place for the iteration.

Unknowns U = (u, p), the first ``nu`` velocity. With viscosity 1 and density rho the residual is
``stokes @ U`` plus rho times the convection ``(u . grad) u`` tested against v; the Jacobian adds
rho times its linearisation to the viscous block ``A``. Dirichlet dofs ``D`` keep their values
(the step is condensed with zeros there).

The linear solves use Intel MKL PARDISO through ``pypardiso`` when it is installed (multithreaded,
and it finishes the h 0.065 pore mesh that SuperLU did not in 24 min); otherwise scikit-fem's
default (SciPy's SuperLU). ``pypardiso`` is not a dependency of the package: ``pip install
pypardiso`` for these scripts only.
"""

import numpy as np
from scipy.sparse import bmat
from skfem import asm, condense, solve

try:
    from pypardiso import spsolve as _pardiso
except ImportError:        # SciPy's SuperLU through scikit-fem
    _pardiso = None


def linear_solve(A, b, x=None, D=None):
    """``solve(*condense(A, b, x=x, D=D))`` with PARDISO when available (module notes)."""
    if _pardiso is None:
        return solve(*condense(A, b, x=x, D=D))
    return solve(*condense(A, b, x=x, D=D), solver=lambda M, r, **kw: _pardiso(M.tocsr(), r))


def newton(U, rho, *, A, B, stokes, basis_u, nu, D, convection, convection_jacobian,
           rtol, maxiter):
    """Newton from ``U`` at density ``rho`` until ``|dU| <= rtol |U|`` or ``maxiter`` steps:
    (U, steps taken). ``convection`` and ``convection_jacobian`` are the script's forms, each
    reading the current velocity as ``w["u0"]``."""
    for it in range(maxiter):
        u0 = basis_u.interpolate(U[:nu])
        J = bmat([[A + rho * asm(convection_jacobian, basis_u, u0=u0), B.T], [B, None]], "csr")
        F = stokes @ U
        F[:nu] += rho * asm(convection, basis_u, u0=u0)
        dU = linear_solve(J, -F, x=np.zeros_like(U), D=D)
        U = U + dU
        if np.linalg.norm(dU) <= rtol * np.linalg.norm(U):
            break
    return U, it + 1
