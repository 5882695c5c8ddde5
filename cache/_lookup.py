r"""Vectorised Q* lookup for N throats: exact hits, grid interpolation, FE on demand.

Policies
--------
==============  ===============================================================================
``table-only``  an exact hit where ``db`` stores the shape (an FE solve with tolerance
                <= ``rtol``), else interpolation in the grid table for every row it covers,
                with its error estimate; rows it cannot serve go to the shipped extension grids
                (:mod:`cache._orbits`; the deep pairs of grain beds: :mod:`cache._pair`), then
                to the shape-factor estimate (``source='shape-factor'``; 'closed', Q* = 0, where
                the disks cover the triangle).  Never runs FE.
``table+fe``    as ``table-only``, but every interpolated row whose error estimate exceeds
                ``rtol`` is solved by FE (``throats.solve_fem``) and stored.
``fe-only``     exact hits, FE for the rest (stored); no interpolation.
``shape-factor`` ``throats.shape_factor_qstar`` for every row (no table).
==============  ===============================================================================

The hot path of the table policies is one multilinear evaluation per row (no canonical
reordering, see :mod:`cache._interp`), so table lookups run at > 1e6 rows/s on one core.
Rows with NaN/inf, a non-positive length or sides that are not a triangle are reported with
``source='failed'`` and a message (``throats.validate_throats``), never raised.
"""

from __future__ import annotations

import logging
import os
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

import throats

from . import _build
from ._build import precompute_throats, resolve_solver
from ._derived import derived_path, load_derived, save_derived
from ._gridio import grid_from_store, grid_table, read_grid_file
from ._orbits import DEFAULT_GRID, EXTENSION_GRIDS
from ._exact import (CLOSED, EXACT, FAILED, FE, INTERP, SHAPE_FACTOR, SOURCES, assign_exact,
                     exact_rows, stored_first)
from ._signature import as_throats, shape_keys, signature
from ._store import open_store

logger = logging.getLogger(__name__)

__all__ = ["Lookup", "lookup_qstar", "default_db_path", "load_grid_table", "POLICIES", "SOURCES",
           "shipped_grid_path"]

POLICIES = ("table-only", "table+fe", "fe-only", "shape-factor")
_DATA = Path(__file__).resolve().parent / "data"


@dataclass(frozen=True)
class Lookup:
    """Result of :func:`lookup_qstar`: (N,) arrays plus run statistics.

    Attributes
    ----------
    qstar : (N,) float, Q* in units of r̄ (NaN where ``source == 'failed'``)
    error_estimate : (N,) float, relative (NaN for shape-factor rows)
    source : (N,) str, 'exact' | 'interp' | 'fe' | 'shape-factor' | 'closed' | 'failed'
    stats : dict, counts per source, ``hit_rate`` (exact + interp over valid rows), ``n_fe``
        (distinct shapes solved), ``seconds``
    message : (N,) object, reason for 'failed' rows, '' elsewhere
    """

    qstar: np.ndarray
    error_estimate: np.ndarray
    source: np.ndarray
    stats: dict
    message: np.ndarray = field(default=None)


def default_db_path():
    """Default writable table: ``$GRAINFLOW_CACHE_DB`` or ``~/.cache/grainflow/throats.sqlite``."""
    env = os.environ.get("GRAINFLOW_CACHE_DB")
    if env:
        return Path(env)
    return Path.home() / ".cache" / "grainflow" / "throats.sqlite"


def shipped_grid_path(name=DEFAULT_GRID):
    """Path of the grid table shipped with the package (``cache/data/grid_<name>.npz``)."""
    return _DATA / f"grid_{name}.npz"


# cache of loaded tables: (path, grid, solver_version, mtime_ns) -> GridTable
_TABLES: dict = {}
# one loader at a time: threads looking up at once (network's conductance blocks) would
# otherwise build and save the same derived arrays twice
_TABLES_LOCK = threading.RLock()


def load_grid_table(db=None, *, grid=None, solver_version=None):
    """The interpolation table for ``db``: its own grid when complete, else the shipped one.

    Order of preference: a complete grid stored in ``db`` (the newest, or ``grid``), the grid
    shipped in ``cache/data`` if it was built with the current solver version, an incomplete
    grid of ``db`` (cells with unsolved corners are never served).  Returns None when there
    is none for the current solver version.
    """
    with _TABLES_LOCK:
        return _load_grid_table(db, grid, solver_version)


def _load_grid_table(db, grid, solver_version):
    if solver_version is None:
        solver_version = _build.default_solver()[1]
    partial = None
    path = Path(db) if db is not None else default_db_path()
    if path.exists() and path.stat().st_size > 0:
        key = (str(path.resolve()), grid, solver_version)
        cached = _TABLES.get(key)
        mtime = path.stat().st_mtime_ns
        if cached is not None and (cached[0] == mtime or cached[1]):
            table = cached[2]  # unchanged file, or a complete grid (FE rows never alter nodes)
        else:
            with open_store(path, create=False) as store:
                names = store.grid_names()
                name = grid if grid is not None else (names[-1] if names else None)
                table = grid_from_store(store, name, solver_version) if name in names else None
            if table is not None:
                _TABLES[key] = (mtime, table.n_missing == 0, table)
        if table is not None and table.n_missing == 0:
            return table
        partial = table
    shipped = _shipped_table(grid or DEFAULT_GRID, solver_version)
    return shipped if shipped is not None else partial


def _shipped_table(name, solver_version):
    with _TABLES_LOCK:               # threads asking at once: one builds, the others wait
        return _load_shipped(name, solver_version)


def cold_tables(solver_version=None) -> list[str]:
    """Names of the shipped grid tables whose derived arrays are not saved yet in the default
    folder (:func:`default_db_path`'s): the first lookup that needs one derives and saves them,
    once, several seconds per table (``grid_g1`` 28 MB, ``grid_x1`` 127 MB, ``grid_d1``
    71 MB); an empty list when every one is ready or in memory already."""
    if solver_version is None:
        solver_version = _build.default_solver()[1]
    cold = []
    for name in (DEFAULT_GRID, *EXTENSION_GRIDS):
        path = shipped_grid_path(name)
        if not path.exists():
            continue
        if (str(path), name, solver_version, path.stat().st_mtime_ns) in _TABLES:
            continue
        saved = derived_path(path, default_db_path().parent)
        if saved is not None and not saved.exists():
            cold.append(name)
    return cold


def _load_shipped(name, solver_version):
    path = shipped_grid_path(name)
    if not path.exists():
        return None
    key = (str(path), name, solver_version, path.stat().st_mtime_ns)
    if key not in _TABLES:
        spec, built, values = read_grid_file(path)
        if built != str(solver_version):
            logger.warning("shipped grid %s was built with solver %s, the current one is %s: not "
                           "used (rebuild: python -m cache.precompute --grid %s --export ...)",
                           path, built, solver_version, name)
            _TABLES[key] = None
        else:
            # the whole-grid passes of GridTable (0.1-0.2 s) are done once per table and code
            # version, then read back from a memory map (docs/scale.md)
            saved = derived_path(path, default_db_path().parent)
            rows = load_derived(saved, spec.shape)
            if rows is None:
                qstar, fe_error = values()
                table = grid_table(spec, qstar, fe_error)
                if saved is not None:
                    save_derived(saved, dict(table.derived(), qstar=qstar, fe_error=fe_error))
            else:
                table = grid_table(spec, rows["qstar"], rows["fe_error"], derived=rows)
            table.n_missing = 0
            table.single = name not in EXTENSION_GRIDS  # served to few rows: no float32 pass
            _TABLES[key] = table
    return _TABLES[key]


def _quick_valid(r, s):
    """Cheap row checks of the hot path (finite, positive, strict triangle inequality).

    ``0 < x < inf`` is False for NaN, inf and non-positive values; it is tested on the flat
    (3N,) arrays (one contiguous pass; a reduction over a length-3 axis, or three strided
    columns, costs two to three times more) and the rare failures are mapped to their rows.
    """
    l12, l13, l23 = s[:, 0], s[:, 1], s[:, 2]
    with np.errstate(invalid="ignore"):
        ok = (l12 < l13 + l23) & (l13 < l12 + l23) & (l23 < l12 + l13)
        for a in (r, s):
            flat = np.ascontiguousarray(a).ravel()
            ok[np.flatnonzero(~((flat > 0) & (flat < np.inf))) // 3] = False
    return ok


def lookup_qstar(radii, sides, *, db=None, policy="table+fe", rtol=1e-3, workers=1,
                 progress=False, grid=None, solver=None, solver_version=None, table=None,
                 estimate=True):
    r"""Q* of N throats from the cache, by the given policy (see module notes).

    Parameters
    ----------
    radii, sides : (N, 3) array_like, any consistent length unit
        ``[r1, r2, r3]``, ``[l12, l13, l23]``.
    db : path, optional
        Throat table; None means :func:`default_db_path`.  Its grid (or the shipped one)
        serves interpolation; FE results are stored in it.
    policy : {'table-only', 'table+fe', 'fe-only', 'shape-factor'}, keyword-only
    rtol : float, keyword-only, default 1e-3
        Relative tolerance: interpolated rows with a larger error estimate go to FE
        ('table+fe'); FE solves use it as their tolerance.
    workers : int, keyword-only, default 1
        Processes for FE solves.
    progress : bool, keyword-only
        Progress bar for FE solves.
    grid : str, optional
        Name of the grid to interpolate in (default: the newest in ``db``, else shipped).
    solver, solver_version : optional
        Injected FE solver (protocol of ``throats.solve_fem``); default ``throats.solve_fem``.
    table : GridTable, optional
        Use this interpolation table instead of loading one (benchmarks, tests).
    estimate : bool, keyword-only, default True
        False: interpolated rows of ``'table-only'`` get ``error_estimate`` NaN (not
        estimated) and the table's per-cell estimate is never built (callers that only use
        Q*, as the network's conduit sections); the rows served are the same.

    Returns
    -------
    Lookup
        qstar (r̄ units: g = Q* r̄⁴/(μL)), error_estimate, source, stats, message.

    Raises
    ------
    ValueError
        Unknown policy, rtol <= 0, or arrays not both (N, 3).
    """
    t0 = time.perf_counter()
    if policy not in POLICIES:
        raise ValueError(f"unknown policy {policy!r}; expected one of {POLICIES}")
    if not rtol > 0:
        raise ValueError(f"rtol must be > 0, got {rtol}")
    r, s = as_throats(radii, sides)
    n = len(r)
    q = np.full(n, np.nan)
    err = np.full(n, np.nan)
    src = np.full(n, FAILED, dtype=np.int8)
    msg = np.full(n, "", dtype=object)
    stats = {"n": n, "policy": policy, "rtol": rtol, "n_fe": 0, "n_interp_extension": 0}

    ok = _quick_valid(r, s)
    pending = np.flatnonzero(ok)
    if policy == "shape-factor":
        sf = throats.shape_factor_qstar
        q[pending] = sf(r[pending], s[pending])
        src[pending] = SHAPE_FACTOR
    else:
        if solver is not None or policy != "table-only":
            solver, solver_version = resolve_solver(solver, solver_version)
        elif solver_version is None:
            solver_version = _build.default_solver()[1]
        if policy in ("table-only", "table+fe"):
            # FE values already stored in the table beat interpolation
            pending = stored_first(r, s, pending, q, err, src, msg,
                                   db=db if db is not None else default_db_path(), rtol=rtol,
                                    solver_version=solver_version)
            injected = table is not None
            if table is None:
                table = load_grid_table(db, grid=grid, solver_version=solver_version)
            if table is None:
                logger.warning("no grid table for solver %s: every row needs exact hits or FE",
                               solver_version)
            else:
                errors = estimate or policy == "table+fe"
                if len(pending) == n:        # every row (the usual case): no gathered copies
                    q, err = table.at_throats(r, s, errors=errors)
                else:
                    q[pending], err[pending] = table.at_throats(r[pending], s[pending],
                                                                errors=errors)
                src[pending] = INTERP
                ei = err[pending]
                good = (ei <= rtol) if policy == "table+fe" else ~np.isinf(ei)
                pending = pending[~good]
                if not injected and len(pending):
                    pending = _extension_rows(r, s, pending, q, err, src, stats, policy=policy,
                                              rtol=rtol, errors=errors, version=solver_version)
        # rows the table did not settle: exact hits, then FE or shape factor
        if len(pending):
            _settle(r, s, pending, q, err, src, msg, stats, db=db, policy=policy, rtol=rtol,
                    workers=workers, progress=progress, solver=solver,
                    solver_version=solver_version)
    bad = np.flatnonzero(~ok)
    if len(bad):
        _, m = throats.validate_throats(r[bad], s[bad])
        msg[bad] = [mm or "invalid throat" for mm in m]
        q[bad], err[bad], src[bad] = np.nan, np.nan, FAILED
    counts = np.bincount(src, minlength=len(SOURCES))
    for name, count in zip(SOURCES, counts):
        stats[f"n_{name.replace('-', '_')}"] = int(count)
    # the estimate's rows with a deep overlap (its own constants, within a few % of FE) apart
    # from the others, which outside the table may be 2x too open (docs/throats-shape-factor.md)
    sf_rows = np.flatnonzero(src == SHAPE_FACTOR)
    stats["n_shape_factor_deep"] = int(throats.deep_overlap(r[sf_rows], s[sf_rows]).sum())
    n_valid = max(n - stats["n_failed"], 1)
    stats["hit_rate"] = (stats["n_exact"] + stats["n_interp"]) / n_valid
    stats["seconds"] = time.perf_counter() - t0
    return Lookup(q, err, np.asarray(SOURCES)[src], stats, msg)


def _extension_rows(r, s, rows, q, err, src, stats, *, policy, rtol, errors, version):
    """Interpolate ``rows`` the grid table does not serve in the extension grids in turn (in
    place); the rest back."""
    todo = rows[np.isinf(err[rows])]       # table+fe: rows the grid serves too roughly go to FE
    done, rp, sp = [], r[todo], s[todo]
    for name in EXTENSION_GRIDS:
        ext = _shipped_table(name, version)
        if ext is None or not len(todo):
            continue
        qe, ee = ext.at_throats(rp, sp, errors=errors)
        good = (ee <= rtol) if policy == "table+fe" else ~np.isinf(ee)
        q[todo[good]], err[todo[good]], src[todo[good]] = qe[good], ee[good], INTERP
        stats[f"n_interp_{name}"] = int(good.sum())
        done.append(todo[good])
        todo, rp, sp = todo[~good], rp[~good], sp[~good]
    stats["n_interp_extension"] = int(sum(d.size for d in done))
    return np.setdiff1d(rows, np.concatenate([rows[:0], *done]), assume_unique=True)


def _settle(r, s, rows, q, err, src, msg, stats, *, db, policy, rtol, workers, progress, solver,
            solver_version):
    """Exact hits / FE / shape-factor for ``rows`` (in place)."""
    ok, m = throats.validate_throats(r[rows], s[rows])
    bad = rows[~ok]
    msg[bad] = m[~ok]
    q[bad], err[bad], src[bad] = np.nan, np.nan, FAILED
    rows = rows[ok]
    if not len(rows):
        return
    path = Path(db) if db is not None else default_db_path()
    need_store = policy != "table-only" or (path.exists() and path.stat().st_size > 0)
    if not need_store:
        _shape_factor_rows(r, s, rows, q, err, src)
        return
    keys = shape_keys(signature(r[rows], s[rows]))
    with open_store(path, create=policy != "table-only") as store:
        found = exact_rows(store, keys, rtol, solver_version)
        hit = found["found"]
        assign_exact(rows[hit], found, hit, q, err, src, msg, EXACT)
        miss, mkeys = rows[~hit], keys[~hit]
        if not len(miss):
            return
        if policy == "table-only":
            unserved = miss[~np.isfinite(err[miss])]
            _shape_factor_rows(r, s, unserved, q, err, src)
            return
        summ = precompute_throats(store, r[miss], s[miss], rtol=rtol, solver=solver,
                                  solver_version=solver_version, workers=workers,
                                  progress=progress, retry_failed=True)
        stats["n_fe"] += summ.solved + summ.failed
        stats["fe_seconds"] = stats.get("fe_seconds", 0.0) + summ.seconds
        found = exact_rows(store, mkeys, rtol, solver_version, statuses=None)
        hit = found["found"]
        assign_exact(miss[hit], found, hit, q, err, src, msg, FE)
        lost = miss[~hit]
        q[lost], err[lost], src[lost] = np.nan, np.nan, FAILED
        msg[lost] = "no stored result after the FE solve"


def _shape_factor_rows(r, s, rows, q, err, src):
    """The shape-factor estimate for ``rows`` (in place); a row whose disks cover its triangle
    (open area 0, where the estimate is 0) is 'closed' with Q* = 0 and error 0, as the FE
    solver reports it (``throats.solve_fem``), not an estimate."""
    if not len(rows):
        return
    q[rows] = throats.shape_factor_qstar(r[rows], s[rows])
    closed = q[rows] == 0
    err[rows] = np.where(closed, 0.0, np.nan)
    src[rows] = np.where(closed, CLOSED, SHAPE_FACTOR)
