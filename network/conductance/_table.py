"""The Q* table as the network sees it: which file, whether it interpolates, what FE it holds.

With :mod:`._qstar`, the only place in ``network`` that imports ``cache`` (through its public API).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from cache import cold_tables, default_db_path, load_grid_table, open_store

__all__ = ["default_table", "grid_alone", "has_grid", "table_totals"]


def default_table() -> Path | None:
    """The cache's default table (``$GRAINFLOW_CACHE_DB`` or the user's), None when unknown."""
    try:
        return Path(default_db_path())
    except Exception:  # noqa: BLE001 - callers go on without a table
        return None


def has_grid(db) -> bool:
    """True when ``db`` (None: the default table) gives an interpolation grid."""
    try:
        return load_grid_table(db) is not None
    except Exception:  # noqa: BLE001 - no cache, no grid, foreign file: no table
        return False


def grid_alone(db):
    """The grid's :meth:`cache.GridTable.kernel_arrays` when the 'table-only' policy is served
    by the interpolation grid alone (``db``, None the default table, holds no stored FE rows,
    which would come first); None otherwise (no grid, stored rows, a grid the kernel cannot
    take)."""
    path = Path(db) if db is not None else default_table()
    if path is None:
        return None
    try:
        if path.exists() and path.stat().st_size > 0:
            with open_store(path, create=False, check=False) as store:
                if store.count() > 0:
                    return None
        table = load_grid_table(db)
    except Exception:  # noqa: BLE001 - no cache, foreign file: the general path decides
        return None
    return None if table is None else table.kernel_arrays()


def table_totals(path) -> tuple[int, float]:
    """(rows, summed FE seconds) of a throat table; (0, 0.0) when it does not exist."""
    if not Path(path).exists() or Path(path).stat().st_size == 0:
        return 0, 0.0
    with open_store(path, create=False, check=False) as store:
        n = store.count()
        seconds = float(np.nansum(store.load()["seconds"])) if n else 0.0
    return int(n), seconds


def first_run_note(policy: str | None = None) -> str | None:
    """One line for a command's start when the Q* tables are used for the first time on this
    machine (:func:`cache.cold_tables`: their derived arrays are not saved yet, and deriving
    them takes several seconds, once), else None; None for the shape-factor policy, which
    uses no table."""
    if policy == "shape-factor":
        return None
    cold = cold_tables()
    if not cold:
        return None
    return (f"first use of the Q* tables ({', '.join(cold)}) on this machine: deriving their "
            f"interpolation arrays takes several seconds, once; they are kept in "
            f"{default_db_path().parent}")

