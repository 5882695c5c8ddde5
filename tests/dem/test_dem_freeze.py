"""Stepping the active part of a grain bed (dem._freeze): frozen grains stay put, the per-sphere
neighbour rows hold exactly the pairs a full rebuild lists, the contact springs survive
freezing and release, the step equals the whole-bed step, and a pour with freezing gives the
porosity of one without."""

import json
from dataclasses import replace

import numpy as np
import pytest

from dem import Container, FillOptions, Material, pour_grains
from dem._clump_pack import union_porosity_in_box
from dem._neighbors import build_pairs
from dem.clumps import ClumpSimulation
from dem.pack import main
from dem.templates import library_template


def _bed(seed=0, jitter=0.0, settle=300, kind="box", shrink=0.0):
    """36 soybean grains stacked on a lattice in a box their size (or the cylinder around that
    box), scaled by 1 - ``shrink`` U(0, 1) each (seed 99), settled ``settle`` steps into
    contact, then given random velocities (normal, ``jitter`` m/s)."""
    t = library_template("soybean")
    ex = t.extent_m
    nx, ny, layers = 3, 4, 3
    g = np.stack(np.meshgrid(np.arange(nx), np.arange(ny), np.arange(layers), indexing="ij"), -1).reshape(-1, 3)
    x = (g + 0.5) * ex - np.array([nx * ex[0] / 2, ny * ex[1] / 2, 0.0])
    q = np.tile([1.0, 0, 0, 0], (len(x), 1))
    side = (nx * ex[0] + 1e-4, ny * ex[1] + 1e-4)
    box = Container("box", side, 0.03) if kind == "box" else Container("cylinder", (float(np.hypot(*side)),), 0.03)
    scales = 1.0 - shrink * np.random.default_rng(99).uniform(size=len(x))
    sim = ClumpSimulation([t], np.zeros(len(x), int), x, q, scales, box.walls(lid=False), Material(),
                          mass_scale=100.0, threads=1)
    for _ in range(settle):
        sim.step()
    sim.V[:] += np.random.default_rng(seed).normal(0.0, jitter, sim.V.shape)
    lo, hi = box.bounds(t.bounding_radius_m, headroom=0.0)
    return sim, box, lo, hi


def _listed(sim):
    """Pairs (i < j) of spheres of different grains whose reference positions are within
    r_i + r_j + skin: what a full rebuild at the references lists."""
    reg = sim.active
    p = build_pairs(reg.ref[:reg.n], sim.radii, reg.skin)
    return p[sim.gid[p[:, 0]] != sim.gid[p[:, 1]]]


def _skipped_slots_are_evaluated_elsewhere(reg):
    """The first ``below`` slots of each row, which the step skips, hold only active partners
    below the row's sphere (their pairs are evaluated from the partner's row); some rows skip."""
    nbr, below = reg.nbr[:reg.n], reg.below[:reg.n]
    slot = np.arange(nbr.shape[1])[None, :] < below[:, None]
    i = np.broadcast_to(np.arange(reg.n)[:, None], nbr.shape)
    return (bool(np.all(nbr[slot] < i[slot])) and not np.any(reg.frozen_s[nbr[slot]])
            and np.all(below <= reg.cnt[:reg.n]) and below.sum() > 0)


def _touching(sim):
    """Touching pairs (i < j, different grains) by brute force over all spheres."""
    x, r = sim._x, sim.radii
    d = np.linalg.norm(x[:, None] - x[None], axis=2)
    i, j = np.nonzero((d < r[:, None] + r[None]) & (sim.gid[:, None] != sim.gid[None]))
    keep = i < j
    return set(zip(i[keep].tolist(), j[keep].tolist()))


def test_rows_after_partial_relists_are_the_full_rebuild_and_its_contacts():
    sim, _, lo, hi = _bed(jitter=0.3)
    reg = sim.attach_active(lo_m=lo, hi_m=hi)
    for _ in range(600):
        sim.step()
    assert reg.relists > 1 and reg.relisted_spheres < reg.relists * sim.n   # rows searched alone
    assert np.array_equal(reg.pairs(), _listed(sim))
    # every sphere within half a skin of its reference: the rows hold every touching pair
    assert np.max(np.linalg.norm(sim._x - reg.ref[:sim.n], axis=1)) <= 0.5 * reg.skin
    listed = {tuple(p) for p in reg.pairs().tolist()}
    touching = _touching(sim)
    assert touching <= listed
    assert _skipped_slots_are_evaluated_elsewhere(reg)


def _wall_touching(sim):
    """(walls, spheres) bool: sphere centre closer to the wall (plane or cylinder) than its
    radius, by brute force."""
    d = sim._wall_offsets()[:, None] + sim._wall_normal @ sim._x.T
    cyl = sim._wall_kind == 1
    c = sim._wall_cyl[cyl]
    d[cyl] = c[:, 2:3] - np.hypot(sim._x[:, 0][None] - c[:, 0:1], sim._x[:, 1][None] - c[:, 1:2])
    return d < sim.radii[None]


@pytest.mark.parametrize("kind", ["box", "cylinder"])
def test_wall_contacts_are_evaluated_for_every_sphere_that_touches_a_wall(kind):
    """The wall flags (a wall within r + skin of the reference) miss no wall contact, skip the
    spheres far from every wall, and follow the walls when the container moves."""
    sim, _, lo, hi = _bed(jitter=0.3, kind=kind)
    reg = sim.attach_active(lo_m=lo, hi_m=hi)
    for _ in range(300):
        sim.step()
    truth = _wall_touching(sim)
    assert truth.any() and not reg.near[:sim.n].all()
    assert np.array_equal(sim._wall_touch.view(bool), truth)
    assert not np.any(sim.wall_shear[:, ~reg.near[:sim.n]])
    near = reg.near[:sim.n].copy()
    sim.z_offset_m = 8e-3                       # the floor rises through the bottom layer
    sim.step()
    truth = _wall_touching(sim)
    floor = sim._wall_normal[:, 2] == 1.0
    assert np.any(truth[floor] & ~near)         # spheres far from every wall before now touch the floor
    assert np.array_equal(sim._wall_touch.view(bool), truth)


@pytest.mark.parametrize("shrink", [0.0, 0.01])
def test_active_step_without_frozen_grains_is_the_whole_bed_step(shrink):
    """Only the order of each sphere's force sum differs: the same trajectories to round-off,
    with one mass for every grain (one pair of dashpots) and with grains of different masses."""
    a, _, lo, hi = _bed(seed=1, jitter=0.005, shrink=shrink)
    b, _, _, _ = _bed(seed=1, jitter=0.005, shrink=shrink)
    reg = b.attach_active(lo_m=lo, hi_m=hi)
    for _ in range(400):
        a.step()
        b.step()
    assert (reg._dash[0] > 0) == (shrink == 0)
    assert len(a.touching_pairs) > 10
    assert np.max(np.abs(a.X - b.X)) < 1e-12
    assert np.max(np.abs(a.V - b.V)) < 1e-9
    assert a.unbalanced_force_ratio(a._force_g) == pytest.approx(b.unbalanced_force_ratio(b._force_g), rel=1e-6)


def test_frozen_grains_do_not_move_and_active_ones_feel_them_as_walls():
    sim, _, lo, hi = _bed()
    reg = sim.attach_active(lo_m=lo, hi_m=hi)
    frozen = sim.X[:, 2] < np.sort(sim.X[:, 2])[-12]      # all but the top layer
    reg.set_frozen(frozen)
    X0, q0, x0 = sim.X.copy(), sim.q.copy(), sim._x.copy()
    sim.V[~frozen, 2] = -0.2                   # the top layer thrown onto the frozen ones
    for _ in range(800):
        sim.step()
    fs = frozen[sim.gid]
    assert np.array_equal(sim.X[frozen], X0[frozen]) and np.array_equal(sim.q[frozen], q0[frozen])
    assert np.array_equal(sim._x[fs], x0[fs])
    assert not np.any(sim.V[frozen]) and not np.any(sim.L[frozen])
    top = ~frozen
    assert np.all(sim.X[top, 2] > X0[top, 2] - 0.5e-3)   # held up by the frozen layers, not through them
    assert np.max(reg.push_n[frozen]) > 0      # and the frozen grains saw the push
    assert _skipped_slots_are_evaluated_elsewhere(reg)


def test_springs_survive_freezing_release_and_detaching():
    sim, _, lo, hi = _bed()
    sim.forces()
    before = dict(zip(sim.verlet.keys[sim._touch.view(bool)].tolist(), sim.shear[sim._touch.view(bool)].tolist()))
    assert len(before) > 10
    reg = sim.attach_active(lo_m=lo, hi_m=hi)
    reg.set_frozen(np.arange(sim.n_grains) % 2 == 0)
    reg.set_frozen(np.arange(sim.n_grains) % 3 == 0)
    reg.set_frozen(np.ones(sim.n_grains, bool))
    sim.detach_active()
    keys, hist = reg.pair_history()
    after = {int(k): h[:3].tolist() for k, h in zip(keys, hist) if h[3]}
    assert after.keys() == before.keys()
    assert all(np.array_equal(after[k], before[k]) for k in before)


def test_release_by_a_hard_push():
    """A frozen grain pushed by an active neighbour harder than the policy's weights is released."""
    from dem._freeze import FreezePolicy
    sim, _, lo, hi = _bed()
    pol = FreezePolicy(depth_m=1.0, drift_m=1e-5, window_s=1.0, speed_m_s=1e-3, push_weights=5.0, cell_m=0.008,
                       length_m=0.008, falling_m_s=1.0)
    reg = sim.attach_active(lo_m=lo, hi_m=hi, policy=pol)
    frozen = sim.X[:, 2] < np.sort(sim.X[:, 2])[-12]
    reg.set_frozen(frozen)
    sim.V[~frozen, 2] = -0.5
    sim.run(max_steps=400, check_every=200)
    assert reg.released_events > 0
    assert reg.n_frozen < frozen.sum()


def _pour_porosity(freeze, seed):
    """A 0.02 m box of 60 soybeans (about five kernel lengths deep), frozen from 1.5 kernel lengths
    below the surface (half the pour's depth: a harder test than the default): interior porosity."""
    from dem._pour import freeze_policy
    t = library_template("soybean")
    box = Container("box", (0.02, 0.02), 0.04)
    pol = replace(freeze_policy(t, 2.43), depth_m=1.5 * float(t.extent_m[0]))
    sim, rec = pour_grains(box, t, material=Material(), fill=FillOptions(mass_scale=100.0, freeze=freeze),
                           n_grains=60, rng=seed, policy=pol)
    xs = sim.sphere_centers()
    top = float(np.max(xs[:, 2] + sim.radii))
    m = 0.003
    phi, _ = union_porosity_in_box(xs, sim.radii, np.array([-0.01 + m, -0.01 + m, m]),
                                   np.array([0.01 - m, 0.01 - m, top - 2 * m]))
    return phi, rec


@pytest.mark.slow
def test_a_pour_with_freezing_has_the_porosity_of_one_without():
    """Three seeds each way: the mean porosities agree within 0.03, about twice the standard error
    of the difference of two 3-seed means (seed-to-seed standard deviation of these tiny beds
    about 0.02), and the frozen pours froze grains."""
    on = [_pour_porosity(True, s) for s in (1, 2, 3)]
    off = [_pour_porosity(False, s) for s in (1, 2, 3)]
    assert all(r["converged"] for _, r in on + off)
    assert all(r["freeze"]["frozen_at_fill_end"] > 0 for _, r in on)
    assert abs(np.mean([p for p, _ in on]) - np.mean([p for p, _ in off])) < 0.03


def test_no_freeze_needs_a_poured_fill(tmp_path, capsys):
    out = tmp_path / "bed.csv"
    rc = main(["--scene", "box", "--grain", "wheat", "--fill", "grow", "--no-freeze", "--out", str(out), "--quiet"])
    assert rc == 2 and list(tmp_path.iterdir()) == []
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error: --no-freeze needs a poured fill")


def test_pour_records_its_freezing(tmp_path):
    out = tmp_path / "bed.csv"
    rc = main(["--scene", "box", "--size", "0.02", "0.02", "--height", "0.02", "--grain", "soybean",
               "--n-grains", "4", "--mass-scale", "100", "--max-steps", "400", "--quiet", "--no-freeze",
               "--out", str(out)])
    s = json.loads(out.with_suffix(".json").read_text())
    assert rc in (0, 1)
    f = s["fill"]["freeze"]
    assert f["enabled"] is False and f["freeze_events"] == 0 and f["relists"] > 0


def test_the_lid_loads_a_bed_with_no_grain_frozen():
    from dem import load_bed
    sim, box, lo, hi = _bed()
    reg = sim.attach_active(lo_m=lo, hi_m=hi)
    reg.set_frozen(sim.X[:, 2] < np.median(sim.X[:, 2]))
    X0 = sim.X.copy()
    load_bed(sim, box, 2000.0, max_steps=400)
    assert sim.active is None
    low = X0[:, 2] < np.median(X0[:, 2])
    assert np.all(np.any(sim.X[low] != X0[low], axis=1))     # the lower half moves under the lid too
