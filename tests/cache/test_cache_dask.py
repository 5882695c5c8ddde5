"""Distributed precompute on Dask: a LocalCluster of two workers fills the same
table as the serial run, bit for bit; an interrupted run resumes without solving anything twice;
a lost worker's batches are solved elsewhere; an unreachable scheduler is one line, exit 2,
nothing written.  Skipped only when dask.distributed is not installed (extra ``grainflow[dask]``)."""

import os
import signal
import time

import numpy as np
import pytest

distributed = pytest.importorskip("distributed")

import cache                                          # noqa: E402
import network                                        # noqa: E402
from cache import precompute as precompute_cli        # noqa: E402

COLUMNS = ("keys", "radii", "sides", "rtol", "qstar", "open_area", "contact_type",
           "error_estimate", "n_elements", "status")


@pytest.fixture(scope="module")
def shapes():
    """40 packing throats, the same 40 permuted and scaled, one invalid row."""
    r, s = network.sample_throats(40, rng=3)
    rp, sp = r[:, [1, 0, 2]] * 2.0, s[:, [0, 2, 1]] * 2.0   # swap vertices 1 and 2
    return np.r_[r, rp, [[1.0, 1.0, 1.0]]], np.r_[s, sp, [[1.0, 1.0, 5.0]]]


@pytest.fixture(scope="module")
def serial(shapes, tmp_path_factory):
    db = tmp_path_factory.mktemp("serial") / "s.sqlite"
    with cache.open_store(db) as st:
        summ = cache.precompute_throats(st, *shapes, batch_size=4)
        assert (summ.n_unique, summ.solved, summ.failed) == (41, 40, 1)
        return _table(st)


def _table(store):
    rows = store.load()
    order = np.lexsort(rows["keys"].T[::-1])
    out = {k: rows[k][order] for k in COLUMNS}
    out["message"] = list(rows["message"][order])
    return out


def _assert_same_table(got, want):
    for k in COLUMNS:
        np.testing.assert_array_equal(got[k], want[k], err_msg=k)   # bit for bit, NaN = NaN
    assert got["message"] == want["message"]


@pytest.mark.slow
def test_local_cluster_equals_serial_and_resumes(shapes, serial, tmp_path):
    db = tmp_path / "d.sqlite"
    with cache.dask_executor("local", workers=2) as (ex, slots), cache.open_store(db) as st:
        assert slots == 2
        # stop after the first window (2 x 2 batches of 4): an interrupted run
        first = cache.precompute_throats(st, *shapes, batch_size=4, workers=slots,
                                         executor=ex, max_seconds=0.0)
        assert first.solved == 16 and first.extra["remaining"] == 24
        stored = st.count()
        again = cache.precompute_throats(st, *shapes, batch_size=4, workers=slots, executor=ex)
        # nothing stored is solved again (the invalid row is re-recorded, never solved)
        assert (again.solved, again.reused, again.failed) == (24, 16, 1)
        assert st.count() == stored + 24
        _assert_same_table(_table(st), serial)


@pytest.mark.slow
def test_lost_worker_is_replaced_and_the_table_is_complete(shapes, serial, tmp_path):
    db = tmp_path / "k.sqlite"
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, dashboard_address=None,
                                  silence_logs=40) as cluster, \
            distributed.Client(cluster) as client, cache.open_store(db) as st:
        pids = sorted(client.run(os.getpid).values())
        put, killed = st.put, []

        def put_then_kill(*args, **kwargs):   # kill worker 0 once the first batch is stored
            n = put(*args, **kwargs)
            if not killed and n == 2:
                os.kill(pids[0], signal.SIGKILL)
                killed.append(pids[0])
            return n

        st.put = put_then_kill
        summ = cache.precompute_throats(st, *shapes, batch_size=2, workers=2,
                                        executor=client.get_executor(pure=False))
        assert killed and summ.solved == 40 and summ.extra["remaining"] == 0
        assert pids[0] not in client.run(os.getpid).values()    # the nanny started a new one
        _assert_same_table(_table(st), serial)


@pytest.mark.slow
def test_unreachable_scheduler_is_one_line_and_writes_nothing(tmp_path, capsys):
    db = tmp_path / "never.sqlite"
    t0 = time.perf_counter()
    code = precompute_cli.main(["--db", str(db), "--grid", "tiny", "--dask", "tcp://127.0.0.1:9",
                                "--quiet"])
    assert code == 2 and time.perf_counter() - t0 < 10
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "cannot reach the Dask scheduler" in err[0]
    assert not db.exists()
