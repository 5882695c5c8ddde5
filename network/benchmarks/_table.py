"""The throat table as the benchmark sees it: which file, does it interpolate, what FE it holds.

Stand-in until ``network.conductance`` exposes these (issue 12: it is the network's one importer
of ``cache``); the bench reads the table only through this module and ``cache``'s public API.
"""

from __future__ import annotations

import sqlite3
from pathlib import Path

import numpy as np
from cache import default_db_path, load_grid_table, open_store

__all__ = ["copy_table", "default_table", "drop_table", "has_grid", "table_totals"]


def default_table() -> Path | None:
    """The cache's default table (``$GRAINFLOW_CACHE_DB`` or the user's), None when unknown."""
    try:
        return Path(default_db_path())
    except Exception:  # noqa: BLE001 - bench goes on without a table
        return None


def has_grid(db) -> bool:
    """True when ``db`` (None: the default table) gives an interpolation grid."""
    try:
        return load_grid_table(db) is not None
    except Exception:  # noqa: BLE001 - no cache, no grid, foreign file: no table
        return False


def copy_table(src: Path | None, dst: Path) -> None:
    """Consistent copy of a (WAL-mode) SQLite table through the backup API; no source, no copy."""
    if src is None or not Path(src).exists():
        return
    with sqlite3.connect(f"file:{src}?mode=ro", uri=True) as a, sqlite3.connect(dst) as b:
        a.backup(b)


def drop_table(path: Path) -> None:
    """Delete a table file and its WAL companions."""
    for extra in ("", "-wal", "-shm"):
        Path(f"{path}{extra}").unlink(missing_ok=True)


def table_totals(path: Path) -> tuple[int, float]:
    """(rows, summed FE seconds) of a throat table; (0, 0.0) when it does not exist."""
    if not Path(path).exists() or Path(path).stat().st_size == 0:
        return 0, 0.0
    with open_store(path, create=False, check=False) as store:
        n = store.count()
        seconds = float(np.nansum(store.load()["seconds"])) if n else 0.0
    return int(n), seconds
