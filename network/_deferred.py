"""SciPy submodules imported on first use, so that a command process imports them beside gmsh.

``scipy.sparse.csgraph`` (with ``scipy.sparse.linalg`` and ``scipy.linalg`` behind it) and
``scipy.spatial`` take 0.10-0.15 s to import, most of what the package's own import costs
after NumPy and ``scipy.sparse``; the pipeline first needs them after the Delaunay kernel has
run. :class:`Deferred` stands for such a module: its first attribute access imports it through
the import system (whose per-module lock makes a concurrent first use from two threads safe)
and every later one is a dictionary lookup. The gmsh Delaunay path (``network.pores``) imports
them (:func:`import_now`) on a thread of its own while gmsh, which releases the GIL, runs
(``threads`` > 1); :func:`beside` starts such a side job.
"""

from __future__ import annotations

import importlib
from concurrent.futures import Future, ThreadPoolExecutor

__all__ = ["Deferred", "beside", "csgraph", "import_now", "sparse", "sparse_linalg", "spatial"]


class Deferred:
    """Module ``name``, imported when one of its attributes is first asked for."""

    __slots__ = ("_name", "_module")

    def __init__(self, name: str):
        self._name = name
        self._module = None

    def __getattr__(self, attr: str):
        return getattr(_load(self), attr)

    def __repr__(self) -> str:
        return f"<deferred module {self._name!r}>"


def _load(deferred: Deferred):
    """The module ``deferred`` stands for, imported on the first call."""
    if deferred._module is None:
        # through the import system, never sys.modules directly: a module that another thread
        # is importing is there half-executed, and import_module waits for it
        deferred._module = importlib.import_module(deferred._name)
    return deferred._module


csgraph = Deferred("scipy.sparse.csgraph")
sparse = Deferred("scipy.sparse")
sparse_linalg = Deferred("scipy.sparse.linalg")
spatial = Deferred("scipy.spatial")


def import_now() -> None:
    """Import every deferred module now: for a thread with time to spare (beside gmsh)."""
    for deferred in (spatial, csgraph, sparse_linalg):
        _load(deferred)


def beside(fn, *args) -> Future:
    """``fn(*args)`` started on a thread of its own, which ends with it: its future. For work
    that overlaps a GIL-free stretch of the caller (gmsh, Qhull, large NumPy passes)."""
    side = ThreadPoolExecutor(1)
    job = side.submit(fn, *args)
    side.shutdown(wait=False)
    return job
