"""Dask back end of the batch precompute: a running scheduler or a LocalCluster, as an executor.

Optional: ``pip install 'grainflow[dask]'`` (``dask[distributed]``); nothing here imports
Dask until :func:`dask_executor` is called, and the multiprocessing path needs none of it.
Each batch of ``batch_size`` shapes is one Dask task (``cache._build._solve_chunk``); results
come back to the client, which alone writes the SQLite table.  A worker lost mid-run has its
tasks rescheduled on the others by the scheduler.  Workers of a remote cluster need grainflow
installed (same ``throats.SOLVER_VERSION``: the client stores the version it runs).
"""

from __future__ import annotations

import contextlib
import logging

__all__ = ["DaskConnectError", "dask_executor"]

logger = logging.getLogger(__name__)


class DaskConnectError(OSError):
    """The Dask scheduler could not be reached (or Dask is not installed)."""


@contextlib.contextmanager
def dask_executor(address, *, workers=1, timeout_s=5.0):
    """Yield ``(executor, slots)``: a ``concurrent.futures`` executor on a Dask cluster.

    Parameters
    ----------
    address : str
        ``'local'`` for a LocalCluster of ``workers`` single-threaded processes on this
        machine, else a scheduler address (``'tcp://host:8786'``).
    workers : int, keyword-only, default 1
        Worker processes of the local cluster (ignored for a remote scheduler).
    timeout_s : float, keyword-only, default 5
        How long to try to reach the scheduler.

    Yields
    ------
    executor : distributed.cfexecutor.ClientExecutor
    slots : int
        Worker threads of the cluster (the number of batches solved at once).

    Raises
    ------
    DaskConnectError
        Dask is not installed, or the scheduler cannot be reached within ``timeout_s``.
    """
    try:
        from distributed import Client, LocalCluster
    except ImportError as exc:
        raise DaskConnectError("--dask needs dask.distributed: pip install 'grainflow[dask]' "
                               f"(or dask[distributed]) ({exc})") from exc
    cluster = None
    try:
        if address == "local":
            cluster = LocalCluster(n_workers=int(workers), threads_per_worker=1, processes=True,
                                   dashboard_address=None, silence_logs=logging.ERROR)
            client = Client(cluster, timeout=f"{timeout_s}s")
        else:
            client = Client(address, timeout=f"{timeout_s}s")
    except (OSError, TimeoutError, ValueError) as exc:
        if cluster is not None:
            cluster.close()
        raise DaskConnectError(f"cannot reach the Dask scheduler {address!r} within "
                               f"{timeout_s:g} s: {exc}") from exc
    try:
        slots = max(sum(client.nthreads().values()), 1)
        logger.info("dask: %s, %d worker threads", client.scheduler.address, slots)
        yield client.get_executor(pure=False), slots
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
