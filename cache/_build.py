r"""Batch precomputation: solve the throat shapes a table lacks and store them, batch by batch.

The solver is any callable with the signature of ``throats.solve_fem``::

    solver(radii, sides, *, rtol, workers=1, progress=False) -> ThroatSolution-like

returning (N,) arrays ``qstar, open_area, contact_type, error_estimate, n_elements, seconds,
status, message``.  Production code uses ``throats.solve_fem`` (the default); tests inject
cheap analytic stand-ins.  Shapes are deduplicated by signature key before solving, shapes
already stored for the same ``(solver_version, rtol)`` are reused, and every batch of
``batch_size`` solves is written in one transaction as soon as it is done: a run killed at
any moment loses at most the batches in flight, and a rerun solves only what is missing.
Rows the solver could not solve are stored with status ``'failed'``/``'invalid'`` and their
reason; a rerun skips them unless ``retry_failed=True``.
"""

from __future__ import annotations

import concurrent.futures as cf
import contextlib
import logging
import os
import signal
import threading
import time
from dataclasses import dataclass, field

import numpy as np

import throats

from ._claims import claim, new_owner, release
from ._signature import as_throats, shape_keys, signature

logger = logging.getLogger(__name__)

__all__ = ["precompute_throats", "precompute_grid", "PrecomputeSummary", "default_solver",
           "resolve_solver"]


@dataclass
class PrecomputeSummary:
    """Counts of one precompute run (unique shapes)."""

    n_input: int = 0
    n_unique: int = 0
    solved: int = 0          #: new rows with status ok or closed
    failed: int = 0          #: new rows with status failed or invalid (recorded)
    reused: int = 0          #: shapes already in the table (ok/closed)
    reused_failed: int = 0   #: shapes recorded as failed earlier and not retried
    seconds: float = 0.0
    solve_seconds: float = 0.0  #: sum of the per-throat solver wall times
    extra: dict = field(default_factory=dict)

    def as_dict(self):
        d = {k: getattr(self, k) for k in ("n_input", "n_unique", "solved", "failed", "reused",
                                            "reused_failed", "seconds", "solve_seconds")}
        d.update(self.extra)
        return d


def default_solver():
    """``(throats.solve_fem, throats.SOLVER_VERSION)``."""
    return throats.solve_fem, throats.SOLVER_VERSION


def resolve_solver(solver, solver_version):
    """``(solver, solver_version)``: the injected pair, or :func:`default_solver`'s.

    ``default_solver`` is looked up at call time (a module global), so tests may patch it.
    """
    if solver is None:
        solver, version = default_solver()
        return solver, (version if solver_version is None else solver_version)
    if solver_version is None:
        solver_version = getattr(solver, "SOLVER_VERSION", None)
    if solver_version is None:
        raise ValueError("an injected solver needs a solver_version (or a SOLVER_VERSION attribute)")
    return solver, str(solver_version)


def _solve_chunk(solver, radii, sides, rtol):
    """Run the solver on one chunk; a raising solver marks the whole chunk failed."""
    t0 = time.perf_counter()
    n = len(radii)
    try:
        sol = solver(radii, sides, rtol=rtol, workers=1, progress=False)
        out = {k: np.asarray(getattr(sol, k)) for k in
               ("qstar", "open_area", "contact_type", "error_estimate", "n_elements",
                "seconds", "status", "message")}
        for k, v in out.items():
            if v.shape != (n,):
                raise ValueError(f"solver returned {k} of shape {v.shape}, expected ({n},)")
    except Exception as e:  # noqa: BLE001 - recorded per row, never dropped
        if n > 1:  # isolate the row(s) that make the solver raise: solve one by one
            logger.warning("solver raised on a chunk of %d throats (%s: %s); retrying row by row",
                           n, type(e).__name__, e)
            parts = [_solve_chunk(solver, radii[i:i + 1], sides[i:i + 1], rtol) for i in range(n)]
            return {k: np.concatenate([p[k] for p in parts]) for k in parts[0]}
        logger.warning("solver raised on a throat: %s: %s", type(e).__name__, e)
        dt = (time.perf_counter() - t0) / max(n, 1)
        out = {"qstar": np.full(n, np.nan), "open_area": np.full(n, np.nan),
               "contact_type": np.full(n, "", dtype=object),
               "error_estimate": np.full(n, np.nan), "n_elements": np.full(n, -1),
               "seconds": np.full(n, dt), "status": np.full(n, "failed", dtype=object),
               "message": np.full(n, f"solver raised {type(e).__name__}: {e}", dtype=object)}
    return out


def _worker_init(parent_pid):
    """Pool worker: Ctrl-C is the parent's to handle, and the worker exits within 0.5 s of
    its parent's death (``kill -9``), instead of waiting for work forever."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)

    def watch():
        while os.getppid() == parent_pid:
            time.sleep(0.5)
        os._exit(1)

    threading.Thread(target=watch, daemon=True).start()


def _drain(pool, chunks, window, solve_args, write, stop):
    """Solve ``chunks`` on ``pool`` (any ``concurrent.futures.Executor``: a process pool or a
    Dask client's executor) with at most ``window`` batches in flight; ``write(chunk, result)``
    runs here, in the one writing process, as each batch finishes; after ``stop()`` is true no
    batch is submitted.  On Ctrl-C the batches already finished are written, the others
    cancelled, and KeyboardInterrupt goes on up."""
    pending = {}
    it = iter(chunks)

    def submit_next():
        nxt = next(it, None)
        if nxt is not None:
            pending[pool.submit(_solve_chunk, *solve_args(nxt))] = nxt

    try:
        for _ in range(window):
            submit_next()
        while pending:
            done, _ = cf.wait(pending, return_when=cf.FIRST_COMPLETED)
            for fut in done:
                write(pending.pop(fut), fut.result())
                if not stop():
                    submit_next()
    except KeyboardInterrupt:
        for fut in pending:
            fut.cancel()           # not started: dropped; running: finished and written
        running = [f for f in pending if not f.cancelled()]
        cf.wait(running, timeout=60)
        for fut, chunk in list(pending.items()):
            if fut.done() and not fut.cancelled() and fut.exception() is None:
                write(pending.pop(fut), fut.result())
        raise
    finally:
        for fut in pending:
            fut.cancel()


def precompute_throats(store, radii, sides, *, rtol=1e-3, solver=None, solver_version=None,
                       workers=1, batch_size=16, retry_failed=False, progress=False,
                       max_seconds=None, executor=None):
    """Solve every shape of ``(radii, sides)`` that ``store`` lacks and store the results.

    Parameters
    ----------
    store : ThroatStore
        Open table (:func:`cache.open_store`).
    radii, sides : (N, 3) array_like, any consistent length unit
        Throat shapes; rows that ``throats.validate_throats`` rejects are recorded as
        ``'invalid'`` with its message (never dropped).
    rtol : float, keyword-only, default 1e-3
        Tolerance passed to the solver and stored with each row.
    solver : callable, optional
        Defaults to ``throats.solve_fem``; see the module notes for the protocol.
    solver_version : str, optional
        Defaults to ``throats.SOLVER_VERSION`` (or the injected solver's ``SOLVER_VERSION``).
    workers : int, keyword-only, default 1
        Local processes (1: this process); with ``executor``, its number of parallel slots
        (``2 * workers`` batches are kept in flight).
    batch_size : int, keyword-only, default 16
        Solves per task and per transaction.
    retry_failed : bool, keyword-only, default False
        Solve again the shapes recorded as failed/invalid.
    progress : bool, keyword-only, default False
        tqdm progress bar with rate and ETA on stderr.
    max_seconds : float, optional
        Stop submitting new batches after this many seconds (what is done is stored).
    executor : concurrent.futures.Executor, optional
        Where the batches run instead of a local process pool, e.g. a Dask client's
        ``get_executor()`` (:func:`cache.dask_executor`); results come back here and only this
        process writes the table.

    Returns
    -------
    PrecomputeSummary

    Notes
    -----
    Each finished batch is stored at once in one transaction, so an interruption loses only
    the batches still being solved (and at most the one being written, never part of it);
    a rerun solves only the shapes not stored.  Ctrl-C stores the batches already finished
    and returns the summary with ``extra['interrupted'] = True``.
    """
    t0 = time.perf_counter()
    r, s = as_throats(radii, sides)
    if workers < 1 or batch_size < 1:
        raise ValueError(f"workers and batch_size must be >= 1, got {workers}, {batch_size}")
    if not rtol > 0:
        raise ValueError(f"rtol must be > 0, got {rtol}")
    solver, solver_version = resolve_solver(solver, solver_version)
    summary = PrecomputeSummary(n_input=len(r))

    validate = throats.validate_throats
    ok_rows, messages = validate(r, s)
    sig = np.full((len(r), 5), np.nan)
    if ok_rows.any():
        sig[ok_rows] = signature(r[ok_rows], s[ok_rows])
    keys = shape_keys(sig)

    # invalid input rows: record them under a key of their raw numbers (never dropped)
    bad = np.flatnonzero(~ok_rows)
    if len(bad):
        with np.errstate(invalid="ignore", divide="ignore"):
            raw = np.concatenate([r[bad, :2], s[bad]], axis=1)
        bad_keys = shape_keys(np.where(np.isfinite(raw), raw, -1.0)) ^ np.int64(1 << 61)
        nb = len(bad)
        store.put(bad_keys, r[bad], s[bad], solver_version=solver_version, rtol=rtol,
                  qstar=np.full(nb, np.nan), open_area=np.full(nb, np.nan),
                  contact_type=np.full(nb, "", dtype=object), error_estimate=np.full(nb, np.nan),
                  n_elements=np.full(nb, -1), seconds=np.zeros(nb),
                  status=np.full(nb, "invalid", dtype=object), message=messages[bad])
        summary.failed += nb
        logger.warning("%d invalid throat rows recorded (first: %s)", nb, messages[bad[0]])

    good = np.flatnonzero(ok_rows)
    _, first = np.unique(keys[good], axis=0, return_index=True)
    uniq = good[np.sort(first)]
    summary.n_unique = len(uniq) + len(bad)

    have = store.lookup_keys(keys[uniq], solver_version=solver_version, rtol=rtol)
    hit = have["found"]
    done_ok = hit & np.isin(have["status"], ["ok", "closed"])
    done_bad = hit & ~done_ok
    summary.reused = n_reused0 = int(done_ok.sum())
    summary.reused_failed = int(done_bad.sum()) if not retry_failed else 0
    todo = uniq[~done_ok & (retry_failed | ~done_bad)]

    canon_r = np.concatenate([sig[:, :2], 3.0 - sig[:, :1] - sig[:, 1:2]], axis=1)
    canon_s = sig[:, 2:]
    chunks = [todo[i:i + batch_size] for i in range(0, len(todo), batch_size)]
    logger.info("precompute: %d input rows, %d unique shapes, %d stored, %d to solve",
                len(r), summary.n_unique, summary.reused, len(todo))

    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=len(todo), unit="throat", smoothing=0.05, dynamic_ncols=True)

    processed = [0]

    def write(chunk, out):
        processed[0] += len(chunk)
        store.put(keys[chunk], canon_r[chunk], canon_s[chunk], solver_version=solver_version,
                  rtol=rtol, **out)
        good_out = np.isin(out["status"].astype(str), ["ok", "closed"])
        summary.solved += int(good_out.sum())
        summary.failed += int((~good_out).sum())
        summary.solve_seconds += float(np.nansum(out["seconds"].astype(float)))
        if bar is not None:
            bar.update(len(chunk))
            bar.set_postfix(failed=summary.failed, refresh=False)

    def out_of_time():
        return max_seconds is not None and time.perf_counter() - t0 > max_seconds

    def solve_args(chunk):
        return solver, canon_r[chunk], canon_s[chunk], rtol

    owner = new_owner()
    done_st = ("ok", "closed") if retry_failed else ("ok", "closed", "failed", "invalid")
    others = []                     # shapes another run claimed: checked again at the end

    def claimed(batches):
        """Each batch cut to the shapes this run claims (module _claims)."""
        for chunk in batches:
            mine, stored = claim(store, keys[chunk], solver_version=solver_version, rtol=rtol,
                                 owner=owner, done_statuses=done_st)
            summary.reused += int(stored.sum())
            others.extend(chunk[~mine & ~stored].tolist())
            processed[0] += int(stored.sum())
            if mine.any():
                yield chunk[mine]

    def run(batches, pool):
        if pool is None:
            for chunk in claimed(batches):
                if out_of_time():
                    break
                write(chunk, _solve_chunk(*solve_args(chunk)))
        else:
            _drain(pool, claimed(batches), 2 * workers, solve_args, write, out_of_time)

    try:
        with contextlib.ExitStack() as stack:
            pool = executor
            if executor is None and workers > 1:
                pool = stack.enter_context(cf.ProcessPoolExecutor(
                    max_workers=workers, initializer=_worker_init, initargs=(os.getpid(),)))
            run(chunks, pool)
            while others and not out_of_time():   # wait for the other runs' shapes
                again = np.array(others)
                others.clear()
                run([again[i:i + batch_size] for i in range(0, len(again), batch_size)], pool)
                if others:
                    time.sleep(0.5)
    except KeyboardInterrupt:
        summary.extra["interrupted"] = True
        logger.warning("interrupted: %d solved shapes stored in this run; rerun to resume",
                       summary.solved + summary.failed)
    finally:
        release(store, owner)
        if bar is not None:
            bar.close()
    summary.extra["solved_by_other_runs"] = int(summary.reused - n_reused0)
    summary.seconds = time.perf_counter() - t0
    summary.extra["remaining"] = int(len(todo) - processed[0])   # others' shapes included
    return summary


def precompute_grid(store, spec, *, rtol=1e-3, solver=None, solver_version=None, **kwargs):
    """Register grid ``spec`` (a :class:`cache.GridSpec`) in ``store`` and solve its nodes.

    Keyword arguments go to :func:`precompute_throats`; returns its summary.
    """
    solver, solver_version = resolve_solver(solver, solver_version)
    d = spec.to_dict()
    d.update(rtol=float(rtol), solver_version=str(solver_version))
    store.put_grid(spec.name, d)
    r, s = getattr(spec, "solve_shapes", spec.node_shapes)()
    return precompute_throats(store, r, s, rtol=rtol, solver=solver, solver_version=solver_version,
                              **kwargs)
