"""Q* stored in a throat table, answered exactly before interpolation (the rows a store holds).

The row source codes of :func:`cache.lookup_qstar` (:data:`SOURCES`) live here with the two
steps every policy shares: :func:`stored_first` (a filter that costs nothing for the rows a
store cannot hold, then one indexed join) and :func:`assign_exact`.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ._signature import near_side_sums, shape_keys, signature
from ._store import KEYS_LOADED_PER_QUERY, open_store

__all__ = ["SOURCES", "EXACT", "INTERP", "FE", "SHAPE_FACTOR", "CLOSED", "FAILED",
           "stored_first", "exact_rows", "assign_exact"]

#: where a row's Q* came from (:attr:`cache.Lookup.source`), in the order of their codes
SOURCES = ("exact", "interp", "fe", "shape-factor", "closed", "failed")
EXACT, INTERP, FE, SHAPE_FACTOR, CLOSED, FAILED = range(len(SOURCES))


def stored_first(r, s, rows, q, err, src, msg, *, db, rtol, solver_version):
    """Answer ``rows`` stored in ``db`` (tolerance <= rtol) exactly, in place; returns the rest.

    Only when ``db`` (a path) exists and holds rows. A store of at most
    ``KEYS_LOADED_PER_QUERY`` rows per row asked hands over its keys' side sums first: the rows none of them is near
    (:func:`~cache._signature.near_side_sums`, two sums and a sorted search a row) cannot be
    stored and cost nothing more; the others get a signature and one indexed join, which
    asks SQLite once per stored key among them (:meth:`~cache._store.ThroatStore.lookup_keys`).
    """
    path = Path(db)
    if not len(rows) or not path.exists() or path.stat().st_size == 0:
        return rows
    with open_store(path, create=False, check=False) as store:
        if store.count() == 0:
            return rows
        sums = store.side_sums(solver_version=solver_version, max_rtol=rtol,
                               statuses=("ok", "closed"),
                               limit=KEYS_LOADED_PER_QUERY * len(rows))
        ask = rows if sums is None else rows[near_side_sums(r[rows], s[rows], sums)]
        if not len(ask):
            return rows
        found = exact_rows(store, shape_keys(signature(r[ask], s[ask])), rtol, solver_version)
    hit = found["found"]
    assign_exact(ask[hit], found, hit, q, err, src, msg, EXACT)
    return rows[~np.isin(rows, ask[hit])]


def exact_rows(store, keys, rtol, solver_version, statuses=("ok", "closed")):
    """Stored rows for ``keys`` with tolerance <= rtol (the most accurate one per shape)."""
    return store.lookup_keys(keys, solver_version=solver_version, max_rtol=rtol, statuses=statuses)


def assign_exact(dest, rows, sel, q, err, src, msg, label):
    """Rows ``dest`` from the stored rows ``sel`` of :func:`exact_rows`'s answer (in place):
    Q* and its error (0 for a closed throat), source ``label``, or failed with its message."""
    st = rows["status"][sel]
    q[dest] = np.where(st == "closed", 0.0, rows["qstar"][sel])
    err[dest] = np.where(st == "closed", 0.0, rows["error_estimate"][sel])
    src[dest] = np.where(st == "closed", CLOSED, np.where(st == "ok", label, FAILED))
    msg[dest] = np.where(st == "ok", "", rows["message"][sel])
