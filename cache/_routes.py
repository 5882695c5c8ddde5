"""Which shipped table the 'table-only' lookup answers each throat from (benchmarks, studies).

The order of :func:`cache.lookup_qstar`: the default grid (g1) in the throat's given vertex
order, then each of :data:`cache.EXTENSION_GRIDS` in turn on the rows the grids before it do not
serve, reordered by :func:`cache._orbits.toward_extension` as the lookup reorders them.
"""

from __future__ import annotations

import numpy as np

from ._lookup import load_grid_table
from ._orbits import DEFAULT_GRID, EXTENSION_GRIDS, toward_extension

__all__ = ["table_routes"]


def table_routes(radii, sides, *, solver_version=None):
    """``[(name, rows, radii, sides, served), ...]`` for the default grid and then each
    extension grid: the rows (indices into ``radii``) that reach it, in the vertex order it
    is asked in, and which of them it serves (bool); a grid that is not shipped for this
    solver version is left out. Rows no grid serves are the last entry's ``~served``."""
    r, s = np.asarray(radii, dtype=float), np.asarray(sides, dtype=float)
    rows = np.arange(r.shape[0])
    out = []
    for name in (DEFAULT_GRID,) + EXTENSION_GRIDS:
        table = load_grid_table(grid=name, solver_version=solver_version)
        if table is None:
            continue
        if name != DEFAULT_GRID and not (out and out[-1][0] in EXTENSION_GRIDS):
            r, s = toward_extension(r, s)          # one order for every extension grid
        served = ~np.isinf(table.at_throats(r, s, errors=False)[1])
        out.append((name, rows, r, s, served))
        rows, r, s = rows[~served], r[~served], s[~served]
    return out
