"""The compiled exact-area loop (throats._area_kernel) against the vectorised boundary engine it
replaces for areas, and against closed forms: deep overlaps, disks covering the triangle, disks
reaching across the opposite edge, the sections of multi-sphere grains."""

import numpy as np
import pytest

from throats._area import boundary_area_perimeter, exact_area_perimeter


def _random_rows(rng, n, r_lo, r_hi):
    """n valid triangles (sides from random points, no sliver) with random radii."""
    p = rng.uniform(0, 3, (n, 3, 2))
    s = np.stack([np.linalg.norm(p[:, 0] - p[:, 1], axis=1),
                  np.linalg.norm(p[:, 0] - p[:, 2], axis=1),
                  np.linalg.norm(p[:, 1] - p[:, 2], axis=1)], axis=1)
    srt = np.sort(s, axis=1)
    keep = srt[:, 2] < 0.99 * (srt[:, 0] + srt[:, 1])
    r = rng.uniform(r_lo, r_hi, (n, 3))
    s, r = s[keep], r[keep]
    scale = r.mean(axis=1, keepdims=True)          # units of the mean radius, as the callers
    return r / scale, s / scale


@pytest.mark.parametrize("r_lo, r_hi", [(0.2, 3.0), (0.5, 1.5), (0.05, 0.5)])
def test_loop_equals_the_boundary_engine(r_lo, r_hi):
    rng = np.random.default_rng(int(10 * r_hi))
    r, s = _random_rows(rng, 6000, r_lo, r_hi)
    a, per = exact_area_perimeter(r, s)
    a_ref, per_ref = boundary_area_perimeter(r, s)
    np.testing.assert_allclose(a, a_ref, rtol=0, atol=1e-12)
    np.testing.assert_allclose(per, per_ref, rtol=0, atol=1e-12)
    assert np.all(a >= 0) and np.isfinite(per).all()
    if r_hi == 3.0:                                  # deep overlaps: covered and split rows too
        assert np.sum(a == 0) > 1000 and np.sum(a > 0) > 300


def test_closed_forms():
    r = np.array([[1.0, 1.0, 1.0],      # touching: the cusped region sqrt(3) - pi/2, arcs pi
                  [0.5, 0.5, 0.5],      # 3-4-5 triangle, three r = 0.5 sectors: half a disk
                  [2.0, 0.5, 0.5],      # disk 1 covers the equilateral triangle of side 2
                  [1.0, 1.0, 1.0]])     # side 4: no overlap, A = 4 sqrt(3) - pi/2, P = pi
    s = np.array([[2.0, 2.0, 2.0], [3.0, 4.0, 5.0], [2.0, 2.0, 2.0], [4.0, 4.0, 4.0]])
    a, per = exact_area_perimeter(r, s)
    np.testing.assert_allclose(a, [np.sqrt(3) - np.pi / 2, 6 - np.pi / 8, 0.0,
                                   4 * np.sqrt(3) - np.pi / 2], rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(per, [np.pi, np.pi / 2, 0.0, np.pi], rtol=1e-12, atol=1e-15)


def test_lens_of_two_overlapping_disks():
    """Two unit disks 1 apart at the ends of a long thin isoceles triangle's base, the third
    vertex far away with a tiny disk: the open area is the triangle minus the two 60/90-degree
    sectors plus the lens part inside the triangle, checked against the engine and by area
    bookkeeping: A(overlap) - A(apart) = lens area inside the triangle."""
    r = np.array([[1.0, 1.0, 1e-3]])
    s = np.array([[1.0, 10.0, 10.0]])
    a, _ = exact_area_perimeter(r, s)
    a_ref, _ = boundary_area_perimeter(r, s)
    np.testing.assert_allclose(a, a_ref, atol=1e-13)
    theta = np.arccos(0.5 / 10.0)                      # base angles
    tri = 0.5 * 1.0 * 10.0 * np.sin(theta)
    apex = np.pi - 2 * theta
    # the two disks' union inside the triangle: both sectors (angle theta) minus their overlap
    # inside the triangle, which is the whole lens of two unit disks 1 apart cut to the upper
    # half (the lens is symmetric about the base): half the lens area
    lens = 2 * np.arccos(0.5) - 0.5 * np.sqrt(3)
    union = 2 * 0.5 * theta - 0.5 * lens
    np.testing.assert_allclose(a[0], tri - union - 0.5 * apex * 1e-6, rtol=1e-12)


@pytest.mark.slow
def test_first_calls_from_several_threads_at_once():
    """A fresh process whose first exact-area calls come from four threads at once (the
    network's conductance blocks): the kernel is compiled once, every thread gets the serial
    answer (before the lock, a second thread re-jitted the jitted helper: TypeError)."""
    import subprocess
    import sys
    code = """
import threading, numpy as np
from throats._area import exact_area_perimeter
rng = np.random.default_rng(0)
r = rng.uniform(0.5, 1.5, (500, 3)); s = np.tile([2.0, 2.2, 2.4], (500, 1))
gate, out, err = threading.Barrier(4), [None] * 4, []
def work(i):
    gate.wait()
    try:
        out[i] = exact_area_perimeter(r, s)
    except Exception as exc:
        err.append(repr(exc))
ts = [threading.Thread(target=work, args=(i,)) for i in range(4)]
[t.start() for t in ts]; [t.join() for t in ts]
assert not err, err
ref = exact_area_perimeter(r, s)
assert all(np.array_equal(o[0], ref[0]) and np.array_equal(o[1], ref[1]) for o in out)
print("ok")
"""
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=300)
    assert res.returncode == 0 and res.stdout.strip() == "ok", res.stderr[-2000:]
