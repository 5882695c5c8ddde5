"""Grid tables from their stored and exported forms: a spec from its dict, the table of a spec.

A grid lives in a throat table (``ThroatStore.grid``: its spec as a dict, its node values as
solved throat rows) or in an exported ``.npz`` (the spec as JSON, the node Q* and FE errors,
every node or one per orbit, :mod:`cache._orbits`).  These functions turn either form into the
interpolation table of its kind (:class:`cache.GridTable`, or :class:`cache._pair.PairTable`
on a deep-pair grid) and write the export; which table a lookup serves, and its cache of loaded
tables, are :mod:`cache._lookup`'s.
"""

from __future__ import annotations

import json
import logging
from pathlib import Path

import numpy as np

import throats

from ._grids import GridSpec
from ._interp import GridTable
from ._orbits import compact, expand
from ._pair import PairSpec, PairTable
from ._signature import match_keys, shape_keys, signature

logger = logging.getLogger(__name__)

__all__ = ["export_grid", "grid_from_store", "grid_table", "read_grid_file", "spec_from_dict"]


def spec_from_dict(d):
    """The grid spec a stored or exported dict describes: a :class:`cache._pair.PairSpec` when
    its ``kind`` is 'pair', else a :class:`GridSpec`."""
    return (PairSpec if d.get("kind") == PairSpec.kind else GridSpec).from_dict(d)


def grid_table(spec, qstar, fe_error=None, **kwargs):
    """The interpolation table of ``spec``: :class:`cache._pair.PairTable` on a pair grid,
    else :class:`GridTable` (same arguments)."""
    return (PairTable if isinstance(spec, PairSpec) else GridTable)(spec, qstar, fe_error, **kwargs)


def grid_from_store(store, name, solver_version):
    """The :class:`GridTable` of grid ``name`` in ``store`` for ``solver_version`` (None if absent).

    Nodes not solved yet are NaN (cells with such corners are never served); the table's
    ``n_missing`` counts the valid nodes still to solve.
    """
    spec_d = store.grid(name)
    if spec_d is None:
        return None
    spec = spec_from_dict(spec_d)
    rtol = float(spec_d.get("rtol", 1e-3))
    nr, ns = spec.node_shapes()
    keys = shape_keys(signature(nr, ns))
    rows = store.load(solver_version=solver_version)
    same = np.isclose(rows["rtol"], rtol, rtol=1e-9, atol=0)
    idx = match_keys(keys, rows["keys"][same])
    q = np.full(len(keys), np.nan)
    fe = np.full(len(keys), np.nan)
    hit = idx >= 0
    st = rows["status"][same][idx[hit]]
    qq = rows["qstar"][same][idx[hit]]
    q[hit] = np.where(st == "closed", 0.0, np.where(st == "ok", qq, np.nan))
    fe[hit] = rows["error_estimate"][same][idx[hit]]
    valid, _ = throats.validate_throats(nr, ns)
    if hasattr(spec, "needed"):
        valid &= spec.needed()
        q[~spec.needed()] = np.nan
    n_missing = int(np.sum(valid & ~hit))
    logger.info("grid %r from %s: %d of %d nodes solved, %d valid nodes missing", name, store.path,
                int(np.isfinite(q).sum()), len(q), n_missing)
    table = grid_table(spec, q, fe)
    table.n_missing = n_missing
    return table


def export_grid(store, name, path, *, solver_version, orbits=False):
    """Write grid ``name`` of ``store`` as ``.npz`` (spec, node Q*, node FE errors); ``orbits``:
    one value per vertex-permutation orbit (``orbit_*``, :mod:`cache._orbits`), a sixth as many."""
    table = grid_from_store(store, name, solver_version)
    if table is None:
        raise ValueError(f"{store.path} holds no grid named {name!r} (grids: {store.grid_names()})")
    spec = dict(store.grid(name))
    values = {"qstar": getattr(table, "fe_qstar", table.qstar), "fe_error": table.fe_error}
    if orbits:
        values = dict(zip(("orbit_qstar", "orbit_fe_error"), compact(table.spec, *values.values())))
    np.savez_compressed(path, spec=json.dumps(spec), solver_version=str(solver_version), **values)
    return Path(path)


def read_grid_file(path):
    """(GridSpec, solver version, ``values()``) of an exported grid ``.npz`` (either form of
    :func:`export_grid`); ``values()`` reads the node Q* and FE errors, (``spec.shape``) each."""
    z = np.load(path, allow_pickle=False)
    spec = spec_from_dict(json.loads(str(z["spec"])))

    def values():
        if "orbit_qstar" in z:
            return tuple(expand(spec, z["orbit_qstar"], z["orbit_fe_error"]))
        return z["qstar"], z["fe_error"]
    return spec, str(z["solver_version"]), values
