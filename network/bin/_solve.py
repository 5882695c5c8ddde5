r"""The bin's pressure: a nonlinear Poisson problem solved with scikit-fem, Newton's method.

Weak form, P1 elements, test functions φ_i vanishing on the plenum and the grain surface:

.. math:: R_i(p) = \int_\Omega M(G)\,(A\nabla p)\cdot\nabla\varphi_i\;w\,d\Omega = 0,

w = 2πr in r-z (axisymmetric, the forms weighted by r), 1 in 3-D; M(G) = W(G)/G the law's
mobility (:mod:`network.bin._law`). The gradient and the porosity are constant on an element, so
one quadrature point (the centroid) integrates the forms exactly, r-weighting included. The
Newton matrix is the symmetric

.. math:: J_{ij} = \int_\Omega \big[M\,A\nabla\varphi_j\cdot\nabla\varphi_i + (W' - M)
          (n\cdot\nabla\varphi_j)(n\cdot\nabla\varphi_i)\big]\,w\,d\Omega, \quad n = A\nabla p/G,

positive definite (W' > 0): the first step from p = 0 is the Darcy solve (W' = M there), then
Newton with a backtracking line search on the residual. Linear solves: a sparse LU in r-z, CG
preconditioned by pyamg's smoothed aggregation in 3-D.

Fluxes. R_i at a Dirichlet node is minus the outward flux through φ_i's share of the boundary,
so the plenum inflow is Σ_plenum R_i and the surface outflow -Σ_surface R_i; their difference is
-Σ_interior R_i (Σ_i φ_i = 1), which Newton drives to round-off: mass balance to the solver
tolerance by construction.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np
import scipy.sparse.linalg as spla

from ..flow._amg import one_blas_thread, seeded_numpy_random

__all__ = ["BinProblem", "Solution", "NewtonFailure"]

log = logging.getLogger(__name__)
logging.getLogger("skfem").setLevel(logging.WARNING)     # one INFO line per assembly


class NewtonFailure(RuntimeError):
    """Newton's method did not converge (the message names the pressure)."""


@dataclass
class Solution:
    """A converged (or not) pressure field and its fluxes."""

    pressure_pa: float
    p: np.ndarray               # nodal pressure, Pa
    velocity: np.ndarray        # (dim, Ne) superficial velocity per element, m/s
    inflow_m3_s: float          # through the plenum
    outflow_m3_s: float         # through the grain surface
    iterations: int
    residual: float             # ||R_interior|| / inflow
    converged: bool


class BinProblem:
    """Mesh, law and boundary values of one bin; :meth:`solve` for one fan pressure.

    Parameters
    ----------
    mesh : network.bin._geometry.Mesh
    material : network.bin._material.Material
    surface_height : callable
        z_s(r), m: the grain surface's height (the porosity's depth is z_s(r) - z).
    """

    def __init__(self, mesh, material, surface_height):
        from skfem import Basis, ElementTetP1, ElementTriP1, MeshTet, MeshTri

        self.mesh = mesh
        self.axisymmetric = mesh.axisymmetric
        if self.axisymmetric:
            m = MeshTri(mesh.points, mesh.cells)
            self.basis = Basis(m, ElementTriP1(), intorder=1)
        else:
            m = MeshTet(mesh.points, mesh.cells)
            self.basis = Basis(m, ElementTetP1(), intorder=1)
        self.skmesh = m
        self.dim = mesh.points.shape[0]
        cen = mesh.points[:, mesh.cells].mean(axis=1)
        self.centroids = cen
        r = cen[0] if self.axisymmetric else np.hypot(cen[0], cen[1])
        self.depth_m = np.maximum(surface_height(r) - cen[-1], 0.0)
        self.porosity = material.profile(self.depth_m)
        self.material = material
        self.law = material.element_law(self.porosity)
        a = material.anisotropy
        self.adiag = np.array([a, 1.0] if self.axisymmetric else [a, a, 1.0])
        self.weight = (2 * np.pi * np.asarray(self.basis.global_coordinates()[0])
                       if self.axisymmetric else np.ones((m.t.shape[1], 1)))
        self.volumes = np.asarray(self.basis.dx).sum(axis=1) * (
            self.weight[:, 0] if self.axisymmetric else 1.0)
        # element gradients of the basis functions, (dim, nodes per element, Ne): ∇p per
        # element is one contraction, without skfem's interpolate (its index bookkeeping
        # costs more than the sum)
        self.grads = np.stack([np.asarray(self.basis.basis[i][0].grad)[:, :, 0]
                               for i in range(m.t.shape[0])], axis=1)
        n = m.p.shape[1]
        self.fixed = np.union1d(mesh.plenum, mesh.surface)
        self.free = np.setdiff1d(np.arange(n), self.fixed)
        self._ml = None                 # pyamg hierarchy of an earlier Newton matrix, reused
        self._cg_iterations = 0         # while CG needs at most 40 iterations with it

    # ---------------------------------------------------------------- fields
    def _fields(self, p):
        """Per element (one quadrature point): g, G, W, W', M, n."""
        g = np.einsum("dve,ve->de", self.grads, p[self.skmesh.t])[:, :, None]  # (dim, Ne, 1)
        ag = self.adiag[:, None, None] * g
        G = np.sqrt(np.sum(g * ag, axis=0))           # (Ne, 1)
        w, dw = self.law.speed(G[:, 0])
        w, dw = w[:, None], dw[:, None]
        with np.errstate(invalid="ignore", divide="ignore"):
            M = np.where(G > 0, w / G, dw)            # W/G -> W'(0) at G = 0
            nvec = np.where(G > 0, ag / G, 0.0)
        return g, ag, G, w, dw, M, nvec

    def residual(self, p):
        """R (N,) of the assembled system: Σ over elements of M (A∇p)·∇φ_i w |e|."""
        from skfem import LinearForm

        _, ag, _, _, _, M, _ = self._fields(p)

        @LinearForm
        def form(v, w):
            return w.wM * sum(w.ag[k] * v.grad[k] for k in range(self.dim))

        return form.assemble(self.basis, wM=M * self.weight, ag=ag)

    def jacobian(self, p):
        """dR/dp, symmetric positive definite (csr)."""
        from skfem import BilinearForm

        _, _, _, _, dw, M, nvec = self._fields(p)
        ad = self.adiag

        @BilinearForm
        def form(u, v, w):
            aa = sum(ad[k] * u.grad[k] * v.grad[k] for k in range(self.dim))
            nu = sum(w.n[k] * u.grad[k] for k in range(self.dim))
            nv = sum(w.n[k] * v.grad[k] for k in range(self.dim))
            return w.wM * aa + w.wT * nu * nv

        return form.assemble(self.basis, wM=M * self.weight, wT=(dw - M) * self.weight,
                             n=nvec).tocsr()

    # ---------------------------------------------------------------- solve
    def _linear(self, J, rhs):
        Jii = J[self.free][:, self.free]
        if self.axisymmetric:
            return spla.spsolve(Jii.tocsc(), rhs)
        import pyamg

        with one_blas_thread(), seeded_numpy_random():
            if self._ml is None or self._cg_iterations > 40:
                self._ml = pyamg.smoothed_aggregation_solver(
                    Jii, symmetry="symmetric", max_coarse=500,
                    coarse_solver="splu").aspreconditioner()
            count = [0]

            def step(_):
                count[0] += 1

            x, info = spla.cg(Jii, rhs, rtol=1e-11, maxiter=500, M=self._ml, callback=step)
        self._cg_iterations = count[0]
        if info != 0:
            log.warning("CG with pyamg did not reach 1e-11 in 500 iterations: sparse LU")
            x = spla.spsolve(Jii.tocsc(), rhs)
        return x

    def boundary_values(self, pressure_pa):
        p = np.zeros(self.skmesh.p.shape[1])
        p[self.mesh.plenum] = pressure_pa
        return p

    def solve(self, pressure_pa: float, p0=None, *, rtol: float = 1e-12,
              maxiter: int = 60) -> Solution:
        """Newton's method at fan static pressure ``pressure_pa`` (Pa above atmospheric) from
        ``p0`` (a previous solution, scaled to this pressure) or from the Darcy solve.
        Converged when ||R_interior||_2 <= rtol x the plenum inflow."""
        if not (np.isfinite(pressure_pa) and pressure_pa > 0):
            raise ValueError(f"the fan's static pressure must be finite and > 0, got "
                             f"{pressure_pa!r}")
        free = self.free
        if p0 is None:
            p = self.boundary_values(pressure_pa)
            J = self.jacobian(np.zeros_like(p))       # the Darcy matrix
            R = self.residual(p)
            p[free] -= self._linear(J, R[free])
        else:
            p = np.array(p0, dtype=float) * (pressure_pa / max(np.max(p0), 1e-300))
            p[self.fixed] = self.boundary_values(pressure_pa)[self.fixed]
        R = self.residual(p)
        scale = max(abs(R[self.mesh.plenum].sum()), 1e-300)
        res = np.linalg.norm(R[free]) / scale
        it = 0
        while res > rtol and it < maxiter:
            it += 1
            J = self.jacobian(p)
            dp = self._linear(J, R[free])
            t, accepted = 1.0, False
            for _ in range(30):
                trial = p.copy()
                trial[free] -= t * dp
                Rt = self.residual(trial)
                st = max(abs(Rt[self.mesh.plenum].sum()), 1e-300)
                rt = np.linalg.norm(Rt[free]) / st
                if rt < (1 - 1e-4 * t) * res or rt <= rtol:
                    accepted = True
                    break
                t *= 0.5
            if not accepted:
                break
            p, R, res, scale = trial, Rt, rt, st
            log.debug("Newton %d at %.6g Pa: residual %.3e (step %.3g)", it, pressure_pa,
                      res, t)
        q_in = float(R[self.mesh.plenum].sum())
        q_out = float(-R[self.mesh.surface].sum())
        return Solution(float(pressure_pa), p, self.velocity(p), q_in, q_out, it, float(res),
                        bool(res <= rtol))

    def velocity(self, p):
        """Superficial velocity per element, (dim, Ne), m/s: u = -M A ∇p."""
        _, ag, _, _, _, M, _ = self._fields(p)
        return -(M * ag)[:, :, 0]

    def grain_mass_kg(self) -> float:
        """∫ ρ_p (1 - ε) dV, kg."""
        return float(np.sum(self.material.particle_density_kg_m3 * (1 - self.porosity)
                            * self.volumes))
