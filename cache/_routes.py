"""Which shipped table the 'table-only' lookup answers each throat from (benchmarks, studies).

The order of :func:`cache.lookup_qstar`: the default grid (g1), then each of
:data:`cache.EXTENSION_GRIDS` in turn on the rows the grids before it do not serve; every grid
reads a throat in its lookup order (:func:`cache._order.lookup_order`).
"""

from __future__ import annotations

import numpy as np

from ._lookup import load_grid_table
from ._orbits import DEFAULT_GRID, EXTENSION_GRIDS
from ._order import lookup_order

__all__ = ["table_routes"]


def table_routes(radii, sides, *, solver_version=None):
    """``[(name, rows, radii, sides, served), ...]`` for the default grid and then each
    extension grid: the rows (indices into ``radii``) that reach it, in their lookup order,
    and which of them it serves (bool); a grid that is not shipped for this solver version
    is left out. Rows no grid serves are the last entry's ``~served``."""
    r, s = lookup_order(radii, sides)
    rows = np.arange(r.shape[0])
    out = []
    for name in (DEFAULT_GRID,) + EXTENSION_GRIDS:
        table = load_grid_table(grid=name, solver_version=solver_version)
        if table is None:
            continue
        served = ~np.isinf(table.at_throats(r, s, errors=False)[1])
        out.append((name, rows, r, s, served))
        rows, r, s = rows[~served], r[~served], s[~served]
    return out
