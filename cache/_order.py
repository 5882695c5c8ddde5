r"""The one vertex order in which the tables read a throat.

A permutation of a throat's vertices maps a grid's nodes to nodes (:mod:`cache._orbits`), but
not its cells: moving the third vertex maps the radius lattice's square cells
:math:`(\rho_1, \rho_2)` onto parallelograms (:math:`\rho_3 = -\rho_1-\rho_2`), so the
interpolant, read in the given order, changed with the order (by 5e-4 in the median and 3 % at
most on 300 packing throats against the table's own 0.1 % error; a packing's k by 3e-5 when
its rows were shuffled). Every lookup therefore reads the throat in one order, a function of
its shape alone:

* the vertices sorted by radius, ties by the opposite side (vertices equal in both are
  mirror images of each other: either order gives the same coordinates);
* the vertex of largest :math:`|\rho_i| = |r_i/\bar r - 1|` third (the smallest radius when
  :math:`2 r_b > r_a + r_c` for sorted :math:`r_a \le r_b \le r_c`, else the largest): the two
  explicit deviations are then the two smallest, so a throat lies in a grid's box whenever any
  of its orders does (the box bounds :math:`\rho_1, \rho_2`; :math:`\rho_3` reaches twice as far).

:func:`lookup_order` is the numpy form; :func:`cache._kernel.interp_point` applies the same
comparisons to one throat, so both read the same cell (``tests/cache/test_cache_kernel.py``).
"""

from __future__ import annotations

import numpy as np

__all__ = ["lookup_order"]


def _tables():
    """Per code of the three pair tests (bit 0: vertex 1 before 0, bit 1: 2 before 1, bit 2: 2
    before 0), the sorted vertex order (8, 3) and, with the odd vertex moved last or not, the
    final order and the columns of its sides in ``[l12, l13, l23]`` (8, 2, 3); codes no
    order gives (a cycle) are left at the identity."""
    order = np.tile(np.arange(3), (8, 1))
    for code in range(8):
        b10, b21, b20 = code & 1, code >> 1 & 1, code >> 2 & 1
        ranks = [b10 + b20, 1 - b10 + b21, 2 - b20 - b21]
        if sorted(ranks) == [0, 1, 2]:
            order[code] = np.argsort(ranks)
    final = np.stack([order, order[:, [1, 2, 0]]], axis=1)
    pair = np.array([[0, 0, 1], [0, 0, 2], [1, 2, 0]])
    sides = np.stack([pair[final[..., 0], final[..., 1]], pair[final[..., 0], final[..., 2]],
                      pair[final[..., 1], final[..., 2]]], axis=-1)
    return order, final, sides


_ORDER, _FINAL, _SIDES = _tables()
#: per output column j and combined code 2 code + flip: the source vertex (radii) / side column
_RADIUS_FROM = _FINAL.reshape(16, 3).T.astype(np.int8).copy()
_SIDE_FROM = _SIDES.reshape(16, 3).T.astype(np.int8).copy()


def lookup_order(radii, sides):
    """Throats (N, 3) in their lookup order (module docstring): radii ``[r1, r2, r3]`` and sides
    ``[l12, l13, l23]``, reordered together; the same rows for every order of the input's
    vertices, bit for bit. The comparisons of :func:`cache._kernel._lookup_order` (a stable
    sort by radius, then opposite side), so both pick the same order; about 0.1 us a row."""
    r = np.asarray(radii, dtype=float)
    s = np.asarray(sides, dtype=float)
    r0, r1, r2, o0, o1, o2 = r[:, 0], r[:, 1], r[:, 2], s[:, 2], s[:, 1], s[:, 0]
    code = (((r1 < r0) | ((r1 == r0) & (o1 < o0))).view(np.int8)
            + 2 * ((r2 < r1) | ((r2 == r1) & (o2 < o1))).view(np.int8)
            + 4 * ((r2 < r0) | ((r2 == r0) & (o2 < o0))).view(np.int8))
    a, b = np.minimum(r0, r1), np.maximum(r0, r1)            # the sorted radii, by value
    lo, hi, mid = np.minimum(a, r2), np.maximum(b, r2), np.maximum(a, np.minimum(b, r2))
    cf = 2 * code + (2.0 * mid > lo + hi).view(np.int8)
    rr, ss = (r0, r1, r2), (s[:, 0], s[:, 1], s[:, 2])
    return (np.column_stack([np.choose(_RADIUS_FROM[j][cf], rr) for j in range(3)]),
            np.column_stack([np.choose(_SIDE_FROM[j][cf], ss) for j in range(3)]))
