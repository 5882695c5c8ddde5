"""Rigid multi-sphere grains (dem.clumps): free rotation, an analytic
clump-clump contact, and one-sphere templates against the sphere engine."""

import numpy as np
import pytest

from dem import Container, Material, Simulation, generate_spheres
from dem.clumps import ClumpSimulation
from dem.templates import Template, read_template, sphere_template


@pytest.fixture(scope="module")
def top(tmp_path_factory):
    f = tmp_path_factory.mktemp("t") / "top.csv"  # an L of three spheres: three different moments
    f.write_text("x,y,z,r\n0,0,0,1\n1.5,0,0,1\n0,0.8,0,0.9\n")
    return read_template(f, units="mm")


@pytest.mark.slow
def test_free_asymmetric_top_conserves_energy_and_angular_momentum(top):
    assert np.all(np.diff(top.inertia_unit) > 0.05 * top.inertia_unit[0])  # asymmetric
    sim = ClumpSimulation([top], [0], [[0, 0, 0]], [[1, 0, 0, 0]], [1.0], [], gravity_m_s2=0.0)
    rot = np.eye(3)
    # spin mostly about the intermediate axis plus a little about the others: tumbling motion
    steps = 20000
    spin = 2 * np.pi * 20 / (sim.dt * steps)  # 20 turns over the run, 0.006 rad a step
    sim.L[0] = sim.inertia[0] * np.array([0.006, 1.0, 0.004]) * spin
    l0, e0 = sim.L.copy(), sim.kinetic_energy()
    turns = spin * sim.dt * steps / (2 * np.pi)
    energy = []
    for _ in range(steps):
        sim.step()
        energy.append(sim.kinetic_energy())
    assert turns > 10
    np.testing.assert_array_equal(sim.L, l0)  # no torque: L exactly constant
    assert np.max(np.abs(np.array(energy) / e0 - 1)) < 1e-5
    assert abs(np.linalg.norm(sim.q[0]) - 1) < 1e-12
    w_body = rot @ sim.omega()[0]
    assert np.isfinite(w_body).all()


def test_clump_clump_contact_force_and_torque_are_analytic():
    # dumbbells of two 1 mm spheres 1.6 mm apart along y; B's lower sphere overlaps A's upper one by
    # delta along x: F = kn_pp delta on the line of centres, torque about A's centroid = arm x F
    t = sphere_template(1e-3)
    body = np.array([[0, -0.8e-3, 0], [0, 0.8e-3, 0]])
    bell = Template("bell", body, np.array([1e-3, 1e-3]), 1.0e-9, 0.0, np.array([1e-16, 2e-16, 2e-16]))
    delta = 1e-5
    xa, xb = np.zeros(3), np.array([2e-3 - delta, 1.6e-3, 0])
    mat = Material(friction=0.0)
    sim = ClumpSimulation([bell, t], [0, 0], [xa, xb], [[1, 0, 0, 0]] * 2, [1.0, 1.0], [], mat, gravity_m_s2=0.0)
    f, tq = sim.forces()
    fn = mat.kn_pp * delta
    np.testing.assert_allclose(f[0], [-fn, 0, 0], rtol=1e-12, atol=1e-12 * fn)
    np.testing.assert_allclose(f[1], [fn, 0, 0], rtol=1e-12, atol=1e-12 * fn)
    # contact point on A: its upper sphere (0, 0.8 mm) + r n = (1 mm, 0.8 mm); arm x F = (0, 0, 0.8e-3 fn)
    np.testing.assert_allclose(tq[0], [0, 0, 0.8e-3 * fn], rtol=1e-9, atol=1e-15)
    # on B: contact point (1 - delta mm, 0.8 mm) relative to B's centre (2 - delta, 1.6): (-1, -0.8) mm x (+fn x)
    np.testing.assert_allclose(tq[1], [0, 0, 0.8e-3 * fn], rtol=1e-9, atol=1e-15)
    assert len(sim.contact_fn) == 1  # the spheres inside one grain are not contacts


def test_one_sphere_templates_reproduce_the_sphere_engine():
    # 20 spheres dropped with spin into a 20 x 20 x 30 mm box with a lid: 3000 steps, pair and wall
    # contacts on the way; the two engines agree to round-off (the sums run in another order)
    c = Container("box", (0.02, 0.02), 0.03)
    rng = np.random.default_rng(5)
    x, r = generate_spheres(c, 20, 0.0027, 0.0037, rng)
    walls = c.walls(lid=True)
    ref = Simulation(x, r, walls, mass_scale=100.0, threads=1)
    ref.spins[:] = rng.normal(0, 20.0, (20, 3))
    cl = ClumpSimulation([sphere_template(1.0)], np.zeros(20, int), x, np.tile([1.0, 0, 0, 0], (20, 1)), r, walls,
                         mass_scale=100.0)
    cl.L[:] = ref.spins * (ref.inertia * 100.0)[:, None]
    assert cl.dt == ref.dt
    contacts = 0
    for _ in range(3000):
        ref.step()
        cl.step()
        assert len(cl.contact_fn) == len(ref.contact_fn)
        contacts += len(ref.contact_fn)
    assert contacts > 500 and len(ref.last_wall_fn) > 0
    np.testing.assert_allclose(cl.X, ref.centers, rtol=0, atol=1e-11)
    np.testing.assert_allclose(cl.V, ref.velocities, rtol=0, atol=1e-8)
    np.testing.assert_allclose(cl.omega(), ref.spins, rtol=0, atol=1e-5)


def _soybean_drop(n=12, seed=3):
    """n soybean grains at random orientations thrown (0.5 m/s, spinning) into a 20 x 20 x 30 mm box."""
    from dem import library_template
    from dem._rigid import random_quaternions
    t = library_template("soybean")
    c = Container("box", (0.02, 0.02), 0.03)
    rng = np.random.default_rng(seed)
    x, _ = generate_spheres(c, n, t.bounding_radius_m, t.bounding_radius_m, rng)
    sim = ClumpSimulation([t], np.zeros(n, int), x, random_quaternions(n, rng), np.ones(n), c.walls(lid=True),
                          Material(friction=0.47), mass_scale=100.0)
    sim.V[:] = rng.normal(0, 0.5, (n, 3))
    sim.L[:] = sim.inertia * 100.0 * rng.normal(0, 50.0, (n, 3))
    return sim


@pytest.mark.slow
def test_grain_step_continues_bit_for_bit_from_a_saved_state():
    # 12 soybeans falling and colliding: 600 steps in one go, or 300, get_state, a new simulation, 300
    a, b = _soybean_drop(), _soybean_drop()
    touching = walls = 0
    for k in range(600):
        a.step()
        touching += (k >= 300) * len(a.contact_fn)
        walls += (k >= 300) * len(a.last_wall_fn)
    for _ in range(300):
        b.step()
    c = _soybean_drop()
    c.set_state(b.get_state())
    for _ in range(300):
        c.step()
    assert touching > 50 and walls > 50  # grain-grain and wall contacts after the restart (springs carried)
    np.testing.assert_array_equal(c.X, a.X)
    np.testing.assert_array_equal(c.q, a.q)
    np.testing.assert_array_equal(c.L, a.L)


def test_no_sphere_pair_of_one_grain_is_in_the_neighbour_list():
    sim = _soybean_drop()
    sim.step()
    p = sim.verlet.pairs
    assert len(p) > 0 and np.all(sim.gid[p[:, 0]] != sim.gid[p[:, 1]])
    # the spheres of a soybean overlap heavily (centres 0.5-0.8 mm apart, radii 2.8-2.9 mm): every one
    # of the 15 pairs inside each of the 12 grains would be a candidate without the filter
    from dem._neighbors import build_pairs
    allp = build_pairs(sim.centers, sim.radii, sim.verlet.skin)
    assert np.sum(sim.gid[allp[:, 0]] == sim.gid[allp[:, 1]]) == 12 * 15


def test_grain_forces_equal_a_brute_force_sum_over_sphere_pairs_and_walls():
    # 10 soybeans dropped anywhere in a 16 mm box (deep overlaps with each other and the walls), moving
    # and spinning: the grain kernels' forces and torques against the issue's definition summed here
    # pair by pair: every pair of spheres of different grains, every sphere against every wall, the
    # contact law (linear_contact_forces, zero spring history) at the contact point x_s + r_s n, its
    # velocity V + w x (x_s + r_s n - X), torque (x_s + r_s n - X) x F, weight S m g
    from dem import library_template, linear_contact_forces
    from dem._rigid import quat_to_matrix, random_quaternions
    t = library_template("soybean")
    c = Container("box", (0.016, 0.016), 0.016)
    rng = np.random.default_rng(11)
    g = 10
    x0 = rng.uniform([-0.006, -0.006, 0.002], [0.006, 0.006, 0.014], (g, 3))
    mat = Material(friction=0.47)
    sim = ClumpSimulation([t], np.zeros(g, int), x0, random_quaternions(g, rng), np.ones(g), c.walls(lid=True), mat,
                          mass_scale=100.0)
    sim.V[:] = rng.normal(0, 0.3, (g, 3))
    sim.L[:] = sim.inertia * 100.0 * rng.normal(0, 30.0, (g, 3))
    f_grain, t_grain = sim.forces()
    rot = quat_to_matrix(sim.q)
    w = np.einsum("gij,gj->gi", rot, np.einsum("gji,gj->gi", rot, sim.L) / (sim.inertia * 100.0))
    xs = sim.X[sim.gid] + np.einsum("nij,nj->ni", rot[sim.gid], sim.body)
    ms = sim.mass * 100.0
    force, torque = np.zeros((g, 3)), np.zeros((g, 3))
    force[:, 2] -= ms * 9.81

    def add(gi, arm, f):
        force[gi] += f
        torque[gi] += np.cross(arm, f)

    pairs = 0
    for a in range(len(xs)):
        for b in range(a + 1, len(xs)):
            ga, gb = sim.gid[a], sim.gid[b]
            d = xs[b] - xs[a]
            dist = np.linalg.norm(d)
            if ga == gb or dist >= sim.radii[a] + sim.radii[b]:
                continue
            pairs += 1
            n = d / dist
            arm_a, arm_b = xs[a] + sim.radii[a] * n - sim.X[ga], xs[b] - sim.radii[b] * n - sim.X[gb]
            v = sim.V[ga] + np.cross(w[ga], arm_a) - sim.V[gb] - np.cross(w[gb], arm_b)
            meff = ms[ga] * ms[gb] / (ms[ga] + ms[gb])
            f = linear_contact_forces([sim.radii[a] + sim.radii[b] - dist], n[:, None], v[:, None], np.zeros((3, 1)),
                                      kn=mat.kn_pp, ks=mat.ks_pp, cn=0.2 * np.sqrt(meff * mat.kn_pp),
                                      ct=0.2 * np.sqrt(meff * mat.ks_pp), mu=mat.friction, dt=sim.dt)[0][:, 0]
            add(ga, arm_a, f)
            add(gb, arm_b, -f)
    walls = 0
    for wall in sim.walls:
        nw = np.asarray(wall.normal, float)
        for s in range(len(xs)):
            ov = sim.radii[s] - (xs[s] - np.asarray(wall.point_m, float)) @ nw
            if ov <= 0:
                continue
            walls += 1
            gs = sim.gid[s]
            arm = xs[s] - sim.radii[s] * nw - sim.X[gs]
            v = sim.V[gs] + np.cross(w[gs], arm)
            f = linear_contact_forces([ov], -nw[:, None], v[:, None], np.zeros((3, 1)), kn=mat.kn_pw, ks=mat.ks_pw,
                                      cn=0.2 * np.sqrt(ms[gs] * mat.kn_pw), ct=0.2 * np.sqrt(ms[gs] * mat.ks_pw),
                                      mu=mat.wall_friction, dt=sim.dt)[0][:, 0]
            add(gs, arm, f)
    # seed 11: 367 sphere contacts, 22 wall contacts; agreement measured 5e-16 (forces), 1.3e-15 (torques)
    assert pairs == len(sim.contact_fn) == 367 and walls == len(sim.last_wall_fn) == 22
    scale_f, scale_t = np.abs(force).max(), np.abs(torque).max()
    np.testing.assert_allclose(f_grain, force, rtol=0, atol=1e-12 * scale_f)
    np.testing.assert_allclose(t_grain, torque, rtol=0, atol=1e-12 * scale_t)
