"""The Q* table as the network sees it: which file, whether it interpolates, what FE it holds.

With :mod:`._qstar`, the only place in ``network`` that imports ``cache`` (through its public API).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from cache import default_db_path, load_grid_table, open_store

__all__ = ["default_table", "has_grid", "table_totals"]


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


def table_totals(path) -> tuple[int, float]:
    """(rows, summed FE seconds) of a throat table; (0, 0.0) when it does not exist."""
    if not Path(path).exists() or Path(path).stat().st_size == 0:
        return 0, 0.0
    with open_store(path, create=False, check=False) as store:
        n = store.count()
        seconds = float(np.nansum(store.load()["seconds"])) if n else 0.0
    return int(n), seconds
