"""Work claims: concurrent precompute runs on one table split the shapes instead of each
solving all of them.

Before a batch is submitted, the run claims its shapes in the table ``claims`` in one
``BEGIN IMMEDIATE`` transaction: shapes already stored or claimed by another live run are left
out, the rest are claimed for ``LEASE_S`` seconds.  A claim of a process that is gone (same
host, pid no longer running) or whose lease ran out is void, so a run killed with ``kill -9``
blocks nobody for long; a run releases its claims when it ends.  Details and measurements:
``docs/cache-precompute.md``.
"""

from __future__ import annotations

import os
import platform
import time

import numpy as np

__all__: list[str] = []

#: seconds a claim holds; batches are claimed when submitted (at most 2 x workers in flight)
LEASE_S = 300.0

_SCHEMA = ("CREATE TABLE IF NOT EXISTS claims (k1 INTEGER, k2 INTEGER, k3 INTEGER, k4 INTEGER, "
           "k5 INTEGER, solver_version TEXT, rtol REAL, owner TEXT, expires REAL, "
           "PRIMARY KEY (k1, k2, k3, k4, k5, solver_version, rtol))")


def new_owner():
    """``host:pid:random`` naming one run."""
    return f"{platform.node()}:{os.getpid()}:{os.urandom(4).hex()}"


def _alive(owner):
    host, pid, _ = (owner.split(":") + ["", "", ""])[:3]
    if host != platform.node():
        return True            # another machine: only the lease can tell
    try:
        os.kill(int(pid), 0)
    except (ValueError, ProcessLookupError):
        return False
    except PermissionError:
        return True
    return True


def claim(store, keys, *, solver_version, rtol, owner, done_statuses):
    """Claim the shapes ``keys`` (M, 5) that are neither stored nor claimed by a live run.

    Returns ``(mine, stored)``, (M,) bool: claimed now by ``owner`` / already stored with a
    status in ``done_statuses``.  Rows in neither are being solved by another run.
    """
    keys = np.asarray(keys, dtype=np.int64).reshape(-1, 5)
    m = len(keys)
    now = time.time()
    conn = store.conn
    with store.transaction():
        conn.execute(_SCHEMA)
        have = store.lookup_keys(keys, solver_version=solver_version, rtol=rtol)
        stored = have["found"] & np.isin(have["status"], list(done_statuses))
        rows = [(*map(int, k), str(solver_version), float(rtol)) for k in keys]
        where = ("k1 = ? AND k2 = ? AND k3 = ? AND k4 = ? AND k5 = ? AND solver_version = ? "
                 "AND rtol = ?")
        mine = np.zeros(m, dtype=bool)
        dead = {}
        for i in np.flatnonzero(~stored):
            got = conn.execute(f"SELECT owner, expires FROM claims WHERE {where}",
                               rows[i]).fetchone()
            if got is not None and got[0] != owner and got[1] > now:
                if got[0] not in dead:
                    dead[got[0]] = not _alive(got[0])
                if not dead[got[0]]:
                    continue
            conn.execute(f"INSERT OR REPLACE INTO claims VALUES ({', '.join('?' * 9)})",
                         rows[i] + (owner, now + LEASE_S))
            mine[i] = True
    return mine, stored


def release(store, owner):
    """Drop every claim of ``owner`` (its run ended), and the void ones of other runs (lease
    run out, or a process on this host that is gone: a run killed with ``kill -9`` left its
    claims in the table for good); never raises."""
    try:
        with store.transaction():
            store.conn.execute(_SCHEMA)
            others = [o for (o,) in store.conn.execute("SELECT DISTINCT owner FROM claims")]
            gone = [owner] + [o for o in others if o != owner and not _alive(o)]
            store.conn.executemany("DELETE FROM claims WHERE owner = ?", [(o,) for o in gone])
            store.conn.execute("DELETE FROM claims WHERE expires < ?", (time.time(),))
    except Exception:  # noqa: BLE001 - a claim left behind expires on its own
        pass
