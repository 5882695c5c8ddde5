r"""Conduit conductance model: pore body → window → pore body resistance from the geometry.

Derivation, validation tables and where the model misses: ``docs/conduit-model.md``.

The conduit on side P of a throat runs from the face (h = 0) along its normal to the height
:math:`h_P` of the pore body's centre. Its section at height h is the face triangle minus the
sections of the three vertex spheres, disks of radius :math:`\rho_k(h) = \sqrt{r_k^2 - h^2}`,
an ordinary throat shape that ``throats``/``cache`` answer with :math:`Q^*`. With
:math:`y = 1/(Q^*\bar\rho^4)` and the slope of the equivalent tube radius
:math:`a_{eq} = (8 Q^*\bar\rho^4/\pi)^{1/4}` (second-order slowly-varying-tube theory,
Manton 1971, in a bounded form)

.. math:: R_P = \mu \int_0^{H_P} y(h)\Bigl[1 + \frac{s}{1+s}\Bigr] dh,
          \qquad s = \tfrac43 a_{eq}'(h)^2, \qquad H_P = \min(h_P, \max_k r_k),

and :math:`g = 1/(R_P + R_Q)` (m³ Pa⁻¹ s⁻¹). Throats inside one merged pore body get
``internal_factor`` times the largest conduit conductance (one pressure node); a hull face
counts its one side twice; a closed window (Q* = 0) has g = 0.

Accuracy (FE Q*, sample core): simple cubic 1.087-1.099 of Zick & Homsy (1982), BCC
0.871-0.989, FCC 0.979-1.020 of Stokes FE of the cell, random packings at porosity 0.36-0.45
1.4-5.4 % above the LBM law of van der Hoef et al. (2005); the thesis model gives 0.24-0.63.
"""

from __future__ import annotations

import logging
import time
from concurrent.futures import ThreadPoolExecutor

import numpy as np

import throats

from .._air import MU_AIR_PA_S, check_viscosity
from .._json import jsonable
from ..pores import PoreMerge, merge_pores
from ._qstar import qstar_from_function, throat_qstar as policy_qstar
from ._result import ConductanceResult

__all__ = [
    "SECTION_MODES",
    "section_estimate",
    "side_resistance",
    "conduit_conductance",
]

logger = logging.getLogger(__name__)

#: How section flow rates are obtained: closed-form ratio to the window, or Q* per section.
SECTION_MODES = ("ratio", "qstar")


def section_estimate(rho, sides):
    r"""Closed-form flow-rate estimate of throat sections: Happel's cell model.

    The section (triangle with a disk at each vertex, symmetry on the edges) is a cell of a
    2-D array of cylinders with flow along their axes. Happel's (1959) free-surface cell model
    of that flow (AIChE J. 5:174; also Sparrow & Loeffler 1959 for exact square and hexagonal
    arrays) gives the permeability :math:`K = (b^2/4) f(\phi)` of a cell of radius b, with

    .. math:: f(\phi) = -\ln\phi - \tfrac32 + 2\phi - \tfrac12\phi^2,
              \qquad \phi = 1 - A/A_\triangle,

    the solid fraction of the section (A: exact open area, :func:`throats.open_area`;
    :math:`A_\triangle`: triangle area). The disks' angles at the vertices add up to
    :math:`\pi`, so a triangle holds half a cylinder and is half a cell,
    :math:`\pi b^2 = 2A_\triangle`, and the flow rate per unit pressure gradient is

    .. math:: Q \approx K A_\triangle = \frac{A_\triangle^2}{2\pi} f(\phi).

    Against FE on the simple-cubic section (right isosceles triangle, legs 1, equal disks
    :math:`\rho`): -0.7, -1.2, -2.8, -4.5, -7.5, -13, -24 % at :math:`\rho` = 0.05, 0.1, 0.2, 0.25,
    0.3, 0.35, 0.4 (the cell model is a dilute theory), where the previous estimate
    :math:`A^3/(2P_w^2)` was 18, 7.1, 3.2, 2.5, 2.1, 1.7, 1.4 times FE. Used for ratios
    :math:`Q(h)/Q(h')` along one conduit: all sections share the triangle, so the ratio
    depends on the solid fractions alone. :math:`f` falls to 0 as :math:`(1-\phi)^3/3` when
    the disks close the section.

    Parameters
    ----------
    rho : (N, 3) array_like
        Disk radii at the vertices (0 allowed), any length unit.
    sides : (N, 3) array_like
        [l12, l13, l23], same unit.

    Returns
    -------
    q : (N,) ndarray
        Flow rate per unit pressure gradient times viscosity, unit⁴; ``inf`` where no disk
        is left (no wall).

    Examples
    --------
    Square array of cylinders of radius 0.1 (spacing 1), half a cell; FE gives 0.0814:

    >>> round(float(section_estimate([[0.1] * 3], [[1.0, 1.0, 2 ** 0.5]])[0]), 4)
    0.0805
    """
    rho = np.asarray(rho, dtype=float)
    s = np.asarray(sides, dtype=float)
    q = np.full(rho.shape[0], np.inf)
    live = rho.max(axis=1) > 0
    if not live.any():
        return q
    # throats.open_area wants positive radii: a vanished disk becomes a point (area 1e-24 l²)
    point = 1e-12 * s[live].min(axis=1, keepdims=True)
    area = throats.open_area(np.maximum(rho[live], point), s[live])
    a_tri = throats.triangle_area(s[live])
    phi = np.clip(1.0 - area / a_tri, 0.0, 1.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        f = -np.log(phi) - 1.5 + 2.0 * phi - 0.5 * phi**2
        q[live] = np.where(phi > 0, a_tri**2 * np.maximum(f, 0.0) / (2.0 * np.pi), np.inf)
    return q


def _section_radii(radii, h):
    """Disk radii (N, m, 3) of the sections at heights h (N, m)."""
    out = np.square(radii)[:, None, :] - np.square(h)[..., None]     # same bits as r**2 - h**2
    np.maximum(out, 0.0, out=out)
    return np.sqrt(out, out=out)


def _colmax(a):
    """Largest entry along the last axis (length 2 or 3): np.max(a, axis=-1), same values,
    without numpy's slow reduction over a short axis."""
    out = np.maximum(a[..., 0], a[..., 1])
    for c in range(2, a.shape[-1]):
        np.maximum(out, a[..., c], out=out)
    return out


def side_resistance(radii, sides, h_side, y_window, *, n_sections: int = 8,
                    section_q=None):
    r"""Viscosity-free resistance :math:`R_P/\mu` of N conduit halves (unit⁻³).

    .. math:: \frac{R_P}{\mu} = \int_0^{H_P} y\,\Bigl[1 + \frac{s}{1+s}\Bigr] dh,\quad
              s = \tfrac43 a_{eq}'^2 = \frac{1}{12}\sqrt{\frac{8}{\pi y}}\Bigl(\frac{y'}{y}\Bigr)^2

    Parameters
    ----------
    radii, sides : (N, 3) array_like
        The window's sphere radii and side lengths (one length unit).
    h_side : (N,) or (N, k) array_like
        Height of the pore centre above the face plane (same unit), >= 0; with k columns
        (the two sides of a throat) all sides share one set of sections, sampled up to the
        largest height, and each is integrated up to its own.
    y_window : (N,) array_like
        :math:`1/(Q^*\bar r^4)` of the window (unit⁻⁴); ``inf`` for a closed window.
    n_sections : int, keyword-only
        Intervals per side (default 8).
    section_q : callable or None, keyword-only
        ``section_q(rho (M,3), sides (M,3)) -> (M,)`` flow rate of sections (unit⁴, inf when
        no wall, NaN when the source cannot answer reliably: such a section is continued
        from the last answered one by :func:`section_estimate` ratios). None: the window
        value scaled by :func:`section_estimate` ratios.

    Returns
    -------
    (N,) or (N, k) ndarray
        Resistance divided by viscosity; 0 where ``h_side`` is 0, ``inf`` for closed windows.

    Examples
    --------
    A section that does not change (here: h beyond the disks is cut off, radii 0) gives
    ``y * h``; with no disk at all the conduit has no wall and no resistance:

    >>> float(side_resistance([[0., 0., 0.]], [[1., 1., 1.]], [0.5], [2.0])[0])
    0.0
    """
    radii = np.asarray(radii, dtype=float)
    sides = np.asarray(sides, dtype=float)
    h_side = np.asarray(h_side, dtype=float)
    one = h_side.ndim == 1
    hs = h_side[:, None] if one else h_side                      # (N, k) sides
    y0 = np.asarray(y_window, dtype=float)
    n = radii.shape[0]
    m = int(n_sections)
    if m < 2:
        raise ValueError(f"n_sections must be >= 2, got {n_sections!r}")
    rmax = _colmax(radii)
    H = np.minimum(np.maximum(hs, 0.0), rmax[:, None])           # (N, k)
    Hmax = _colmax(H) if H.shape[1] > 1 else H[:, 0]
    # one set of nodes serves every side of a throat (the sections depend on h only),
    # uniform in theta with h = rmax sin(theta): the disks shrink smoothly,
    # rho_k = sqrt(r_k^2 - h^2), and the nodes gather where the sphere walls turn steep
    with np.errstate(invalid="ignore", divide="ignore"):
        th_end = np.arcsin(np.clip(np.where(rmax > 0, Hmax / rmax, 0.0), 0.0, 1.0))
    t = np.linspace(0.0, 1.0, m + 1)
    theta = th_end[:, None] * t[None, :]                          # (N, m+1)
    h = rmax[:, None] * np.sin(theta)
    dhdth = rmax[:, None] * np.cos(theta)
    rho = _section_radii(radii, h)                               # (N, m+1, 3)
    flat_rho = rho.reshape(-1, 3)
    if section_q is None:
        q = section_estimate(flat_rho, np.repeat(sides, m + 1, axis=0)).reshape(n, m + 1)
        with np.errstate(divide="ignore", invalid="ignore"):
            y = np.where(np.isinf(q), 0.0, y0[:, None] * q[:, :1] / q)
        y[:, 0] = y0
    else:
        q = np.full(n * (m + 1), np.inf)
        # the window (node 0) is y_window already; sections with no disk left have no wall
        live = _colmax(rho) > 0                                  # (N, m+1)
        live[:, 0] = False
        live &= (Hmax > 0)[:, None]
        idx = np.flatnonzero(live)
        if idx.size:
            q[idx] = section_q(flat_rho[idx], sides[idx // (m + 1)])
        q = q.reshape(n, m + 1)
        with np.errstate(divide="ignore", invalid="ignore"):
            y = np.where(np.isinf(q), 0.0, 1.0 / q)
        y[:, 0] = y0
        miss = np.isnan(y)
        if miss.any():
            # sections the Q* source could not answer reliably (outside the table: NaN) are
            # continued from the last answered section by closed-form ratios
            bad = np.flatnonzero(miss.any(axis=1))
            mb = miss[bad]
            ce = section_estimate(rho[bad].reshape(-1, 3),
                                  np.repeat(sides[bad], m + 1, axis=0)).reshape(-1, m + 1)
            j = np.arange(m + 1)[None, :]
            last = np.maximum.accumulate(np.where(~mb, j, 0), axis=1)
            rows = np.arange(bad.size)[:, None]
            yb = y[bad]
            with np.errstate(divide="ignore", invalid="ignore"):
                cont = np.where(np.isinf(ce), 0.0, yb[rows, last] * ce[rows, last] / ce)
            y[bad] = np.where(mb, cont, yb)
    fin = np.isfinite(y)
    closed = ~np.isfinite(y0)
    for c in range(m + 1):                                      # any(~fin, axis=1), by columns
        closed |= ~fin[:, c]
    y = np.where(fin, y, 0.0)
    dth = np.maximum(th_end / m, 1e-300)
    with np.errstate(divide="ignore", invalid="ignore"):
        dy = np.gradient(y, axis=1) / dth[:, None] / dhdth
    dy[:, 0] = 0.0                                              # symmetry at the window
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        s = np.sqrt(8.0 / (np.pi * y)) * (dy / y) ** 2 / 12.0
        f = np.where(y > 0, 1.0 + s / (1.0 + s), 1.0)
    f = np.where(np.isnan(f), 2.0, f)                           # s = inf/inf: steep wall
    F = y * f                                                   # (N, m+1)
    seg = 0.5 * (F[:, 1:] + F[:, :-1]) * np.diff(h, axis=1)     # (N, m)
    C = np.concatenate([np.zeros((n, 1)), np.cumsum(seg, axis=1)], axis=1)
    R = np.empty_like(H)
    rows = np.arange(n)
    for c in range(H.shape[1]):
        Hc = H[:, c]
        # the segment [h_{j-1}, h_j] holding Hc; trapezoid up to h_{j-1}, then the part
        # segment with F linearly interpolated
        below = Hc * (1 - 1e-12)
        j = np.zeros(n, dtype=np.int64)
        for c2 in range(m + 1):                                 # nodes below Hc, by columns
            j += h[:, c2] < below
        np.clip(j, 1, m, out=j)
        h0, h1 = h[rows, j - 1], h[rows, j]
        F0, F1 = F[rows, j - 1], F[rows, j]
        with np.errstate(divide="ignore", invalid="ignore"):
            w = np.where(h1 > h0, (Hc - h0) / (h1 - h0), 0.0)
        w = np.clip(w, 0.0, 1.0)
        R[:, c] = C[rows, j - 1] + (Hc - h0) * (F0 + 0.5 * w * (F1 - F0))
    R = np.where(H > 0, R, 0.0)
    R = np.where(closed[:, None], np.inf, R)
    return R[:, 0] if one else R


def conduit_conductance(tessellation, throats_idx=None, *, viscosity_pa_s: float = MU_AIR_PA_S,
                        policy: str = "table+fe", rtol: float = 1e-3, db=None,
                        workers: int = 1, progress: bool = False, sections: str = "qstar",
                        n_sections: int = 6, merge: PoreMerge | bool = True,
                        merge_tolerance: float = 0.02, internal_factor: float = 1e6,
                        qstar_fn=None, section_rtol: float | None = None, threads: int = 1):
    r"""Conduit-model conductance of throats, m³ Pa⁻¹ s⁻¹ (module docstring for the model).

    Parameters
    ----------
    tessellation : Tessellation
    throats_idx : (M,) array_like of int or None
        Throats to evaluate (default all).
    viscosity_pa_s : float, keyword-only
        μ (default 1.932e-5 Pa s, air as in the thesis).
    policy, rtol, db, workers, progress : keyword-only
        Q* policy and options, as ``network._conductance.throat_qstar``.
    sections : {'qstar', 'ratio'}, keyword-only
        'qstar' (default): the Q* policy answers every section (n_sections + 1 per throat);
        'ratio': the policy answers the window only, the profile comes from
        :func:`section_estimate` ratios (fast, but 18-44 % too permeable on simple cubic
        arrays: the cell model overstates how fast nearly closed sections open).
    n_sections : int, keyword-only
        Intervals of the shared section grid (default 6; simple cubic arrays: +8.7 to +9.9 %
        against Zick & Homsy with 6, +7.6 to +8.7 % with 8, +6.1 to +7.0 % converged;
        random packings change by < 0.5 % from 6 to 12).
    merge : PoreMerge or bool, keyword-only
        Pore bodies from :func:`network._merge.merge_pores` (True: computed here with
        ``merge_tolerance``; False: every tetrahedron is its own pore body).
    merge_tolerance : float, keyword-only
        Co-sphericity tolerance when ``merge`` is True (default 0.02).
    internal_factor : float, keyword-only
        Conductance of throats inside a merged body, relative to the largest conduit
        conductance of this call (default 1e6).
    section_rtol : float or None, keyword-only
        Q* tolerance for the sections away from the window (default ``max(rtol, 1e-2)``:
        a 1 % error there changes the conduit resistance by well under 1 %, and with
        'table+fe' a tighter tolerance sends many sections to FE).
    qstar_fn : callable or None, keyword-only
        ``qstar_fn(radii (M,3), sides (M,3)) -> (M,)`` Q* in r̄ units, used instead of the
        policy (tests, or a caller with its own Q* source). Default: the policy.
    threads : int, keyword-only
        Threads over the blocks of throats (default 1). Used for the 'table-only' and
        'shape-factor' policies without ``qstar_fn`` (numpy and the table lookups release the
        GIL; FE and the table's SQLite writes stay in one thread); the result does not depend
        on it (every row is computed alone). Two threads: 0.99 -> 0.57 s for the 249 000
        throats of the 20 000-sphere bench packing.

    Returns
    -------
    ConductanceResult
        ``g`` (M,) m³ Pa⁻¹ s⁻¹, window ``qstar``, conduit heights ``h_m`` (M, 2), ``internal``;
        ``stats``: sections, n_sections, merge summary, n_internal, qstar_stats (the windows),
        section_qstar_stats (the sections away from the windows: count and Q* sources, e.g.
        how many ran FE), seconds.

    Raises
    ------
    ValueError
        Unknown ``sections``, non-positive viscosity, bad indices.
    """
    def throat_qstar(r_, s_, **kw):
        if qstar_fn is None:
            return policy_qstar(r_, s_, **kw)
        return qstar_from_function(qstar_fn, r_, s_)

    t0 = time.perf_counter()
    if sections not in SECTION_MODES:
        raise ValueError(f"unknown sections mode {sections!r}; choose one of {SECTION_MODES}")
    mu = check_viscosity(viscosity_pa_s)
    t = tessellation
    idx = np.arange(t.n_throats) if throats_idx is None else np.asarray(throats_idx, np.int64)
    if idx.size and (idx.min() < 0 or idx.max() >= t.n_throats):
        raise ValueError(f"throat indices must lie in [0, {t.n_throats})")
    if merge is True:
        pm = merge_pores(t, tolerance=merge_tolerance)
    elif merge is False or merge is None:
        n_p = t.n_pores
        pm = PoreMerge(np.arange(n_p), n_p, np.ones(n_p, dtype=np.int64), t.pore_centroid,
                       np.zeros(t.n_throats, dtype=bool), 0.0)
    elif isinstance(merge, PoreMerge):
        pm = merge
    else:
        raise TypeError(f"merge must be a PoreMerge or bool, got {type(merge).__name__}")

    radii = t.throat_radii[idx]
    sides = t.throat_sides[idx]
    tp = t.throat_pores[idx]
    internal = pm.internal_throat[idx]
    # conduit heights: normal distance from the face plane to each pore body centre
    xyz = t.packing.centers[t.throat_vertices[idx]]
    nrm = np.cross(xyz[:, 1] - xyz[:, 0], xyz[:, 2] - xyz[:, 0])
    nrm /= np.maximum(np.sqrt(nrm[:, 0] * nrm[:, 0] + nrm[:, 1] * nrm[:, 1]
                              + nrm[:, 2] * nrm[:, 2]), 1e-300)[:, None]
    h = np.zeros((idx.size, 2))
    for side in (0, 1):
        pore = tp[:, side]
        ok = pore >= 0
        cen = pm.center[pm.labels[pore[ok]]]
        h[ok, side] = np.abs(np.einsum("ij,ij->i", cen - xyz[ok, 0], nrm[ok]))
    hull = tp[:, 1] < 0
    h[hull, 1] = h[hull, 0]

    need = ~internal
    g = np.zeros(idx.size)
    qstar = np.full(idx.size, np.nan)
    qstats: dict = {}
    section_stats = {"n_sections": 0, "sources": {}}
    srtol = max(rtol, 1e-2) if section_rtol is None else float(section_rtol)
    rows = np.flatnonzero(need)
    threads = int(threads)
    if threads < 1:
        raise ValueError(f"threads must be >= 1, got {threads}")
    if qstar_fn is not None or policy not in ("table-only", "shape-factor"):
        threads = 1
    # blocks of throats bound the memory of the section arrays (n_sections + 1 sections of
    # each throat and the table's temporaries: 3 GB at 100 000 spheres in one block); with
    # threads, at least one block per thread
    size = max(1, min(_BLOCK, -(-rows.size // threads)))
    blocks = [rows[a:a + size] for a in range(0, rows.size, size)]

    def block(blk):
        stats = {"n_sections": 0, "sources": {}}
        out = _conduit_block(radii[blk], sides[blk], h[blk], mu, stats, throat_qstar,
                             sections=sections, n_sections=n_sections,
                             qkw=dict(policy=policy, rtol=rtol, db=db, workers=workers,
                                      progress=progress, estimate=False),
                             srtol=srtol)
        return out + (stats,)

    if threads > 1 and len(blocks) > 1:
        with ThreadPoolExecutor(min(threads, len(blocks))) as pool:
            parts = list(pool.map(block, blocks))
    else:
        parts = [block(blk) for blk in blocks]
    for blk, (q_win, gg, st, sst) in zip(blocks, parts):
        qstar[blk] = q_win
        g[blk] = gg
        qstats = _merge_stats(qstats, st)
        section_stats["n_sections"] += sst["n_sections"]
        for kind, count in sst["sources"].items():
            section_stats["sources"][kind] = section_stats["sources"].get(kind, 0) + count
    finite = g[need & np.isfinite(g)]
    g_big = internal_factor * (finite.max() if finite.size and finite.max() > 0 else 1.0)
    g[internal] = g_big
    g[np.isnan(g)] = g_big            # both sides of zero length (sliver to sliver)
    seconds = time.perf_counter() - t0
    stats = jsonable({"model": "conduit", "sections": sections, "n_sections": int(n_sections),
                      "merge": pm, "n_internal": int(internal.sum()), "qstar_stats": qstats,
                      "section_qstar_stats": section_stats, "seconds": seconds})
    logger.info("conduit conductance of %d throats (%d inside merged bodies) in %.2f s",
                idx.size, int(internal.sum()), seconds)
    return ConductanceResult(g, "conduit", qstar, stats, h_m=h, internal=internal)


#: Throats per block of :func:`conduit_conductance` (memory: about 30 MB per 1000 throats).
_BLOCK = 100_000


def _merge_stats(total: dict, part: dict) -> dict:
    """Q* lookup stats of several blocks: counts and seconds added, the rest from the first."""
    if not total:
        return dict(part)
    out = dict(total)
    for key in ("seconds", "n_throats", "n_shape_factor_fallback"):
        if key in part:
            out[key] = out.get(key, 0) + part[key]
    src = dict(out.get("sources", {}))
    for kind, count in part.get("sources", {}).items():
        src[kind] = src.get(kind, 0) + count
    out["sources"] = src
    return out


def _conduit_block(r_n, s_n, h_n, mu, section_stats, throat_qstar, *, sections, n_sections,
                   qkw, srtol):
    """Window Q*, conductance (NaN: zero length) and window lookup stats of one block."""
    qres = throat_qstar(r_n, s_n, **qkw)
    q_win = np.asarray(qres.qstar, dtype=float)
    rbar = (r_n[:, 0] + r_n[:, 1] + r_n[:, 2]) / 3.0       # r_n.mean(axis=1), same bits
    with np.errstate(divide="ignore"):
        y0 = np.where(q_win > 0, 1.0 / (q_win * rbar**4), np.inf)
    section_q = None
    if sections == "qstar":
        def section_q(rho, s):
            out = np.full(rho.shape[0], np.inf)
            # a vanished disk: keep a small one (2e-2 of the shortest side) so the section
            # is still a valid throat (a pinpoint wall, nearly free flow)
            smin = np.minimum(np.minimum(s[:, 0], s[:, 1]), s[:, 2])
            rr = np.maximum(rho, 2e-2 * smin[:, None])
            live = _colmax(rho) > 0
            if not live.all():
                rr, s = rr[live], s[live]
            res = throat_qstar(rr, s, **dict(qkw, rtol=srtol))
            rb = (rr[:, 0] + rr[:, 1] + rr[:, 2]) / 3.0
            qq = np.asarray(res.qstar, dtype=float) * rb**4
            section_stats["n_sections"] += int(qq.size)
            for kind, count in res.stats.get("sources", {}).items():
                section_stats["sources"][kind] = section_stats["sources"].get(kind, 0) + count
            if qkw["policy"] != "shape-factor" and "shape-factor" in res.stats.get("sources", {}):
                # outside the table the cache falls back to the shape factor, which is
                # 2-10 times off for these open sections: continue by ratios instead
                qq = np.where(np.asarray(res.source) == "shape-factor", np.nan, qq)
            out[live] = qq
            return out
    R = side_resistance(r_n, s_n, h_n, y0, n_sections=n_sections, section_q=section_q)
    Rt = R.sum(axis=1) * mu
    with np.errstate(divide="ignore"):
        gg = np.where(np.isinf(Rt), 0.0, 1.0 / np.where(Rt > 0, Rt, np.nan))
    return q_win, np.where(Rt == 0, np.nan, gg), qres.stats
