r"""An AMG hierarchy built once for a matrix and reused: the state behind every pressure solve.

:class:`AMGSolver` holds pyamg's smoothed-aggregation hierarchy of the diagonally scaled
matrix :math:`\tilde A = D^{-1/2} A D^{-1/2}` (near-null space :math:`D^{1/2}\mathbf 1`).
The unknowns are renumbered by reverse Cuthill-McKee (SciPy's ``csgraph``) before the hierarchy
is built: pyamg's greedy aggregation and the Gauss-Seidel sweeps follow the node order, and a
banded order smooths better, with smaller aggregates (operator complexity 1.67 -> 1.83), than
the tessellation's: at 20 000 spheres CG takes 31 iterations in this order against 40 in the
tessellation's, and setup plus solve take about a third less time at 1e6 spheres
(``docs/network-bench.md``). It is built on
the first solve; later right-hand sides reuse it. If CG has not converged after
150 iterations the hierarchy is rebuilt once with ``strength='evolution'`` and kept: later
solves with the same matrix start from it and never rebuild. :meth:`AMGSolver.preconditioner`
turns the hierarchy into an approximate inverse of :math:`A` for CG on a nearby matrix (the
Newton Jacobians of :mod:`network.flow._inertial` differ from the Stokes Laplacian only in
their weights).

The finest prolongator is smoothed with the weight :math:`\omega/\rho` of pyamg's Jacobi
smoother, :math:`P = (I - \tfrac{4}{3\rho}\tilde A)\,T`, but :math:`\rho` is Gershgorin's
bound :math:`\max_i \sum_j |a_{ij}|/a_{ii}` of the spectrum of :math:`D^{-1}A` (that of
:math:`\tilde A`) instead of pyamg's restarted Arnoldi estimate: a diagonally dominant
Laplacian (every network matrix here) has the bound 2, and the estimate is 1.99 at 20 000
spheres. Same CG iterations (22 / 24 / 27 at 5 000 / 20 000 / 100 000 spheres), setup 0.24-0.28
-> 0.12-0.18 s at 20 000 and 1.7-2.1 -> 0.8-1.0 s at 100 000. A matrix whose bound exceeds 2
(not diagonally dominant) keeps pyamg's estimate.
"""

from __future__ import annotations

import contextlib
import dataclasses
import importlib
import logging
import time

import numpy as np
import scipy.sparse as sp

from .._deferred import csgraph, sparse_linalg
from .._lean import BLAS_SINGLE

__all__ = ["AMGSolver", "SMOOTHERS", "SolveInfo"]

log = logging.getLogger(__name__)

_BLAS = None


def one_blas_thread():
    """Context manager limiting BLAS to one thread (threadpoolctl). The loaded BLAS libraries
    are found once per process (a ``ThreadpoolController``): 0.03 ms a call instead of the
    1.2 ms of ``threadpool_limits``, which searches them again on every call. Nothing to limit
    in a command process whose OpenBLAS started with one thread (``network._lean``)."""
    global _BLAS
    if BLAS_SINGLE:                 # a command process whose OpenBLAS started with one thread
        return contextlib.nullcontext()
    if _BLAS is None:
        from threadpoolctl import ThreadpoolController
        _BLAS = ThreadpoolController()
    return _BLAS.limit(limits=1, user_api="blas")


def import_pyamg() -> None:
    """Import the pyamg modules :class:`AMGSolver` uses (smoothed aggregation, Krylov,
    smoothing): for a thread with time to spare before the first setup."""
    for name in ("pyamg.aggregation", "pyamg.krylov", "pyamg.relaxation.smoothing"):
        importlib.import_module(name)


@contextlib.contextmanager
def seeded_numpy_random(seed: int = 0):
    """NumPy's legacy global generator seeded for the block, its state restored after.
    pyamg's spectral-radius estimates (the prolongation smoother's weight) start Arnoldi from
    ``np.random.rand``: unseeded, two setups of one matrix differ in the last bits, and so
    do the solutions (~1e-13) and, at the tolerance's edge, the CG counts."""
    state = np.random.get_state()
    np.random.seed(seed)
    try:
        yield
    finally:
        np.random.set_state(state)


def gershgorin_bound(A, diagonal=None) -> float:
    r"""Gershgorin's bound on the spectral radius of :math:`D^{-1}A` (D = diag A > 0, given as
    ``diagonal`` where the caller has it): :math:`\max_i \sum_j |a_{ij}| / a_{ii}`; 2 for a
    weakly diagonally dominant matrix with one row in balance (a Laplacian's interior row), less
    when every row is strictly dominant.
    """
    A = sp.csr_array(A)
    if A.shape[0] == 0:
        return 0.0
    d = A.diagonal() if diagonal is None else diagonal
    return float(np.max(abs(A) @ np.ones(A.shape[1]) / d))


#: Largest Gershgorin bound used as the finest level's rho: 2, and the round-off of a
#: balanced row's sum (2.000000000000001 at 20 000 spheres).
_DOMINANT = 2.0 * (1.0 + 1e-12)


#: Gauss-Seidel smoothing: pyamg's default symmetric sweeps before and after the coarse
#: correction, or one forward sweep before and one backward after (still a symmetric
#: V-cycle, half the smoothing work; the Newton Jacobians of network.flow._inertial use it).
SMOOTHERS = ("symmetric", "forward-backward")

#: CG iterations with the classical strength measure before the evolution measure is tried.
_SWITCH_ITERATIONS = 150


@dataclasses.dataclass
class SolveInfo:
    """What :func:`network.flow.solve_pressure` / :meth:`AMGSolver.solve` did.

    Attributes: ``converged`` (bool), ``iterations`` (int), ``residual`` (final relative residual
    ‖b − Ax‖/‖b‖ of the unscaled system), ``residuals`` (history of the preconditioned CG,
    relative), ``setup_s`` and ``solve_s`` (s; ``setup_s`` is 0 when the hierarchy was reused),
    ``method`` (str); ``amg``: the :class:`AMGSolver` that solved it (None for other solvers),
    for a caller that solves a nearby system next (the Newton steps of an inertial solve).
    """

    converged: bool
    iterations: int
    residual: float
    residuals: list
    setup_s: float
    solve_s: float
    method: str
    assemble_s: float = 0.0
    amg: "AMGSolver | None" = dataclasses.field(default=None, repr=False, compare=False)


class AMGSolver:
    """Smoothed-aggregation AMG + CG for one SPD matrix, hierarchy built once.

    Parameters
    ----------
    A : (n, n) sparse array
        SPD with a positive diagonal (a condensed pore-network Laplacian).
    smoother : {'symmetric', 'forward-backward'}, keyword-only
        Gauss-Seidel sweeps of the V-cycle (:data:`SMOOTHERS`; default pyamg's symmetric).

    Attributes
    ----------
    strength : str
        ``'symmetric'``, or ``'evolution'`` once CG has needed the evolution measure.
    builds : int
        Hierarchies built so far (1 after any number of solves that converge with the first).
    setup_s : float
        Seconds spent building them.
    rho : float or None
        The spectral radius bound of :math:`D^{-1}A` that smooths the finest prolongator
        (:func:`gershgorin_bound`), or None where it exceeds 2 and pyamg estimates it.
    """

    def __init__(self, A, *, smoother: str = "symmetric"):
        if smoother not in SMOOTHERS:
            raise ValueError(f"smoother must be one of {SMOOTHERS}, got {smoother!r}")
        self.smoother = smoother
        A = sp.csr_array(A)
        n = A.shape[0]
        if A.shape != (n, n):
            raise ValueError(f"A must be square, got {A.shape}")
        d = A.diagonal()
        if np.any(d <= 0):
            raise ValueError("matrix has a non-positive diagonal entry: a free pore with no "
                             "conducting throat (prune disconnected pores first)")
        self.A = A
        self.n = n
        # the solver's unknown k is the caller's order[k], scaled: x[order[k]] = s_k y_k
        rcm = csgraph.reverse_cuthill_mckee(sp.csr_matrix(A), symmetric_mode=True)
        self._order = np.asarray(rcm, dtype=np.int64)
        self._inverse = np.empty(n, dtype=np.int64)
        self._inverse[self._order] = np.arange(n)
        self._s = (1.0 / np.sqrt(d))[self._order]
        self._As = self._scaled(A)
        self._B = np.sqrt(d)[self._order][:, None]
        bound = gershgorin_bound(A, d)
        self.rho = bound if bound <= _DOMINANT else None
        self._ml = None
        self.strength = "symmetric"
        self.builds = 0
        self.setup_s = 0.0

    def _scaled(self, A) -> sp.csr_matrix:
        """:math:`D^{-1/2} A D^{-1/2}` in the solver's order (D the held diagonal): the rows
        gathered, the column indices renumbered, :math:`a_{ij} s_i s_j`."""
        R = sp.csr_array(A)[self._order]
        cols = self._inverse[R.indices]
        rows = np.repeat(np.arange(self.n), np.diff(R.indptr))
        M = sp.csr_matrix((R.data * self._s[rows] * self._s[cols], cols, R.indptr),
                          shape=(self.n, self.n))
        M.sort_indices()
        return M

    def _to(self, v: np.ndarray) -> np.ndarray:
        """A vector of the caller's unknowns in the solver's: scaled and reordered."""
        return self._s * np.ravel(v)[self._order]

    def _back(self, y: np.ndarray) -> np.ndarray:
        """The inverse of :meth:`_to`."""
        out = np.empty(self.n)
        out[self._order] = self._s * y
        return out

    def _hierarchy(self, strength: str):
        """The hierarchy for ``strength``, built only when the held one is another."""
        if self._ml is not None and self.strength == strength:
            return self._ml, 0.0
        from pyamg.aggregation import smoothed_aggregation_solver
        t0 = time.perf_counter()
        with one_blas_thread(), seeded_numpy_random():
            # B = D^(1/2) 1 is the scaled Laplacian's exact null vector away from the
            # Dirichlet rows: pyamg's default Gauss-Seidel improvement of it (4 sweeps, a
            # quarter of the setup) leaves the iterations unchanged (29 -> 30 at 20 000
            # spheres) and is skipped
            # the finest level: tilde A has a unit diagonal, so pyamg's Richardson smoothing
            # of T with rho read from the matrix (pyamg's cache, tilde A.rho) is its Jacobi one
            smooth = "jacobi"
            if self.rho is not None:
                self._As.rho = self.rho
                smooth = [("richardson", {"omega": 4.0 / 3.0}), "jacobi"]
            self._ml = smoothed_aggregation_solver(
                self._As, B=self._B, symmetry="symmetric", strength=strength, max_coarse=500,
                coarse_solver="splu", improve_candidates=None, smooth=smooth)
        for level in self._ml.levels:       # pyamg's 1x1 BSR kernels are slower than CSR's
            for name in ("A", "P", "R"):
                M = getattr(level, name, None)
                if sp.issparse(M) and M.format == "bsr" and M.blocksize == (1, 1):
                    setattr(level, name, sp.csr_matrix(M))
        if self.smoother == "forward-backward":
            from pyamg.relaxation.smoothing import change_smoothers
            change_smoothers(self._ml, ("gauss_seidel", {"sweep": "forward"}),
                             ("gauss_seidel", {"sweep": "backward"}))
        dt = time.perf_counter() - t0
        self.strength = strength
        self.builds += 1
        self.setup_s += dt
        return self._ml, dt

    def solve(self, b, *, x0=None, tol: float = 1e-10, maxiter: int = 500):
        """Solve :math:`A x = b` by CG preconditioned with the held hierarchy.

        Returns ``(x, SolveInfo)``; ``tol`` is relative to ‖b‖ in the scaled system.
        """
        b = np.asarray(b, dtype=float)
        if b.shape != (self.n,):
            raise ValueError(f"b must have shape ({self.n},), got {b.shape}")
        bnorm = np.linalg.norm(b)
        if bnorm == 0:
            return np.zeros(self.n), SolveInfo(True, 0, 0.0, [], 0.0, 0.0, "zero rhs")
        As = self._As
        bs = self._to(b)
        bsn = np.linalg.norm(bs)
        y = (np.zeros(self.n) if x0 is None
             else np.asarray(x0, dtype=float)[self._order] / self._s)
        hist: list[float] = []
        setup = solve_t = 0.0
        converged = False
        stages = ([("symmetric", min(maxiter, _SWITCH_ITERATIONS)), ("evolution", maxiter)]
                  if self.strength == "symmetric" else [("evolution", maxiter)])
        from pyamg.krylov import cg as pyamg_cg
        for strength, limit in stages:
            ml, dt = self._hierarchy(strength)
            setup += dt
            res_abs: list[float] = []
            t1 = time.perf_counter()
            with one_blas_thread():
                # pyamg's CG (its residual history) with the project's V-cycle: what
                # ml.solve(accel='cg') does, less two residual norms per V-cycle
                M = sparse_linalg.LinearOperator((self.n, self.n),
                                                 matvec=self._held_cycle(ml), dtype=float)
                y, _ = pyamg_cg(ml.levels[0].A, bs, x0=y, tol=tol, maxiter=limit, M=M,
                                residuals=res_abs)
            solve_t += time.perf_counter() - t1
            hist.extend(r / bsn for r in res_abs[1:])    # res_abs[0] is the initial residual
            if np.linalg.norm(bs - As @ y) <= tol * bsn * 1.0000001:
                converged = True
                break
            if strength == "symmetric":
                log.info("SA-PCG not converged after %d iterations (residual %.2e): rebuilding "
                         "with evolution strength", len(hist), hist[-1] if hist else np.nan)
        x = self._back(y)
        res = float(np.linalg.norm(b - self.A @ x) / bnorm)
        method = "pyamg-sa-pcg" if self.strength == "symmetric" else "pyamg-sa(evolution)-pcg"
        info = SolveInfo(converged=converged, iterations=len(hist), residual=res,
                         residuals=hist, setup_s=setup, solve_s=solve_t, method=method, amg=self)
        if not converged:
            log.warning("CG did not converge after %d iterations, residual %.3g",
                        len(hist), hist[-1] if hist else float("nan"))
        else:
            log.info("%s: %d unknowns, %d levels, %d iterations, setup %.3f s, solve %.3f s",
                     method, self.n, len(self._ml.levels), len(hist), setup, solve_t)
        return x, info

    def preconditioner(self, A=None) -> sparse_linalg.LinearOperator:
        r"""The hierarchy as an approximate :math:`A^{-1}` (one V-cycle), in unscaled variables.

        :math:`M r = D^{-1/2} V(D^{-1/2} r)`; good for CG on any matrix whose weights are
        close to :math:`A`'s (built now if no solve has built it yet).

        With ``A`` (same sparsity graph, other weights: a Newton Jacobian) the held
        aggregation is kept and the level operators are recomputed for it (Galerkin,
        :math:`A_{l+1} = R_l A_l P_l`, :math:`\tilde A_0 = D^{-1/2} A D^{-1/2}` with the held
        D), a new coarse LU: about 10 V-cycles of work instead of a new setup, and a
        V-cycle that is exact for ``A`` on the coarse space. The held hierarchy is unchanged.
        """
        ml, _ = self._hierarchy(self.strength)
        if A is None:
            cycle = self._held_cycle(ml)
        else:
            A = sp.csr_array(A)
            if A.shape != (self.n, self.n):
                raise ValueError(f"A must have shape ({self.n}, {self.n}), got {A.shape}")
            ops = [self._scaled(A)]
            for lv in ml.levels[:-1]:
                ops.append(sp.csr_matrix(lv.R @ (ops[-1] @ lv.P)))
            cycle = _VCycle(ops, [lv.P for lv in ml.levels[:-1]],
                            [lv.R for lv in ml.levels[:-1]], self.smoother)

        def apply(r):           # callers limit BLAS threads around the whole CG
            return self._back(cycle(self._to(r)))

        return sparse_linalg.LinearOperator((self.n, self.n), matvec=apply, dtype=float)

    def _held_cycle(self, ml) -> "_VCycle":
        """One V-cycle of hierarchy ``ml`` (scaled variables), built once per hierarchy."""
        if getattr(self, "_cycle_of", None) is not ml:
            self._cycle = _VCycle([lv.A for lv in ml.levels], [lv.P for lv in ml.levels[:-1]],
                                  [lv.R for lv in ml.levels[:-1]], self.smoother)
            self._cycle_of = ml
        return self._cycle


class _VCycle:
    """One V-cycle of a hierarchy (level operators ``ops``, prolongations ``P``, restrictions
    ``R``), zero initial guess: the cycle pyamg's ``aspreconditioner(cycle='V')`` applies, less
    its two residual norms per application (a sixth of its cost at 20 000 spheres). Smoothing:
    one forward Gauss-Seidel sweep before and one backward after ('forward-backward'), or a
    symmetric sweep on both sides ('symmetric'); LU on the coarsest level."""

    def __init__(self, ops, P, R, smoother):
        from pyamg.relaxation.relaxation import gauss_seidel   # pyamg: imported when used
        self.gs = gauss_seidel
        self.ops, self.P, self.R = ops, P, R
        self.pre, self.post = (("forward", "backward") if smoother == "forward-backward"
                               else ("symmetric", "symmetric"))
        self.lu = sparse_linalg.splu(sp.csc_matrix(ops[-1]))

    def __call__(self, b):
        gauss_seidel = self.gs
        xs, bs = [], [b]
        for A, R in zip(self.ops[:-1], self.R):        # down: pre-smooth, restrict
            x = np.zeros_like(bs[-1])
            gauss_seidel(A, x, bs[-1], iterations=1, sweep=self.pre)
            xs.append(x)
            bs.append(R @ (bs[-1] - A @ x))
        x = self.lu.solve(bs[-1])
        for k in range(len(xs) - 1, -1, -1):            # up: prolong, post-smooth
            xf = xs[k]
            xf += self.P[k] @ x
            gauss_seidel(self.ops[k], xf, bs[k], iterations=1, sweep=self.post)
            x = xf
        return x
