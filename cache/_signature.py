r"""Shape signature of a throat: the scale- and permutation-invariant key of the cache.

A throat is six numbers, ``radii = [r1, r2, r3]`` and ``sides = [l12, l13, l23]``; Q* (in
units of the mean radius r̄) depends only on its shape, i.e. on the six numbers up to a common
scale and a permutation of the vertices (a mirror image or rotation of the face gives the
same six numbers).  ``throats.canonical_form`` scales by r̄ and picks the canonical vertex
order; the signature is the five independent numbers of that canonical row,

.. math:: s = (r_1^*, r_2^*, l_{12}^*, l_{13}^*, l_{23}^*), \qquad r_3^* = 3 - r_1^* - r_2^*,

and the table key is ``round(s / QUANTUM)`` as five int64 (QUANTUM = 1e-9 r̄): two throats
share a key when their shapes agree to 1e-9 r̄, far below any solver tolerance.  Every writer
and reader computes the key with this one function from float64 lengths; files that carry
shapes between commands must hold them losslessly (17 significant digits, ``repr``): a length
written with 9 digits moves the key (docs/cache-table.md).  Solver
settings (``SOLVER_VERSION``, ``rtol``) are stored beside the key and are part of the unique
index, so a changed solver never serves a stale value.
"""

from __future__ import annotations

import numpy as np

import throats
from throats import as_throats

__all__ = ["signature", "shape_keys", "QUANTUM"]

#: quantum of the integer key, in units of the mean radius
QUANTUM = 1e-9


def signature(radii, sides):
    r"""Scale- and permutation-invariant signature of N throats, (N, 5).

    Parameters
    ----------
    radii, sides : (N, 3) array_like
        A throat a row (``[r1, r2, r3]``, ``[l12, l13, l23]``); the unit drops out.

    Returns
    -------
    (N, 5) ndarray, dimensionless (units of r̄)
        ``[r1*, r2*, l12*, l13*, l23*]`` of the canonical form (``throats.canonical_form``);
        rows with NaN stay NaN.

    Examples
    --------
    >>> a = signature([[1.0, 2.0, 3.0]], [[3.5, 4.5, 5.0]])
    >>> b = signature([[6.0, 4.0, 2.0]], [[10.0, 9.0, 7.0]])   # permuted and scaled x2
    >>> bool(np.allclose(a, b, rtol=0, atol=1e-12))
    True
    """
    r, s = as_throats(radii, sides)
    rs, ss = throats.canonical_form(r, s)
    return np.concatenate([rs[:, :2], ss], axis=1)


#: Largest gap, in quanta, between a throat's side sum :func:`side_sum` and the sum of its
#: three side keys: each key is its side rounded to the nearest quantum (1.5 quanta at most
#: together) and float rounding adds far less than one
SIDE_SUM_SLACK = 2.0


def side_sum(radii, sides):
    r"""(N,) :math:`(l_{12} + l_{13} + l_{23}) / \bar r` in quanta, the sum of a throat's side keys
    (``k3 + k4 + k5`` of :func:`shape_keys`) to within :data:`SIDE_SUM_SLACK`, for a sixth of
    the signature's cost: no canonical form (a sum is the same in every vertex order).

    >>> sig = signature([[1.0, 2.0, 3.0]], [[3.5, 4.5, 5.0]])
    >>> k = shape_keys(sig)
    >>> bool(abs(side_sum([[1.0, 2.0, 3.0]], [[3.5, 4.5, 5.0]])[0] - k[0, 2:].sum()) <= 2)
    True
    """
    r, s = as_throats(radii, sides)
    return (s[:, 0] + s[:, 1] + s[:, 2]) / ((r[:, 0] + r[:, 1] + r[:, 2]) / 3.0) / QUANTUM


def near_side_sums(radii, sides, stored_sums):
    """(N,) bool: throats whose :func:`side_sum` lies within :data:`SIDE_SUM_SLACK` of one of
    ``stored_sums`` (the ``k3 + k4 + k5`` of stored keys): the only ones whose key can be
    stored. A conservative filter: a throat it drops has no stored key."""
    x = side_sum(radii, sides)
    table = np.sort(np.asarray(stored_sums, dtype=float))
    if not len(table):
        return np.zeros(len(x), dtype=bool)
    pos = np.minimum(np.searchsorted(table, x - SIDE_SUM_SLACK), len(table) - 1)
    return np.abs(table[pos] - x) <= SIDE_SUM_SLACK


def shape_keys(sig):
    """Integer keys (N, 5) int64 of signatures: ``rint(sig / QUANTUM)``; NaN rows give -2**62."""
    sig = np.asarray(sig, dtype=float)
    with np.errstate(invalid="ignore"):
        k = np.rint(sig / QUANTUM)
    k[~np.isfinite(k)] = -(2.0**62)
    return k.astype(np.int64)


def key_hash(keys):
    """One uint64 per key row (multiplicative mixing); equal keys give equal hashes."""
    k = np.asarray(keys, dtype=np.int64).view(np.uint64)
    mult = np.array([0x9E3779B97F4A7C15, 0xC2B2AE3D27D4EB4F, 0x165667B19E3779F9,
                     0xD6E8FEB86659FD93, 0xFF51AFD7ED558CCD], dtype=np.uint64)
    with np.errstate(over="ignore"):
        h = np.zeros(len(k), dtype=np.uint64)
        for c in range(5):
            h = (h ^ (k[:, c] * mult[c])) * np.uint64(0x94D049BB133111EB)
            h ^= h >> np.uint64(31)
    return h


def match_keys(query, table):
    """Row index into ``table`` of each ``query`` key (N,), -1 where absent.

    Vectorised hash join: sort the table's hashes once, ``searchsorted`` the queries, then
    verify all five integers (a hash collision can only turn a hit into a miss).
    """
    query = np.asarray(query, dtype=np.int64).reshape(-1, 5)
    table = np.asarray(table, dtype=np.int64).reshape(-1, 5)
    out = np.full(len(query), -1, dtype=np.int64)
    if len(table) == 0 or len(query) == 0:
        return out
    ht = key_hash(table)
    order = np.argsort(ht, kind="stable")
    hs = ht[order]
    hq = key_hash(query)
    pos = np.minimum(np.searchsorted(hs, hq), len(hs) - 1)
    cand = order[pos]
    ok = (hs[pos] == hq) & np.all(table[cand] == query, axis=1)
    out[ok] = cand[ok]
    return out
