r"""grainflow.cache — SQLite tables of throat Q*: signatures, batch precomputation, lookup.

A packing of 20 000 grains has about 240 000 throats; at tens of milliseconds per FE solve
that is hours.  The cache answers most throats from a precomputed table at > 1e6 throats/s,
each with an error estimate, and solves by FE (``throats.solve_fem``) only what the table
cannot answer to the requested tolerance.

Public functions
----------------
signature(radii, sides)
    (N, 5) scale/permutation-invariant key parameters ``[r1*, r2*, l12*, l13*, l23*]``.
lookup_qstar(radii, sides, *, db=None, policy='table+fe', rtol=1e-3, workers=1, progress=False)
    :class:`Lookup` of (N,) ``qstar``, ``error_estimate``, ``source`` (one of ``SOURCES``) plus
    ``stats``; policies: ``'table-only'``, ``'table+fe'``, ``'fe-only'``, ``'shape-factor'``.
precompute_throats(store, radii, sides, *, rtol, workers, retry_failed, ...)
    Solve and store what a table lacks, one transaction per batch.
precompute_grid(store, spec, *, rtol, ...)
    Register an interpolation grid (``GRIDS[name]``) and solve its nodes.
dask_executor(address, *, workers) / DaskConnectError
    Run precompute batches on Dask (optional extra ``grainflow[dask]``).
open_store(path) / ThroatStore
    The SQLite file (WAL, format-checked; :class:`CacheFileError` on corrupt/foreign files).
default_db_path()
    ``$GRAINFLOW_CACHE_DB`` or ``~/.cache/grainflow/throats.sqlite``.
GridSpec, GridTable, GRIDS, grid_coordinates, load_grid_table, CALIBRATED_SAFETY
    The interpolation grid over :math:`(\delta_{12}, \delta_{13}, \delta_{23}, \rho_1, \rho_2)`;
    ``export_grid``/``read_grid_file`` write and read one (every node, or one per orbit).
point_kernel() / GridTable.kernel_arrays()
    The grid's evaluation at one throat, numba-compiled (bit for bit the table's own).

Command lines: ``python -m cache.precompute``, ``python -m cache.lookup``, ``python -m cache.bench``.

The shipped table ``cache/data/grid_g1.npz`` (Q* at the 390 625 nodes of grid ``g1``, solved
by ``throats.solve_fem`` at rtol 1e-3) and, for rows it cannot serve, ``EXTENSION_GRIDS``
(radius deviations to ±0.5, gaps -2.2 to 4.6 r̄; the deep pairs of grain beds, :mod:`cache._pair`)
are served only while ``throats.SOLVER_VERSION`` equals the version they were built with; how to
rebuild them: ``docs/cache-table.md``.  Accuracy and speed: ``python -m cache.bench``.
Of ``network`` ``cache`` imports only ``network.core`` (its benchmark: ``network``); data flows
network → cache through arrays and CSV files. It never meshes or solves itself: it calls ``throats``.
"""

from ._build import PrecomputeSummary, precompute_grid, precompute_throats
from ._dask import DaskConnectError, dask_executor
from ._kernel import point_kernel
from ._grids import GRIDS, GridSpec
from ._interp import CALIBRATED_SAFETY, ERROR_SAFETY, GridTable, grid_coordinates
from ._gridio import export_grid, read_grid_file
from ._lookup import (POLICIES, SOURCES, Lookup, cold_tables, default_db_path, load_grid_table,
                      lookup_qstar, shipped_grid_path)
from ._orbits import EXTENSION_GRIDS, table_coverage
from ._routes import table_routes
from ._signature import QUANTUM, shape_keys, signature
from ._store import CacheFileError, ThroatStore, open_store

__all__ = ["signature", "shape_keys", "QUANTUM", "lookup_qstar", "Lookup", "POLICIES", "SOURCES",
           "default_db_path", "precompute_throats", "precompute_grid", "PrecomputeSummary", "open_store",
           "ThroatStore", "CacheFileError", "GridSpec", "GridTable", "GRIDS",
           "grid_coordinates", "load_grid_table", "export_grid", "shipped_grid_path",
           "dask_executor", "DaskConnectError", "CALIBRATED_SAFETY", "ERROR_SAFETY",
           "point_kernel", "read_grid_file", "EXTENSION_GRIDS",
           "table_coverage", "table_routes", "cold_tables"]
