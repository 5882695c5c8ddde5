r"""The signed flow of one conduit under its nonlinear law, vectorised over conduits.

A conduit obeys :math:`\Delta p = q/g + K_\pm\, q|q|\,\phi` (:mod:`network.conductance._inertial`;
φ = 1, or the window-Reynolds onset factor): :func:`conduit_flow` inverts it for q and its slope
w = dq/dΔp, the weights of :func:`network.flow.solve_inertial`'s Jacobian.
"""

from __future__ import annotations

import numpy as np

__all__ = ["conduit_flow"]


def conduit_flow(dp, g, K, *, onset_scale=None, q_start=None):
    r"""Signed conduit flows q and slopes w = dq/dΔp for pressure drops ``dp`` (module formula).

    ``K`` is (Nt, 2) (direction-dependent) or (Nt,). K = 0 gives q = g Δp exactly. With
    ``onset_scale`` c (per conduit, s/m³) the inertial loss sets in with the window Reynolds
    number: :math:`\Delta p = q/g + K q|q|\,t/\sqrt{1+t^2}`, :math:`t = c|q| = Re_w/Re_c`
    (:func:`network.conductance.onset_scales`); q is found by Newton from an upper bound,
    monotone onto the root, and ``q_start`` (signed flows of a nearby state) starts that Newton
    where the sign is kept (same root). Without it the loss is :math:`K q|q|` from the start
    (the limit c → ∞), solved in closed form.

    >>> q, w = conduit_flow(np.array([1.5, -1.5]), np.array([1.0, 1.0]), np.array([0.5, 0.5]))
    >>> q.tolist(), w.tolist()
    ([1.0, -1.0], [0.5, 0.5])
    """
    K = np.asarray(K, dtype=float)
    k = np.where(dp >= 0, K[:, 0], K[:, 1]) if K.ndim == 2 else K
    a = np.abs(dp)
    inv_g = 1.0 / g
    if onset_scale is not None:
        c = np.asarray(onset_scale, dtype=float)
        c = np.where(dp >= 0, c[:, 0], c[:, 1]) if c.ndim == 2 else c
        return _throat_onset_flow(dp, a, g, inv_g, k, c, q_start)
    q = 2.0 * a / (inv_g + np.sqrt(inv_g**2 + 4.0 * k * a))
    w = 1.0 / (inv_g + 2.0 * k * q)
    return np.sign(dp) * q, w


def _upper_bound(a, g, k, b, live):
    """Newton's start above the root: the positive root of k q² + b q = |Δp| (b of either
    sign), at most g|Δp|; g|Δp| (the Stokes flow) where ``live`` is False."""
    disc = np.sqrt(b * b + 4.0 * k * a)
    with np.errstate(divide="ignore", invalid="ignore"):
        up = np.where(b > 0, 2.0 * a / (b + disc), (disc - b) / (2.0 * k))
    return np.where(live, np.minimum(g * a, np.nan_to_num(up, nan=np.inf, posinf=np.inf)), g * a)


def _throat_onset_flow(dp, a, g, inv_g, k, c, q_start=None):
    r"""|Δp| = q/g + k q² φ(cq), φ(t) = t/√(1+t²): Newton from an upper bound
    (φ(t) >= 1 - 1/t bounds q by the root of k q² + (1/g - k/c) q = |Δp|, and by g|Δp|);
    the residual is convex and increasing in q (d²/dt² t³/√(1+t²) >= 0), so the iterates
    descend onto the root. ``q_start`` (signed flows of a nearby state, e.g. the last Newton
    iterate of the network) starts the rows whose flow keeps its sign there instead: from
    below the root the first step lands above it (convexity), then the descent is monotone."""
    with np.errstate(divide="ignore", invalid="ignore"):
        b = inv_g - np.where(c > 0, k / c, 0.0)
    live = (k > 0) & (c > 0)
    q = _upper_bound(a, g, k, b, live)
    if q_start is not None:
        qs = np.asarray(q_start, dtype=float)
        warm = live & (qs * dp > 0)
        q = np.where(warm, np.minimum(q, np.abs(qs)), q)
    # Newton on the rows not yet converged only (most settle in a few steps, a few need more)
    act = np.flatnonzero(live)
    qa, ia, ka, ca, aa = q[act], inv_g[act], k[act], c[act], a[act]
    for _ in range(60):
        if not act.size:
            break
        t = ca * qa
        t2 = t * t
        s2 = 1.0 + t2
        kqt = ka * qa * t
        kqt /= np.sqrt(s2)                          # k q phi(t)
        f = qa * (ia + kqt) - aa
        kqt *= (3.0 + 2.0 * t2) / s2                # d(k q^2 phi)/dq = k q phi (3 + 2t^2)/(1+t^2)
        kqt += ia
        step = f / kqt
        qa -= step
        np.maximum(qa, 0.0, out=qa)
        done = np.abs(step) <= 1e-9 * qa              # quadratic: the error left is ~step^2
        if done.any():
            q[act[done]] = qa[done]
            keep = ~done
            act, qa, ia, ka, ca, aa = act[keep], qa[keep], ia[keep], ka[keep], ca[keep], aa[keep]
    q[act] = qa
    t = c * q
    s2 = 1.0 + t * t
    w = 1.0 / (inv_g + k * q * t * (3.0 + 2.0 * t * t) / (s2 * np.sqrt(s2)))
    return np.sign(dp) * q, w
