r"""Nonlinear network flow: Newton's method on the pore pressures, AMG-preconditioned CG inside.

Every conduit obeys :math:`\Delta p = q/g + K_\pm\, q|q|` (:mod:`network.conductance._inertial`;
:math:`K_+` for flow from ``conns[:, 0]`` to ``conns[:, 1]``, :math:`K_-` the reverse), so its
signed flow is the monotone function

.. math:: q(\Delta p) = \frac{2\,\Delta p}{1/g + \sqrt{1/g^2 + 4K|\Delta p|}},\qquad
          \frac{dq}{d\Delta p} = w = \frac{1}{1/g + 2K|q|} \in (0, g].

With ``onset_scale`` c the inertial term sets in with the window Reynolds number,
:math:`K q|q|\,t/\sqrt{1+t^2}`, :math:`t = c|q|` (:func:`network.conductance.onset_scales`):
its excess over the viscous drop starts as Re² per conduit and tends to :math:`Kq|q|` at high
Re (``docs/inertial-flow.md``).

The unknowns are the free pore pressures and the common inlet pressure P (outlet pores at 0);
the equations are mass balance in every free pore and a total inlet flow :math:`Q = UA`. The
Jacobian is the graph Laplacian of the weights w, condensed like the Stokes system, with one
extra row for P: the Laplacian with all inlet pores merged into one node, SPD, its CSR pattern
built once. A Newton step is one CG solve of that bordered system, preconditioned by the held
AMG hierarchy of the Stokes matrix as the free block's inverse inside an exact block inverse
(one V-cycle per application), with backtracking on the residual. From the second flow on,
each flow's first step recomputes the level operators for its Jacobian on the held
aggregation (Galerkin; about 10 V-cycles of work); a new hierarchy is built only when CG
still needs more than 40 iterations.
At K = 0 the first step from zero is the Stokes solution. Velocities are solved in ascending
order from the previous solution, every pore pressure extrapolated by its own power law of the
last two points (from three on, a parabola in log p against log Q, held between the viscous
and fully inertial powers 1 and 2), the whole field then scaled so that the inlet throats carry
the flow's Q (the extrapolation's largest error: 1-2 % of Q, against 2e-4 in the pore
balances; 20 000 spheres, one chain: 638 -> 557 CG iterations over 12 flows). With
``workers`` > 1 the sorted flows are cut into contiguous chains solved in parallel
processes, the later chains two flows shorter for their cold start (20 000 spheres, 12 flows,
two chains of 7 and 5: 307 and 358 CG iterations against 557 for one chain; interleaved
chains took 357 and 383; ``docs/inertial-flow.md``).
"""

from __future__ import annotations

import dataclasses
import logging
import time

import numpy as np
import scipy.sparse as sp

from .._deferred import sparse_linalg
from ._amg import AMGSolver, one_blas_thread
from ._conduit_flow import conduit_flow

__all__ = ["InertialPoint", "solve_inertial"]

log = logging.getLogger(__name__)

#: CG iterations on a Newton Jacobian above which its own hierarchy is built.
_REBUILD_ITERATIONS = 40


@dataclasses.dataclass
class InertialPoint:
    """One solved total flow: ``flow_m3_s``, inlet pressure ``dp_pa`` (outlet at 0),
    ``converged``, Newton ``iterations``, CG iterations ``cg_iterations``, final relative
    residual ``residual`` (max pore imbalance / Q), ``seconds``; ``pressure_pa`` (Np,) and
    ``throat_flow_m3_s`` (Nt,)."""

    flow_m3_s: float
    dp_pa: float
    converged: bool
    iterations: int
    cg_iterations: int
    residual: float
    seconds: float
    pressure_pa: np.ndarray = dataclasses.field(repr=False)
    throat_flow_m3_s: np.ndarray = dataclasses.field(repr=False)


def solve_inertial(n_pores, conns, g, K, inlet, outlet, flows_m3_s, *, tol: float = 1e-10,
                   maxiter: int = 30, amg: AMGSolver | None = None,
                   onset_scale=None, workers: int = 1,
                   stokes=None) -> list[InertialPoint]:
    """Solve the nonlinear network at every total flow (ascending), reusing one hierarchy.

    Parameters
    ----------
    n_pores : int
    conns : (Nt, 2) int array_like
    g : (Nt,) array_like, m³ Pa⁻¹ s⁻¹
        Viscous conductances (> 0: prune closed throats first).
    K : (Nt, 2) or (Nt,) array_like, Pa s² m⁻⁶
        Inertial coefficients (>= 0).
    inlet, outlet : int array_like
        Inlet pores (common unknown pressure) and outlet pores (0 Pa).
    flows_m3_s : (n,) array_like, m³/s
        Total flows, > 0; solved in ascending order, returned in the given order.
    tol : float, keyword-only
        Relative residual: max pore imbalance (and inlet flow error) / Q (default 1e-10).
    maxiter : int, keyword-only
        Newton iterations per flow (default 30).
    amg : AMGSolver, optional
        Hierarchy of the condensed Stokes matrix (built here when not given).
    onset_scale : (Nt, 2) or (Nt,) array_like, optional, s/m³
        Window-Reynolds onset of :func:`conduit_flow`; None: the loss is K q|q| from the start.
    workers : int, keyword-only
        Processes (default 1): the sorted flows are cut into ``workers`` contiguous
        continuation chains (:func:`_chain_sizes`; at least 4 flows per chain on average),
        solved side by side in forked processes; each chain converges every flow to ``tol``
        as one chain would.
    stokes : (pressures (Np,), flow), optional
        A Stokes solution of the same network (pressures in Pa, outlet 0, and its total flow
        in m³/s): the first flow of each chain starts from it scaled to that flow instead
        of from rest (whose first Newton step is that Stokes solution, solved loosely).

    Returns
    -------
    list of InertialPoint
    """
    c = np.asarray(conns, dtype=np.int64)
    g = np.asarray(g, dtype=float)
    K = np.asarray(K, dtype=float)
    flows = np.asarray(flows_m3_s, dtype=float)
    if int(workers) < 1:
        raise ValueError(f"workers must be >= 1, got {workers!r}")
    if np.any(~np.isfinite(flows)) or np.any(flows <= 0) or flows.ndim != 1 or not flows.size:
        raise ValueError(f"flows must be a non-empty list of finite values > 0, got {flows}")
    if np.any(g <= 0) or np.any(~np.isfinite(g)):
        raise ValueError("conductances must be finite and > 0 (prune closed throats first)")
    if np.any(K < 0) or np.any(~np.isfinite(K)):
        raise ValueError("inertial coefficients must be finite and >= 0")
    c_on = None if onset_scale is None else np.asarray(onset_scale, dtype=float)
    if c_on is not None and (c_on.shape[0] != g.size or np.any(c_on < 0)
                             or np.any(~np.isfinite(c_on))):
        raise ValueError(f"onset_scale must have {g.size} rows, finite and >= 0")
    inlet = np.asarray(inlet, dtype=np.int64)
    outlet = np.asarray(outlet, dtype=np.int64)
    is_in = np.zeros(n_pores, bool)
    is_in[inlet] = True
    fixed = is_in.copy()
    fixed[outlet] = True
    free = np.flatnonzero(~fixed)
    nf = free.size
    # reduced index of every pore: free pores 0..nf-1, all inlet pores one node nf, outlet -1
    red = np.full(n_pores, -1, dtype=np.int64)
    red[free] = np.arange(nf)
    red[inlet] = nf
    J = _BorderedLaplacian(red[c[:, 0]], red[c[:, 1]], nf + 1)
    if amg is None:
        amg = AMGSolver(J.matrix(g)[:nf, :nf], smoother="forward-backward")
    i, j = c[:, 0], c[:, 1]

    # throats with exactly one end in the inlet: the total inlet flow is sum(sgn q) over them
    edge = np.flatnonzero(is_in[i] != is_in[j])
    e_sgn = np.where(is_in[i[edge]], 1.0, -1.0)
    e_K = K[edge]
    e_c = None if c_on is None else c_on[edge]

    def match_inlet(p, Q):
        """p scaled by the s that makes the total inlet flow Q (Newton on s over the inlet
        throats alone; the predicted pressures carry the flow's shape, their level is
        what an extrapolation misses most)."""
        d = p[i[edge]] - p[j[edge]]
        s = 1.0
        for _ in range(8):
            q, w = conduit_flow(s * d, g[edge], e_K, onset_scale=e_c)
            f = e_sgn @ q - Q
            df = e_sgn @ (w * d)
            if not df > 0:
                return p
            step = f / df
            s = min(max(s - step, 0.5 * s), 2.0 * s)
            if abs(f) <= 1e-3 * tol * Q:
                break
        return s * p

    def residual(p, Q, q_start=None):
        q, w = conduit_flow(p[i] - p[j], g, K, onset_scale=c_on,
                            q_start=q_start)
        net = np.bincount(i, q, n_pores) - np.bincount(j, q, n_pores)
        return np.append(net[free], net[inlet].sum() - Q), q, w

    def chain(ks):
        """Solve the flows ``flows[ks]`` (ascending) in turn, each from the last ones."""
        state = {"amg": amg, "prec": amg.preconditioner()}

        def solve(Jw, b, eta, refresh):
            """Bordered system by CG; preconditioner: the exact block inverse of
            [[M^-1, j], [j^T, J_PP]] with M the AMG V-cycle of the free block (one V-cycle)."""
            if refresh:     # first step of a new flow: the held aggregation, this Jacobian
                state["prec"] = state["amg"].preconditioner(Jw[:nf, :nf])

            def prec():
                Mf = state["prec"].matvec
                jf = Jw[[nf], :nf].toarray().ravel()
                z = Mf(jf)
                schur = Jw[nf, nf] - jf @ z
                if not schur > 0:                   # V-cycle too far off: block diagonal
                    z, schur = np.zeros(nf), Jw[nf, nf]

                def apply(r):
                    yP = (r[nf] - z @ r[:nf]) / schur
                    return np.append(Mf(r[:nf]) - z * yP, yP)
                return sparse_linalg.LinearOperator(Jw.shape, matvec=apply, dtype=float)

            x, info = _cg(Jw, b, prec(), eta)
            if info[1] > _REBUILD_ITERATIONS:
                log.info("CG needed %d iterations on the Jacobian: building its own hierarchy",
                         info[1])
                state["amg"] = AMGSolver(Jw[:nf, :nf], smoother="forward-backward")
                state["prec"] = state["amg"].preconditioner()
                x, info2 = _cg(Jw, b, prec(), eta)
                info = (info2[0], info[1] + info2[1])
            return x, info

        done = []
        p = np.zeros(n_pores)
        hist: list[tuple[float, np.ndarray]] = []
        for k in ks:
            Q = flows[k]
            t0 = time.perf_counter()
            if hist:
                p = _predict(hist, Q, p)
            elif stokes is not None:
                p = np.asarray(stokes[0], dtype=float) * (Q / float(stokes[1]))
            if hist or stokes is not None:
                p = match_inlet(p, Q)
            r, q, w = residual(p, Q)
            rel = np.abs(r).max() / Q
            it = cg_it = 0
            while rel > tol and it < maxiter:
                it += 1
                # inexact Newton (forcing term eta ~ rel, so the step keeps Newton's quadratic
                # rate) but never tighter than what brings the residual 10x below the target
                eta = float(np.clip(max(0.1 * tol / rel, min(rel, 1e-2)), 1e-13, 1e-2))
                with one_blas_thread():
                    x, info = solve(J.matrix(w), -r, eta, refresh=it == 1 and bool(hist))
                cg_it += info[1]
                log.debug("Newton %d: residual %.2e, eta %.1e, %d CG", it, rel, eta, info[1])
                dp = np.zeros(n_pores)
                dp[free] = x[:nf]
                dp[inlet] = x[nf]
                step = 1.0
                for _ in range(30):
                    r2, q2_, w2 = residual(p + step * dp, Q, q)
                    rel2 = np.abs(r2).max() / Q
                    if rel2 < rel or rel2 <= tol:
                        break
                    step *= 0.5
                p = p + step * dp
                r, q, w, rel = r2, q2_, w2, rel2
            P = float(p[inlet[0]])
            hist.append((Q, p.copy()))
            del hist[:-3]                   # _predict uses the last three
            done.append((k, InertialPoint(float(Q), P, bool(rel <= tol), it, cg_it, float(rel),
                                          time.perf_counter() - t0, p.copy(), q.copy())))
            log.info("Q %.4g m3/s: dP %.5g Pa, %d Newton / %d CG iterations, residual %.1e",
                     Q, P, it, cg_it, rel)
        return done

    order = np.argsort(flows, kind="stable")
    n_chains = max(1, min(int(workers), flows.size // _MIN_CHAIN))
    chains = np.split(order, np.cumsum(_chain_sizes(flows.size, n_chains))[:-1])
    out: list[InertialPoint | None] = [None] * flows.size
    for k, pt in _run_chains(chain, chains):
        out[k] = pt
    return out


def _predict(hist, Q, p):
    """Start of the flow Q from the solved ``hist`` [(flow, pressures), ...] (ascending; ``p``
    the last pressures): every pore's pressure follows its own power law of the last two
    flows, or with three, a parabola in log p against log Q through them, kept between
    p2 (Q/q2)^1 and p2 (Q/q2)^2 (the viscous and the fully inertial limits); with one flow (or
    two equal ones), p scaled by Q/q."""
    if len(hist) < 2 or hist[-1][0] == hist[-2][0]:
        return p * (Q / hist[-1][0])
    (q1, p1), (q2, p2) = hist[-2], hist[-1]
    lo, hi = p2 * (Q / q2), p2 * (Q / q2) ** 2
    with np.errstate(divide="ignore", invalid="ignore"):
        expo = np.log(p2 / p1) / np.log(q2 / q1)
        expo = np.where((p1 > 0) & (p2 > 0) & np.isfinite(expo), expo, 1.0)
        p = p2 * (Q / q2) ** np.clip(expo, 1.0, 2.0)
        if len(hist) >= 3 and hist[-3][0] != q1:
            q0, p0 = hist[-3]
            x0, x1, x2, x = np.log([q0, q1, q2, Q])
            y = (np.log(p0) * (x - x1) * (x - x2) / ((x0 - x1) * (x0 - x2))
                 + np.log(p1) * (x - x0) * (x - x2) / ((x1 - x0) * (x1 - x2))
                 + np.log(p2) * (x - x0) * (x - x1) / ((x2 - x0) * (x2 - x1)))
            ok = (p0 > 0) & (p1 > 0) & (p2 > 0) & np.isfinite(y)
            p = np.where(ok, np.clip(np.exp(y), lo, hi), p)
    return p


#: Fewest flows per continuation chain: a chain's first flow starts cold (one Newton step
#: more), so shorter chains do not pay for their process.
_MIN_CHAIN = 4

#: Flows a chain that starts cold (from the Stokes solution scaled to a flow high on the
#: curve) gives up to the first chain: its first flow costs about three warm ones (20 000
#: spheres: 130 CG iterations against 40-60).
_COLD_START_FLOWS = 2


def _chain_sizes(n: int, chains: int) -> list[int]:
    """Lengths of ``chains`` contiguous runs of ``n`` sorted flows: the runs after the first
    :data:`_COLD_START_FLOWS` shorter than it, the last taking what is left (12 flows, 2
    chains: 7 and 5; 3 chains: 6, 4 and 2)."""
    first = -(-(n + _COLD_START_FLOWS * (chains - 1)) // chains)
    sizes = [first] + [max(1, first - _COLD_START_FLOWS)] * (chains - 1)
    sizes[-1] = n - sum(sizes[:-1])
    return sizes


#: The chain function of the running :func:`solve_inertial`, for the forked workers.
_CHAIN = None


def _chain_job(ks):
    return _CHAIN(ks)


def _run_chains(chain, chains):
    """Run ``chain`` on every list of flow indices: in this process for one list, else in
    forked processes (they inherit the network and the AMG hierarchy; POSIX only: where
    ``fork`` is not available the chains run one after the other here)."""
    global _CHAIN
    if len(chains) == 1:
        return chain(chains[0])
    # the process machinery (0.02 s of imports) only where several chains run
    import multiprocessing as mp
    from concurrent.futures import ProcessPoolExecutor

    if "fork" not in mp.get_all_start_methods():
        return [kp for ks in chains for kp in chain(ks)]
    _CHAIN = chain
    try:
        with ProcessPoolExecutor(len(chains), mp_context=mp.get_context("fork")) as ex:
            return [kp for res in ex.map(_chain_job, chains) for kp in res]
    finally:
        _CHAIN = None


def _cg(J, b, M, eta):
    """CG on J x = b to ``eta`` relative, preconditioned by M: (x, (flag, iterations))."""
    n_it = [0]

    def count(_):
        n_it[0] += 1

    bn = np.linalg.norm(b)
    if bn == 0:
        return np.zeros_like(b), (0, 0)
    x, flag = sparse_linalg.cg(sp.csr_array(J), b, rtol=eta, atol=0.0, maxiter=300, M=M,
                               callback=count)
    return x, (flag, n_it[0])


class _BorderedLaplacian:
    """Weighted graph Laplacian on reduced nodes (index -1: a fixed node, dropped), its CSR
    pattern built once; :meth:`matrix` refills the data for new weights by one bincount."""

    def __init__(self, ri, rj, n):
        rows = np.concatenate([ri, rj, ri, rj])
        cols = np.concatenate([ri, rj, rj, ri])
        sign = np.concatenate([np.ones(2 * ri.size), -np.ones(2 * ri.size)])
        keep = (rows >= 0) & (cols >= 0)
        self._m = ri.size
        key = rows[keep] * n + cols[keep]
        uniq, self._pos = np.unique(key, return_inverse=True)
        self._src = np.flatnonzero(keep) % ri.size        # throat of each entry
        self._sign = sign[keep]
        r_u = uniq // n
        self._indices = (uniq % n).astype(np.int32)
        self._indptr = np.searchsorted(r_u, np.arange(n + 1)).astype(np.int32)
        self.n = n

    def matrix(self, w):
        data = np.bincount(self._pos, weights=self._sign * w[self._src],
                           minlength=self._indices.size)
        return sp.csr_array((data, self._indices, self._indptr), shape=(self.n, self.n))
