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

from cache import table_coverage

from .._air import MU_AIR_PA_S, check_viscosity
from .._json import jsonable
from ..pores import PoreMerge, merge_pores
from ._qstar import SOURCES, qstar_from_function, throat_qstar as policy_qstar
from ._result import ConductanceResult
from ._conduit_kernel import compiled_conduit_rows
from ._heights import conduit_heights
from ._mates import grain_mates as grain_mates_of, section_factors, window_factors_compiled
from ._sections import colmax, side_resistance
from ._table import grid_alone

__all__ = ["KERNEL_MIN_THROATS", "SECTION_MODES", "conduit_conductance", "load_conduit_kernel"]

logger = logging.getLogger(__name__)

#: How section flow rates are obtained: closed-form ratio to the window, or Q* per section.
SECTION_MODES = ("ratio", "qstar")
#: Where grain mates are taken out of the sections (``conduit_conductance``'s grain_mates).
GRAIN_MATE_MODES = ("off", "window", "all")


def conduit_conductance(tessellation, throats_idx=None, *, viscosity_pa_s: float = MU_AIR_PA_S,
                        policy: str = "table+fe", rtol: float = 1e-3, db=None,
                        workers: int = 1, progress: bool = False, sections: str = "qstar",
                        n_sections: int = 6, merge: PoreMerge | bool = True,
                        merge_tolerance: float = 0.02, internal_factor: float = 1e6,
                        qstar_fn=None, section_rtol: float | None = None, threads: int = 1,
                        grain_mates: str = "window", mate_points: int = 16):
    r"""Conduit-model conductance of throats, m³ Pa⁻¹ s⁻¹ (module docstring for the model).

    Parameters
    ----------
    tessellation : Tessellation
    throats_idx : (M,) array_like of int or None
        Throats to evaluate (default all).
    viscosity_pa_s : float, keyword-only
        μ (default 1.932e-5 Pa s, air as in the thesis).
    policy, rtol, db, workers, progress : keyword-only
        Q* policy and options, as ``network._conductance.throat_qstar``. 'table-only' with
        the grid alone (no stored FE rows) on :data:`KERNEL_MIN_THROATS` throats or more runs
        the compiled loop of :mod:`._conduit_kernel` (2-2.5x faster; the same values to 1e-15,
        bit for bit where NumPy's exp, log and arcsin are the C library's, not AVX-512's).
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

    grain_mates : {'off', 'window', 'all'}, keyword-only
        On a bed of multi-sphere grains, the spheres of the vertices' grains that cut a
        section (:mod:`._mates`) are taken out of it, its flow rate the three-disk section's
        times :func:`throats.section_ratio`: 'window' (default) at the window, the section
        every flow between the two pore bodies crosses; 'all' at the window and every
        section; 'off' nowhere. Sphere packings have no grain mates and are unchanged.
        ``docs/validation-grains.md`` compares the three with resolved flow (Stokes k of the
        soybean / wheat / corn beds: +2.2 / +7.4 / +8.8 % 'off', -1.8 / -1.0 / +6.0 %
        'window', -6.6 / -13.9 / -2.4 % 'all'): 'window' is the default as the closest.
        'window' changes one node of the section profile, so its effect shrinks as
        n_sections grows (wheat +1.2 % at 12, +3.1 % at 24; 'all' and 'off' move < 1 %): it
        is the closest mode at the default n_sections, not a converged one; 'all' is, and
        conducts as on spheres between tetrahedra of four grains, less into the pieces of a
        void that one grain's spheres split.
        'window' runs the compiled loop of :mod:`._mates_kernel`, 'all' numpy at every
        section.
    mate_points : int, keyword-only
        Sub-triangles per side of :func:`throats.section_ratio` (default 16).

    Returns
    -------
    ConductanceResult
        ``g`` (M,) m³ Pa⁻¹ s⁻¹, window ``qstar``, conduit heights ``h_m`` (M, 2), ``internal``;
        ``stats``: sections, n_sections, merge summary, n_internal, qstar_stats (the windows),
        grain_mates (mode; n_windows_cut, the windows whose flow rate the mates lower, or
        with 'all' n_conduits_reached, the conduits a mate reaches; seconds),
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
    internal = pm.internal_throat[idx]
    h, sign = conduit_heights(t, idx, pm)

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
    # threads, at least one block per thread and the blocks in flight together no larger
    size = max(1, min(_BLOCK // threads, -(-rows.size // threads)))
    blocks = [rows[a:a + size] for a in range(0, rows.size, size)]

    # the 'table-only' policy served by the grid alone, on enough throats to pay numba's
    # load: the compiled loop, numpy for the throats it flags
    grid = (grid_alone(db) if policy == "table-only" and qstar_fn is None
            and sections == "qstar" and rows.size >= KERNEL_MIN_THROATS else None)

    # grain mates cutting the window (and, with 'all', every section): none on sphere packings
    if grain_mates not in GRAIN_MATE_MODES:
        raise ValueError(f"unknown grain_mates mode {grain_mates!r}; choose one of "
                         f"{GRAIN_MATE_MODES}")
    use_mates = grain_mates != "off" and t.packing.grain_id is not None
    mate_counts, mate_seconds = [], []          # per block (threads append)
    rmax = colmax(radii)

    def factor_of(blk):
        """The block's grain-mate factors (``_conduit_block``'s ``factor``) and the
        positions in ``blk`` of the conduits they change (None, empty: none)."""
        if not use_mates or blk.size == 0:
            return None, np.zeros(0, dtype=np.int64)
        t0 = time.perf_counter()
        if grain_mates == "window":     # the compiled loop over the block's windows
            wf = window_factors_compiled(t.packing, t.throat_vertices[idx[blk]],
                                         n=mate_points)
            has = np.flatnonzero(wf < 1.0)
            mate_counts.append(int(has.size))
            mate_seconds.append(time.perf_counter() - t0)
            return ((wf[has], has) if has.size else None), has
        mates = grain_mates_of(t.packing, t.throat_vertices[idx[blk]],
                               np.minimum(h[blk], rmax[blk, None]), sign[blk])
        has = mates.rows
        mate_counts.append(int(has.size))
        mate_seconds.append(time.perf_counter() - t0)
        if has.size == 0:
            return None, has
        return (lambda hn: section_factors(mates, has, hn, sign[blk], radii[blk], sides[blk],
                                           n=mate_points)), has

    def numpy_block(blk, factor=None):
        stats = {"n_sections": 0, "sources": {}}
        out = _conduit_block(radii[blk], sides[blk], h[blk], mu, stats, throat_qstar,
                             sections=sections, n_sections=n_sections,
                             qkw=dict(policy=policy, rtol=rtol, db=db, workers=workers,
                                      progress=progress, estimate=False),
                             srtol=srtol, factor=factor)
        return out + (stats,)

    def block(blk):
        factor, has = factor_of(blk)
        if grid is None or grain_mates == "all" and has.size:
            return numpy_block(blk, factor)
        if has.size == 0:
            return _kernel_block(radii[blk], sides[blk], h[blk], mu, n_sections, grid,
                                 lambda rows: numpy_block(blk[rows]), rtol)
        # the compiled loop for the conduits no mate changes, numpy for the others
        cut = np.zeros(blk.size, dtype=bool)
        cut[has] = True
        factor = (factor[0], np.arange(has.size))      # the window factors, numpy's order
        flag = lambda rows: numpy_block(blk[~cut][rows])               # noqa: E731
        parts = (_kernel_block(radii[blk[~cut]], sides[blk[~cut]], h[blk[~cut]], mu,
                               n_sections, grid, flag, rtol), numpy_block(blk[cut], factor))
        q_b, g_b = np.empty(blk.size), np.empty(blk.size)
        q_b[~cut], g_b[~cut] = parts[0][0], parts[0][1]
        q_b[cut], g_b[cut] = parts[1][0], parts[1][1]
        st = _merge_stats(parts[0][2], parts[1][2])
        sst = {"n_sections": parts[0][3]["n_sections"] + parts[1][3]["n_sections"],
               "sources": dict(parts[0][3]["sources"])}
        for kind, count in parts[1][3]["sources"].items():
            sst["sources"][kind] = sst["sources"].get(kind, 0) + count
        return q_b, g_b, st, sst

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
    # 'window': the windows the mates cut; 'all': the conduits a mate reaches
    mate_stats = {"mode": grain_mates,
                  ("n_windows_cut" if grain_mates != "all" else "n_conduits_reached"):
                  int(sum(mate_counts)),
                  "seconds": float(sum(mate_seconds))}
    stats = jsonable({"model": "conduit", "sections": sections, "n_sections": int(n_sections),
                      "grain_mates": mate_stats,
                      "merge": pm, "n_internal": int(internal.sum()), "qstar_stats": qstats,
                      "section_qstar_stats": section_stats, "seconds": seconds})
    logger.info("conduit conductance of %d throats (%d inside merged bodies) in %.2f s",
                idx.size, int(internal.sum()), seconds)
    loose = qstats.get("n_shape_factor", 0) - qstats.get("n_shape_factor_deep", 0)
    if policy == "table-only" and qstar_fn is None and loose > 1e-3 * qstats.get("n", 0):
        # outside both tables and no deep overlap: there the estimate is 2-4x too open
        logger.warning("%d of %d windows lie outside the Q* tables (%s) and took the "
                       "shape-factor estimate, 2-4x too open there (an unsettled barley bed: "
                       "0.4 %% of its windows, k +2.9 %%); --policy table+fe solves them by FE "
                       "(docs/cache-table.md)", loose, qstats["n"], table_coverage())
    return ConductanceResult(g, "conduit", qstar, stats, h_m=h, internal=internal)


#: Fewest throats for which :func:`conduit_conductance` runs the compiled loop
#: (:mod:`._conduit_kernel`): importing numba and loading the loop from its cache cost
#: 0.5-0.6 s of one core, with the GIL held, in a fresh process; the loop saves about
#: 1.5-2 µs per throat of a two-thread stage (0.92 -> 0.45-0.59 s at 249 000 throats). At
#: 20 000 spheres (192 000 sample throats) the two cancel (the load slows the tessellation
#: beside it by as much as the stage gains), at 100 000 it gains 2.7 s. A packing of N
#: spheres gives about 10 N sample throats.
KERNEL_MIN_THROATS = 300_000


def load_conduit_kernel(db=None) -> bool:
    """Import numba and load the compiled conduit loop (from numba's cache; compiled on the
    very first run) when the 'table-only' policy of ``db`` can use it: what
    :func:`network.solve_network` does beside the tessellation for large packings. True
    when loaded."""
    grid = grid_alone(db)
    if grid is None:
        return False
    z = np.zeros((0, 3))
    compiled_conduit_rows()(z, z, np.zeros((0, 2)), np.linspace(0.0, 1.0, 3), *grid, np.zeros(0),
                            np.zeros((0, 2)), np.zeros(0, dtype=np.int64),
                            np.zeros(0, dtype=bool))
    return True


#: Throats per block of :func:`conduit_conductance` (memory: about 30 MB per 1000 throats).
_BLOCK = 100_000


def _merge_stats(total: dict, part: dict) -> dict:
    """Q* lookup stats of several blocks: counts (``n``, ``n_*``) and seconds added, the hit
    rate of the sums, the rest from the first."""
    if not total:
        return dict(part)
    out = dict(total)
    for key, value in part.items():
        if key == "seconds" or ((key == "n" or key.startswith("n_")) and isinstance(value, int)):
            out[key] = out.get(key, 0) + value
    if "hit_rate" in out:
        out["hit_rate"] = ((out.get("n_exact", 0) + out.get("n_interp", 0))
                           / max(out.get("n", 0) - out.get("n_failed", 0), 1))
    src = dict(out.get("sources", {}))
    for kind, count in part.get("sources", {}).items():
        src[kind] = src.get(kind, 0) + count
    out["sources"] = src
    return out


def _kernel_block(r_n, s_n, h_n, mu, n_sections, grid, numpy_rows, rtol=1e-3):
    """:func:`_conduit_block`'s outputs by :mod:`._conduit_kernel`'s compiled loop; the throats
    it flags (the table does not serve them) by ``numpy_rows(rows)``, the general path."""
    t0 = time.perf_counter()
    n = r_n.shape[0]
    q_win, R = np.empty(n), np.empty((n, 2))
    flagged = np.empty(n, dtype=bool)
    looked = np.zeros(n, dtype=np.int64)
    compiled_conduit_rows()(np.ascontiguousarray(r_n), np.ascontiguousarray(s_n),
                            np.ascontiguousarray(h_n), np.linspace(0.0, 1.0, int(n_sections) + 1),
                            *grid, q_win, R, looked, flagged)
    gg = _conductance(R, mu)
    rows = np.flatnonzero(flagged)
    done = n - rows.size
    qstats = {"n": done, "policy": "table-only", "rtol": rtol, "n_fe": 0,
              **{f"n_{k.replace('-', '_')}": done if k == "interp" else 0 for k in SOURCES},
              "hit_rate": 1.0, "backend": "conduit kernel", "n_shape_factor_fallback": 0,
              "n_throats": done, "sources": {"interp": done} if done else {},
              "seconds": time.perf_counter() - t0}
    n_sec = int(looked.sum())
    sstats = {"n_sections": n_sec, "sources": {"interp": n_sec} if n_sec else {}}
    if rows.size:
        q_r, g_r, st_r, sst_r = numpy_rows(rows)
        q_win[rows], gg[rows] = q_r, g_r
        qstats = _merge_stats(qstats, st_r)
        sstats["n_sections"] += sst_r["n_sections"]
        for kind, count in sst_r["sources"].items():
            sstats["sources"][kind] = sstats["sources"].get(kind, 0) + count
    return q_win, gg, qstats, sstats


def _conduit_block(r_n, s_n, h_n, mu, section_stats, throat_qstar, *, sections, n_sections,
                   qkw, srtol, factor=None):
    """Window Q*, conductance (NaN: zero length) and window lookup stats of one block.

    ``factor``: None; (window factors (K,), their rows (K,)), the windows' flow rate with
    their grain mates relative to the three-disk window's; or a callable, the
    ``section_factor`` of :func:`._sections.side_resistance`."""
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
            live = colmax(rho) > 0
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
    section_factor = None
    if isinstance(factor, tuple):         # the window's flow rate with its grain mates
        wf, has = factor
        y0 = y0.copy()
        with np.errstate(divide="ignore"):
            y0[has] = y0[has] / wf                          # a window the mates close: inf
    elif factor is not None:
        section_factor = factor
    R = side_resistance(r_n, s_n, h_n, y0, n_sections=n_sections, section_q=section_q,
                        section_factor=section_factor)
    return q_win, _conductance(R, mu), qres.stats


def _conductance(R, mu):
    """g = 1/(μ (R_P + R_Q)) of conduits from their halves' R/μ (N, 2): 0 for a closed one
    (R = inf), NaN for a zero length (R = 0: sliver to sliver)."""
    Rt = (R[:, 0] + R[:, 1]) * mu
    with np.errstate(divide="ignore", over="ignore"):
        gg = np.where(np.isinf(Rt), 0.0, 1.0 / np.where(Rt > 0, Rt, np.nan))
    return np.where(Rt == 0, np.nan, gg)
