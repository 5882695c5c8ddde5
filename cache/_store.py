r"""SQLite store of solved throat shapes (through sqlite-utils).

One table, ``throats``, holds one row per (shape, solver settings):

=================  =======  ===========================================================
column             type     meaning
=================  =======  ===========================================================
id                 INTEGER  row id
k1 … k5            INTEGER  quantised signature (``round(signature / QUANTUM)``), the key
r1, r2, r3         REAL     canonical radii, units of the mean radius r̄
l12, l13, l23      REAL     canonical sides, units of r̄
solver_version     TEXT     ``throats.SOLVER_VERSION`` (or the injected solver's version)
rtol               REAL     tolerance the solve was asked for
qstar              REAL     dimensionless flow Q* (r̄ units); NULL when not solved
open_area          REAL     open area, r̄² units
contact_type       TEXT     'a' | 'b' | 'c' | 'd'
error_estimate     REAL     relative error estimate of the solver
n_elements         INTEGER  mesh elements
seconds            REAL     wall time of the solve
status             TEXT     'ok' | 'closed' | 'invalid' | 'failed'
message            TEXT     reason when status is not 'ok'
created            TEXT     ISO-8601 UTC time of the write
=================  =======  ===========================================================

The key is unique on ``(k1..k5, solver_version, rtol)``, so a changed solver never serves a
stale value and a shape is never stored twice for the same settings.  A write of a row that
already exists keeps an ``ok``/``closed`` row and replaces a ``failed``/``invalid`` one (that is
how ``--retry-failed`` records its new outcome).

Durability and concurrency: the file is in WAL mode; every :meth:`ThroatStore.put` is one
``BEGIN IMMEDIATE … COMMIT`` transaction, so a process killed at any moment (Ctrl-C or
``kill -9``) loses at most the batch it was writing, and two processes may write at once (the
second waits on the lock, up to ``timeout`` seconds).  A file that is not an SQLite database,
fails ``PRAGMA quick_check``, or lacks the ``grainflow_meta`` format marker raises
:class:`CacheFileError` instead of serving values.
"""

from __future__ import annotations

import datetime as _dt
import json
import logging
import os
import sqlite3
from pathlib import Path

import numpy as np

from ._signature import match_keys

logger = logging.getLogger(__name__)

__all__ = ["CacheFileError", "ThroatStore", "open_store", "FORMAT", "FORMAT_VERSION"]

FORMAT = "grainflow.cache.throats"
FORMAT_VERSION = "1"
_SQLITE_MAGIC = b"SQLite format 3\x00"

_COLUMNS = ("k1", "k2", "k3", "k4", "k5", "r1", "r2", "r3", "l12", "l13", "l23",
            "solver_version", "rtol", "qstar", "open_area", "contact_type", "error_estimate",
            "n_elements", "seconds", "status", "message", "created")

_SCHEMA = """
CREATE TABLE IF NOT EXISTS grainflow_meta (key TEXT PRIMARY KEY, value TEXT NOT NULL);
CREATE TABLE IF NOT EXISTS throats (
    id INTEGER PRIMARY KEY,
    k1 INTEGER NOT NULL, k2 INTEGER NOT NULL, k3 INTEGER NOT NULL,
    k4 INTEGER NOT NULL, k5 INTEGER NOT NULL,
    r1 REAL, r2 REAL, r3 REAL, l12 REAL, l13 REAL, l23 REAL,
    solver_version TEXT NOT NULL, rtol REAL NOT NULL,
    qstar REAL, open_area REAL, contact_type TEXT, error_estimate REAL,
    n_elements INTEGER, seconds REAL, status TEXT NOT NULL, message TEXT,
    created TEXT NOT NULL
);
CREATE UNIQUE INDEX IF NOT EXISTS throats_key
    ON throats (k1, k2, k3, k4, k5, solver_version, rtol);
CREATE TABLE IF NOT EXISTS grids (
    name TEXT PRIMARY KEY, spec TEXT NOT NULL, created TEXT NOT NULL
);
"""

_UPSERT = (
    f"INSERT INTO throats ({', '.join(_COLUMNS)}) VALUES ({', '.join('?' * len(_COLUMNS))}) "
    "ON CONFLICT (k1, k2, k3, k4, k5, solver_version, rtol) DO UPDATE SET "
    + ", ".join(f"{c} = excluded.{c}" for c in _COLUMNS[5:] if c not in ("solver_version", "rtol"))
    + " WHERE throats.status NOT IN ('ok', 'closed')"
)


class CacheFileError(ValueError):
    """The file is not a usable grainflow throat cache (corrupt, foreign, or unreadable)."""


def _now():
    return _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds")


class ThroatStore:
    """An open throat table (a connection that persists between calls).

    Use :func:`open_store` to create one; it is a context manager that closes the connection.
    """

    def __init__(self, path, conn):
        import sqlite_utils

        self.path = Path(path)
        self.conn = conn
        self.db = sqlite_utils.Database(conn)

    # -- context management -------------------------------------------------------------
    def close(self):
        self.conn.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    # -- writes ---------------------------------------------------------------------------
    def put(self, keys, canon_radii, canon_sides, *, solver_version, rtol, qstar, open_area,
            contact_type, error_estimate, n_elements, seconds, status, message):
        """Write N solved rows in ONE transaction (all or nothing); returns N.

        Parameters are (N,) arrays (``keys`` (N, 5) int, canonical radii/sides (N, 3));
        ``solver_version`` and ``rtol`` are scalars.  Existing ``ok``/``closed`` rows are kept.
        """
        keys = np.asarray(keys, dtype=np.int64)
        n = len(keys)
        if n == 0:
            return 0
        created = _now()
        cols = [keys[:, 0], keys[:, 1], keys[:, 2], keys[:, 3], keys[:, 4],
                *np.asarray(canon_radii, float).T, *np.asarray(canon_sides, float).T]
        per_row = [np.asarray(qstar, float), np.asarray(open_area, float),
                   np.asarray(contact_type, object), np.asarray(error_estimate, float),
                   np.asarray(n_elements), np.asarray(seconds, float),
                   np.asarray(status, object), np.asarray(message, object)]
        for a in per_row:
            if len(a) != n:
                raise ValueError(f"put: every column needs {n} rows, got {len(a)}")

        def _py(v):
            if isinstance(v, (np.floating, float)):
                return None if not np.isfinite(v) else float(v)
            if isinstance(v, np.integer):
                return int(v)
            return v

        rows = []
        for i in range(n):
            rows.append(tuple(_py(c[i]) for c in cols)
                        + (str(solver_version), float(rtol))
                        + tuple(_py(a[i]) for a in per_row[:4])
                        + (_py(per_row[4][i]) if per_row[4][i] is not None else None,
                           _py(per_row[5][i]), str(per_row[6][i]),
                           None if per_row[7][i] in (None, "") else str(per_row[7][i]),
                           created))
        with self._transaction():
            self.conn.executemany(_UPSERT, rows)
        return n

    def put_grid(self, name, spec):
        """Record a grid definition (JSON-serialisable dict) under ``name``."""
        with self._transaction():
            self.conn.execute("INSERT OR REPLACE INTO grids (name, spec, created) VALUES (?, ?, ?)",
                              (str(name), json.dumps(spec, sort_keys=True), _now()))

    # -- reads ----------------------------------------------------------------------------
    def grid(self, name):
        """The grid definition stored under ``name`` (dict), or None."""
        rows = list(self.db.query("SELECT spec FROM grids WHERE name = ?", [str(name)]))
        return json.loads(rows[0]["spec"]) if rows else None

    def grid_names(self):
        return [r["name"] for r in self.db.query("SELECT name FROM grids ORDER BY created")]

    def load(self, *, solver_version=None, max_rtol=None, statuses=None):
        """All rows matching the filters, as a dict of (M,) numpy arrays (keys as (M, 5) int64).

        Rows for the same shape with several tolerances all come back; callers choose.
        """
        where, args = _row_filters("", solver_version=solver_version, max_rtol=max_rtol,
                                   statuses=statuses)
        sql = ("SELECT k1, k2, k3, k4, k5, r1, r2, r3, l12, l13, l23, rtol, qstar, open_area, "
               "contact_type, error_estimate, n_elements, seconds, status, message FROM throats")
        if where:
            sql += " WHERE " + " AND ".join(where)
        try:
            rows = self.conn.execute(sql, args).fetchall()
        except sqlite3.DatabaseError as e:
            raise CacheFileError(f"{self.path}: cannot read the throat table ({e})") from e
        m = len(rows)
        if m == 0:
            cols = [[]] * 20
        else:
            cols = list(zip(*rows))

        def f(c):
            return np.array([np.nan if v is None else v for v in c], dtype=float)

        return {
            "keys": np.array(cols[:5], dtype=np.int64).T.reshape(m, 5),
            "radii": np.stack([f(c) for c in cols[5:8]], axis=1).reshape(m, 3),
            "sides": np.stack([f(c) for c in cols[8:11]], axis=1).reshape(m, 3),
            "rtol": f(cols[11]), "qstar": f(cols[12]), "open_area": f(cols[13]),
            "contact_type": np.array(["" if v is None else v for v in cols[14]], dtype="<U1"),
            "error_estimate": f(cols[15]),
            "n_elements": np.array([-1 if v is None else v for v in cols[16]], dtype=np.int64),
            "seconds": f(cols[17]),
            "status": np.array(cols[18], dtype="<U8"),
            "message": np.array(["" if v is None else v for v in cols[19]], dtype=object),
        }

    def lookup_keys(self, keys, *, solver_version, rtol=None, max_rtol=None, statuses=None):
        """Stored rows for M given keys: a lookup per stored key asked for, not per key.

        Returns a dict of (M,) arrays aligned with ``keys``: ``found`` (bool), ``rtol``,
        ``qstar``, ``open_area``, ``contact_type``, ``error_estimate``, ``status``,
        ``message``.  ``rtol`` selects exactly that tolerance; ``max_rtol`` any tolerance up to
        it, the smallest winning.

        A store of at most :data:`KEYS_LOADED_PER_QUERY` times M rows hands over its keys
        in one query, matched in NumPy (:func:`~cache._signature.match_keys`); only the hits
        go to SQLite. A larger store is asked through the unique index for every distinct
        key (O(M log N), not O(N))."""
        keys = np.asarray(keys, dtype=np.int64).reshape(-1, 5)
        m = len(keys)
        out = {"found": np.zeros(m, bool), "rtol": np.full(m, np.nan), "qstar": np.full(m, np.nan),
               "open_area": np.full(m, np.nan), "contact_type": np.full(m, "", dtype="<U1"),
               "error_estimate": np.full(m, np.nan), "status": np.full(m, "", dtype="<U8"),
               "message": np.full(m, "", dtype=object)}
        if m == 0:
            return out
        where, args = _row_filters("t.", solver_version=solver_version, rtol=rtol,
                                   max_rtol=max_rtol, statuses=statuses)
        try:
            c = self.conn
            if self.count() <= KEYS_LOADED_PER_QUERY * m:
                stored = np.array(c.execute(
                    "SELECT DISTINCT t.k1, t.k2, t.k3, t.k4, t.k5 FROM throats t WHERE "
                    + " AND ".join(where), args).fetchall(), dtype=np.int64).reshape(-1, 5)
                rows = np.flatnonzero(match_keys(keys, stored) >= 0)
            else:
                rows = np.arange(m)
            if not len(rows):
                return out
            # one row per distinct key asked for: a section's keys repeat
            uniq, back = np.unique(keys[rows], axis=0, return_inverse=True)
            back = back.ravel()
            ask = np.arange(len(uniq))
            c.execute("CREATE TEMP TABLE IF NOT EXISTS _q "
                      "(i INTEGER, k1 INTEGER, k2 INTEGER, k3 INTEGER, k4 INTEGER, k5 INTEGER)")
            c.execute("DELETE FROM _q")
            c.executemany("INSERT INTO _q VALUES (?, ?, ?, ?, ?, ?)",
                          np.column_stack([ask, uniq[ask]]).tolist())
            res = c.execute(
                "SELECT q.i, t.rtol, t.qstar, t.open_area, t.contact_type, t.error_estimate, "
                "t.status, t.message FROM _q q JOIN throats t ON t.k1 = q.k1 AND t.k2 = q.k2 "
                "AND t.k3 = q.k3 AND t.k4 = q.k4 AND t.k5 = q.k5 WHERE " + " AND ".join(where)
                + " ORDER BY q.i, t.rtol DESC", args).fetchall()
            c.execute("DELETE FROM _q")
        except sqlite3.DatabaseError as e:
            if isinstance(e, sqlite3.OperationalError) and "locked" in str(e):
                raise
            raise CacheFileError(f"{self.path}: cannot read the throat table ({e})") from e
        got = {k: v[:len(uniq)].copy() for k, v in out.items()}      # per distinct key
        for i, rt, q, a, ct, ee, st, msg in res:  # smallest rtol last: it wins
            got["found"][i] = True
            got["rtol"][i] = rt
            got["qstar"][i] = np.nan if q is None else q
            got["open_area"][i] = np.nan if a is None else a
            got["contact_type"][i] = ct or ""
            got["error_estimate"][i] = np.nan if ee is None else ee
            got["status"][i] = st
            got["message"][i] = msg or ""
        for k, v in got.items():
            out[k][rows] = v[back]
        return out

    def side_sums(self, *, solver_version, max_rtol=None, statuses=None, limit=None):
        """(K,) distinct ``k3 + k4 + k5`` of the rows the filters select (for
        :func:`~cache._signature.near_side_sums`), or None where the store holds more than
        ``limit`` rows (a scan of them would cost more than it saves)."""
        if limit is not None and self.count() > limit:
            return None
        where, args = _row_filters("", solver_version=solver_version, max_rtol=max_rtol,
                                   statuses=statuses)
        sql = "SELECT DISTINCT k3 + k4 + k5 FROM throats WHERE " + " AND ".join(where or ["1"])
        try:
            return np.array(self.conn.execute(sql, args).fetchall(), dtype=float).ravel()
        except sqlite3.DatabaseError as e:
            raise CacheFileError(f"{self.path}: cannot read the throat table ({e})") from e

    def count(self, **filters):
        """Number of rows (optionally ``status='ok'`` etc.)."""
        if not filters:
            return self.db["throats"].count
        where = " AND ".join(f"{k} = ?" for k in filters)
        return self.conn.execute(f"SELECT count(*) FROM throats WHERE {where}",
                                 list(filters.values())).fetchone()[0]

    def meta(self):
        return {r["key"]: r["value"] for r in self.db.query("SELECT key, value FROM grainflow_meta")}

    def transaction(self):
        """``with store.transaction():`` one ``BEGIN IMMEDIATE`` … ``COMMIT`` (rollback on error)."""
        return _Transaction(self.conn, self.path)

    _transaction = transaction


class _Transaction:
    """``BEGIN IMMEDIATE`` … ``COMMIT`` (``ROLLBACK`` on error); SQLite errors → CacheFileError."""

    def __init__(self, conn, path):
        self.conn, self.path = conn, path

    def __enter__(self):
        try:
            self.conn.execute("BEGIN IMMEDIATE")
        except sqlite3.OperationalError:
            raise
        except sqlite3.DatabaseError as e:
            raise CacheFileError(f"{self.path}: not a usable throat cache ({e})") from e
        return self

    def __exit__(self, exc_type, exc, tb):
        if exc_type is None:
            self.conn.execute("COMMIT")
        else:
            self.conn.execute("ROLLBACK")
            if isinstance(exc, sqlite3.DatabaseError) and not isinstance(exc, sqlite3.OperationalError):
                raise CacheFileError(f"{self.path}: write failed ({exc})") from exc
        return False


#: :meth:`ThroatStore.lookup_keys` loads the store's keys when it holds at most this many rows
#: per distinct key asked for (one scan of the keys beats a B-tree search per key up to here)
KEYS_LOADED_PER_QUERY = 4


def open_store(path, *, create=True, timeout=60.0, check=True):
    """Open (or create) a throat cache file and check that it is one.

    Parameters
    ----------
    path : str or Path
        SQLite file.  A missing or empty file is created (when ``create``).
    create : bool, keyword-only, default True
        Create a missing file; False raises ``FileNotFoundError`` instead.
    timeout : float, keyword-only, default 60 s
        How long a writer waits for another process's lock.
    check : bool, keyword-only, default True
        Run ``PRAGMA quick_check`` (O(file size); about 10 ms per 10 MB).

    Returns
    -------
    ThroatStore

    Raises
    ------
    CacheFileError
        The file is not SQLite, is corrupt, or is an SQLite database of another program.
    """
    path = Path(path)
    exists = path.exists() and path.stat().st_size > 0
    if not exists and not create:
        raise FileNotFoundError(f"no throat cache at {path}")
    if exists:
        with open(path, "rb") as fh:
            head = fh.read(16)
        if head != _SQLITE_MAGIC:
            raise CacheFileError(f"{path} is not an SQLite database (first bytes {head[:16]!r}): "
                                 "corrupt or foreign file; refusing to use it as a throat cache")
    elif path.parent and not path.parent.exists():
        path.parent.mkdir(parents=True, exist_ok=True)
    try:
        conn = sqlite3.connect(os.fspath(path), timeout=timeout, isolation_level=None)
    except sqlite3.Error as e:
        raise CacheFileError(f"cannot open {path} as SQLite: {e}") from e
    try:
        if check and exists:
            res = conn.execute("PRAGMA quick_check").fetchall()
            if res != [("ok",)]:
                raise CacheFileError(f"{path} failed PRAGMA quick_check: "
                                     f"{'; '.join(str(r[0]) for r in res[:5])}")
        conn.execute("PRAGMA journal_mode=WAL")
        conn.execute("PRAGMA synchronous=NORMAL")
        _init_schema(conn, path)
    except CacheFileError:
        conn.close()
        raise
    except sqlite3.OperationalError:
        conn.close()
        raise
    except sqlite3.DatabaseError as e:
        conn.close()
        raise CacheFileError(f"{path} is corrupt or not a throat cache: {e}") from e
    return ThroatStore(path, conn)


def _init_schema(conn, path):
    """Create the schema in an empty database, or verify the format marker of an existing one."""
    conn.execute("BEGIN IMMEDIATE")
    try:
        tables = {r[0] for r in conn.execute("SELECT name FROM sqlite_master WHERE type='table'")}
        if not tables:
            for stmt in _SCHEMA.split(";"):
                if stmt.strip():
                    conn.execute(stmt)
            conn.executemany("INSERT INTO grainflow_meta (key, value) VALUES (?, ?)",
                             [("format", FORMAT), ("format_version", FORMAT_VERSION),
                              ("created", _now())])
        elif "grainflow_meta" not in tables:
            raise CacheFileError(f"{path} is an SQLite database of another program "
                                 f"(tables {sorted(tables)[:5]}), not a grainflow throat cache")
        else:
            meta = dict(conn.execute("SELECT key, value FROM grainflow_meta").fetchall())
            if meta.get("format") != FORMAT:
                raise CacheFileError(f"{path}: format {meta.get('format')!r}, expected {FORMAT!r}")
            if meta.get("format_version") != FORMAT_VERSION:
                raise CacheFileError(f"{path}: format version {meta.get('format_version')!r}, "
                                     f"this code reads {FORMAT_VERSION!r}")
        conn.execute("COMMIT")
    except BaseException:
        if conn.in_transaction:
            conn.execute("ROLLBACK")
        raise


def _row_filters(prefix, *, solver_version=None, rtol=None, max_rtol=None, statuses=None):
    """SQL WHERE terms and their arguments for the throat-table filters (column ``prefix``)."""
    where, args = [], []
    if solver_version is not None:
        where.append(f"{prefix}solver_version = ?")
        args.append(str(solver_version))
    if rtol is not None:
        where.append(f"{prefix}rtol = ?")
        args.append(float(rtol))
    if max_rtol is not None:
        where.append(f"{prefix}rtol <= ?")
        args.append(float(max_rtol) * (1 + 1e-12))
    if statuses is not None:
        statuses = list(statuses)
        where.append(f"{prefix}status IN ({', '.join('?' * len(statuses))})")
        args += statuses
    return where, args
