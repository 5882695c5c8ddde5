"""Throat-table files for the benchmark: fresh copies and clean-up (SQLite files only).

Which table, whether it interpolates and what FE it holds come from ``network.conductance``
(the network's one importer of ``cache``); they are re-exported here for the bench's parts.
"""

from __future__ import annotations

import sqlite3
from pathlib import Path

from ..conductance import default_table, has_grid, table_totals

__all__ = ["copy_table", "default_table", "drop_table", "has_grid", "table_totals"]


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
