"""The compiled step (dem._kernels, dem._neighbors, dem._threads): Newton's laws on a settled
drop, the same numbers for any thread count, the contact law's closed forms."""

import numpy as np
import pytest

from dem import Container, Material, Simulation, generate_spheres, linear_contact_forces
from dem._neighbors import VerletList, build_pairs, remap_history
from dem._threads import MIN_PARALLEL_PARTICLES, ThreadChooser


def _dense_drop(threads=None):
    """60 spheres dropped into a 30 x 20 x 60 mm box with particle friction and spin: 8000
    steps (0.1 s at mass scale 100), settled on the floor. Frictionless walls: with friction
    0 the wall springs' history cannot matter, which the numpy engine lost every step."""
    c = Container("box", (0.03, 0.02), 0.06)
    rng = np.random.default_rng(11)
    x, r = generate_spheres(c, 60, 0.0027, 0.0037, rng)
    sim = Simulation(x, r, c.walls(lid=True), Material(wall_friction=0.0), mass_scale=100.0, threads=threads)
    sim.spins[:] = rng.normal(0, 20.0, (60, 3))
    for _ in range(8000):
        force = sim.step()
    return sim, force


@pytest.fixture(scope="module")
def drops():
    return _dense_drop(threads=1), _dense_drop(threads=2)


@pytest.mark.slow
def test_settled_drop_carries_its_weight():
    # The port was checked number for number against the numpy engine it replaced (commit
    # 4b675fe) on the machine of that session. Those trajectory numbers are not a test on
    # another CPU: numba compiles for the host, a last-bit difference in one step grows
    # through the 8000 steps of collisions to 10 % (seen on an AMD EPYC host). What holds on
    # any CPU is Newton's third law of the settled bed: with frictionless walls only the floor
    # carries the weight, the lid nothing, opposite side walls push alike. How long the bed
    # takes to come to rest depends on the trajectory too (unbalanced-force ratio 4.3e-3 after
    # 32 000 steps on an AVX-512 host, below 2e-3 there on others), so it steps until at rest.
    sim, _ = _dense_drop(threads=1)
    for _ in range(30):                             # up to 120 000 more steps
        for _ in range(4000):
            force = sim.step()
        if sim.unbalanced_force_ratio(force) < 2e-4:
            break
    assert sim.unbalanced_force_ratio(force) < 2e-4
    fn = sim._wall_fn * sim._wall_touch.view(bool)          # (walls, particles), N
    normals = np.array([w.normal for w in sim.walls], dtype=float)
    floor, lid = np.flatnonzero(normals[:, 2] > 0.5), np.flatnonzero(normals[:, 2] < -0.5)
    weight = sim.mass_scale * sim.mass.sum() * sim.gravity_m_s2
    assert fn[floor].sum() == pytest.approx(weight, rel=1e-3)
    assert fn[lid].sum() == 0.0
    for axis in (0, 1):
        plus, minus = (np.flatnonzero(normals[:, axis] > 0.5),
                       np.flatnonzero(normals[:, axis] < -0.5))
        assert fn[plus].sum() == pytest.approx(fn[minus].sum(), rel=2e-3)
        assert fn[plus].sum() > 0.1 * weight                  # the walls do hold the bed


@pytest.mark.slow
def test_thread_count_does_not_change_a_bit(drops):
    (a, fa), (b, fb) = drops
    assert a.threads.steps_by_threads == {1: 8000} and b.threads.steps_by_threads[2] == 8000
    for u, v in [(a.centers, b.centers), (a.velocities, b.velocities), (a.spins, b.spins), (fa, fb),
                 (a.shear, b.shear), (a.wall_shear, b.wall_shear)]:
        np.testing.assert_array_equal(u, v)


def test_contact_law_closed_forms():
    # stick: F = k_n delta n-side push and F_t = -k_s xi - c_t v_t with xi = v_t dt (fresh spring);
    # slide: |F_t| = mu F_n and the spring is reset to -(F_t + c_t v_t)/k_s
    n = np.array([[1.0, 1.0], [0.0, 0.0], [0.0, 0.0]])
    v = np.array([[0.0, 0.0], [1e-3, 1.0], [0.0, 0.0]])
    f, fn, ft, xi = linear_contact_forces([1e-6, 1e-6], n, v, np.zeros((3, 2)), kn=2e6, ks=1e6, cn=0.0, ct=0.5,
                                          mu=0.5, dt=1e-5)
    np.testing.assert_allclose(fn, [2.0, 2.0], rtol=1e-15)
    np.testing.assert_allclose(ft[1, 0], -1e6 * 1e-8 - 0.5 * 1e-3, rtol=1e-12)  # stick: -0.0105 N
    np.testing.assert_allclose(np.linalg.norm(ft[:, 1]), 0.5 * 2.0, rtol=1e-12)  # slide: mu F_n
    np.testing.assert_allclose(xi[1, 1], -(ft[1, 1] + 0.5 * 1.0) / 1e6, rtol=1e-12)
    np.testing.assert_allclose(f[0], -fn, rtol=1e-15)  # normal part pushes i away from j
    with pytest.raises(ValueError, match=r"\(3, Nc\)"):
        linear_contact_forces([1e-6], np.zeros((2, 1)), np.zeros((3, 1)), np.zeros((3, 1)), kn=1, ks=1, cn=0,
                              ct=0, mu=0, dt=1)


@pytest.mark.parametrize("far", [False, True])
def test_cell_list_finds_exactly_the_brute_force_pairs(far):
    rng = np.random.default_rng(4)
    x = rng.uniform(0, 0.05, (400, 3))
    r = rng.uniform(0.002, 0.004, 400)
    if far:  # one escaped particle 10 m away: the grid coarsens instead of growing
        x[7] = [10.0, -3.0, 2.0]
    skin = 0.0004
    d = np.linalg.norm(x[:, None] - x[None], axis=2)
    i, j = np.nonzero(np.triu(d < r[:, None] + r[None] + skin, k=1))
    np.testing.assert_array_equal(build_pairs(x, r, skin), np.column_stack([i, j]))  # sorted by i*N+j


def test_verlet_list_indexes_each_particles_pairs_in_pair_order():
    x = np.array([[0.0, 0, 0], [0.0066, 0, 0], [0, 0.0066, 0], [0.0066, 0.0066, 0]])
    vl = VerletList(skin=0.0004)
    vl.build(x, np.full(4, 0.00325))
    assert vl.pairs.tolist() == [[0, 1], [0, 2], [1, 3], [2, 3]]
    assert vl.first_start.tolist() == [0, 2, 3, 4, 4]
    assert vl.second_start.tolist() == [0, 0, 1, 2, 4]
    assert vl.by_second.tolist() == [0, 1, 2, 3]
    np.testing.assert_array_equal(remap_history(vl.keys, np.eye(4), vl.keys), np.eye(4))


def test_thread_chooser_keeps_small_runs_on_one_thread_and_times_large_ones():
    assert ThreadChooser(MIN_PARALLEL_PARTICLES - 1).candidates == [1]
    assert ThreadChooser(10, threads=1).candidates == [1]
    with pytest.raises(ValueError, match="threads"):
        ThreadChooser(10, threads=0)
    ch = ThreadChooser(MIN_PARALLEL_PARTICLES, probe_steps=2, period=5)
    top = ch.candidates[0]
    if top == 1:
        pytest.skip("numba has one thread here")
    for t in [3.0, 3.0, 1.0, 1.0]:  # probe: two steps with `top` threads (slow), two with 1 (fast)
        ch.record(t)
    assert ch.current == 1
    assert ch.steps_by_threads == {top: 2, 1: 2}
