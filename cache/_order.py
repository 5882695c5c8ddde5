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
comparisons to one throat, so both read the same cell (``tests/test_cache_kernel.py``).
"""

from __future__ import annotations

import numpy as np

__all__ = ["lookup_order"]

#: column of side l_ij in ``[l12, l13, l23]`` for vertices i, j (0-based)
_PAIR = np.array([[0, 0, 1], [0, 0, 2], [1, 2, 0]])


def lookup_order(radii, sides):
    """Throats (N, 3) in their lookup order (module docstring): radii ``[r1, r2, r3]`` and sides
    ``[l12, l13, l23]``, reordered together; the same rows for every order of the input's
    vertices, bit for bit."""
    r = np.asarray(radii, dtype=float)
    s = np.asarray(sides, dtype=float)
    o = np.lexsort((s[:, ::-1], r))                 # vertex i's opposite side: column 2 - i
    rows = np.arange(len(r))[:, None]
    ro = r[rows, o]
    o = np.where((2.0 * ro[:, 1] > ro[:, 0] + ro[:, 2])[:, None], o[:, [1, 2, 0]], o)
    a, b, c = o[:, 0], o[:, 1], o[:, 2]
    rows = rows[:, 0]
    return (r[rows[:, None], o],
            np.column_stack([s[rows, _PAIR[a, b]], s[rows, _PAIR[a, c]], s[rows, _PAIR[b, c]]]))
